/* Memory: what a render will need, estimated before the work, against the
 * limit it may use, so that a render too large for the machine is refused
 * up front with the size it needs instead of dying halfway. */
#ifndef ZT_RENDER_MEMORY_H
#define ZT_RENDER_MEMORY_H

#include <stdint.h>

#include "zonetrace/render.h"
#include "scene/scene.h"

/* Bytes the zone tracer's forest takes during Phase One for that many
 * surface nodes with irradiance maps of map_levels levels: 600 a node (node
 * arrays, sender tree, node life, transfer) and 12 a node and level (the
 * maps); measured on the Cornell box at qualities 2-6 and on the engine
 * room (475-520 bytes a node). */
uint64_t memory_zone_nodes(long long nodes, int map_levels);

/* The limit: requested when not 0, else the machine's physical memory or
 * the control group's limit, whichever is lower.  *source says which
 * ("as asked", "physical memory", "the control group's limit"). */
uint64_t memory_limit(uint64_t requested, const char **source);

/* Estimate of what the renderer and zt_render's image need beyond the
 * scene already loaded: the renderer's copy of the scene, the acceleration
 * structure and the image buffers. */
uint64_t memory_estimate_render(const zt_scene *scene, const zt_render_options *o);

/* ZT_ERR_MEMORY when need passes the limit of o, with a message that starts
 * with what (e.g. "this render") and gives both sizes; else ZT_OK. */
zt_status memory_check(uint64_t need, const char *what, const zt_render_options *o,
                       zt_error *err);

/* "1.5 GiB" and the like, into buf. */
const char *memory_format(uint64_t bytes, char *buf, int size);

#endif
