/* Primary-ray throughput of voxdag_raycast, one thread and all threads, next
   to NanoVDB's hierarchical DDA over the same voxels when its headers are
   installed (BENCH_NANOVDB) and to Embree on the source triangles of mesh
   scenes (BENCH_EMBREE). Prints a markdown table.
     bench_rays DATA_DIR [--quick] [--size N]
   Every scene is viewed from the same diagonal direction, framed on its
   voxels' bounding sphere (fov 40 degrees), N x N rays (default 512). Meshes
   are voxelized by the library (voxdag_builder_add_mesh, the grid fitted to
   the bounding box as `vdag build` does); Embree traces the same triangles in
   the same grid units. Agreement = share of rays on which a voxel peer gives
   the same hit voxel or both miss (NanoVDB marches in float with a small
   forward nudge, so near edges and corners it may pick a neighbour). Besides
   wall-clock rays/s, rays per CPU-second (getrusage: user + system time of
   the process) are reported, which other load on the machine disturbs less.
   A second table sets format version 3 (this voxdag.h) against version 2
   (the last version-2 voxdag.h, bench/v2.c; BENCH_NO_V2 leaves it out) on the
   same voxels: the same primary rays, and voxdag_lookup with index on a fixed
   random point set (half of them voxels of the scene, half uniform in its
   bounding box), after checking that both versions give the same hit voxel
   and voxel index for every ray and the same answer and index for every
   point. */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#include "bench/scenes.h"
#include "bench/bench_rays_peer.h"
#include "bench/v2.h"

#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>
#ifdef BENCH_EMBREE
#include <embree3/rtcore.h>
#endif

typedef struct rays {
    size_t n;
    double eye[3], *dir; /* 3 per ray, normalized */
    uint32_t *order;     /* the ray indices in 8 x 8 tiles, tile rows top to bottom (batches, packets) */
} rays;

enum { TILE = 8, CHUNK = 256 }; /* a batch call: 4 tiles */

static void make_rays(const bscene *s, uint32_t size, rays *r) {
    double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30}, c[3], rad = 0, f[3] = {-0.6, -1.0, -0.8};
    double up[3] = {0, 0, 1}, rt[3], u[3], tn = tan(20 * 3.14159265358979323846 / 180), len;
    size_t i;
    uint32_t x, y, k;
    for (i = 0; i < s->n; i++)
        for (k = 0; k < 3; k++) {
            if (s->xyz[3 * i + k] < lo[k]) lo[k] = s->xyz[3 * i + k];
            if (s->xyz[3 * i + k] + 1.0 > hi[k]) hi[k] = s->xyz[3 * i + k] + 1.0;
        }
    for (k = 0; k < 3; k++) c[k] = (lo[k] + hi[k]) / 2, rad += (hi[k] - lo[k]) * (hi[k] - lo[k]) / 4;
    rad = sqrt(rad);
    len = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (k = 0; k < 3; k++) f[k] /= len, r->eye[k] = c[k] - f[k] * rad * sqrt(1 + 1 / (tn * tn));
    rt[0] = f[1] * up[2] - f[2] * up[1], rt[1] = f[2] * up[0] - f[0] * up[2], rt[2] = f[0] * up[1] - f[1] * up[0];
    len = sqrt(rt[0] * rt[0] + rt[1] * rt[1] + rt[2] * rt[2]);
    for (k = 0; k < 3; k++) rt[k] /= len;
    u[0] = rt[1] * f[2] - rt[2] * f[1], u[1] = rt[2] * f[0] - rt[0] * f[2], u[2] = rt[0] * f[1] - rt[1] * f[0];
    r->n = (size_t)size * size;
    r->dir = (double *)bench_xmalloc(3 * r->n * sizeof(double));
    for (y = 0; y < size; y++)
        for (x = 0; x < size; x++) {
            double sx = (2 * (x + 0.5) / size - 1) * tn, sy = (1 - 2 * (y + 0.5) / size) * tn, *d;
            d = r->dir + 3 * ((size_t)y * size + x);
            for (k = 0; k < 3; k++) d[k] = f[k] + sx * rt[k] + sy * u[k];
            len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            for (k = 0; k < 3; k++) d[k] /= len;
        }
    r->order = (uint32_t *)bench_xmalloc(r->n * sizeof(uint32_t));
    i = 0;
    for (y = 0; y < size; y += TILE)
        for (x = 0; x < size; x += TILE) {
            uint32_t a, b;
            for (b = y; b < y + TILE && b < size; b++)
                for (a = x; a < x + TILE && a < size; a++) r->order[i++] = b * size + a;
        }
}

