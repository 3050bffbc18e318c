/* Model files through Assimp's C API, flattened into one mesh
 * (model_import.h).  Assimp reads and post-processes; everything it hands
 * over is checked again here (indices, finiteness, sizes) before it is
 * used, since a model file is untrusted. */
#define _POSIX_C_SOURCE 200809L
#include "scene/model_import.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <pthread.h>
#include <sys/stat.h>
#include <time.h>

#include <assimp/cimport.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "scene/emissive_split.h"
#include "scene/model_materials.h"
#include "util/error.h"

/* Assimp repairs some broken files and only says so in its log (faces with
 * out-of-range indices are dropped): the importer listens to the log while
 * it reads.  The log is global to the process, so imports take turns. */
static pthread_mutex_t import_lock = PTHREAD_MUTEX_INITIALIZER;

typedef struct import_log {
    int dropped_faces;      /* Assimp dropped faces with bad indices */
} import_log;

static void log_message(const char *message, char *user)
{
    import_log *log = (import_log *)(void *)user;
    if (strstr(message, "out-of-range indices"))
        log->dropped_faces = 1;
}

/* aiImportFile with the log heard. */
/* Degrees: docs/scene-format.md, "Shading normals". */
#define SMOOTHING_ANGLE 60.0f

static const struct aiScene *import_listening(const char *path, unsigned flags, import_log *log)
{
    memset(log, 0, sizeof *log);
    pthread_mutex_lock(&import_lock);
    struct aiLogStream stream = {log_message, (char *)(void *)log};
    aiAttachLogStream(&stream);
    /* Normals made for a file without them are averaged only across
     * edges whose faces meet at less than this (Assimp's default, 175
     * degrees, bent every box's walls toward its corners). */
    struct aiPropertyStore *props = aiCreatePropertyStore();
    aiSetImportPropertyFloat(props, AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, SMOOTHING_ANGLE);
    const struct aiScene *sc = aiImportFileExWithProperties(path, flags, NULL, props);
    aiReleasePropertyStore(props);
    aiDetachLogStream(&stream);
    pthread_mutex_unlock(&import_lock);
    return sc;
}

/* Node hierarchies deeper than this are taken for cycles or mistakes. */
#define MAX_NODE_DEPTH 256

/* Where each of the file's meshes goes, per instance. */
typedef struct flatten {
    const struct aiScene *sc;
    mesh *m;                /* NULL on the counting pass */
    long long vertices, triangles;
    int *slot_of_material;  /* material -> slot, -1 unused */
    int slots;
    int any_normals, any_uv, any_tangents;
    int skipped;
    int bad_normals;        /* vertex normals in the file that are not finite
                               or zero (replaced from the faces) */
    const char *path;
    zt_error *err;
    zt_status status;
} flatten;

static int is_finite3(const struct aiVector3D *v)
{
    return isfinite(v->x) && isfinite(v->y) && isfinite(v->z);
}

static void mat4_mul(const struct aiMatrix4x4 *a, const struct aiMatrix4x4 *b,
                     struct aiMatrix4x4 *out)
{
    const float *x = &a->a1, *y = &b->a1;
    float r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r[4 * i + j] = x[4 * i] * y[j] + x[4 * i + 1] * y[4 + j] + x[4 * i + 2] * y[8 + j] +
                           x[4 * i + 3] * y[12 + j];
    memcpy(&out->a1, r, sizeof r);
}

/* p -> M p (M's rows are a, b, c, d: the last row is the projective one). */
static void transform_point(const struct aiMatrix4x4 *t, const struct aiVector3D *p, double out[3])
{
    out[0] = (double)t->a1 * p->x + (double)t->a2 * p->y + (double)t->a3 * p->z + t->a4;
    out[1] = (double)t->b1 * p->x + (double)t->b2 * p->y + (double)t->b3 * p->z + t->b4;
    out[2] = (double)t->c1 * p->x + (double)t->c2 * p->y + (double)t->c3 * p->z + t->c4;
}

