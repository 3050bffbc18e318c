#include "zone/light/poly2.h"

#include <string.h>

double poly2_area(const poly2 *p)
{
    double a = 0;
    for (int i = 0, j = p->n - 1; i < p->n; j = i++)
        a += p->x[j] * p->y[i] - p->x[i] * p->y[j];
    return 0.5 * a;
}

void poly2_make_ccw(poly2 *p)
{
    if (poly2_area(p) >= 0)
        return;
    for (int i = 0, j = p->n - 1; i < j; i++, j--) {
        double tx = p->x[i], ty = p->y[i];
        p->x[i] = p->x[j];
        p->y[i] = p->y[j];
        p->x[j] = tx;
        p->y[j] = ty;
    }
}

static void push(poly2 *p, double x, double y)
{
    if (p->n < POLY2_MAX) {
        p->x[p->n] = x;
        p->y[p->n] = y;
        p->n++;
    }
}

void poly2_split(const poly2 *p, double a, double b, double c, poly2 *in,
                 poly2 *out)
{
    in->n = 0;
    out->n = 0;
    if (p->n < 3)
        return;
    int j = p->n - 1;
    double dj = a * p->x[j] + b * p->y[j] + c;
    for (int i = 0; i < p->n; i++) {
        double di = a * p->x[i] + b * p->y[i] + c;
        if ((dj >= 0) != (di >= 0)) {
            /* The edge crosses the line: both sides get the crossing. */
            double t = dj / (dj - di);
            double x = p->x[j] + t * (p->x[i] - p->x[j]);
            double y = p->y[j] + t * (p->y[i] - p->y[j]);
            push(in, x, y);
            push(out, x, y);
        }
        if (di >= 0)
            push(in, p->x[i], p->y[i]);
        else
            push(out, p->x[i], p->y[i]);
        j = i;
        dj = di;
    }
}

void poly2_clip(poly2 *p, double a, double b, double c)
{
    poly2 in, out;
    poly2_split(p, a, b, c, &in, &out);
    *p = in;
}

/* Whether the two convex polygons' bounding boxes overlap. */
static int boxes_overlap(const poly2 *p, const poly2 *q)
{
    double pminx = 1e300, pmaxx = -1e300, pminy = 1e300, pmaxy = -1e300;
    double qminx = 1e300, qmaxx = -1e300, qminy = 1e300, qmaxy = -1e300;
    for (int i = 0; i < p->n; i++) {
        if (p->x[i] < pminx) pminx = p->x[i];
        if (p->x[i] > pmaxx) pmaxx = p->x[i];
        if (p->y[i] < pminy) pminy = p->y[i];
        if (p->y[i] > pmaxy) pmaxy = p->y[i];
    }
    for (int i = 0; i < q->n; i++) {
        if (q->x[i] < qminx) qminx = q->x[i];
        if (q->x[i] > qmaxx) qmaxx = q->x[i];
        if (q->y[i] < qminy) qminy = q->y[i];
        if (q->y[i] > qmaxy) qmaxy = q->y[i];
    }
    return pminx <= qmaxx && qminx <= pmaxx && pminy <= qmaxy && qminy <= pmaxy;
}

void poly2_set_subtract(poly2_set *set, const poly2 *hole, poly2 *rest)
{
    if (hole->n < 3)
        return;
    int count = set->count;
    for (int k = 0; k < count; k++) {
        poly2 *piece = &set->piece[k];
        if (piece->n < 3 || !boxes_overlap(piece, hole))
            continue;
        /* Walk the hole's edges: what lies outside an edge is a finished
         * piece, what lies inside goes on to the next edge; what is inside
         * every edge is the hole's and disappears. */
        *rest = *piece;
        int first_slot = k; /* reuse the piece's own slot first */
        piece->n = 0;
        for (int i = 0, j = hole->n - 1; i < hole->n && rest->n >= 3; j = i++) {
            /* Left of edge j->i is inside for a counter-clockwise hole. */
            double a = hole->y[j] - hole->y[i];
            double b = hole->x[i] - hole->x[j];
            double c = -(a * hole->x[j] + b * hole->y[j]);
            poly2 in, out;
            poly2_split(rest, a, b, c, &in, &out);
            if (out.n >= 3 && poly2_area(&out) > 0) {
                if (first_slot >= 0) {
                    set->piece[first_slot] = out;
                    first_slot = -1;
                } else if (set->count < set->capacity) {
                    set->piece[set->count++] = out;
                } else {
                    set->overflow = 1;
                }
            }
            *rest = in;
        }
    }
}

static double cross3(double ox, double oy, double ax, double ay, double bx, double by)
{
    return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox);
}

void poly2_hull(double *xs, double *ys, int n, poly2 *out)
{
    /* Andrew's monotone chain on points sorted by x then y (insertion sort:
     * the sets here are small). */
    for (int i = 1; i < n; i++) {
        double x = xs[i], y = ys[i];
        int j = i - 1;
        while (j >= 0 && (xs[j] > x || (xs[j] == x && ys[j] > y))) {
            xs[j + 1] = xs[j];
            ys[j + 1] = ys[j];
            j--;
        }
        xs[j + 1] = x;
        ys[j + 1] = y;
    }
    double hx[2 * POLY2_MAX + 2], hy[2 * POLY2_MAX + 2];
    int k = 0;
    for (int i = 0; i < n && k < 2 * POLY2_MAX; i++) {
        while (k >= 2 && cross3(hx[k - 2], hy[k - 2], hx[k - 1], hy[k - 1], xs[i], ys[i]) <= 0)
            k--;
        hx[k] = xs[i];
        hy[k] = ys[i];
        k++;
    }
    for (int i = n - 2, lower = k + 1; i >= 0 && k < 2 * POLY2_MAX; i--) {
        while (k >= lower && cross3(hx[k - 2], hy[k - 2], hx[k - 1], hy[k - 1], xs[i], ys[i]) <= 0)
            k--;
        hx[k] = xs[i];
        hy[k] = ys[i];
        k++;
    }
    /* More corners than a piece holds: keep an evenly spread subset (a
     * slightly smaller convex polygon) rather than cutting the hull off. */
    int m = k - 1 > POLY2_MAX ? POLY2_MAX : k - 1;
    out->n = m > 0 ? m : 0;
    for (int i = 0; i < m; i++) {
        int j = (int)((long)i * (k - 1) / m);
        out->x[i] = hx[j];
        out->y[i] = hy[j];
    }
}