// -- Timed runs over all rays, split across threads by interleaved rows

typedef struct run {
    const rays *r;
    const voxdag *dag;
    const bench_v2 *v2;
    const bench_peer *peer;
    const void *embree; /* an RTCScene */
    unsigned packet;    /* voxdag: 0 one call per ray, else voxdag_raycast_many on CHUNK rays in tile order;
                           Embree: 1 rtcIntersect1, 8 or 16 rtcIntersect8/16 on 8 x 1 and 8 x 2 parts of tiles */
    uint32_t *hit_xyz; /* 3 per ray; UINT32_MAX = miss */
    uint64_t *hit_index; /* voxdag and version 2: the hit voxel's index, when not NULL */
    unsigned thread, threads;
    size_t hits;
} run;

/* voxdag_raycast_many on chunks of CHUNK rays in tile order, chunks
   interleaved between threads. */
static void run_batches(run *w) {
    voxdag_ray chunk[CHUNK];
    voxdag_hit hits[CHUNK];
    uint8_t got[CHUNK];
    size_t c, j, m;
    for (c = (size_t)w->thread * CHUNK; c < w->r->n; c += (size_t)w->threads * CHUNK) {
        m = w->r->n - c < CHUNK ? w->r->n - c : CHUNK;
        for (j = 0; j < m; j++) {
            memcpy(chunk[j].origin, w->r->eye, sizeof chunk[j].origin);
            memcpy(chunk[j].dir, w->r->dir + 3 * (size_t)w->r->order[c + j], sizeof chunk[j].dir);
            chunk[j].t_min = 0, chunk[j].t_max = HUGE_VAL;
        }
        voxdag_raycast_many(w->dag, chunk, m, NULL, hits, got);
        for (j = 0; j < m; j++) {
            uint32_t *out = w->hit_xyz + 3 * (size_t)w->r->order[c + j];
            if (got[j]) memcpy(out, hits[j].xyz, sizeof hits[j].xyz);
            else out[0] = out[1] = out[2] = UINT32_MAX;
            w->hits += got[j];
        }
    }
}

#ifdef BENCH_EMBREE
/* Embree's packets of N rays (RTCRayHitN) on tiles in tile order, packets
   interleaved between threads; hits are marked as in run_worker. */
#define EMBREE_PACKETS(N)                                                                                         \
    static void run_embree##N(run *w) {                                                                           \
        struct RTCIntersectContext ctx;                                                                           \
        struct RTCRayHit##N rh;                                                                                   \
        int valid[N];                                                                                             \
        size_t c, j, m;                                                                                           \
        rtcInitIntersectContext(&ctx);                                                                            \
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;                                                          \
        for (c = (size_t)w->thread * N; c < w->r->n; c += (size_t)w->threads * N) {                               \
            m = w->r->n - c < N ? w->r->n - c : N;                                                                \
            memset(&rh, 0, sizeof rh);                                                                            \
            for (j = 0; j < N; j++) {                                                                             \
                const double *d = w->r->dir + 3 * (size_t)w->r->order[c + (j < m ? j : 0)];                       \
                valid[j] = j < m ? -1 : 0;                                                                        \
                rh.ray.org_x[j] = (float)w->r->eye[0], rh.ray.org_y[j] = (float)w->r->eye[1];                     \
                rh.ray.org_z[j] = (float)w->r->eye[2];                                                            \
                rh.ray.dir_x[j] = (float)d[0], rh.ray.dir_y[j] = (float)d[1], rh.ray.dir_z[j] = (float)d[2];      \
                rh.ray.tnear[j] = 0, rh.ray.tfar[j] = INFINITY, rh.ray.mask[j] = ~0u;                             \
                rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;                                                       \
            }                                                                                                     \
            rtcIntersect##N(valid, (RTCScene)(uintptr_t)w->embree, &ctx, &rh);                                    \
            for (j = 0; j < m; j++) {                                                                             \
                uint32_t *out = w->hit_xyz + 3 * (size_t)w->r->order[c + j];                                      \
                int got = rh.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID;                                            \
                out[0] = out[1] = out[2] = got ? 0 : UINT32_MAX;                                                  \
                w->hits += (size_t)got;                                                                           \
            }                                                                                                     \
        }                                                                                                         \
    }
EMBREE_PACKETS(8)
EMBREE_PACKETS(16)
#endif

