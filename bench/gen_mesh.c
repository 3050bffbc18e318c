/* Large test meshes for the benchmarks: a bumpy sphere of about N
 * triangles as a binary little-endian PLY with vertex normals, as a
 * modeller would export it.
 *
 *   gen_mesh [--plain] N out.ply
 *
 * --plain leaves the bumps out: a UV sphere of radius 1.
 * The sphere is a grid of rings (u around, v from pole to pole) displaced
 * by a few sines, so that neighbouring triangles differ in size and
 * orientation as on a scanned or sculpted model; the seam and the poles
 * repeat vertices, as UV spheres from modellers do.  The triangle count is
 * 2 nu (nv - 1) with nu = 2 nv, the first such count from N up. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static int plain;

static void surface(double th, double ph, double p[3])
{
    double bump = plain ? 0.0
                        : 0.04 * sin(7 * th) * sin(9 * ph) + 0.02 * sin(23 * th + 1) * sin(19 * ph) +
                              0.01 * sin(61 * th) * sin(57 * ph + 2);
    double r = 1.0 + bump;
    p[0] = r * sin(th) * cos(ph);
    p[1] = r * cos(th);
    p[2] = r * sin(th) * sin(ph);
}

/* The normal from the surface's partial derivatives (central differences). */
static void normal(double th, double ph, float n[3])
{
    const double h = 1e-5;
    double a[3], b[3], c[3], d[3];
    double t = fmin(fmax(th, 2 * h), PI - 2 * h);
    surface(t + h, ph, a);
    surface(t - h, ph, b);
    surface(t, ph + h, c);
    surface(t, ph - h, d);
    double dt[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    double dp[3] = {c[0] - d[0], c[1] - d[1], c[2] - d[2]};
    double x = dp[1] * dt[2] - dp[2] * dt[1], y = dp[2] * dt[0] - dp[0] * dt[2],
           z = dp[0] * dt[1] - dp[1] * dt[0];
    double l = sqrt(x * x + y * y + z * z);
    n[0] = (float)(x / l);
    n[1] = (float)(y / l);
    n[2] = (float)(z / l);
}

static int put(FILE *f, const void *p, size_t n)
{
    return fwrite(p, 1, n, f) == n;
}

int main(int argc, char **argv)
{
    if (argc == 4 && strcmp(argv[1], "--plain") == 0) {
        plain = 1;
        argv++;
        argc--;
    }
    if (argc != 3) {
        fprintf(stderr, "usage: gen_mesh [--plain] TRIANGLES OUT.ply\n");
        return 1;
    }
    char *end;
    double want = strtod(argv[1], &end);
    if (*end || !(want >= 8) || want > 2e8) {
        fprintf(stderr, "gen_mesh: TRIANGLES must be a number from 8 to 2e8\n");
        return 1;
    }
    int nv = (int)fmax(2.0, ceil(0.25 * (1 + sqrt(1 + 4 * want))));
    int nu = 2 * nv;
    long long tris = 2LL * nu * (nv - 1), verts = (long long)(nu + 1) * (nv + 1);
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.part", argv[2]);
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        perror(tmp);
        return 1;
    }
    fprintf(f, "ply\nformat binary_little_endian 1.0\ncomment zonetrace bench/gen_mesh\n"
               "element vertex %lld\nproperty float x\nproperty float y\nproperty float z\n"
               "property float nx\nproperty float ny\nproperty float nz\n"
               "element face %lld\nproperty list uchar int vertex_indices\nend_header\n",
            verts, tris);
    int ok = 1;
    for (int j = 0; j <= nv && ok; j++)
        for (int i = 0; i <= nu && ok; i++) {
            double th = PI * j / nv, ph = 2 * PI * i / nu, p[3];
            surface(th, ph, p);
            float rec[6] = {(float)p[0], (float)p[1], (float)p[2]};
            normal(th, ph, rec + 3);
            ok = put(f, rec, sizeof rec);
        }
    /* Rows j and j + 1; the pole rows give one triangle per quad. */
    for (int j = 0; j < nv && ok; j++)
        for (int i = 0; i < nu && ok; i++) {
            int32_t a = j * (nu + 1) + i, b = a + 1, c = a + nu + 1, d = c + 1;
            unsigned char three = 3;
            if (j > 0) {
                int32_t t[3] = {a, b, c};
                ok = put(f, &three, 1) && put(f, t, sizeof t);
            }
            if (j < nv - 1 && ok) {
                int32_t t[3] = {b, d, c};
                ok = put(f, &three, 1) && put(f, t, sizeof t);
            }
        }
    if (fclose(f) != 0 || !ok || rename(tmp, argv[2]) != 0) {
        perror(argv[2]);
        remove(tmp);
        return 1;
    }
    printf("%s: %lld triangles, %lld vertices\n", argv[2], tris, verts);
    return 0;
}