/* The inverse transpose of t's 3x3 part (times its determinant, which it
 * returns). */
static double normal_matrix(const struct aiMatrix4x4 *t, double c[9])
{
    double a[9] = {t->a1, t->a2, t->a3, t->b1, t->b2, t->b3, t->c1, t->c2, t->c3};
    return mesh_cofactors(a, c);
}

static zt_status failf(flatten *f, const char *fmt, const char *detail, long long a, long long b,
                       long long c)
{
    char what[300];
    snprintf(what, sizeof what, fmt, detail, a, b, c);
    f->status = zt_fail(f->err, ZT_ERR_PARSE, "%s: %s", f->path, what);
    return f->status;
}

/* Vertex v's tangent (the file's, or Assimp's from aiProcess_CalcTangentSpace)
 * under transform t (det its determinant) into q: the direction, then the
 * bitangent's side w, from the file's frame; w = 0 when there is none.
 * The normal goes by the inverse transpose and the tangent by t, so a
 * mirroring t turns the side (mesh_transform does the same). */
static void set_tangent(const struct aiMesh *am, unsigned v, const struct aiMatrix4x4 *t,
                        double det, float *q)
{
    q[0] = q[1] = q[2] = q[3] = 0.0f;
    if (!am->mTangents || !am->mBitangents || !am->mNormals)
        return;
    const struct aiVector3D *tv = &am->mTangents[v], *bv = &am->mBitangents[v];
    const struct aiVector3D *nv = &am->mNormals[v];
    if (!is_finite3(tv) || !is_finite3(bv) || !is_finite3(nv))
        return;
    double x = (double)t->a1 * tv->x + (double)t->a2 * tv->y + (double)t->a3 * tv->z;
    double y = (double)t->b1 * tv->x + (double)t->b2 * tv->y + (double)t->b3 * tv->z;
    double z = (double)t->c1 * tv->x + (double)t->c2 * tv->y + (double)t->c3 * tv->z;
    double l = sqrt(x * x + y * y + z * z);
    if (!(l > 0) || !isfinite(l))
        return;
    /* (n x t) . b in the file's frame. */
    double cx = (double)nv->y * tv->z - (double)nv->z * tv->y;
    double cy = (double)nv->z * tv->x - (double)nv->x * tv->z;
    double cz = (double)nv->x * tv->y - (double)nv->y * tv->x;
    double side = cx * bv->x + cy * bv->y + cz * bv->z < 0 ? -1.0 : 1.0;
    q[0] = (float)(x / l);
    q[1] = (float)(y / l);
    q[2] = (float)(z / l);
    q[3] = (float)(det < 0 ? -side : side);
}

