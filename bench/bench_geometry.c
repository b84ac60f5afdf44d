/* Geometry size of one DAG under several node layouts; Markdown on stdout.
     bench_geometry DATA_DIR [--quick]
   For every scene two DAGs are built: with reflections (SSVDAG, ours) and
   without (SVDAG). Their encoded levels are walked to recover each node's
   children and mirrors, and the same graph is then sized under each layout:

   - SVO: pointerless octree, 1 byte (child mask) per non-empty node of levels
     0..L-1 (as the SSVDAG paper's Table 2 counts it).
   - Kampe SVDAG layout: an inner node is a 32-bit word holding the child mask
     plus one 32-bit pointer per present child (8..36 bytes); a 4^3 leaf is a
     64-bit mask. On the SVDAG this is the paper's "SVDAG" row; on our
     symmetric DAG (mirror bits in the pointers' spare bits) its "USSVDAG".
   - SSVDAG paper layout (its section 4.3): per level, nodes sorted by the
     number of pointers to them, most referenced first (ties keep our order);
     16-bit header with a 2-bit tag per child; a child pointer is 16 bits (3
     mirror bits + 13-bit offset) when its target's offset, counted in
     level-words of the next level (2 bytes for inner levels, 8 bytes for
     the 4^3 leaf level), is below 2^13, else 32 bits; 4^3 leaves as 64-bit
     words. The index structure (a few words) is left out. On the SVDAG this
     is the paper's "ESVDAG"; on the symmetric DAG its "SSVDAG".
   - the same paper layout plus a per-level voxel count field padded to whole
     16-bit words (none at level L-3): what the paper's layout would pay to
     carry counts at every level whose counts cannot be derived from bricks.
   - ours: voxdag_get_info node_bytes + brick_bytes (the .vdag node and
     brick sections), and the same minus the count bytes of every record.
   Also the load speed of each default file: voxdag_load_memory (full
   validation, checksums included, and with skip_checksums), MB of file per
   CPU-second of this process. */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#include "bench/scenes.h"
#include "bench/v2.h"

/* One level of a DAG as a plain graph: node i has children
   kid[first[i] .. first[i+1]) (target index in the next level << 3 | mirror). */
typedef struct glevel {
    size_t n;
    size_t *first;
    uint64_t *kid;
    uint64_t *count; /* voxels below each node */
} glevel;

typedef struct graph {
    uint32_t levels; /* L; levels 0..L-3 inner, L-2 bricks */
    glevel lv[VOXDAG_MAX_LEVELS];
    size_t bricks;
    uint64_t voxels;
} graph;

static int cmp_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

static size_t find_offset(const uint64_t *off, size_t n, uint64_t v) {
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (off[mid] < v) lo = mid + 1;
        else hi = mid;
    }
    if (lo >= n || off[lo] != v) {
        fprintf(stderr, "bench_geometry: pointer to %llu is not a record start\n", (unsigned long long)v);
        exit(1);
    }
    return lo;
}

/* Walks the encoded DAG D (every inner record, in storage order). */
static void graph_from_dag(const voxdag *d, graph *g) {
    uint32_t B = d->levels - 2, l;
    uint64_t *off[VOXDAG_MAX_LEVELS];
    memset(g, 0, sizeof *g);
    g->levels = d->levels;
    g->bricks = (size_t)d->brick_count;
    g->voxels = d->voxels;
    for (l = 0; l < B; l++) { /* record offsets per level */
        const voxdagi_level *lv = &d->level[l];
        uint64_t at = 0;
        size_t i = 0;
        off[l] = (uint64_t *)bench_xmalloc((size_t)lv->nodes * sizeof(uint64_t));
        while (at < lv->size) {
            unsigned header = (unsigned)voxdagi_le(lv->data + at, 2);
            off[l][i++] = at;
            at += (voxdagi_record_bits(lv, header) + 7) / 8;
        }
        g->lv[l].n = i;
    }
    for (l = 0; l < B; l++) {
        const voxdagi_level *lv = &d->level[l];
        glevel *gl = &g->lv[l];
        size_t i, k = 0;
        gl->first = (size_t *)bench_xmalloc((gl->n + 1) * sizeof *gl->first);
        gl->kid = (uint64_t *)bench_xmalloc(8 * gl->n * sizeof *gl->kid);
        gl->count = (uint64_t *)bench_xmalloc(gl->n * sizeof *gl->count);
        for (i = 0; i < gl->n; i++) {
            const uint8_t *rec = lv->data + off[l][i];
            unsigned header = (unsigned)voxdagi_le(rec, 2), s;
            gl->first[i] = k;
            gl->count[i] = voxdagi_node_count(d, l, off[l][i]);
            for (s = 0; s < 8; s++) {
                uint64_t p, t;
                if (!(header >> (2 * s) & 3)) continue;
                p = voxdagi_child_ref(d, l, rec, header, s, 0);
                t = p >> 6;
                if (l + 1 < B) t = find_offset(off[l + 1], g->lv[l + 1].n, t);
                gl->kid[k++] = t << 6 | (p & 63);
            }
        }
        gl->first[gl->n] = k;
    }
    for (l = 0; l < B; l++) free(off[l]);
    (void)cmp_u64;
}

