/* zonetrace: the whole public API. */
#ifndef ZONETRACE_H
#define ZONETRACE_H
#include "zonetrace/error.h"
#include "zonetrace/image.h"
#include "zonetrace/scene.h"
#include "zonetrace/render.h"
#include "zonetrace/motion.h"
#endif