/* One instance of mesh mi under transform t. */
static zt_status add_mesh(flatten *f, unsigned mi, const struct aiMatrix4x4 *t)
{
    const struct aiMesh *am = f->sc->mMeshes[mi];
    if (!am || !(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || !am->mVertices)
        return ZT_OK;
    unsigned nv = am->mNumVertices;
    if (!f->m) {
        /* Counting pass. */
        f->vertices += nv;
        for (unsigned k = 0; k < am->mNumFaces; k++)
            f->triangles += am->mFaces[k].mNumIndices == 3;
        if (f->vertices > UINT32_MAX / 2 || f->triangles * 3 > INT32_MAX)
            return failf(f, "too large: more than %s%lld vertices or triangles", "", 1LL << 31,
                         0, 0);
        f->any_normals |= am->mNormals != NULL;
        f->any_uv |= am->mTextureCoords[0] != NULL;
        f->any_tangents |= am->mTangents && am->mBitangents && am->mNormals;
        if (am->mMaterialIndex < f->sc->mNumMaterials &&
            f->slot_of_material[am->mMaterialIndex] < 0)
            f->slot_of_material[am->mMaterialIndex] = f->slots++;
        return ZT_OK;
    }
    mesh *m = f->m;
    uint32_t base = (uint32_t)f->vertices;
    double nm[9];
    double det = normal_matrix(t, nm);
    /* Vertices: positions, normals (by the inverse transpose), uv. */
    unsigned char *bad = calloc(nv + 1, 1);
    if (!bad)
        return f->status = zt_fail(f->err, ZT_ERR_MEMORY, "%s: out of memory", f->path);
    for (unsigned v = 0; v < nv; v++) {
        double p[3];
        transform_point(t, &am->mVertices[v], p);
        float *q = m->position + 3 * ((size_t)base + v);
        for (int a = 0; a < 3; a++)
            q[a] = (float)p[a];
        bad[v] = !is_finite3(&am->mVertices[v]) || !isfinite(q[0]) || !isfinite(q[1]) ||
                 !isfinite(q[2]) || fabsf(q[0]) > 1e30f || fabsf(q[1]) > 1e30f ||
                 fabsf(q[2]) > 1e30f;
        if (bad[v])
            q[0] = q[1] = q[2] = 0;
        if (m->normal) {
            float *nn = m->normal + 3 * ((size_t)base + v);
            nn[0] = nn[1] = nn[2] = 0; /* filled from the faces below when missing */
            if (am->mNormals && !is_finite3(&am->mNormals[v]))
                f->bad_normals++;
            else if (am->mNormals) {
                const struct aiVector3D *s = &am->mNormals[v];
                double sg = det < 0 ? -1 : 1;
                double x = sg * (nm[0] * s->x + nm[1] * s->y + nm[2] * s->z);
                double y = sg * (nm[3] * s->x + nm[4] * s->y + nm[5] * s->z);
                double z = sg * (nm[6] * s->x + nm[7] * s->y + nm[8] * s->z);
                double l = sqrt(x * x + y * y + z * z);
                if (l > 0 && isfinite(l)) {
                    nn[0] = (float)(x / l);
                    nn[1] = (float)(y / l);
                    nn[2] = (float)(z / l);
                } else {
                    f->bad_normals++;
                }
            }
        }
        if (m->tangent)
            set_tangent(am, v, t, det, m->tangent + 4 * ((size_t)base + v));
        if (m->uv) {
            float *uv = m->uv + 2 * ((size_t)base + v);
            uv[0] = uv[1] = 0;
            if (am->mTextureCoords[0]) {
                const struct aiVector3D *s = &am->mTextureCoords[0][v];
                uv[0] = isfinite(s->x) ? s->x : 0;
                uv[1] = isfinite(s->y) ? s->y : 0;
            }
        }
    }
    /* Triangles: indices checked, degenerate ones skipped. */
    int slot = am->mMaterialIndex < f->sc->mNumMaterials
                   ? f->slot_of_material[am->mMaterialIndex] : 0;
    for (unsigned k = 0; k < am->mNumFaces; k++) {
        const struct aiFace *face = &am->mFaces[k];
        if (face->mNumIndices != 3)
            continue;
        unsigned idx[3];
        for (int c = 0; c < 3; c++) {
            idx[c] = face->mIndices[c];
            if (idx[c] >= nv) {
                free(bad);
                return failf(f, "%striangle %lld uses vertex %lld, but its mesh has %lld vertices",
                             "", k, idx[c], nv);
            }
        }
        /* A mirroring transform turns the winding: swap two corners. */
        if (det < 0) {
            unsigned tmp = idx[1];
            idx[1] = idx[2];
            idx[2] = tmp;
        }
        const float *p0 = m->position + 3 * ((size_t)base + idx[0]);
        const float *p1 = m->position + 3 * ((size_t)base + idx[1]);
        const float *p2 = m->position + 3 * ((size_t)base + idx[2]);
        double e1[3], e2[3], cr[3];
        for (int a = 0; a < 3; a++) {
            e1[a] = (double)p1[a] - p0[a];
            e2[a] = (double)p2[a] - p0[a];
        }
        cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
        cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
        cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double area2 = cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2];
        if (bad[idx[0]] || bad[idx[1]] || bad[idx[2]] || idx[0] == idx[1] || idx[1] == idx[2] ||
            idx[0] == idx[2] || !(area2 > 0) || !isfinite(area2)) {
            f->skipped++;
            continue;
        }
        size_t tri = (size_t)m->triangle_count++;
        for (int c = 0; c < 3; c++)
            m->index[3 * tri + c] = base + idx[c];
        if (m->slot)
            m->slot[tri] = (uint16_t)slot;
        /* Missing normals: the faces' around the vertex (area-weighted). */
        if (m->normal && !am->mNormals)
            for (int c = 0; c < 3; c++) {
                float *nn = m->normal + 3 * ((size_t)base + idx[c]);
                for (int a = 0; a < 3; a++)
                    nn[a] += (float)cr[a];
            }
    }
    free(bad);
    f->vertices += nv;
    return ZT_OK;
}