static void *run_worker(void *arg) {
    run *w = (run *)arg;
    size_t i;
    w->hits = 0;
    if (w->packet && w->dag) {
        run_batches(w);
        return NULL;
    }
#ifdef BENCH_EMBREE
    if (w->packet == 8 || w->packet == 16) {
        if (w->packet == 8) run_embree8(w);
        else run_embree16(w);
        return NULL;
    }
#endif
    for (i = w->thread; i < w->r->n; i += w->threads) {
        uint32_t *out = w->hit_xyz + 3 * i;
        int got;
        if (w->dag) {
            voxdag_ray ray;
            voxdag_ray_opts opts;
            voxdag_hit hit;
            memcpy(ray.origin, w->r->eye, sizeof ray.origin);
            memcpy(ray.dir, w->r->dir + 3 * i, sizeof ray.dir);
            ray.t_min = 0, ray.t_max = HUGE_VAL;
            memset(&opts, 0, sizeof opts);
            opts.want_index = w->hit_index != NULL;
            got = voxdag_raycast(w->dag, &ray, w->hit_index ? &opts : NULL, &hit);
            if (got) memcpy(out, hit.xyz, sizeof hit.xyz);
            if (w->hit_index) w->hit_index[i] = got ? hit.index : UINT64_MAX;
        } else if (w->v2) {
            uint64_t index;
            got = bench_v2_raycast(w->v2, w->r->eye, w->r->dir + 3 * i, out, w->hit_index ? &index : NULL);
            if (w->hit_index) w->hit_index[i] = got ? index : UINT64_MAX;
        } else if (w->peer) {
            got = bench_peer_trace(w->peer, w->r->eye, w->r->dir + 3 * i, out);
        } else {
#ifdef BENCH_EMBREE
            struct RTCIntersectContext ctx;
            struct RTCRayHit rh;
            const double *d = w->r->dir + 3 * i;
            rtcInitIntersectContext(&ctx);
            memset(&rh, 0, sizeof rh);
            rh.ray.org_x = (float)w->r->eye[0], rh.ray.org_y = (float)w->r->eye[1], rh.ray.org_z = (float)w->r->eye[2];
            rh.ray.dir_x = (float)d[0], rh.ray.dir_y = (float)d[1], rh.ray.dir_z = (float)d[2];
            rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.mask = ~0u;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1((RTCScene)(uintptr_t)w->embree, &ctx, &rh);
            got = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            out[0] = out[1] = out[2] = 0;
#else
            got = 0;
#endif
        }
        if (!got) out[0] = out[1] = out[2] = UINT32_MAX;
        w->hits += (size_t)got;
    }
    return NULL;
}

static double cpu_seconds(void) {
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_utime.tv_sec + u.ru_utime.tv_usec * 1e-6 + (double)u.ru_stime.tv_sec +
           u.ru_stime.tv_usec * 1e-6;
}

typedef struct speed {
    double wall, cpu; /* rays per wall-clock second and per CPU-second, best of 3 */
} speed;

/* Best of 3 runs; fills HIT_XYZ. */
static speed timed_packets(const rays *r, const voxdag *dag, const bench_v2 *v2, const bench_peer *peer,
                           const void *embree, unsigned packet, unsigned threads, uint32_t *hit_xyz, size_t *hits) {
    speed best = {0, 0};
    int rep;
    for (rep = 0; rep < 3; rep++) {
        run w[64];
        pthread_t tid[64];
        unsigned t;
        double t0 = bench_now(), c0 = cpu_seconds(), secs, cpu;
        *hits = 0;
        for (t = 0; t < threads; t++) {
            w[t].r = r, w[t].dag = dag, w[t].v2 = v2, w[t].peer = peer, w[t].embree = embree;
            w[t].hit_xyz = hit_xyz, w[t].hit_index = NULL, w[t].packet = packet;
            w[t].thread = t, w[t].threads = threads;
            if (threads == 1) run_worker(&w[0]);
            else pthread_create(&tid[t], NULL, run_worker, &w[t]);
        }
        for (t = 0; t < threads; t++) {
            if (threads > 1) pthread_join(tid[t], NULL);
            *hits += w[t].hits;
        }
        secs = bench_now() - t0;
        cpu = cpu_seconds() - c0;
        if (r->n / secs > best.wall) best.wall = (double)r->n / secs;
        if (cpu > 0 && r->n / cpu > best.cpu) best.cpu = (double)r->n / cpu;
    }
    return best;
}

/* One call per ray (rtcIntersect1 for Embree). */
static speed timed(const rays *r, const voxdag *dag, const bench_v2 *v2, const bench_peer *peer, const void *embree,
                   unsigned threads, uint32_t *hit_xyz, size_t *hits) {
    return timed_packets(r, dag, v2, peer, embree, 0, threads, hit_xyz, hits);
}

