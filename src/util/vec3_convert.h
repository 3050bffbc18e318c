/* Between the double-precision scene model and the single-precision hot
 * loops. */
#ifndef ZT_UTIL_VEC3_CONVERT_H
#define ZT_UTIL_VEC3_CONVERT_H

#include "util/vec3.h"
#include "util/vec3f.h"

static inline vec3f v3_to_f3(vec3 v) { return f3((float)v.x, (float)v.y, (float)v.z); }
static inline vec3 f3_to_v3(vec3f v) { return v3(v.x, v.y, v.z); }

#endif
