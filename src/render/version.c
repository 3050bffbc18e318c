#include "zonetrace/render.h"
const char *zt_version(void) { return ZT_VERSION; }