static zt_status walk(flatten *f, const struct aiNode *node, const struct aiMatrix4x4 *parent,
                      int depth)
{
    if (!node)
        return ZT_OK;
    if (depth > MAX_NODE_DEPTH)
        return failf(f, "the node hierarchy is deeper than %s%lld levels (a cycle?)", "",
                     MAX_NODE_DEPTH, 0, 0);
    struct aiMatrix4x4 t;
    mat4_mul(parent, &node->mTransformation, &t);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        if (node->mMeshes[i] >= f->sc->mNumMeshes)
            return failf(f, "a node names mesh %s%lld of %lld", "", node->mMeshes[i],
                         f->sc->mNumMeshes, 0);
        if (add_mesh(f, node->mMeshes[i], &t) != ZT_OK)
            return f->status;
    }
    for (unsigned i = 0; i < node->mNumChildren; i++)
        if (walk(f, node->mChildren[i], &t, depth + 1) != ZT_OK)
            return f->status;
    return ZT_OK;
}

/* Normalises the normals, and gives the geometric normal of a face around
 * to any vertex that has none. */
static void finish_normals(mesh *m)
{
    if (!m->normal)
        return;
    for (int v = 0; v < m->vertex_count; v++) {
        float *n = m->normal + 3 * (size_t)v;
        double l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        if (l > 0 && isfinite(l)) {
            for (int a = 0; a < 3; a++)
                n[a] = (float)(n[a] / l);
        } else {
            n[0] = n[1] = n[2] = 0;
        }
    }
    for (int t = 0; t < m->triangle_count; t++) {
        const uint32_t *f = m->index + 3 * (size_t)t;
        for (int c = 0; c < 3; c++) {
            float *n = m->normal + 3 * (size_t)f[c];
            if (n[0] != 0 || n[1] != 0 || n[2] != 0)
                continue;
            const float *p0 = m->position + 3 * (size_t)f[0], *p1 = m->position + 3 * (size_t)f[1];
            const float *p2 = m->position + 3 * (size_t)f[2];
            double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
            double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
            double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                            e1[0] * e2[1] - e1[1] * e2[0]};
            double l = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
            for (int a = 0; a < 3; a++)
                n[a] = (float)(cr[a] / l);
        }
    }
}

/* The file's first camera, through its node's transform. */
static const struct aiNode *find_node(const struct aiNode *n, const struct aiString *name,
                                      const struct aiMatrix4x4 *parent, struct aiMatrix4x4 *out,
                                      int depth)
{
    if (!n || depth > MAX_NODE_DEPTH)
        return NULL;
    struct aiMatrix4x4 t;
    mat4_mul(parent, &n->mTransformation, &t);
    if (n->mName.length == name->length && memcmp(n->mName.data, name->data, name->length) == 0) {
        *out = t;
        return n;
    }
    for (unsigned i = 0; i < n->mNumChildren; i++) {
        const struct aiNode *r = find_node(n->mChildren[i], name, &t, out, depth + 1);
        if (r)
            return r;
    }
    return NULL;
}