static void graph_free(graph *g) {
    uint32_t l;
    for (l = 0; l < VOXDAG_MAX_LEVELS; l++) {
        free(g->lv[l].first);
        free(g->lv[l].kid);
        free(g->lv[l].count);
    }
}

static uint64_t graph_pointers(const graph *g) {
    uint64_t p = 0;
    uint32_t l;
    for (l = 0; l + 2 < g->levels; l++) p += g->lv[l].first[g->lv[l].n];
    return p;
}

static uint64_t graph_nodes(const graph *g) {
    uint64_t n = g->bricks;
    uint32_t l;
    for (l = 0; l + 2 < g->levels; l++) n += g->lv[l].n;
    return n;
}

/* Kampe et al.: 4-byte mask word + 4 bytes per child; 8-byte leaves. */
static uint64_t size_kampe(const graph *g) {
    uint64_t inner = 0;
    uint32_t l;
    for (l = 0; l + 2 < g->levels; l++) inner += 4 * (uint64_t)g->lv[l].n;
    return inner + 4 * graph_pointers(g) + 8 * (uint64_t)g->bricks;
}

typedef struct rankrec {
    uint64_t refs;
    size_t i;
} rankrec;

static int rank_cmp(const void *a, const void *b) {
    const rankrec *x = (const rankrec *)a, *y = (const rankrec *)b;
    if (x->refs != y->refs) return x->refs > y->refs ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

static unsigned bytes_for(uint64_t v) {
    unsigned n = 1;
    while (n < 8 && (v >> (8 * n))) n++;
    return n;
}

/* The SSVDAG paper's section 4.3 layout on G. WITH_COUNTS adds a voxel count
   per record (levels 0..L-4) of the level's width rounded up to 2 bytes.
   SHORT_OUT (optional) receives the fraction of 16-bit pointers. */
static uint64_t size_paper(const graph *g, int with_counts, double *short_out) {
    uint32_t L = g->levels, B = L - 2, l;
    uint64_t *refs[VOXDAG_MAX_LEVELS], *pos[VOXDAG_MAX_LEVELS], total = 0, shorts = 0, ptrs = 0;
    size_t i, n;
    memset(refs, 0, sizeof refs);
    memset(pos, 0, sizeof pos);
    for (l = 0; l <= B; l++) {
        n = l == B ? g->bricks : g->lv[l].n;
        refs[l] = (uint64_t *)calloc(n ? n : 1, sizeof(uint64_t));
        pos[l] = (uint64_t *)bench_xmalloc((n ? n : 1) * sizeof(uint64_t));
    }
    refs[0][0] = 1;
    for (l = 0; l < B; l++)
        for (i = 0; i < g->lv[l].first[g->lv[l].n]; i++) refs[l + 1][g->lv[l].kid[i] >> 6]++;
    for (l = B + 1; l-- > 0;) {
        rankrec *r;
        uint64_t at = 0, maxc = 0;
        unsigned cw = 0;
        n = l == B ? g->bricks : g->lv[l].n;
        r = (rankrec *)bench_xmalloc((n ? n : 1) * sizeof *r);
        for (i = 0; i < n; i++) {
            r[i].refs = refs[l][i];
            r[i].i = i;
            if (l < B && g->lv[l].count[i] > maxc) maxc = g->lv[l].count[i];
        }
        qsort(r, n, sizeof *r, rank_cmp);
        if (with_counts && l + 1 < B) cw = (bytes_for(maxc) + 1) & ~1u;
        for (i = 0; i < n; i++) {
            size_t id = r[i].i, k;
            if (l == B) {
                pos[l][id] = i; /* in 8-byte words */
                continue;
            }
            pos[l][id] = at / 2; /* in 2-byte words */
            at += 2 + cw;
            for (k = g->lv[l].first[id]; k < g->lv[l].first[id + 1]; k++) {
                int s = pos[l + 1][g->lv[l].kid[k] >> 6] < (1u << 13);
                at += s ? 2 : 4;
                shorts += (uint64_t)s;
                ptrs++;
            }
        }
        total += l == B ? 8 * (uint64_t)n : at;
        free(r);
    }
    for (l = 0; l <= B; l++) {
        free(refs[l]);
        free(pos[l]);
    }
    if (short_out) *short_out = ptrs ? (double)shorts / (double)ptrs : 0;
    return total;
}

static voxdag *build(const bscene *s, voxdag_symmetry symmetry) {
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag *d = NULL;
    voxdag_error e;
    memset(&o, 0, sizeof o);
    o.levels = s->levels;
    o.symmetry = symmetry;
    o.threads = 2;
    if (voxdag_builder_create(&o, &b, &e) != VOXDAG_OK || voxdag_builder_add(b, s->xyz, NULL, s->n, &e) != VOXDAG_OK ||
        voxdag_builder_finish(b, &d, NULL, &e) != VOXDAG_OK) {
        fprintf(stderr, "bench_geometry: %s\n", e.message);
        exit(1);
    }
    return d;
}

static uint64_t count_bytes(const voxdag *d) {
    uint64_t c = 0;
    uint32_t l;
    for (l = 0; l + 2 < d->levels; l++) c += d->level[l].nodes * d->level[l].count_bits;
    return c / 8;
}

/* Bits of the encoded inner levels of D by component: [0] headers, [1]
   counts, [2] pointer targets (with the base fields of private children),
   [3] transform codes, [4] record padding. */
static void components(const voxdag *d, uint64_t bits[5]) {
    uint32_t l;
    memset(bits, 0, 5 * sizeof *bits);
    for (l = 0; l + 2 < d->levels; l++) {
        const voxdagi_level *lv = &d->level[l];
        uint64_t at = 0;
        while (at < lv->size) {
            unsigned header = (unsigned)voxdagi_le(lv->data + at, 2), s;
            uint64_t rec = voxdagi_record_bits(lv, header);
            bits[0] += 16;
            bits[1] += lv->count_bits;
            bits[2] += lv->base_bits * voxdagi_has_private(header);
            for (s = 0; s < 8; s++) {
                unsigned t = header >> (2 * s) & 3;
                bits[2] += (unsigned)lv->width[t] - lv->code_bits[t];
                bits[3] += lv->code_bits[t];
            }
            bits[4] += 8 * ((rec + 7) / 8) - rec;
            at += (rec + 7) / 8;
        }
    }
}

typedef struct row {
    const bscene *s;
    uint64_t svo_nodes, svdag_nodes, ssvdag_nodes, full_nodes, svdag_ptrs, ssvdag_ptrs, v2;
    uint64_t comp[5], tables;
    uint64_t svo, kampe_svdag, kampe_ssvdag, paper_svdag, paper_ssvdag, paper_ssvdag_counts;
    uint64_t ours, ours_nocount, ours_svdag, file;
    double short_frac;
    double load_mbs, load_skip_mbs; /* file MB per CPU-second of voxdag_load_memory */
} row;

/* MB of IMAGE validated per CPU-second by voxdag_load_memory (no copy), over
   at least 0.3 s of CPU. */
static double load_speed(const void *image, size_t size, int skip_checksums) {
    voxdag_load_opts o;
    clock_t t0 = clock(), t;
    long reps = 0;
    memset(&o, 0, sizeof o);
    o.skip_checksums = skip_checksums;
    do {
        voxdag *d;
        if (voxdag_load_memory(image, size, &o, &d, NULL) != VOXDAG_OK) return 0;
        voxdag_free(d);
        reps++;
        t = clock();
    } while (reps < 3 || (double)(t - t0) < 0.3 * CLOCKS_PER_SEC);
    return (double)size * (double)reps / 1e6 / ((double)(t - t0) / CLOCKS_PER_SEC);
}

static double mib(uint64_t b) { return (double)b / 1048576.0; }

static double bpv(uint64_t b, const bscene *s) { return 8.0 * (double)b / (double)s->n; }

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : "bench/data";
    int quick = argc > 2 && !strcmp(argv[2], "--quick");
    char path[512];
    bscene scenes[24];
    row rows[24];
    size_t ns, k;
    static const char *meshes[] = {"bunny.off", "armadillo.off", "dragon.off"};

    fprintf(stderr, "bench_geometry: loading scenes\n");
    ns = bscene_voxel_scenes(scenes, dir, quick ? 2 : 3);
    for (k = 0; k < 3; k++) {
        uint32_t L, lmax = quick ? 10 : 12;
        if (quick && k) break;
        for (L = 10; L <= lmax; L++) {
            snprintf(path, sizeof path, "%s/%s", dir, meshes[k]);
            if (bscene_mesh(&scenes[ns], path, meshes[k], L)) ns++;
        }
    }
    bscene_terrain(&scenes[ns++], quick ? 10 : 12);

    for (k = 0; k < ns; k++) {
        const bscene *s = &scenes[k];
        voxdag *sym, *plain, *full;
        voxdag_info info;
        graph gs, gp;
        row *r = &rows[k];
        uint32_t l;
        voxdag_build_opts o;
        fprintf(stderr, "bench_geometry: %s (L=%u, %zu voxels)\n", s->name, s->levels, s->n);
        memset(r, 0, sizeof *r);
        memset(&o, 0, sizeof o);
        r->s = s;
        full = build(s, VOXDAG_SYMMETRY_FULL);
        sym = build(s, VOXDAG_SYMMETRY_REFLECT);
        plain = build(s, VOXDAG_SYMMETRY_NONE);
        graph_from_dag(sym, &gs);
        graph_from_dag(plain, &gp);
        voxdag_get_info(full, &info);
        r->ours = info.node_bytes + info.brick_bytes;
        r->ours_nocount = r->ours - count_bytes(full);
        r->file = info.file_bytes;
        {
            size_t size;
            const void *img = voxdag_image(full, &size);
            r->load_mbs = load_speed(img, size, 0);
            r->load_skip_mbs = load_speed(img, size, 1);
        }
        r->tables = (uint64_t)(s->levels - 2) * VOXDAG_FILE_LEVEL_ENTRY_SIZE + VOXDAG_FILE_HEADER_SIZE;
        for (l = 0; l + 1 < s->levels; l++) r->full_nodes += info.nodes[l];
        components(full, r->comp);
        r->v2 = bench_v2_geometry_bytes(s->xyz, s->n, s->levels);
        voxdag_get_info(plain, &info);
        r->ours_svdag = info.node_bytes + info.brick_bytes;
        r->ssvdag_nodes = graph_nodes(&gs);
        r->svdag_nodes = graph_nodes(&gp);
        r->ssvdag_ptrs = graph_pointers(&gs);
        r->svdag_ptrs = graph_pointers(&gp);
        r->kampe_svdag = size_kampe(&gp);
        r->kampe_ssvdag = size_kampe(&gs);
        r->paper_svdag = size_paper(&gp, 0, NULL);
        r->paper_ssvdag = size_paper(&gs, 0, &r->short_frac);
        r->paper_ssvdag_counts = size_paper(&gs, 1, NULL);
        { /* SVO: nodes of levels 0..L-1 from the sorted voxels */
            uint64_t prev[VOXDAG_MAX_LEVELS + 1];
            size_t i;
            for (l = 0; l <= s->levels; l++) prev[l] = UINT64_MAX;
            for (i = 0; i < s->n; i++) {
                uint64_t c = voxdag_morton_encode(s->xyz[3 * i], s->xyz[3 * i + 1], s->xyz[3 * i + 2]);
                for (l = 0; l < s->levels; l++) {
                    uint64_t p = c >> (3 * (s->levels - l));
                    if (p != prev[l]) { r->svo_nodes++; prev[l] = p; }
                }
            }
            r->svo = r->svo_nodes;
        }
        graph_free(&gs);
        graph_free(&gp);
        voxdag_free(sym);
        voxdag_free(plain);
        voxdag_free(full);
    }

    printf("### Format version 3 against version 2 (same voxels)\n\n");
    printf("Geometry bytes (node records + bricks) of the default build, next to the version-2 writer (the last "
           "version-2 `voxdag.h`, built into this program) on the same voxels, and where version 3's bytes go. "
           "Nodes: all levels, 4^3 bricks included; reflect = the 8 reflections (version 2's group), full = all 48 cube "
           "symmetries (version 3's default).\n\n");
    printf("| scene | L | nodes, reflect | nodes, full | version 2 | **version 3** | v3 / v2 | v3 / paper layout | headers | counts | pointer targets | transform codes | padding | bricks | header + level table |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (k = 0; k < ns; k++) {
        const row *r = &rows[k];
        printf("| %s | %u | %llu | %llu | %llu | **%llu** | %.3f | %.3f | %llu | %llu | %llu | %llu | %llu | %llu | %llu |\n",
               r->s->name, r->s->levels, (unsigned long long)r->ssvdag_nodes, (unsigned long long)r->full_nodes,
               (unsigned long long)r->v2, (unsigned long long)r->ours, r->v2 ? (double)r->ours / (double)r->v2 : 0.0,
               (double)r->ours / (double)r->paper_ssvdag, (unsigned long long)(r->comp[0] / 8),
               (unsigned long long)(r->comp[1] / 8), (unsigned long long)(r->comp[2] / 8),
               (unsigned long long)(r->comp[3] / 8), (unsigned long long)(r->comp[4] / 8),
               (unsigned long long)(r->ours - (r->comp[0] + r->comp[1] + r->comp[2] + r->comp[3] + r->comp[4]) / 8),
               (unsigned long long)r->tables);
    }
    printf("\nComponents in bytes (bits / 8, rounded down). The version-2 column is 0 when the program was built "
           "without that header (no git history).\n\n");
    printf("### Geometry size (SSVDAG Table 2 shape)\n\n");
    printf("Bytes of geometry for the same voxels (colours excluded). Nodes: total nodes of all levels "
           "(SVO: levels 0..L-1; DAGs: inner levels 0..L-3 plus 4^3 bricks). Layouts as described below the table.\n\n");
    printf("| scene | L | voxels | SVO nodes | SVDAG nodes | SSVDAG nodes | SVO 1 B/node | SVDAG, Kampe layout | SSVDAG, Kampe layout | SVDAG, paper layout | SSVDAG, paper layout | paper layout + counts | **ours** (with counts) | ours without counts | ours / paper layout |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (k = 0; k < ns; k++) {
        const row *r = &rows[k];
        printf("| %s | %u | %zu | %llu | %llu | %llu | %.3f MiB | %.3f MiB | %.3f MiB | %.3f MiB | %.3f MiB | %.3f MiB | **%.3f MiB** | %.3f MiB | %.3f |\n",
               r->s->name, r->s->levels, r->s->n, (unsigned long long)r->svo_nodes, (unsigned long long)r->svdag_nodes,
               (unsigned long long)r->ssvdag_nodes, mib(r->svo), mib(r->kampe_svdag), mib(r->kampe_ssvdag),
               mib(r->paper_svdag), mib(r->paper_ssvdag), mib(r->paper_ssvdag_counts), mib(r->ours),
               mib(r->ours_nocount), (double)r->ours / (double)r->paper_ssvdag);
    }
    printf("\nBits per voxel (8 x bytes / voxels):\n\n");
    printf("| scene | L | SVO | SVDAG (Kampe) | SSVDAG (Kampe) | SVDAG (paper layout) | SSVDAG (paper layout) | paper layout + counts | **ours** | ours without counts | short pointers, paper layout | ours: bytes exact |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (k = 0; k < ns; k++) {
        const row *r = &rows[k];
        const bscene *s = r->s;
        printf("| %s | %u | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | **%.3f** | %.3f | %.1f %% | %llu |\n", s->name,
               s->levels, bpv(r->svo, s), bpv(r->kampe_svdag, s), bpv(r->kampe_ssvdag, s), bpv(r->paper_svdag, s),
               bpv(r->paper_ssvdag, s), bpv(r->paper_ssvdag_counts, s), bpv(r->ours, s), bpv(r->ours_nocount, s),
               100.0 * r->short_frac, (unsigned long long)r->ours);
    }
    {
        size_t wins = 0;
        for (k = 0; k < ns; k++) wins += rows[k].ours <= rows[k].paper_ssvdag;
        printf("\nOurs with counts <= the paper's layout without counts on %zu of %zu scenes.\n", wins, ns);
    }
    printf("\nLayouts. *SVO*: pointerless, 1 byte (child mask) per node. *Kampe layout*: inner node = 32-bit child-mask "
           "word + 32-bit pointer per child (8..36 bytes), 4^3 leaf = 64-bit mask; on the symmetric DAG the mirror bits "
           "fit in the pointers' spare bits (the paper's USSVDAG). *Paper layout*: the SSVDAG paper's section 4.3 "
           "rule computed on our DAG: per level nodes sorted by reference count, most referenced first; 16-bit header "
           "with a 2-bit tag per child; 16-bit pointer (3 mirror bits + 13-bit offset in level-words: 2 bytes for "
           "inner levels, 8 bytes for the 4^3 leaf level) when the target's word offset is below 2^13, else 32-bit; "
           "leaves as 64-bit words; its small index header left out. On the SVDAG it is the paper's ESVDAG. "
           "*Paper layout + counts*: the same with a voxel count per record at each level's width rounded up to "
           "16-bit words (none at level L-3). *Ours*: `voxdag_get_info` node_bytes + brick_bytes (byte-granular "
           "records: 16-bit header, count, 2/3/4+-byte pointers); without counts = minus each level's count "
           "bytes. Our file adds a 64-byte header, section and level tables.\n\n");

    printf("### Load speed\n\n");
    printf("`voxdag_load_memory` on each default file (in memory, no copy): the complete validation (every record, "
           "pointer and count) with the sections' CRC-32C, and with `skip_checksums` (the same structural checks). "
           "MB of file per CPU-second, one thread.\n\n");
    printf("| scene | L | file | MB/s | MB/s, skip_checksums |\n|---|---:|---:|---:|---:|\n");
    for (k = 0; k < ns; k++)
        printf("| %s | %u | %.3f MiB | %.1f | %.1f |\n", rows[k].s->name, rows[k].s->levels, mib(rows[k].file),
               rows[k].load_mbs, rows[k].load_skip_mbs);
    printf("\n");

    printf("Published (SSVDAG paper, Table 2: MB and bits per voxel for its scenes; not our data). "
           "Bits/voxel at 2K^3 derived here from Table 2 MB and Table 1 MVoxels:\n\n");
    printf("| scene (published) | structure | MB 2K^3 | MB 64K^3 | bits/voxel 64K^3 (published) | bits/voxel 2K^3 (derived) |\n");
    printf("|---|---|---:|---:|---:|---:|\n");
    {
        static const struct { const char *scene, *st; double mb2k, mb64k, bpv64, mvox2k; } pub[] = {
            {"Crytek Sponza", "SSVDAG", 1.7, 315.3, 0.064, 40}, {"Crytek Sponza", "ESVDAG", 2.1, 417.3, 0.085, 40},
            {"Crytek Sponza", "USSVDAG", 3.4, 436.8, 0.089, 40}, {"Crytek Sponza", "SVDAG", 4.2, 563.5, 0.115, 40},
            {"Crytek Sponza", "SVO", 12.21, 13062.9, 2.665, 40},
            {"San Miguel", "SSVDAG", 1.0, 295.9, 0.206, 12},    {"San Miguel", "SVDAG", 2.3, 621.3, 0.433, 12},
            {"Lucy", "SSVDAG", 1.5, 642.2, 0.852, 6},           {"Lucy", "SVDAG", 4.0, 1212.0, 1.608, 6},
            {"David 1mm", "SSVDAG", 1.1, 486.7, 0.992, 4},      {"David 1mm", "SVDAG", 3.0, 938.6, 1.913, 4},
            {"Powerplant", "SSVDAG", 0.7, 85.8, 0.123, 4},      {"Powerplant", "SVDAG", 1.9, 167.3, 0.241, 4},
            {"Boeing 777", "SSVDAG", 3.0, 2314.4, 0.788, 12},   {"Boeing 777", "SVDAG", 9.2, 4307.9, 1.467, 12}};
        size_t j;
        for (j = 0; j < sizeof pub / sizeof pub[0]; j++)
            printf("| %s | %s | %.1f | %.1f | %.3f | %.2f |\n", pub[j].scene, pub[j].st, pub[j].mb2k, pub[j].mb64k,
                   pub[j].bpv64, pub[j].mb2k * 1048576.0 * 8.0 / (pub[j].mvox2k * 1e6));
    }
    printf("\nInputs:\n\n");
    for (k = 0; k < ns; k++)
        if (!k || strcmp(scenes[k].name, scenes[k - 1].name))
            printf("- %s: %s\n", scenes[k].name, scenes[k].input);
    printf("\n");
    for (k = 0; k < ns; k++) bscene_free(&scenes[k]);
    return 0;
}
