/* Meshes of the scene model (mesh.h): flat arrays, shared by count. */
#include "scene/mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

mesh *mesh_create(int vertex_count, int triangle_count, int with_normals, int with_uv,
                  int with_slot_per_triangle)
{
    if (vertex_count < 0 || triangle_count < 0 || (long long)triangle_count * 3 > INT32_MAX)
        return NULL;
    mesh *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->refs = 1;
    m->vertex_count = vertex_count;
    m->triangle_count = triangle_count;
    size_t v = (size_t)vertex_count, t = (size_t)triangle_count;
    /* One float past the last vertex: Embree reads vertices 16 bytes at a
     * time. */
    m->position = calloc(3 * v + 1, sizeof(float));
    m->index = calloc(3 * t + 1, sizeof(uint32_t));
    if (with_normals)
        m->normal = calloc(3 * v + 1, sizeof(float));
    if (with_uv)
        m->uv = calloc(2 * v + 1, sizeof(float));
    if (with_slot_per_triangle)
        m->slot = calloc(t + 1, sizeof(uint16_t));
    if (!m->position || !m->index || (with_normals && !m->normal) || (with_uv && !m->uv) ||
        (with_slot_per_triangle && !m->slot)) {
        mesh_release(m);
        return NULL;
    }
    return m;
}

mesh *mesh_retain(mesh *m)
{
    m->refs++;
    return m;
}

static void free_arrays(mesh *m)
{
    free(m->position);
    free(m->normal);
    free(m->uv);
    free(m->tangent);
    free(m->index);
    free(m->slot);
    free(m->slots);
    for (int i = 0; i < m->texture_count; i++)
        free(m->textures[i].rgba);
    free(m->textures);
}

void mesh_release(mesh *m)
{
    if (!m || --m->refs > 0)
        return;
    free_arrays(m);
    free(m);
}

/* A copy of n bytes, or NULL for none (and *ok cleared when out of memory). */
static void *dup_bytes(const void *p, size_t n, int *ok)
{
    if (!p)
        return NULL;
    void *q = malloc(n ? n : 1);
    if (!q) {
        *ok = 0;
        return NULL;
    }
    memcpy(q, p, n);
    return q;
}

mesh *mesh_copy(const mesh *m)
{
    mesh *c = calloc(1, sizeof *c);
    if (!c)
        return NULL;
    *c = *m;
    c->refs = 1;
    size_t v = (size_t)m->vertex_count, t = (size_t)m->triangle_count;
    int ok = 1;
    c->position = dup_bytes(m->position, (3 * v + 1) * sizeof(float), &ok);
    c->normal = dup_bytes(m->normal, (3 * v + 1) * sizeof(float), &ok);
    c->uv = dup_bytes(m->uv, (2 * v + 1) * sizeof(float), &ok);
    c->tangent = dup_bytes(m->tangent, (4 * v + 1) * sizeof(float), &ok);
    c->index = dup_bytes(m->index, (3 * t + 1) * sizeof(uint32_t), &ok);
    c->slot = dup_bytes(m->slot, (t + 1) * sizeof(uint16_t), &ok);
    c->slots = dup_bytes(m->slots, (size_t)m->slot_count * sizeof(mesh_slot), &ok);
    c->textures = NULL;
    c->texture_count = 0;
    if (ok && m->texture_count) {
        c->textures = calloc((size_t)m->texture_count, sizeof(mesh_texture));
        ok = c->textures != NULL;
        for (int i = 0; ok && i < m->texture_count; i++) {
            const mesh_texture *tx = &m->textures[i];
            c->textures[i] = *tx;
            c->textures[i].rgba = dup_bytes(tx->rgba, (size_t)tx->width * tx->height * 4, &ok);
            c->texture_count = i + 1;
        }
    }
    if (!ok) {
        free_arrays(c);
        free(c);
        return NULL;
    }
    return c;
}

int mesh_make_unique(mesh **m)
{
    if ((*m)->refs <= 1)
        return 1;
    mesh *c = mesh_copy(*m);
    if (!c)
        return 0;
    mesh_release(*m);
    *m = c;
    return 1;
}

double mesh_cofactors(const double a[9], double c[9])
{
    c[0] = a[4] * a[8] - a[5] * a[7];
    c[1] = a[5] * a[6] - a[3] * a[8];
    c[2] = a[3] * a[7] - a[4] * a[6];
    c[3] = a[2] * a[7] - a[1] * a[8];
    c[4] = a[0] * a[8] - a[2] * a[6];
    c[5] = a[1] * a[6] - a[0] * a[7];
    c[6] = a[1] * a[5] - a[2] * a[4];
    c[7] = a[2] * a[3] - a[0] * a[5];
    c[8] = a[0] * a[4] - a[1] * a[3];
    return a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
}