// -- Scenes: the DAG, the voxels (for NanoVDB), the source triangles (for Embree)

typedef struct scene {
    bscene v;
    voxdag *dag;
    bmesh mesh; /* source triangles in grid units; empty for voxel scenes */
} scene;

static int build_dag(scene *s, unsigned threads) {
    voxdag_build_opts o;
    voxdag_builder *b;
    memset(&o, 0, sizeof o);
    o.levels = s->v.levels;
    o.threads = threads;
    return voxdag_builder_create(&o, &b, NULL) == VOXDAG_OK && voxdag_builder_add(b, s->v.xyz, NULL, s->v.n, NULL) == VOXDAG_OK &&
           voxdag_builder_finish(b, &s->dag, NULL, NULL) == VOXDAG_OK;
}

/* A mesh voxelized by the library into 2^L, fitted to its bounding box. */
static int scene_mesh(scene *s, const char *path, const char *name, uint32_t L, unsigned threads) {
    memset(s, 0, sizeof *s);
    if (!bmesh_load(&s->mesh, path, L)) return 0;
    s->dag = bmesh_voxelize(&s->mesh, L, threads, NULL);
    bscene_from_dag(&s->v, s->dag, L);
    snprintf(s->v.name, sizeof s->v.name, "%s", name);
    return 1;
}

#ifdef BENCH_EMBREE
static bool embree_memory(void *user, ssize_t bytes, bool post) {
    (void)post;
    *(long long *)user += (long long)bytes;
    return true;
}

/* The triangles of S in an Embree scene (default build quality); *BYTES: the
   memory Embree reported allocating for it. */
static RTCScene embree_scene(RTCDevice dev, const bmesh *s) {
    RTCScene sc = rtcNewScene(dev);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = (float *)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                s->verts);
    unsigned *t = (unsigned *)rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                      3 * sizeof(unsigned), s->tris);
    size_t i;
    for (i = 0; i < 3 * s->verts; i++) v[i] = (float)s->pos[i];
    for (i = 0; i < 3 * s->tris; i++) t[i] = s->idx[i];
    rtcCommitGeometry(g);
    rtcAttachGeometry(sc, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(sc);
    return sc;
}
#endif

// -- Batches: primary rays through voxdag_raycast_many, shadow rays through voxdag_occluded_many

static const double LIGHT[3] = {0.5, 0.3, 0.8}; /* towards the light, as vdag render's default */

/* Shadow rays towards LIGHT from the lit hits of R's rays (voxdag_ray_from_hit),
   in tile order, as a renderer casts them; *N: how many. */
static voxdag_ray *shadow_rays(const rays *r, const voxdag *dag, size_t *n) {
    voxdag_ray *out = (voxdag_ray *)bench_xmalloc((r->n + 1) * sizeof *out), ray;
    voxdag_hit hit;
    size_t i;
    *n = 0;
    memset(&ray, 0, sizeof ray);
    memcpy(ray.origin, r->eye, sizeof ray.origin);
    ray.t_max = HUGE_VAL;
    for (i = 0; i < r->n; i++) {
        memcpy(ray.dir, r->dir + 3 * (size_t)r->order[i], sizeof ray.dir);
        if (voxdag_raycast(dag, &ray, NULL, &hit) == 1 && voxdag_ray_from_hit(dag, &ray, &hit, LIGHT, &out[*n]) > 0)
            ++*n;
    }
    return out;
}

/* Shadow rays per CPU-second, best of 3, one thread: voxdag_occluded per
   ray (BATCH 0) or voxdag_occluded_many on CHUNK rays at a time; OCC: the
   answers. */
static double timed_shadows(const voxdag *dag, const voxdag_ray *shadow, size_t n, int batch, uint8_t *occ) {
    double best = 0;
    int rep;
    for (rep = 0; rep < 3; rep++) {
        double c0 = cpu_seconds(), cpu;
        size_t i;
        for (i = 0; i < n; i += batch ? CHUNK : 1) {
            if (batch) voxdag_occluded_many(dag, shadow + i, n - i < CHUNK ? n - i : CHUNK, NULL, occ + i);
            else occ[i] = (uint8_t)voxdag_occluded(dag, &shadow[i]);
        }
        cpu = cpu_seconds() - c0;
        if (cpu > 0 && n / cpu > best) best = (double)n / cpu;
    }
    return best;
}

// -- Format version 3 against version 2: the same rays and points

/* NP lookup points (3 per point): half random voxels of S, half uniform in
   the bounding box of its voxels; a fixed seed. */
