/* Build throughput and memory of the voxdag builder on real and generated
   scenes; prints Markdown tables on stdout (progress on stderr).
     bench_build DATA_DIR [--quick] [--threads N] [--profile SCENE]
   DATA_DIR holds what bench/fetch.sh fetched. Times are wall-clock seconds,
   the best of a few runs for small scenes. Peak memory is the builder's own
   accounting (voxdag_build_stats.peak_memory): the voxel buffer, the sort
   buffer, the unique-node tables and the encoder, not the caller's input.
   Two tables set this builder against the last version-2 voxdag.h
   (bench/v2.c) on the same voxels and the same triangles, one thread, timed
   in turn. */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#include "bench/scenes.h"
#include "bench/v2.h"

#include <unistd.h>

static double bench_cpu(void);

#define STREAM_CHUNK ((size_t)1 << 20) /* voxels per add + flush when streaming */

typedef struct run {
    double add, reduce, encode, total, cpu; /* cpu: process CPU seconds, all threads */
    uint64_t peak;
    voxdag_build_stats st;
    uint64_t bytes;
} run;

/* Builds S from XYZ (in the given order) with THREADS; the best of REPEAT.
   ENDS (NENDS > 0): add and flush the voxels before ENDS[0], then before
   ENDS[1], ... (XYZ must be Morton-sorted); else all in one add and flush. */
static run build_chunked(const bscene *s, const uint32_t *xyz, unsigned threads, int compare, int repeat,
                         const size_t *ends, size_t nends) {
    run best;
    int r;
    memset(&best, 0, sizeof best);
    best.total = 1e300;
    for (r = 0; r < repeat; r++) {
        voxdag_build_opts o;
        voxdag_builder *b;
        voxdag *d = NULL;
        voxdag_error e;
        voxdag_info info;
        run cur;
        double t0, t1, t2, t3, c0;
        memset(&o, 0, sizeof o);
        memset(&cur, 0, sizeof cur);
        o.levels = s->levels;
        o.threads = threads;
        o.compare_structures = compare;
        c0 = bench_cpu();
        t0 = bench_now();
        if (voxdag_builder_create(&o, &b, &e) != VOXDAG_OK) {
            fprintf(stderr, "bench_build: %s\n", e.message);
            exit(1);
        }
        t1 = t0;
        {
            size_t at = 0, c = 0;
            double in_add = 0;
            do {
                size_t m = (c < nends ? ends[c++] : s->n) - at;
                double a = bench_now();
                if (voxdag_builder_add(b, xyz + 3 * at, NULL, m, &e) != VOXDAG_OK) {
                    fprintf(stderr, "bench_build: %s\n", e.message);
                    exit(1);
                }
                in_add += bench_now() - a;
                if (voxdag_builder_flush(b, &e) != VOXDAG_OK) {
                    fprintf(stderr, "bench_build: %s\n", e.message);
                    exit(1);
                }
                at += m;
            } while (at < s->n);
            t1 = t0 + in_add;
        }
        t2 = bench_now();
        if (voxdag_builder_finish(b, &d, &cur.st, &e) != VOXDAG_OK) {
            fprintf(stderr, "bench_build: %s\n", e.message);
            exit(1);
        }
        t3 = bench_now();
        cur.cpu = bench_cpu() - c0;
        voxdag_get_info(d, &info);
        cur.bytes = info.node_bytes + info.brick_bytes;
        voxdag_free(d);
        cur.add = t1 - t0;
        cur.reduce = t2 - t1;
        cur.encode = t3 - t2;
        cur.total = t3 - t0;
        cur.peak = cur.st.peak_memory;
        if (cur.st.voxels != s->n) {
            fprintf(stderr, "bench_build: %s: %llu voxels built, %zu given\n", s->name,
                    (unsigned long long)cur.st.voxels, s->n);
            exit(1);
        }
        if (cur.total < best.total) best = cur;
    }
    return best;
}