void mesh_transform(mesh *m, const double a[9], const double t[3])
{
    for (int v = 0; v < m->vertex_count; v++) {
        float *p = m->position + 3 * (size_t)v;
        double x = p[0], y = p[1], z = p[2];
        p[0] = (float)(a[0] * x + a[1] * y + a[2] * z + t[0]);
        p[1] = (float)(a[3] * x + a[4] * y + a[5] * z + t[1]);
        p[2] = (float)(a[6] * x + a[7] * y + a[8] * z + t[2]);
    }
    double c[9];
    double det = mesh_cofactors(a, c);
    if (m->normal) {
        double s = det < 0 ? -1.0 : 1.0;
        for (int v = 0; v < m->vertex_count; v++) {
            float *q = m->normal + 3 * (size_t)v;
            double x = q[0], y = q[1], z = q[2];
            double nx = s * (c[0] * x + c[1] * y + c[2] * z);
            double ny = s * (c[3] * x + c[4] * y + c[5] * z);
            double nz = s * (c[6] * x + c[7] * y + c[8] * z);
            double l = sqrt(nx * nx + ny * ny + nz * nz);
            if (l > 0) {
                q[0] = (float)(nx / l);
                q[1] = (float)(ny / l);
                q[2] = (float)(nz / l);
            }
        }
    }
    /* Tangents go with the positions; a mirror turns the bitangent's side
     * (the normal is mapped by the inverse transpose, the tangent by a). */
    if (m->tangent)
        for (int v = 0; v < m->vertex_count; v++) {
            float *q = m->tangent + 4 * (size_t)v;
            double x = q[0], y = q[1], z = q[2];
            double tx = a[0] * x + a[1] * y + a[2] * z;
            double ty = a[3] * x + a[4] * y + a[5] * z;
            double tz = a[6] * x + a[7] * y + a[8] * z;
            double l = sqrt(tx * tx + ty * ty + tz * tz);
            if (l > 0 && isfinite(l)) {
                q[0] = (float)(tx / l);
                q[1] = (float)(ty / l);
                q[2] = (float)(tz / l);
                if (det < 0)
                    q[3] = -q[3];
            } else {
                q[3] = 0.0f;
            }
        }
    /* A mirror turns the winding: swap two corners so the front stays on
     * the normals' side. */
    if (det < 0)
        for (int i = 0; i < m->triangle_count; i++) {
            uint32_t *f = m->index + 3 * (size_t)i;
            uint32_t tmp = f[1];
            f[1] = f[2];
            f[2] = tmp;
        }
}

void mesh_bounds(const mesh *m, vec3 *lo, vec3 *hi)
{
    *lo = v3(1e300, 1e300, 1e300);
    *hi = v3(-1e300, -1e300, -1e300);
    for (int v = 0; v < m->vertex_count; v++) {
        const float *p = m->position + 3 * (size_t)v;
        vec3 q = v3(p[0], p[1], p[2]);
        *lo = v3_min3(*lo, q);
        *hi = v3_max3(*hi, q);
    }
}

uint64_t mesh_memory(const mesh *m)
{
    uint64_t v = (uint64_t)m->vertex_count, t = (uint64_t)m->triangle_count;
    uint64_t b = sizeof *m + (3 * v + 1) * sizeof(float) + (3 * t + 1) * sizeof(uint32_t);
    if (m->normal)
        b += (3 * v + 1) * sizeof(float);
    if (m->uv)
        b += (2 * v + 1) * sizeof(float);
    if (m->tangent)
        b += (4 * v + 1) * sizeof(float);
    if (m->slot)
        b += (t + 1) * sizeof(uint16_t);
    b += (uint64_t)m->slot_count * sizeof(mesh_slot);
    for (int i = 0; i < m->texture_count; i++)
        b += (uint64_t)m->textures[i].width * m->textures[i].height * 4;
    return b;
}

const char *mesh_unused_name(int k)
{
    static const char *const names[MESH_UNUSED_COUNT] = {
        "emissive textures under a black emissive factor",
        "occlusion textures",
        "specular layers or textures",
        "clearcoat layers",
        "sheen layers",
        "bump (height) maps",
        "other textures",
    };
    return k >= 0 && k < MESH_UNUSED_COUNT ? names[k] : "?";
}
