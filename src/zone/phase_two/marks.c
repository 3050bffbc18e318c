/* Phase Two: what the pixels' own rays may miss, found from the eye before
 * any pixel is sampled.
 *
 * Tips: the pixel where each vertex of a light part falls.  A light's
 * corner can enter a pixel between its corner and sample rays; listed
 * there, it gets its exact level-0 coverage like any light seen.
 *
 * Vertices: the pixel where each triangle's vertex falls.  A tip can
 * enter a pixel between every signature; such a pixel takes the edge grid.
 *
 * Fine pixels: where a light's image in a mirror, metal or glass sphere
 * falls.  Such an image can be smaller than a pixel's corner and sample
 * spacing, so no signature finds it and the pixel is shaded as smooth,
 * without the light.  Each light's
 * points are carried to their specular points on the sphere for the
 * viewpoint (as glint.c does for texels) and projected onto the screen; the
 * pixels under the box they span, one pixel wider each way, take the fine
 * coverage grid, which finds the image if it covers a few of its cells. */
#include <stdlib.h>
#include <string.h>

#include "util/vec3_convert.h"
#include "zone/phase_one/glint.h"
#include "zone/phase_two/phase_two.h"

#define LIGHT_STEPS 4      /* a triangle light's points: a 4 x 4 lattice */
#define SMALL_IMAGE 3.0    /* images at least this wide both ways are seen */

/* Where the line from the viewpoint through w meets the screen, in pixels;
 * returns 0 when w is not in front of the viewpoint. */
static int project(const cam *c, vec3 w, double *px, double *py)
{
    vec3 v = f3_to_v3(c->viewpoint), tl = v3_add(v, f3_to_v3(c->to_screen));
    vec3 r = f3_to_v3(c->right), dn = f3_to_v3(c->down);
    vec3 ns = v3_cross(r, dn), d = v3_sub(w, v);
    double den = v3_dot(ns, d);
    if (fabs(den) < 1e-300)
        return 0;
    double t = v3_dot(ns, v3_sub(tl, v)) / den;
    if (t <= 0)
        return 0;
    /* q = a r + b dn on the screen plane: the 2 x 2 normal equations. */
    vec3 q = v3_sub(v3_add(v, v3_scale(d, t)), tl);
    double rr = v3_dot(r, r), rd = v3_dot(r, dn), dd = v3_dot(dn, dn);
    double qr = v3_dot(q, r), qd = v3_dot(q, dn), det = rr * dd - rd * rd;
    if (fabs(det) < 1e-300)
        return 0;
    *px = (qr * dd - qd * rd) / det * c->width;
    *py = (qd * rr - qr * rd) / det * c->height;
    return 1;
}

typedef struct box {
    double x0, y0, x1, y1;
    int points;
} box;

/* Adds the screen position of y's image in sphere (sc, sr) to b. */
static void add_image(const cam *c, vec3 eye, vec3 sc, double sr, vec3 y, box *b)
{
    vec3 s;
    double px, py;
    if (!glint_specular_point(sc, sr, eye, y, &s) || !project(c, s, &px, &py))
        return;
    b->x0 = fmin(b->x0, px);
    b->y0 = fmin(b->y0, py);
    b->x1 = fmax(b->x1, px);
    b->y1 = fmax(b->y1, py);
    b->points++;
}

static void mark_box(const cam *c, const box *b, unsigned char *mark)
{
    if (b->points == 0 || (b->x1 - b->x0 >= SMALL_IMAGE && b->y1 - b->y0 >= SMALL_IMAGE))
        return;
    /* One pixel of margin: the lattice's images bound the image only
     * roughly, and a pixel's corner signatures see a little beyond it. */
    double x0 = fmax(b->x0 - 1.0, 0.0), y0 = fmax(b->y0 - 1.0, 0.0);
    double x1 = fmin(b->x1 + 1.0, c->width - 1.0), y1 = fmin(b->y1 + 1.0, c->height - 1.0);
    if (!(x0 <= x1 && y0 <= y1))
        return; /* off screen: nothing to convert to pixel indices */
    for (int y = (int)y0; y <= (int)y1; y++)
        for (int x = (int)x0; x <= (int)x1; x++)
            mark[(size_t)y * c->width + x] = 1;
}

/* A light's vertex seen in pixel p: a tip of a light can enter a pixel
 * without reaching any of its corners or samples, and would be lost. */
