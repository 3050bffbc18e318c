/* Convex polygons in a plane, for exact soft shadows: a light's polygon on
 * its own plane minus the shadows of occluders projected onto that plane.
 * Coordinates are doubles: the pieces feed a closed-form integral whose
 * accuracy should not be lost to rounding. */
#ifndef ZT_ZONE_POLY2_H
#define ZT_ZONE_POLY2_H

#define POLY2_MAX 48   /* vertices of one convex piece */

typedef struct poly2 {
    int n;
    double x[POLY2_MAX], y[POLY2_MAX];
} poly2;

/* Signed area: positive when the vertices run counter-clockwise. */
double poly2_area(const poly2 *p);

/* Makes the vertex order counter-clockwise. */
void poly2_make_ccw(poly2 *p);

/* Keeps the part of p where a*x + b*y + c >= 0 (in place). */
void poly2_clip(poly2 *p, double a, double b, double c);

/* Splits p by the half-plane a*x + b*y + c >= 0: *inside gets that part,
 * *outside the rest.  Either may come out empty (n < 3). */
void poly2_split(const poly2 *p, double a, double b, double c, poly2 *inside,
                 poly2 *outside);

/* The convex hull of n points (counter-clockwise, at most POLY2_MAX
 * vertices; xs and ys are reordered). */
void poly2_hull(double *xs, double *ys, int n, poly2 *out);

/* A list of disjoint convex pieces. */
typedef struct poly2_set {
    poly2 *piece;
    int count, capacity;
    int overflow;    /* pieces were dropped for lack of room */
} poly2_set;

/* Removes convex polygon hole (counter-clockwise) from every piece of set,
 * leaving disjoint convex pieces.  Pieces are taken from the fixed capacity
 * of the set; when it runs out, overflow is set and the remainder kept. */
void poly2_set_subtract(poly2_set *set, const poly2 *hole, poly2 *scratch);

#endif
