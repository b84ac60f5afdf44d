/* Primary-ray throughput of voxdag_raycast, one thread and all threads, next
   to NanoVDB's hierarchical DDA over the same voxels when its headers are
   installed (BENCH_NANOVDB). Prints a markdown table.
     bench_rays DATA_DIR [--quick] [--size N]
   Every scene is viewed from the same diagonal direction, framed on its
   voxels' bounding sphere (fov 40 degrees), N x N rays (default 512). Agreement
   = share of rays on which both give the same hit voxel or both miss
   (NanoVDB marches in float with a small forward nudge, so near edges and
   corners it may pick a neighbour). */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#include "bench/scenes.h"
#include "bench/bench_rays_peer.h"

#include <pthread.h>
#include <unistd.h>

typedef struct rays {
    size_t n;
    double eye[3], *dir; /* 3 per ray, normalized */
} rays;

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
}

// -- Timed runs over all rays, split across threads by interleaved rows

typedef struct run {
    const rays *r;
    const voxdag *dag;
    const bench_peer *peer;
    uint32_t *hit_xyz; /* 3 per ray; UINT32_MAX = miss */
    unsigned thread, threads;
    size_t hits;
} run;

static void *run_worker(void *arg) {
    run *w = (run *)arg;
    size_t i;
    w->hits = 0;
    for (i = w->thread; i < w->r->n; i += w->threads) {
        uint32_t *out = w->hit_xyz + 3 * i;
        int got;
        if (w->dag) {
            voxdag_ray ray;
            voxdag_hit hit;
            memcpy(ray.origin, w->r->eye, sizeof ray.origin);
            memcpy(ray.dir, w->r->dir + 3 * i, sizeof ray.dir);
            ray.t_min = 0, ray.t_max = HUGE_VAL;
            got = voxdag_raycast(w->dag, &ray, NULL, &hit);
            if (got) memcpy(out, hit.xyz, sizeof hit.xyz);
        } else {
            got = bench_peer_trace(w->peer, w->r->eye, w->r->dir + 3 * i, out);
        }
        if (!got) out[0] = out[1] = out[2] = UINT32_MAX;
        w->hits += (size_t)got;
    }
    return NULL;
}