static double bench_cpu(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static run build(const bscene *s, const uint32_t *xyz, unsigned threads, int compare, int repeat) {
    return build_chunked(s, xyz, threads, compare, repeat, NULL, 0);
}

/* Chunk ends for build_chunked: every CHUNK voxels (CHUNK > 0), or (CHUNK =
   0) at the borders of the aligned 2^BENCH_CHUNK_LEVELS cells that
   voxdag_builder_add_mesh voxelizes and flushes one at a time. */
static size_t *chunk_ends(const bscene *s, size_t chunk, size_t *nends) {
    size_t *ends = (size_t *)bench_xmalloc((s->n + 1) * sizeof *ends), i, n = 0;
    uint64_t prev = 0;
    for (i = 0; i < s->n; i++) {
        uint64_t cell = voxdag_morton_encode(s->xyz[3 * i], s->xyz[3 * i + 1], s->xyz[3 * i + 2]) >>
                        (3 * BENCH_CHUNK_LEVELS);
        if (i && (chunk ? i % chunk == 0 : cell != prev)) ends[n++] = i;
        prev = cell;
    }
    ends[n++] = s->n;
    *nends = n;
    return ends;
}

/* Format version 3 (this voxdag.h) against version 2 on one thread: the
   triangles of M (when not NULL; voxelize + reduce + encode) or the
   Morton-sorted voxels of S (add + flush + finish), into 2^(S's levels).
   The two builds run in turn, REPEAT times each, so that a change in the
   machine's load moves both; CPU[0] / CPU[1] = the least process CPU seconds
   of version 3 / 2, *V2_VOXELS = version 2's voxel count. Returns 0 without
   version 2. */
static int versus_v2(const bscene *s, const bmesh *m, int repeat, double cpu[2], uint64_t *v2_voxels) {
    int r;
    cpu[0] = cpu[1] = 1e300;
    for (r = 0; r < repeat; r++) {
        double c0 = bench_cpu(), c;
        bench_v2 *d2 = m ? bench_v2_build_mesh(m->pos, m->verts, m->idx, m->tris, s->levels, BENCH_CHUNK_LEVELS, 1)
                         : bench_v2_build(s->xyz, s->n, s->levels, 1);
        c = bench_cpu() - c0;
        if (!d2) return 0;
        *v2_voxels = bench_v2_voxels(d2);
        bench_v2_free(d2);
        if (c < cpu[1]) cpu[1] = c;
        if (m) {
            voxdag *d3;
            c0 = bench_cpu();
            d3 = bmesh_voxelize(m, s->levels, 1, NULL);
            c = bench_cpu() - c0;
            voxdag_free(d3);
        } else {
            c = build(s, s->xyz, 1, 0, 1).cpu;
        }
        if (c < cpu[0]) cpu[0] = c;
    }
    return 1;
}

static void shuffle(uint32_t *xyz, size_t n) {
    uint64_t x = 0x2545F4914F6CDD1Dull;
    size_t i;
    for (i = n; i > 1; i--) {
        size_t j;
        uint32_t t[3];
        x ^= x << 13; x ^= x >> 7; x ^= x << 17;
        j = (size_t)(x % i);
        memcpy(t, xyz + 3 * (i - 1), sizeof t);
        memcpy(xyz + 3 * (i - 1), xyz + 3 * j, sizeof t);
        memcpy(xyz + 3 * j, t, sizeof t);
    }
}

typedef struct result {
    bscene *s;
    run sorted[2], unsorted[2], cmp, streamed;
    uint64_t cells2;
    double cpu[2];  /* v3, v2 CPU seconds, Morton-sorted, 1 thread */
} result;

static double mb(uint64_t b) { return (double)b / 1048576.0; }

static uint64_t sum(const uint64_t *a, uint32_t n) {
    uint64_t t = 0;
    uint32_t i;
    for (i = 0; i < n; i++) t += a[i];
    return t;
}

/* Triangle scenes (SSVDAG Table 1 shape, voxelization included): the mesh
   voxelized and reduced by voxdag_builder_add_mesh + finish, then its voxels
   reduced alone, replayed through add + flush in the same aligned cells the
   voxelizer flushes; voxelization = the difference. The rows of the table
   against version 2 (versions_table) go to VERSIONS (CAP bytes). */
static void mesh_table(const char *dir, int quick, const unsigned tcount[2], char *versions, size_t cap) {
    static const char *meshes[] = {"bunny.off", "armadillo.off", "dragon.off"};
    uint32_t L, Lmax = quick ? 11 : 12;
    size_t k, used = 0;
    printf("### Triangle scenes: voxelization and DAG reduction\n\n");
    printf("Each mesh fitted into the 2^L grid and voxelized by `voxdag_builder_add_mesh` (exact conservative "
           "voxelization, aligned 2^%u-voxel cells, each reduced as soon as it is voxelized), then `finish`: "
           "*voxelize + reduce*. *Reduce alone*: the resulting voxels, Morton-sorted, added and flushed cell by cell "
           "as the voxelizer does, then `finish`. *Voxelize* = the difference (derived). Seconds wall-clock, CPU "
           "seconds = user + system of the process (all threads); %s. Peak = the builder's accounted memory "
           "(voxelizer bins, one cell's voxels, the unique nodes, the encoder).\n\n",
           BENCH_CHUNK_LEVELS, quick ? "one run each" : "best of 3 runs below 4 M voxels, else one run");
    printf("| scene | L | triangles | voxels | threads | voxelize + reduce s | CPU s | peak MiB | reduce alone s | CPU s "
           "| peak MiB | voxelize s (derived) | CPU s | M vox/CPU-s, whole build | M vox/CPU-s, reduce alone |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (k = 0; k < sizeof meshes / sizeof meshes[0]; k++)
        for (L = 10; L <= Lmax; L++) {
            char path[512];
            bmesh m;
            bscene s;
            size_t nends, *ends;
            int t, rep = 1;
            if (quick && k > 0) break;
            snprintf(path, sizeof path, "%s/%s", dir, meshes[k]);
            if (!bmesh_load(&m, path, L)) break;
            memset(&s, 0, sizeof s);
            for (t = 0; t < 2; t++) {
                double wall = 1e300, cpu = 0;
                uint64_t peak = 0;
                run red;
                int r;
                if (t == 1 && tcount[1] == 1) break;
                fprintf(stderr, "bench_build: %s voxelized (L=%u, %u thread%s)\n", meshes[k], L, tcount[t],
                        tcount[t] > 1 ? "s" : "");
                for (r = 0; r < rep; r++) {
                    voxdag_build_stats st;
                    double c0 = bench_cpu(), t0 = bench_now(), w;
                    voxdag *d = bmesh_voxelize(&m, L, tcount[t], &st);
                    w = bench_now() - t0;
                    if (w < wall) wall = w, cpu = bench_cpu() - c0, peak = st.peak_memory;
                    if (!s.xyz) {
                        bscene_from_dag(&s, d, L);
                        snprintf(s.name, sizeof s.name, "%s", meshes[k]);
                        rep = quick || s.n >= 4000000 ? 1 : 3;
                    }
                    voxdag_free(d);
                }
                ends = chunk_ends(&s, 0, &nends);
                red = build_chunked(&s, s.xyz, tcount[t], 0, rep, ends, nends);
                free(ends);
                printf("| %s | %u | %zu | %zu | %u | %.3f | %.3f | %.1f | %.3f | %.3f | %.1f | %.3f | %.3f | %.1f | %.1f |\n",
                       meshes[k], L, m.tris, s.n, tcount[t], wall, cpu, mb(peak), red.total, red.cpu, mb(red.peak),
                       wall - red.total, cpu - red.cpu, (double)s.n / cpu / 1e6, (double)s.n / red.cpu / 1e6);
                fflush(stdout);
            }
            {
                double c[2];
                uint64_t v2n = 0;
                fprintf(stderr, "bench_build: %s voxelized by versions 3 and 2 (L=%u, 1 thread)\n", meshes[k], L);
                if (versus_v2(&s, &m, quick ? 1 : 3, c, &v2n) && used < cap)
                    used += (size_t)snprintf(versions + used, cap - used,
                                             "| %s | %u | %zu | %zu | %.3f | %.3f | %.1f | %.1f | **%.2f** | %s |\n",
                                             meshes[k], L, m.tris, s.n, c[1], c[0], (double)s.n / c[1] / 1e6,
                                             (double)s.n / c[0] / 1e6, c[1] / c[0], v2n == s.n ? "yes" : "**no**");
            }
            bscene_free(&s);
            bmesh_free(&m);
        }
    printf("\n");
}

/* The triangle builds against version 2: ROWS from mesh_table, if any. */
static void versions_table(int quick, const char *rows) {
    if (!*rows) return;
    printf("### Build from triangles, format 3 vs 2 (same meshes, 1 thread)\n\n");
    printf("The meshes and grids of the triangle-scene table, voxelized and built by `voxdag_builder_add_mesh` + `finish` of this voxdag.h "
           "(format version 3, 48 cube symmetries) and of the last version-2 voxdag.h (git history, 8 reflections), "
           "each with its default options and the same 2^%u-voxel cells, one thread; the two versions timed in turn, "
           "%s. CPU s = process CPU seconds of the whole build. v3 / v2 speed = v2 CPU s / v3 CPU s; target: >= 0.9, "
           "i.e. no more than 10 %% slower than version 2. Same voxels: both voxelizers gave the same voxel count.\n\n",
           BENCH_CHUNK_LEVELS, quick ? "one run each" : "least CPU time of 3 runs each");
    printf("| scene | L | triangles | voxels | v2 CPU s | v3 CPU s | v2 M vox/CPU-s | v3 M vox/CPU-s | v3 / v2 speed "
           "| same voxels |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n%s\n", rows);
}

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "bench/data";
    int quick = 0, i;
    const char *profile = NULL; /* --profile NAME: only repeat NAME's sorted 1-thread build */
    unsigned threads = (unsigned)sysconf(_SC_NPROCESSORS_ONLN), tcount[2];
    char path[512], versions[4096];
    bscene scenes[16];
    result res[16];
    size_t ns, k;
    int v2 = 0; /* 1: version 2 was timed */
    for (i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) quick = 1;
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc) threads = (unsigned)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--profile") && i + 1 < argc) profile = argv[++i];
    }
    if (threads < 1) threads = 1;
    tcount[0] = 1;
    tcount[1] = threads;

    fprintf(stderr, "bench_build: loading scenes\n");
    ns = bscene_voxel_scenes(scenes, dir, quick ? 1 : 3);
    if (!quick) {
        snprintf(path, sizeof path, "%s/armadillo.off", dir);
        if (bscene_mesh(&scenes[ns], path, "armadillo.off", 12)) ns++;
    }
    bscene_terrain(&scenes[ns++], quick ? 11 : 12);

    if (profile) {
        for (k = 0; k < ns; k++)
            if (!strcmp(scenes[k].name, profile)) {
                run u = build(&scenes[k], scenes[k].xyz, 1, 0, 10);
                printf("%s: %.1f M voxels/s (best of 10, Morton-sorted, 1 thread)\n", profile,
                       (double)scenes[k].n / u.total / 1e6);
            }
        return 0;
    }
    for (k = 0; k < ns; k++) {
        bscene *s = &scenes[k];
        uint32_t *shuf;
        int rep = s->n < 4000000 ? 3 : 1, t;
        result *r = &res[k];
        memset(r, 0, sizeof *r);
        r->s = s;
        r->cells2 = bscene_cells2(s);
        fprintf(stderr, "bench_build: %s (L=%u, %zu voxels)\n", s->name, s->levels, s->n);
        shuf = (uint32_t *)bench_xmalloc(3 * s->n * sizeof *shuf);
        memcpy(shuf, s->xyz, 3 * s->n * sizeof *shuf);
        shuffle(shuf, s->n);
        for (t = 0; t < 2; t++) {
            r->sorted[t] = build(s, s->xyz, tcount[t], 0, rep);
            r->unsorted[t] = build(s, shuf, tcount[t], 0, rep);
        }
        r->cmp = build(s, s->xyz, threads, 1, 1);
        {
            uint64_t v2n = 0;
            v2 = versus_v2(s, NULL, quick ? 1 : 3, r->cpu, &v2n);
            if (v2 && v2n != s->n)
                fprintf(stderr, "bench_build: %s: version 2 built %llu voxels of %zu\n", s->name,
                        (unsigned long long)v2n, s->n);
        }
        {
            size_t nends, *ends = chunk_ends(s, STREAM_CHUNK, &nends);
            r->streamed = build_chunked(s, s->xyz, 1, 0, rep, ends, nends);
            free(ends);
        }
        free(shuf);
    }

    printf("### Build throughput (SSVDAG Table 1 shape)\n\n");
    printf("Wall-clock seconds for `voxdag_builder_add` (Morton encoding and checks), `flush` "
           "(sort when unsorted, deduplicate, reduce) and `finish` (encode), with symmetry on; "
           "%s of %s. M vox/s = voxels / total time; per thread = that divided by the thread count. "
           "M vox/CPU-s = voxels / CPU seconds of the process over the build (all threads): "
           "unlike wall-clock time it does not count time other processes held the cores. "
           "Peak = the builder's accounted memory. *1 Mi-voxel flushes*: the same sorted voxels added and flushed "
           "2^20 at a time (streaming: the builder then holds one chunk plus the unique nodes).\n\n",
           quick ? "one run" : "best", quick ? "each configuration" : "3 runs below 4 M voxels, else one run");
    printf("| scene | L | voxels | input | threads | add s | reduce s | encode s | total s | M vox/s | M vox/s/thread | CPU s | M vox/CPU-s | peak MiB | bytes/voxel peak |\n");
    printf("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (k = 0; k < ns; k++) {
        int o, t;
        for (o = 0; o < 3; o++)
            for (t = 0; t < 2; t++) {
                const run *u = o == 2 ? &res[k].streamed : o ? &res[k].unsorted[t] : &res[k].sorted[t];
                double mvs = (double)res[k].s->n / u->total / 1e6;
                if (t == 1 && (tcount[1] == 1 || o == 2)) continue;
                printf("| %s | %u | %zu | %s | %u | %.3f | %.3f | %.3f | %.3f | %.1f | %.1f | %.3f | %.1f | %.1f | %.1f |\n",
                       res[k].s->name, res[k].s->levels, res[k].s->n, o == 2 ? "Morton-sorted, 1 Mi-voxel flushes" : o ? "shuffled" : "Morton-sorted",
                       tcount[t], u->add, u->reduce, u->encode, u->total, mvs, mvs / tcount[t], u->cpu,
                       (double)res[k].s->n / u->cpu / 1e6, mb(u->peak),
                       (double)u->peak / (double)res[k].s->n);
            }
    }
    printf("\nTarget: 30 M voxels/s per core from Morton-sorted input.\n\n");
    if (v2) {
        printf("### Build from voxels, format 3 vs 2 (same voxels, 1 thread)\n\n");
        printf("The Morton-sorted voxels above, built by this voxdag.h (format version 3, 48 cube symmetries: add, "
               "flush, finish) and by the last version-2 voxdag.h (git history, 8 reflections: add, finish), each "
               "with its default options, one thread; the two versions timed in turn, %s. CPU s = process CPU "
               "seconds of the build. v3 / v2 speed = v2 CPU s / v3 CPU s. Target: version 3 >= 30 M voxels per "
               "CPU-second.\n\n",
               quick ? "one run each" : "least CPU time of 3 runs each");
        printf("| scene | L | voxels | v2 CPU s | v3 CPU s | v2 M vox/CPU-s | v3 M vox/CPU-s | v3 / v2 speed |\n");
        printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
        for (k = 0; k < ns; k++)
            printf("| %s | %u | %zu | %.3f | %.3f | %.1f | %.1f | **%.2f** |\n", res[k].s->name, res[k].s->levels,
                   res[k].s->n, res[k].cpu[1], res[k].cpu[0], (double)res[k].s->n / res[k].cpu[1] / 1e6,
                   (double)res[k].s->n / res[k].cpu[0] / 1e6, res[k].cpu[1] / res[k].cpu[0]);
        printf("\n");
    }
    versions[0] = 0;
    mesh_table(dir, quick, tcount, versions, sizeof versions);

    printf("Published (SSVDAG paper, Table 1; Intel i7-4790K, 8 threads, reduction from an SVO on disk, "
           "excluding voxelization); M vox/s derived here as MVoxels / SSVDAG time:\n\n");
    printf("| scene (published) | resolution | MVoxels | SVDAG s | SSVDAG s | SSVDAG M vox/s | per thread (8) |\n");
    printf("|---|---|---:|---:|---:|---:|---:|\n");
    {
        static const struct { const char *n, *res; double mv, svdag, ssvdag; } pub[] = {
            {"Crytek Sponza", "2K^3", 40, 0.2, 0.6},      {"Crytek Sponza", "64K^3", 41124, 116.0, 226.6},
            {"San Miguel", "2K^3", 12, 0.1, 0.4},         {"San Miguel", "64K^3", 12045, 70.4, 232.8},
            {"Lucy", "2K^3", 6, 0.2, 0.6},                {"Lucy", "64K^3", 6321, 131.7, 472.9},
            {"Powerplant", "64K^3", 5827, 29.1, 52.8},    {"Boeing 777", "64K^3", 24633, 495.71, 1846.2},
            {"David 1mm", "64K^3", 4116, 91.2, 342.7}};
        size_t j;
        for (j = 0; j < sizeof pub / sizeof pub[0]; j++)
            printf("| %s | %s | %.0f | %.1f | %.1f | %.1f | %.1f |\n", pub[j].n, pub[j].res, pub[j].mv,
                   pub[j].svdag, pub[j].ssvdag, pub[j].mv / pub[j].ssvdag, pub[j].mv / pub[j].ssvdag / 8);
    }

    printf("\n");
    versions_table(quick, versions);
    printf("### Node counts per structure (SSVDAG Table 2 shape)\n\n");
    printf("Total nodes over all levels. SVO: every non-empty octree node of levels 0..L-1 "
           "(level L-1 = 2^3 cells). SVDAG / SSVDAG: unique nodes of levels 0..L-3 plus unique 4^3 bricks "
           "(level L-2), from one build with `compare_structures`; SSVDAG = exact merging up to the 8 reflections; "
           "full = exact merging up to all 48 cube symmetries (the default).\n\n");
    printf("| scene | L | voxels | SVO nodes | SVDAG nodes | SSVDAG nodes | full-symmetry nodes | SSVDAG / SVDAG | full / SSVDAG | compare build s |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (k = 0; k < ns; k++) {
        const voxdag_build_stats *st = &res[k].cmp.st;
        uint32_t L = st->levels;
        uint64_t svo = sum(st->svo_nodes, L - 1) + res[k].cells2;
        uint64_t a = sum(st->svdag_nodes, L - 1), b = sum(st->reflect_nodes, L - 1), c = sum(st->full_nodes, L - 1);
        printf("| %s | %u | %zu | %llu | %llu | %llu | %llu | %.3f | %.3f | %.2f |\n", res[k].s->name, L, res[k].s->n,
               (unsigned long long)svo, (unsigned long long)a, (unsigned long long)b, (unsigned long long)c,
               (double)b / (double)a, (double)c / (double)b, res[k].cmp.total);
    }
    for (k = 0; k < ns; k++) {
        const voxdag_build_stats *st = &res[k].cmp.st;
        uint32_t L = st->levels, l;
        if (k + 1 < ns && strncmp(res[k].s->name, "liver", 5) && strncmp(res[k].s->name, "armadillo", 9) &&
            strcmp(res[k].s->name, "tree.vox"))
            continue;
        if (!strncmp(res[k].s->name, "liver", 5) && k + 1 < ns && !strncmp(res[k + 1].s->name, "liver", 5))
            continue; /* per-level table only for the finest liver */
        printf("\nPer level, %s at L = %u (level L-2 = 4^3 bricks, L-1 = 2^3 cells, SVO only):\n\n", res[k].s->name, L);
        printf("| level | SVO | SVDAG | SSVDAG | full | SSVDAG / SVDAG |\n|---:|---:|---:|---:|---:|---:|\n");
        for (l = 0; l + 1 < L; l++)
            printf("| %u | %llu | %llu | %llu | %llu | %.3f |\n", l, (unsigned long long)st->svo_nodes[l],
                   (unsigned long long)st->svdag_nodes[l], (unsigned long long)st->reflect_nodes[l],
                   (unsigned long long)st->full_nodes[l],
                   st->svdag_nodes[l] ? (double)st->reflect_nodes[l] / (double)st->svdag_nodes[l] : 0.0);
        printf("| %u | %llu | - | - | - | - |\n", L - 1, (unsigned long long)res[k].cells2);
    }
    printf("\nInputs:\n\n");
    for (k = 0; k < ns; k++) printf("- %s (L = %u): %s\n", res[k].s->name, res[k].s->levels, res[k].s->input);
    printf("\n");
    for (k = 0; k < ns; k++) bscene_free(&scenes[k]);
    return 0;
}