static void read_camera(const struct aiScene *sc, const char *path, model_camera *cam)
{
    memset(cam, 0, sizeof *cam);
    if (!sc->mNumCameras || !sc->mCameras || !sc->mCameras[0])
        return;
    const struct aiCamera *c = sc->mCameras[0];
    struct aiMatrix4x4 id, t;
    aiIdentityMatrix4(&id);
    if (!find_node(sc->mRootNode, &c->mName, &id, &t, 0))
        t = id;
    double pos[3], at[3], nm[9];
    struct aiVector3D p = c->mPosition;
    transform_point(&t, &p, pos);
    struct aiVector3D look = {c->mPosition.x + c->mLookAt.x, c->mPosition.y + c->mLookAt.y,
                              c->mPosition.z + c->mLookAt.z};
    transform_point(&t, &look, at);
    normal_matrix(&t, nm);
    /* Directions go by the 3x3 part itself (not its inverse transpose). */
    double up[3] = {(double)t.a1 * c->mUp.x + (double)t.a2 * c->mUp.y + (double)t.a3 * c->mUp.z,
                    (double)t.b1 * c->mUp.x + (double)t.b2 * c->mUp.y + (double)t.b3 * c->mUp.z,
                    (double)t.c1 * c->mUp.x + (double)t.c2 * c->mUp.y + (double)t.c3 * c->mUp.z};
    double aspect = c->mAspect > 0 && isfinite(c->mAspect) ? c->mAspect : 1.0;
    /* Assimp documents mHorizontalFOV as half the horizontal angle, but its
     * glTF reader (5.2) stores the vertical angle times the aspect. */
    const char *dot = strrchr(path, '.');
    int gltf = dot && (strcasecmp(dot, ".gltf") == 0 || strcasecmp(dot, ".glb") == 0);
    double h = c->mHorizontalFOV, fov;
    if (gltf)
        fov = h / aspect * 180.0 / 3.14159265358979323846;
    else if (h > 0 && h < 1.5707963)
        fov = 2.0 * atan(tan(h) / aspect) * 180.0 / 3.14159265358979323846;
    else
        return;
    cam->position = v3(pos[0], pos[1], pos[2]);
    cam->lookat = v3(at[0], at[1], at[2]);
    cam->up = v3(up[0], up[1], up[2]);
    cam->fov = fov;
    cam->aspect = c->mAspect > 0 && isfinite(c->mAspect) ? c->mAspect : 0;
    cam->present = v3_isfinite(cam->position) && v3_isfinite(cam->lookat) &&
                   v3_isfinite(cam->up) && fov > 0 && fov < 180;
}

int model_import_known_extension(const char *path)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash) || strcasecmp(dot, ".json") == 0)
        return 0;
    return aiIsExtensionSupported(dot) == AI_TRUE;
}