/* Best of 3 runs, in rays per second; fills HIT_XYZ. */
static double timed(const rays *r, const voxdag *dag, const bench_peer *peer, unsigned threads, uint32_t *hit_xyz,
                    size_t *hits) {
    double best = 0;
    int rep;
    for (rep = 0; rep < 3; rep++) {
        run w[64];
        pthread_t tid[64];
        unsigned t;
        double t0 = bench_now(), secs;
        *hits = 0;
        for (t = 0; t < threads; t++) {
            w[t].r = r, w[t].dag = dag, w[t].peer = peer, w[t].hit_xyz = hit_xyz;
            w[t].thread = t, w[t].threads = threads;
            if (threads == 1) run_worker(&w[0]);
            else pthread_create(&tid[t], NULL, run_worker, &w[t]);
        }
        for (t = 0; t < threads; t++) {
            if (threads > 1) pthread_join(tid[t], NULL);
            *hits += w[t].hits;
        }
        secs = bench_now() - t0;
        if (r->n / secs > best) best = (double)r->n / secs;
    }
    return best;
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "bench/data";
    int quick = 0, i;
    uint32_t size = 512;
    unsigned threads;
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    bscene scenes[8];
    size_t ns = 0, k;
    char path[512];
    for (i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = (uint32_t)atoi(argv[++i]);
    }
    threads = cpus < 1 ? 1 : cpus > 64 ? 64 : (unsigned)cpus;
    snprintf(path, sizeof path, "%s/tree.vox", dir);
    if (bscene_vox(&scenes[ns], path, "tree.vox")) ns++;
    snprintf(path, sizeof path, "%s/bunny.off", dir);
    if (bscene_mesh(&scenes[ns], path, "bunny.off", 10)) ns++;
    if (!quick) {
        snprintf(path, sizeof path, "%s/dragon.off", dir);
        if (bscene_mesh(&scenes[ns], path, "dragon.off", 11)) ns++;
    }
    bscene_terrain(&scenes[ns++], quick ? 10 : 11);

    printf("### Primary rays (%ux%u per scene, best of 3; %u threads)\n\n", size, size, threads);
#ifdef BENCH_NANOVDB
    printf("Peer: %s.\n\n", bench_peer_name());
    printf("| scene | L | voxels | hit rays | voxdag Mrays/s, 1 thread | voxdag Mrays/s, %u threads "
           "| NanoVDB Mrays/s, 1 thread | NanoVDB Mrays/s, %u threads | 1-thread ratio | voxdag MB | NanoVDB MB "
           "| agreement |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n", threads, threads);
#else
    printf("(NanoVDB headers not installed: voxdag only.)\n\n");
    printf("| scene | L | voxels | hit rays | voxdag Mrays/s, 1 thread | voxdag Mrays/s, %u threads | voxdag MB |\n"
           "|---|---|---|---|---|---|---|\n", threads);
#endif
    for (k = 0; k < ns; k++) {
        const bscene *s = &scenes[k];
        voxdag_build_opts o;
        voxdag_builder *b;
        voxdag *dag;
        voxdag_info info;
        rays r;
        uint32_t *mine;
        size_t hits;
        double one, all;
        memset(&o, 0, sizeof o);
        o.levels = s->levels;
        o.threads = threads;
        if (voxdag_builder_create(&o, &b, NULL) != VOXDAG_OK || voxdag_builder_add(b, s->xyz, NULL, s->n, NULL) ||
            voxdag_builder_finish(b, &dag, NULL, NULL) != VOXDAG_OK) {
            fprintf(stderr, "bench_rays: cannot build %s\n", s->name);
            return 1;
        }
        fprintf(stderr, "bench_rays: %s (L=%u, %zu voxels)\n", s->name, s->levels, s->n);
        voxdag_get_info(dag, &info);
        make_rays(s, size, &r);
        mine = (uint32_t *)bench_xmalloc(3 * r.n * sizeof(uint32_t));
        one = timed(&r, dag, NULL, 1, mine, &hits);
        all = timed(&r, dag, NULL, threads, mine, &hits);
        printf("| %s | %u | %zu | %.1f%% | %.2f | %.2f |", s->name, s->levels, s->n, 100.0 * hits / r.n, one * 1e-6,
               all * 1e-6);
#ifdef BENCH_NANOVDB
        {
            size_t bytes, same = 0, j, peer_hits;
            uint32_t *theirs = (uint32_t *)bench_xmalloc(3 * r.n * sizeof(uint32_t));
            bench_peer *p = bench_peer_build(s->xyz, s->n, &bytes);
            double pone = timed(&r, NULL, p, 1, theirs, &peer_hits), pall = timed(&r, NULL, p, threads, theirs, &peer_hits);
            for (j = 0; j < r.n; j++) same += !memcmp(mine + 3 * j, theirs + 3 * j, 3 * sizeof(uint32_t));
            printf(" %.2f | %.2f | %.2f | %.2f | %.2f | %.2f%% |", pone * 1e-6, pall * 1e-6, one / pone,
                   (info.node_bytes + info.brick_bytes) / 1e6, bytes / 1e6, 100.0 * same / r.n);
            bench_peer_free(p);
            free(theirs);
        }
#else
        printf(" %.2f |", (info.node_bytes + info.brick_bytes) / 1e6);
#endif
        printf("\n");
        fflush(stdout);
        free(mine);
        free(r.dir);
        voxdag_free(dag);
    }
    printf("\nvoxdag MB: encoded nodes and bricks (geometry only); NanoVDB MB: the grid buffer.\n");
    for (k = 0; k < ns; k++) bscene_free(&scenes[k]);
    return 0;
}
