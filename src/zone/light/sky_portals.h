/* Window panes as portals for the sky's light.
 *
 * Inside a building the sky is seen only through its windows: a small
 * share of each point's hemisphere, which a gather over fixed directions
 * finds with a handful of them or none.  The count jumps as the point
 * moves (flat patches of light with steps between them) and the nodes and
 * pixels beside a window disagree.  Thin panes (materials with "thin") are
 * where that light comes in, so they are made portals: the panes of one
 * window (touching, parallel triangles; the sheets of a double glazing)
 * become one rectangle, and a point aims part of its sky directions at
 * the rectangles it faces, evenly in solid angle over each (Urena, Fajardo
 * and King 2013), in proportion to each one's solid angle and to how much
 * sky lies behind it (measured once per portal from its own surface).
 *
 * The sky is then split between the two estimates by the first pane a
 * direction crosses: a direction whose first pane belongs to a portal that
 * the point aims at, and that crosses that portal's rectangle, counts in
 * that portal's estimate only, every other direction (one that enters the
 * window's box by its side, say) in the fixed gather.  Nothing is counted twice or dropped, and
 * a portal a point does not aim at (behind it, dark behind, or too small
 * for a direction of the budget) is gathered as before. */
#ifndef ZT_ZONE_LIGHT_SKY_PORTALS_H
#define ZT_ZONE_LIGHT_SKY_PORTALS_H

#include <stdint.h>

#include "render/render_scene.h"
#include "util/vec3.h"

typedef struct sky_portal {
    vec3 corner, eu, ev;  /* the rectangle corner + s eu + t ev, s, t in [0, 1],
                             halfway across the panes' spread */
    vec3 n;               /* eu x ev, unit */
    double half;          /* half the spread across: the sheets of a glazing,
                             a pane's thickness */
    double area;
    float open[2];        /* the share of directions from the panes into the
                             half-space n points to [0] and the other [1]
                             that reach the sky */
} sky_portal;

typedef struct sky_portals {
    sky_portal *p;
    int count;
    int32_t *of_prim;     /* each primitive's portal, -1 (NULL when none) */
    int prim_count;       /* of_prim's length */
} sky_portals;

/* The most portal directions a point takes (the budget's cap), and the
 * most portals it aims at (the largest). */
#define SKY_PORTAL_BUDGET_MAX 256
#define SKY_PORTAL_PICKS_MAX 64

/* A portal as seen from a point: the frame and the spherical rectangle's
 * terms that its directions are drawn from. */
typedef struct sky_portal_view {
    vec3 ex, ey, ez;
    double x0, y0, z0, x1, y1;
    double b0, b1, g23;
    double omega;         /* the solid angle */
    double area;
    int by_area;          /* far and small: drawn evenly in area */
} sky_portal_view;

typedef struct sky_portal_pick {
    int portal;
    int count;            /* directions aimed at it */
    sky_portal_view view;
} sky_portal_pick;

/* Finds the scene's portals (none without thin panes).  0: out of memory. */
int sky_portals_build(sky_portals *sp, const rscene *rs);
void sky_portals_free(sky_portals *sp);

/* The portals that a point x of unit normal n aims at and how many of
 * `budget` (at most SKY_PORTAL_BUDGET_MAX) directions each takes: at least
 * one, in proportion to solid angle x cosine x the sky behind.  Fills
 * picks (room for SKY_PORTAL_PICKS_MAX), returns how many. */
int sky_portals_pick(const sky_portals *sp, vec3 x, vec3 n, int budget, sky_portal_pick *picks);

/* Portal p seen from x; 0 when x lies in its plane. */
int sky_portal_view_make(const sky_portal *p, vec3 x, sky_portal_view *v);

/* Direction j of `count` toward the portal of view v (a stratified set,
 * even in solid angle): the unit direction in *dir; returns the
 * direction's share of the estimate (the solid angle / count). */
double sky_portal_view_direction(const sky_portal_view *v, int j, int count, vec3 *dir);

/* Whether unit direction d (world) from the view's point crosses its
 * rectangle. */
static inline int sky_portal_view_covers(const sky_portal_view *v, vec3 d)
{
    double dz = v3_dot(d, v->ez);
    if (!(dz < 0))
        return 0;
    double t = v->z0 / dz, x = t * v3_dot(d, v->ex), y = t * v3_dot(d, v->ey);
    return x >= v->x0 && x <= v->x1 && y >= v->y0 && y <= v->y1;
}

/* Whether the portals' estimate takes direction d, whose first pane
 * belongs to portal g: g is among the picks and d crosses its rectangle
 * (what its directions are drawn over).  Every other direction is the
 * gather's. */
static inline int sky_portals_claim(const sky_portal_pick *picks, int count, int g, vec3 d)
{
    for (int i = 0; i < count; i++)
        if (picks[i].portal == g)
            return sky_portal_view_covers(&picks[i].view, d);
    return 0;
}

#endif