static int add_tip(p2_marks *m, const cam *c, vec3 w, int part)
{
    double px, py;
    if (!project(c, w, &px, &py) || !(px >= 0 && py >= 0 && px < c->width && py < c->height))
        return 1; /* off screen (or not a number) */
    if (m->tip_count == m->tip_capacity) {
        size_t cap = m->tip_capacity ? 2 * m->tip_capacity : 16;
        uint64_t *nt = realloc(m->tips, cap * sizeof *nt);
        if (!nt)
            return 0;
        m->tips = nt;
        m->tip_capacity = cap;
    }
    uint64_t pixel = (uint64_t)(int)py * (uint64_t)c->width + (uint64_t)(int)px;
    m->tips[m->tip_count++] = pixel << 32 | (uint32_t)part;
    return 1;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The three corners of triangle part p. */
static void triangle_corners(const rs_part *p, vec3 w[3])
{
    w[0] = f3_to_v3(p->p0);
    w[1] = v3_add(w[0], f3_to_v3(p->e1));
    w[2] = v3_add(w[0], f3_to_v3(p->e2));
}

static int mark_tips(p2_marks *m, const rscene *rs, const cam *c)
{
    for (int j = 0; j < rs->light_count; j++) {
        int part = rs->lights[j].part;
        /* Mesh lights are shaded on the samples, not by coverage. */
        if (part >= rs->part_count)
            continue;
        const rs_part *lp = &rs->parts[part];
        int ok = 1;
        if (lp->shape == SHAPE_TRIANGLE) {
            vec3 w[3];
            triangle_corners(lp, w);
            ok = add_tip(m, c, w[0], part) && add_tip(m, c, w[1], part) &&
                 add_tip(m, c, w[2], part);
        } else if (lp->shape == SHAPE_SPHERE) {
            ok = add_tip(m, c, f3_to_v3(lp->p0), part);
        }
        if (!ok)
            return 0;
    }
    if (m->tip_count > 1)
        qsort(m->tips, m->tip_count, sizeof *m->tips, cmp_u64);
    return 1;
}

/* The pixels where a triangle part's vertex falls.  A mesh's vertices are
 * not marked: its triangles meet their neighbours, and a tip between the
 * samples is one of many (the coverage grid is for outlines). */
static void mark_vertices(const rscene *rs, const cam *c, unsigned char *vertex)
{
    for (int i = 0; i < rs->part_count; i++) {
        const rs_part *p = &rs->parts[i];
        if (p->shape != SHAPE_TRIANGLE)
            continue;
        vec3 w[3];
        triangle_corners(p, w);
        for (int k = 0; k < 3; k++) {
            double px, py;
            if (project(c, w[k], &px, &py) && px >= 0 && py >= 0 && px < c->width &&
                py < c->height)
                vertex[(size_t)(int)py * c->width + (int)px] = 1;
        }
    }
}

int p2_marks_build(p2_marks *m, const p2_ctx *ctx)
{
    const rscene *rs = &ctx->r->rs;
    const cam *c = &ctx->c;
    memset(m, 0, sizeof *m);
    m->fine = calloc((size_t)c->width * c->height, 1);
    m->vertex = calloc((size_t)c->width * c->height, 1);
    if (!m->fine || !m->vertex || !mark_tips(m, rs, c))
        return 0;
    mark_vertices(rs, c, m->vertex);
    vec3 eye = f3_to_v3(c->viewpoint);
    for (int i = 0; i < rs->part_count; i++) {
        if (!glint_sphere(rs, i))
            continue;
        const rs_part *sp = &rs->parts[i];
        vec3 sc = f3_to_v3(sp->p0);
        if (v3_length(v3_sub(eye, sc)) <= sp->radius)
            continue;
        for (int j = 0; j < rs->light_count; j++) {
            if (rs->lights[j].part >= rs->part_count)
                continue;
            const rs_part *lp = &rs->parts[rs->lights[j].part];
            box b = {1e300, 1e300, -1e300, -1e300, 0};
            if (lp->shape == SHAPE_TRIANGLE) {
                vec3 p0 = f3_to_v3(lp->p0), e1 = f3_to_v3(lp->e1), e2 = f3_to_v3(lp->e2);
                for (int a = 0; a <= LIGHT_STEPS; a++)
                    for (int k = 0; a + k <= LIGHT_STEPS; k++)
                        add_image(c, eye, sc, sp->radius,
                                  v3_add(p0, v3_add(v3_scale(e1, (double)a / LIGHT_STEPS),
                                                    v3_scale(e2, (double)k / LIGHT_STEPS))),
                                  &b);
            } else if (lp->shape == SHAPE_SPHERE) {
                /* The corners of the light's bounding cube and its centre. */
                vec3 lc = f3_to_v3(lp->p0);
                double r = lp->radius;
                add_image(c, eye, sc, sp->radius, lc, &b);
                for (int k = 0; k < 8; k++)
                    add_image(c, eye, sc, sp->radius,
                              v3_add(lc, v3(k & 1 ? r : -r, k & 2 ? r : -r, k & 4 ? r : -r)), &b);
            }
            mark_box(c, &b, m->fine);
        }
    }
    return 1;
}

void p2_marks_free(p2_marks *m)
{
    free(m->fine);
    free(m->vertex);
    free(m->tips);
    memset(m, 0, sizeof *m);
}

int p2_marks_tips(const p2_marks *m, size_t pixel, const uint64_t **tips)
{
    *tips = NULL;
    if (m->tip_count == 0)
        return 0;
    /* The first entry of the pixel, by bisection over the sorted keys. */
    size_t lo = 0, hi = m->tip_count;
    uint64_t key = (uint64_t)pixel << 32;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (m->tips[mid] < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    size_t end = lo;
    while (end < m->tip_count && m->tips[end] >> 32 == pixel)
        end++;
    *tips = m->tips + lo;
    return (int)(end - lo);
}