static uint32_t *make_points(const bscene *s, size_t np) {
    uint32_t *p = (uint32_t *)bench_xmalloc(3 * np * sizeof(uint32_t)), lo[3] = {UINT32_MAX, UINT32_MAX, UINT32_MAX},
             hi[3] = {0, 0, 0}, k;
    uint64_t seed = 0x9E3779B97F4A7C15ull;
    size_t i;
    for (i = 0; i < s->n; i++)
        for (k = 0; k < 3; k++) {
            if (s->xyz[3 * i + k] < lo[k]) lo[k] = s->xyz[3 * i + k];
            if (s->xyz[3 * i + k] > hi[k]) hi[k] = s->xyz[3 * i + k];
        }
    for (i = 0; i < np; i++) {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        if (i & 1 || !s->n) {
            for (k = 0; k < 3; k++) {
                seed = seed * 6364136223846793005ull + 1442695040888963407ull;
                p[3 * i + k] = lo[k] + (uint32_t)((seed >> 33) % ((uint64_t)hi[k] - lo[k] + 1));
            }
        } else {
            memcpy(p + 3 * i, s->xyz + 3 * (size_t)((seed >> 20) % s->n), 3 * sizeof(uint32_t));
        }
    }
    return p;
}

/* voxdag_lookup with index (DAG, else version 2's V2) at the NP points, one
   thread: lookups per CPU-second. INDEX[i]: the voxel index of point i,
   UINT64_MAX when it is empty. */
static double timed_lookups(const voxdag *dag, const bench_v2 *v2, const uint32_t *p, size_t np, uint64_t *index) {
    double c0 = cpu_seconds(), cpu;
    size_t i;
    for (i = 0; i < np; i++) {
        const uint32_t *x = p + 3 * i;
        int got = dag ? voxdag_lookup(dag, x[0], x[1], x[2], index + i) : bench_v2_lookup(v2, x[0], x[1], x[2], index + i);
        if (!got) index[i] = UINT64_MAX;
    }
    cpu = cpu_seconds() - c0;
    return cpu > 0 ? (double)np / cpu : 0;
}

/* Rays with the voxel index (one thread, untimed) into XYZ and INDEX. */
static void indexed_rays(const rays *r, const voxdag *dag, const bench_v2 *v2, uint32_t *xyz, uint64_t *index) {
    run w;
    memset(&w, 0, sizeof w);
    w.r = r, w.dag = dag, w.v2 = v2, w.hit_xyz = xyz, w.hit_index = index, w.threads = 1;
    run_worker(&w);
}

/* One row of the version table for scene S, appended to OUT; 0 without
   version 2. The two versions are timed in turn (rays: 2 x best of 3 each;
   lookups: best of 4 each), so that a change in the machine's load between
   them moves both. */
static int versions_row(const scene *s, const rays *r, unsigned threads, char *out, size_t cap) {
    enum { POINTS = 1 << 19 };
    bench_v2 *v2 = bench_v2_build(s->v.xyz, s->v.n, s->v.levels, threads);
    uint32_t *xyz3, *xyz2, *p;
    uint64_t *index3, *index2;
    size_t hits, j, same = 0, same_points = 0, found = 0;
    speed mine = {0, 0}, theirs = {0, 0}, t;
    double look3 = 0, look2 = 0, u;
    int rep;
    if (!v2) return 0;
    xyz3 = (uint32_t *)bench_xmalloc(3 * r->n * sizeof(uint32_t));
    xyz2 = (uint32_t *)bench_xmalloc(3 * r->n * sizeof(uint32_t));
    index3 = (uint64_t *)bench_xmalloc((r->n > POINTS ? r->n : POINTS) * sizeof(uint64_t));
    index2 = (uint64_t *)bench_xmalloc((r->n > POINTS ? r->n : POINTS) * sizeof(uint64_t));
    for (rep = 0; rep < 2; rep++) {
        t = timed(r, s->dag, NULL, NULL, NULL, 1, xyz3, &hits);
        if (t.cpu > mine.cpu) mine = t;
        t = timed(r, NULL, v2, NULL, NULL, 1, xyz2, &hits);
        if (t.cpu > theirs.cpu) theirs = t;
    }
    indexed_rays(r, s->dag, NULL, xyz3, index3);
    indexed_rays(r, NULL, v2, xyz2, index2);
    for (j = 0; j < r->n; j++)
        same += !memcmp(xyz3 + 3 * j, xyz2 + 3 * j, 3 * sizeof(uint32_t)) && index3[j] == index2[j];
    p = make_points(&s->v, POINTS);
    for (rep = 0; rep < 4; rep++) {
        if ((u = timed_lookups(s->dag, NULL, p, POINTS, index3)) > look3) look3 = u;
        if ((u = timed_lookups(NULL, v2, p, POINTS, index2)) > look2) look2 = u;
    }
    for (j = 0; j < POINTS; j++) {
        same_points += index3[j] == index2[j];
        found += index3[j] != UINT64_MAX;
    }
    if (same != r->n || same_points != POINTS)
        fprintf(stderr, "bench_rays: %s: versions 3 and 2 disagree on %zu of %zu rays and %zu of %d points\n",
                s->v.name, r->n - same, r->n, POINTS - same_points, (int)POINTS);
    snprintf(out, cap, "| %s | %u | %zu | %.2f | %.2f | **%.2f** | %d (%.0f%% full) | %.2f | %.2f | **%.2f** | %s |\n",
             s->v.name, s->v.levels, s->v.n, mine.cpu * 1e-6, theirs.cpu * 1e-6, mine.cpu / theirs.cpu, (int)POINTS,
             100.0 * found / POINTS, look3 * 1e-6, look2 * 1e-6, look3 / look2,
             same == r->n && same_points == POINTS ? "yes" : "**no**");
    free(p), free(xyz3), free(xyz2), free(index3), free(index2);
    bench_v2_free(v2);
    return 1;
}