/* Whether path can be read as a file: ZT_OK, or ZT_ERR_READ with why. */
static zt_status check_file(const char *path, zt_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return zt_fail(err, ZT_ERR_READ, "%s: cannot open model file: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode))
        return zt_fail(err, ZT_ERR_READ, "%s: cannot open model file: it is a directory", path);
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return zt_fail(err, ZT_ERR_READ, "%s: cannot open model file: %s", path, strerror(errno));
    fclose(fp);
    if (st.st_size == 0)
        return zt_fail(err, ZT_ERR_PARSE, "%s: empty file", path);
    return ZT_OK;
}

zt_status model_import(const char *path, const model_import_options *options, mesh **out,
                       model_camera *camera, zt_error *err)
{
    *out = NULL;
    if (camera)
        memset(camera, 0, sizeof *camera);
    zt_status st = check_file(path, err);
    if (st != ZT_OK)
        return st;
    const char *dot = strrchr(path, '.');
    if (!model_import_known_extension(path))
        return zt_fail(err, ZT_ERR_PARSE, "%s: unknown model format '%s' (Assimp reads OBJ, "
                       "PLY, STL, glTF, FBX, Collada, IFC, 3DS and more: `assimp listext`)",
                       path, dot ? dot : "(no extension)");
    unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                     aiProcess_SortByPType | aiProcess_ValidateDataStructure;
    if (options->smooth)
        flags |= aiProcess_GenSmoothNormals;
    /* Tangents for normal maps where the file has none (Assimp's own
     * method, not MikkTSpace: docs/scene-format.md, "Textures"). */
    flags |= aiProcess_CalcTangentSpace;
    import_log log;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    const struct aiScene *sc = import_listening(path, flags, &log);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (options->read_seconds)
        *options->read_seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec);
    if (!sc) {
        const char *why = aiGetErrorString();
        return zt_fail(err, ZT_ERR_PARSE, "%s: the model cannot be read: %s", path,
                       why && why[0] ? why : "Assimp gives no reason");
    }
    if (log.dropped_faces) {
        aiReleaseImport(sc);
        return zt_fail(err, ZT_ERR_PARSE, "%s: the model cannot be read: some faces have "
                       "vertex indices out of range", path);
    }
    flatten f;
    memset(&f, 0, sizeof f);
    f.sc = sc;
    f.path = path;
    f.err = err;
    f.slot_of_material = malloc(((size_t)sc->mNumMaterials + 1) * sizeof(int));
    if (!f.slot_of_material) {
        aiReleaseImport(sc);
        return zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory", path);
    }
    for (unsigned i = 0; i <= sc->mNumMaterials; i++)
        f.slot_of_material[i] = -1;
    struct aiMatrix4x4 id;
    aiIdentityMatrix4(&id);
    st = walk(&f, sc->mRootNode, &id, 0);
    if (st == ZT_OK && f.triangles == 0)
        st = zt_fail(err, ZT_ERR_PARSE, "%s: the model has no triangles", path);
    if (st == ZT_OK && f.slots > 65535)
        st = zt_fail(err, ZT_ERR_PARSE, "%s: more than 65535 materials", path);
    mesh *m = NULL;
    if (st == ZT_OK) {
        int slots = f.slots ? f.slots : 1;
        m = mesh_create((int)f.vertices, (int)f.triangles, options->smooth, f.any_uv, slots > 1);
        if (m && f.any_tangents) {
            m->tangent = calloc(4 * (size_t)f.vertices + 1, sizeof(float));
            if (!m->tangent) {
                mesh_release(m);
                m = NULL;
            }
        }
        if (!m)
            st = zt_fail(err, ZT_ERR_MEMORY, "%s: out of memory for %lld triangles", path,
                         f.triangles);
    }
    if (st == ZT_OK) {
        m->triangle_count = 0; /* counted again as they are kept */
        f.m = m;
        f.vertices = 0;
        st = walk(&f, sc->mRootNode, &id, 0);
    }
    if (st == ZT_OK) {
        m->skipped_degenerate = f.skipped;
        m->replaced_normals = f.bad_normals;
        if (m->triangle_count == 0)
            st = zt_fail(err, ZT_ERR_PARSE, "%s: the model has no triangles left (%d were "
                         "degenerate or had vertices that are not finite)", path, f.skipped);
    }
    if (st == ZT_OK) {
        finish_normals(m);
        st = model_materials(sc, path, f.slot_of_material, f.slots ? f.slots : 1, m, err);
    }
    if (st == ZT_OK && m->tangent) {
        /* Tangents serve normal maps alone. */
        int used = 0;
        for (int s = 0; s < m->slot_count; s++)
            used |= m->slots[s].normal_texture >= 0;
        if (!used) {
            free(m->tangent);
            m->tangent = NULL;
        }
    }
    if (st == ZT_OK)
        st = mesh_split_emissive(m, path, &m->emissive_pieces, err);
    if (st == ZT_OK && camera)
        read_camera(sc, path, camera);
    free(f.slot_of_material);
    aiReleaseImport(sc);
    if (st != ZT_OK) {
        mesh_release(m);
        return st;
    }
    snprintf(m->file, sizeof m->file, "%s", path);
    *out = m;
    return ZT_OK;
}