static void row(const char *scene_name, uint32_t L, size_t voxels, const char *engine, double mb, size_t hits,
                size_t n, speed one, speed all, const speed *ref, double agree) {
    printf("| %s | %u | %zu | %s | %.2f | %.1f%% | %.2f | %.2f | %.2f | %.2f |", scene_name, L, voxels, engine, mb,
           100.0 * hits / n, one.wall * 1e-6, one.cpu * 1e-6, all.wall * 1e-6, all.cpu * 1e-6);
    if (ref) printf(" %.2f | %.2f |", ref->cpu / one.cpu, ref[1].cpu / all.cpu);
    else printf(" | |");
    if (agree >= 0) printf(" %.2f%% |\n", agree);
    else printf(" |\n");
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "bench/data";
    int quick = 0, i;
    uint32_t size = 512;
    unsigned threads;
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    size_t k;
    char path[512], versions[4096] = "", batches[4096] = "";
    static const struct {
        const char *file;
        uint32_t L;
        int full_only;
    } plan[] = {{"tree.vox", 0, 0}, {"bunny.off", 11, 0}, {"bunny.off", 12, 1}, {"dragon.off", 11, 1},
                {"terrain", 11, 1}, {"terrain", 10, 0}};
#ifdef BENCH_EMBREE
    RTCDevice dev = rtcNewDevice(NULL);
    long long embree_bytes = 0;
    rtcSetDeviceMemoryMonitorFunction(dev, embree_memory, &embree_bytes);
#endif
    for (i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = (uint32_t)atoi(argv[++i]);
    }
    threads = cpus < 1 ? 1 : cpus > 64 ? 64 : (unsigned)cpus;

    printf("### Primary rays (%ux%u per scene, best of 3; 1 and %u threads)\n\n", size, size, threads);
#ifdef BENCH_NANOVDB
    printf("Voxel peer: %s.", bench_peer_name());
#else
    printf("(NanoVDB headers not installed: no voxel peer.)");
#endif
#ifdef BENCH_EMBREE
    printf(" Triangle peer: Embree %d.%d.%d (`rtcIntersect1`, default BVH) on the source triangles of the mesh scenes.\n\n",
           RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH);
#else
    printf(" (Embree headers not installed: no triangle peer.)\n\n");
#endif
    printf("| scene | L | voxels | engine | MB | hit rays | Mrays/s, 1 thread | Mrays/CPU-s, 1 thread | Mrays/s, %u threads "
           "| Mrays/CPU-s, %u threads | voxdag speed-up, 1 thread (CPU-s) | voxdag speed-up, %u threads (CPU-s) "
           "| agreement with voxdag |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
           threads, threads, threads);
    for (k = 0; k < sizeof plan / sizeof plan[0]; k++) {
        scene s;
        voxdag_info info;
        rays r;
        uint32_t *mine;
        size_t hits, batch_hits, shadow_n, ray_i, same_batch = 0, same_shadows = 0;
        speed mine_speed[2], single = {0, 0}, batch = {0, 0}, t, embree_best = {0, 0};
        const char *embree_call = "";
        uint32_t *batch_xyz;
        voxdag_ray *shadows;
        uint8_t *occ1, *occ2;
        double shadow1 = 0, shadow2 = 0, u;
        int rep;
        if (quick ? plan[k].full_only : plan[k].L == 10) continue;
        memset(&s, 0, sizeof s);
        snprintf(path, sizeof path, "%s/%s", dir, plan[k].file);
        if (!strcmp(plan[k].file, "terrain")) {
            bscene_terrain(&s.v, plan[k].L);
            if (!build_dag(&s, threads)) return 1;
        } else if (!strcmp(plan[k].file, "tree.vox")) {
            if (!bscene_vox(&s.v, path, "tree.vox")) continue;
            if (!build_dag(&s, threads)) return 1;
        } else if (!scene_mesh(&s, path, plan[k].file, plan[k].L, threads)) {
            continue;
        }
        fprintf(stderr, "bench_rays: %s (L=%u, %zu voxels)\n", s.v.name, s.v.levels, s.v.n);
        voxdag_get_info(s.dag, &info);
        make_rays(&s.v, size, &r);
        mine = (uint32_t *)bench_xmalloc(3 * r.n * sizeof(uint32_t));
        mine_speed[0] = timed(&r, s.dag, NULL, NULL, NULL, 1, mine, &hits);
        mine_speed[1] = timed(&r, s.dag, NULL, NULL, NULL, threads, mine, &hits);
        row(s.v.name, s.v.levels, s.v.n, "voxdag", (info.node_bytes + info.brick_bytes) / 1e6, hits, r.n,
            mine_speed[0], mine_speed[1], NULL, -1);
        fflush(stdout);
        /* batch against one call per ray, in turn (best of 9 each), so that a
           change in the machine's load moves both */
        batch_xyz = (uint32_t *)bench_xmalloc(3 * r.n * sizeof(uint32_t));
        for (rep = 0; rep < 3; rep++) {
            if ((t = timed(&r, s.dag, NULL, NULL, NULL, 1, mine, &hits)).cpu > single.cpu) single = t;
            if ((t = timed_packets(&r, s.dag, NULL, NULL, NULL, 1, 1, batch_xyz, &batch_hits)).cpu > batch.cpu) batch = t;
        }
        for (ray_i = 0; ray_i < r.n; ray_i++)
            same_batch += !memcmp(mine + 3 * ray_i, batch_xyz + 3 * ray_i, 3 * sizeof(uint32_t));
        shadows = shadow_rays(&r, s.dag, &shadow_n);
        occ1 = (uint8_t *)bench_xmalloc(shadow_n + 1), occ2 = (uint8_t *)bench_xmalloc(shadow_n + 1);
        for (rep = 0; rep < 3; rep++) {
            if ((u = timed_shadows(s.dag, shadows, shadow_n, 0, occ1)) > shadow1) shadow1 = u;
            if ((u = timed_shadows(s.dag, shadows, shadow_n, 1, occ2)) > shadow2) shadow2 = u;
        }
        for (ray_i = 0; ray_i < shadow_n; ray_i++) same_shadows += occ1[ray_i] == occ2[ray_i];
#ifdef BENCH_NANOVDB
        {
            size_t bytes, same = 0, j, peer_hits;
            uint32_t *theirs = (uint32_t *)bench_xmalloc(3 * r.n * sizeof(uint32_t));
            bench_peer *p = bench_peer_build(s.v.xyz, s.v.n, &bytes);
            speed one = timed(&r, NULL, NULL, p, NULL, 1, theirs, &peer_hits);
            speed all = timed(&r, NULL, NULL, p, NULL, threads, theirs, &peer_hits);
            for (j = 0; j < r.n; j++) same += !memcmp(mine + 3 * j, theirs + 3 * j, 3 * sizeof(uint32_t));
            row(s.v.name, s.v.levels, s.v.n, "NanoVDB", bytes / 1e6, peer_hits, r.n, one, all, mine_speed,
                100.0 * same / r.n);
            bench_peer_free(p);
            free(theirs);
        }
#endif
#ifdef BENCH_EMBREE
        if (s.mesh.tris) {
            size_t peer_hits;
            uint32_t *theirs = (uint32_t *)bench_xmalloc(3 * r.n * sizeof(uint32_t));
            RTCScene es;
            speed one, all;
            embree_bytes = 0;
            es = embree_scene(dev, &s.mesh);
            one = timed(&r, NULL, NULL, NULL, es, 1, theirs, &peer_hits);
            all = timed(&r, NULL, NULL, NULL, es, threads, theirs, &peer_hits);
            embree_best = one, embree_call = "rtcIntersect1";
            if ((t = timed_packets(&r, NULL, NULL, NULL, es, 8, 1, theirs, &peer_hits)).cpu > embree_best.cpu)
                embree_best = t, embree_call = "rtcIntersect8";
            if ((t = timed_packets(&r, NULL, NULL, NULL, es, 16, 1, theirs, &peer_hits)).cpu > embree_best.cpu)
                embree_best = t, embree_call = "rtcIntersect16";
            row(s.v.name, s.v.levels, s.v.n, "Embree (triangles)", embree_bytes / 1e6, peer_hits, r.n, one, all,
                mine_speed, -1);
            rtcReleaseScene(es);
            free(theirs);
        }
#endif
        fflush(stdout);
        {
            size_t len = strlen(batches);
            char embree_cols[128] = "| | | ";
            if (embree_best.cpu > 0)
                snprintf(embree_cols, sizeof embree_cols, "| %.2f (`%s`) | %.2f | **%.2f** ", embree_best.cpu * 1e-6,
                         embree_call, single.cpu / embree_best.cpu, batch.cpu / embree_best.cpu);
            snprintf(batches + len, sizeof batches - len,
                     "| %s | %u | %.2f | %.2f | **%.2f** %s| %zu | %.2f | %.2f | **%.2f** | %s |\n", s.v.name,
                     s.v.levels, single.cpu * 1e-6, batch.cpu * 1e-6, batch.cpu / single.cpu, embree_cols, shadow_n,
                     shadow1 * 1e-6, shadow2 * 1e-6, shadow2 / shadow1,
                     same_batch == r.n && same_shadows == shadow_n ? "yes" : "**no**");
        }
        free(batch_xyz), free(shadows), free(occ1), free(occ2);
        versions_row(&s, &r, threads, versions + strlen(versions), sizeof versions - strlen(versions));
        free(r.order);
        free(mine);
        free(r.dir);
        bmesh_free(&s.mesh);
        voxdag_free(s.dag);
        bscene_free(&s.v);
    }
    printf("\nMB: voxdag, encoded nodes and bricks (geometry only); NanoVDB, the grid buffer; Embree, the bytes its "
           "memory monitor reported for the scene (BVH and copies of the triangles). Mrays/CPU-s: rays per second of "
           "process CPU time (getrusage), less sensitive than wall-clock time to other jobs on a shared machine. "
           "Speed-up: voxdag's rays per CPU-second divided by the peer's. Mesh voxels come from "
           "`voxdag_builder_add_mesh` (exact conservative voxelization, the grid fitted to the bounding box).\n");
    printf("\n### Ray batches (1 thread, rays per CPU-second)\n\n"
           "| scene | L | voxdag_raycast Mrays/CPU-s | voxdag_raycast_many Mrays/CPU-s | batch / single "
           "| Embree at its best Mrays/CPU-s | single / Embree | batch / Embree | shadow rays "
           "| voxdag_occluded Mrays/CPU-s | voxdag_occluded_many Mrays/CPU-s | batch / single | same answers |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n%s\n"
           "The primary rays above; batches of %d rays in 8 x 8 tiles (`voxdag_raycast_many`), one call per ray and "
           "the batches timed in turn (best of 9 each). Embree at its best: the fastest of `rtcIntersect1` and its "
           "packets of 8 (8 x 1 in a tile) and 16 (8 x 2, coherent flag), one thread. Shadow rays: from the lit "
           "hits towards (0.5, 0.3, 0.8) through `voxdag_ray_from_hit`, in tile order, `voxdag_occluded` per ray "
           "against `voxdag_occluded_many` on %d rays at a time, in turn (best of 9 each). Same: the batch calls "
           "give every ray's hit voxel and every shadow ray's answer of the single calls, checked in this run.\n",
           batches, (int)CHUNK, (int)CHUNK);
    if (versions[0])
        printf("\n### Format version 3 against version 2 (same voxels, rays and points; 1 thread)\n\n"
               "| scene | L | voxels | v3 Mrays/CPU-s | v2 Mrays/CPU-s | v3 / v2 rays | lookup points | v3 M lookups/CPU-s "
               "| v2 M lookups/CPU-s | v3 / v2 lookups | same hits and indices |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|\n%s\n"
               "Version 2: the last version-2 voxdag.h (git history), built from the same voxels. Rays: the primary "
               "rays above, the two versions timed in turn (best of 6 each). Lookups: `voxdag_lookup` with the voxel index, half of the points "
               "voxels of the scene, half uniform in its bounding box, timed in turn, best of 4. Same: every ray hits the same voxel "
               "with the same index (or both miss) and every point gives the same answer and index, checked in this "
               "run.\n",
               versions);
#ifdef BENCH_EMBREE
    rtcReleaseDevice(dev);
#endif
    return 0;
}
