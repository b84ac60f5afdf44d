/* vdag rays / vdag render: ray casting of a .vdag file.

   The picture model (tests/test_raytrace.c renders the same model by brute
   force and compares pixels, so it is spelled out exactly):
   - Camera: f = normalize(target - eye), r = normalize(f x up) with up = +z
     (+y when f is vertical), u = r x f. Pixel (i, j), rows top to bottom,
     looks along normalize(f + sx r + sy u) with s = tan(fov / 2),
     sx = (2 (i + 0.5) / W - 1) s W / H and sy = (1 - 2 (j + 0.5) / H) s.
     Rays start at the eye with t in [0, inf), so t is a distance.
   - Axes: z up, as every built file has them (vdag build --up).
   - Default camera, a three-quarter view of the occupied voxels: target the
     centre of their box (the file's voxel box; the whole grid when there is no
     voxel), eye along (1, -1.4, 0.9) from it, far enough that the box's
     bounding sphere fits the narrower field of view.
   - Shading: colour x (AMBIENT + (1 - AMBIENT) max(0, n . l)) with n the
     entry face normal and l = normalize(LIGHT) (--light x y z: towards the
     light); the voxel a ray starts in gets factor 1. With --shadows, a lit
     face whose shadow ray towards l is blocked gets AMBIENT alone; the
     shadow ray starts on the hit face (voxdag_ray_from_hit: on the face's
     plane exactly, inside its square), so it starts in the neighbouring
     voxel and needs no offset. Each channel is (int)(c * factor + 0.5).
     Misses are BACKGROUND.
   - --samples N (N = n^2, n = 1..8): pixel (i, j) averages the n x n rays
     of pixels (n i + a, n j + b), a, b in 0..n-1, of the same view at n W x
     n H (an ordered grid), each channel (sum + N / 2) / N of the samples'
     8-bit values: the picture is exactly that larger one's n x n blocks
     averaged.
   - --lod P stops at cells smaller than P pixels (lod_factor = 2 s / H),
     or P samples with --samples (2 s / (n H)). Such a cell (level q < L,
     side 2^(L-q)) is drawn as what it stands for, the voxels it holds: its
     colour is their mean (voxdag_cell_color), and max(0, n . l) becomes
     the lighting of a voxel staircase (cell_lit: a normal m gives faces
     n_k = sign(m_k) e_k areas |m_k|, each seen in proportion to
     max(0, -d . n_k) for ray direction d: the mean of max(0, n_k . l) with
     weights |m_k| max(0, -d . n_k); the face's own value when all weights
     are 0). m: the least-spread direction of the voxel counts of the cell
     and its 26 neighbours of level q (their covariance's eigenvector of
     least eigenvalue), turned against d. Its shadow ray starts past the
     cell's own staircase, at t_min = its side. A cell covers its pixel in
     part: 4 x 4 sub-rays parallel to the ray, across a square of side
     P / 2 pixels at the first hit's distance, are tested against the
     cell's cells two levels finer (footprint_cover); each cell met takes
     the share of the sub-rays it newly stops, and the ray goes on past it
     (t_min = where it leaves the cell) until every sub-ray is stopped, it
     misses (the rest is BACKGROUND) or it has met LAYERS cells (the last
     takes the rest). A cell entered less than RUN_GAP of the last cell's
     chords after it shows the colour of the first cell of that run (the
     same surface, not its inside). The sample is the weighted sum,
     rounded. With --lod-opaque (the GPU kernel's model), a cell takes the
     whole sample and m is the occupancy gradient,
     m_k = count(cell - e_k) - count(cell + e_k). */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <errno.h>
#include <unistd.h>

#include "cli.h"
#include "gpu.h"

#define AMBIENT 0.3
static const double LIGHT[3] = {0.5, 0.3, 0.8};
static const uint8_t BACKGROUND[3] = {205, 218, 235};

// -- vdag rays

/* Prints a double with the fewest of 15 or 17 digits that read back equal. */
static void print_double(double v) {
    char buf[40];
    snprintf(buf, sizeof buf, "%.15g", v);
    if (strtod(buf, NULL) != v) snprintf(buf, sizeof buf, "%.17g", v);
    fputs(buf, stdout);
}

/* vdag rays --gpu: every ray read first, traced in one run of the kernel
   (origins and directions rounded to float32), printed as without --gpu. */
static int gpu_rays(vdag_file *f, vdag_gpu_target target) {
    char line[1024], err[256];
    unsigned long lineno = 0;
    uint32_t *in = NULL, *out = NULL, n = 0, cap = 0, i;
    vdag_gpu *g;
    vdag_gpu_work w;
    int rc = 0;
    while (fgets(line, sizeof line, stdin)) {
        char *p = line, *end;
        int k;
        lineno++;
        if (n == cap) {
            uint32_t *grown = cap < (1u << 26) ? (uint32_t *)realloc(in, 10 * sizeof *in * (cap ? 2 * (size_t)cap : 1024)) : NULL;
            if (!grown) {
                free(in);
                return vdag_fail("rays: out of memory at line %lu", lineno);
            }
            in = grown, cap = cap ? 2 * cap : 1024;
        }
        for (k = 0; k < 6; k++, p = end) {
            double v = strtod(p, &end);
            float fv = (float)v;
            if (end == p || !isfinite(v)) {
                free(in);
                return vdag_fail("rays: line %lu: expected 6 numbers 'ox oy oz dx dy dz'", lineno);
            }
            memcpy(&in[10 * n + k], &fv, 4);
        }
        if (strspn(p, " \t\r\n") != strlen(p)) {
            free(in);
            return vdag_fail("rays: line %lu: trailing text after 6 numbers", lineno);
        }
        for (k = 6; k < 9; k++) in[10 * n + k] = 0; /* t_min 0, t_max none, lod 0 */
        in[10 * n + 9] = 1;                        /* the voxel index */
        n++;
    }
    memset(&w, 0, sizeof w);
    w.mode = VDAG_GPU_RAYS, w.count = n;
    out = (uint32_t *)malloc(12 * sizeof *out * (n ? n : 1));
    if (!out) rc = vdag_fail("rays: out of memory");
    else if (vdag_gpu_open(&g, target, f->dag, vdag_cpu_count(), err, sizeof err)) rc = vdag_fail("rays --gpu: %s", err);
    else {
        if (n && vdag_gpu_run(g, &w, in, 10 * (size_t)n, out, 12 * (size_t)n, 1, NULL, err, sizeof err))
            rc = vdag_fail("rays --gpu: %s", err);
        vdag_gpu_close(g);
    }
    for (i = 0; !rc && i < n; i++) {
        const uint32_t *h = out + 12 * i;
        float t;
        if (!h[0]) {
            puts("miss");
            continue;
        }
        memcpy(&t, &h[1], 4);
        fputs("hit ", stdout);
        print_double(t);
        printf(" %u %u %u %d %d %d %llu %u %u %u\n", h[2], h[3], h[4], (int)h[5], (int)h[6], (int)h[7],
               (unsigned long long)((uint64_t)h[10] << 32 | h[9]), h[11] & 0xFF, h[11] >> 8 & 0xFF, h[11] >> 16 & 0xFF);
    }
    free(in);
    free(out);
    return rc ? rc : fflush(stdout) ? vdag_fail("rays: write error") : 0;
}

int vdag_cmd_rays(int argc, char **argv) {
    vdag_file f;
    voxdag_ray_opts opts;
    char line[1024];
    unsigned long lineno = 0;
    if (argc == 3 && (!strcmp(argv[2], "--gpu") || !strcmp(argv[2], "--gpu-emulate"))) {
        int rc;
        if (!vdag_open(argv[1], &f)) return 1;
        rc = gpu_rays(&f, !strcmp(argv[2], "--gpu") ? VDAG_GPU_GLSL : VDAG_GPU_EMULATE);
        vdag_close(&f);
        return rc;
    }
    if (argc != 2) return vdag_fail("usage: vdag rays FILE [--gpu | --gpu-emulate]  (rays 'ox oy oz dx dy dz' on stdin)");
    if (!vdag_open(argv[1], &f)) return 1;
    memset(&opts, 0, sizeof opts);
    opts.want_index = 1;
    while (fgets(line, sizeof line, stdin)) {
        voxdag_ray ray;
        voxdag_hit hit;
        char *p = line, *end;
        int k;
        lineno++;
        memset(&ray, 0, sizeof ray);
        ray.t_max = HUGE_VAL;
        for (k = 0; k < 6; k++, p = end) {
            double v = strtod(p, &end);
            if (end == p || !isfinite(v)) {
                vdag_close(&f);
                return vdag_fail("rays: line %lu: expected 6 numbers 'ox oy oz dx dy dz'", lineno);
            }
            if (k < 3) ray.origin[k] = v;
            else ray.dir[k - 3] = v;
        }
        if (strspn(p, " \t\r\n") != strlen(p)) {
            vdag_close(&f);
            return vdag_fail("rays: line %lu: trailing text after 6 numbers", lineno);
        }
        if (voxdag_raycast(f.dag, &ray, &opts, &hit)) {
            uint8_t rgb[3];
            vdag_voxel_color(&f, hit.index, rgb);
            fputs("hit ", stdout);
            print_double(hit.t);
            printf(" %u %u %u %d %d %d %llu %u %u %u\n", hit.xyz[0], hit.xyz[1], hit.xyz[2], hit.normal[0],
                   hit.normal[1], hit.normal[2], (unsigned long long)hit.index, rgb[0], rgb[1], rgb[2]);
        } else {
            puts("miss");
        }
    }
    vdag_close(&f);
    return fflush(stdout) ? vdag_fail("rays: write error") : 0;
}

// -- PNG output: zlib stored blocks, CRC-32, Adler-32

static uint32_t crc32_update(uint32_t crc, const uint8_t *p, size_t n) {
    static uint32_t table[256];
    static int ready; /* filled before any thread starts: PNGs are written by the main thread */
    size_t i;
    if (!ready) {
        uint32_t k, c;
        for (k = 0; k < 256; k++) {
            for (c = k, i = 0; i < 8; i++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1)));
            table[k] = c;
        }
        ready = 1;
    }
    crc = ~crc;
    for (i = 0; i < n; i++) crc = table[(crc ^ p[i]) & 0xFF] ^ (crc >> 8);
    return ~crc;
}

static void put_be32(uint8_t *p, uint32_t v) {
    p[0] = (uint8_t)(v >> 24), p[1] = (uint8_t)(v >> 16), p[2] = (uint8_t)(v >> 8), p[3] = (uint8_t)v;
}

static int write_chunk(FILE *out, const char *type, const uint8_t *data, size_t n) {
    uint8_t head[8], tail[4];
    put_be32(head, (uint32_t)n);
    memcpy(head + 4, type, 4);
    put_be32(tail, crc32_update(crc32_update(0, head + 4, 4), data, n));
    return fwrite(head, 1, 8, out) == 8 && (n == 0 || fwrite(data, 1, n, out) == n) && fwrite(tail, 1, 4, out) == 4;
}

/* Writes W x H RGB8 pixels (rows top to bottom) as a PNG. Returns 1 on success. */
static int write_png(const char *path, const uint8_t *rgb, uint32_t w, uint32_t h) {
    static const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    size_t row = 1 + 3 * (size_t)w, raw = row * h, blocks = raw / 65535 + 1, at = 0, i;
    uint8_t ihdr[13] = {0}, *z = (uint8_t *)malloc(2 + raw + 5 * blocks + 4);
    uint32_t a = 1, b = 0;
    FILE *out;
    int ok;
    if (!z) return 0;
    put_be32(ihdr, w);
    put_be32(ihdr + 4, h);
    ihdr[8] = 8, ihdr[9] = 2; /* 8-bit RGB, no interlace */
    z[at++] = 0x78, z[at++] = 0x01;
    for (i = 0; i < raw;) {
        size_t n = raw - i < 65535 ? raw - i : 65535, k;
        z[at++] = i + n == raw; /* final-block flag, type 0 (stored) */
        z[at++] = (uint8_t)n, z[at++] = (uint8_t)(n >> 8);
        z[at++] = (uint8_t)~n, z[at++] = (uint8_t)(~n >> 8);
        for (k = 0; k < n; k++, i++) { /* row filter byte 0, then the pixels */
            size_t y = i / row, x = i % row;
            uint8_t v = x ? rgb[y * 3 * w + x - 1] : 0;
            z[at++] = v;
            a = (a + v) % 65521, b = (b + a) % 65521;
        }
    }
    put_be32(z + at, b << 16 | a);
    at += 4;
    out = fopen(path, "wb");
    ok = out && fwrite(signature, 1, 8, out) == 8 && write_chunk(out, "IHDR", ihdr, 13) &&
         write_chunk(out, "IDAT", z, at) && write_chunk(out, "IEND", NULL, 0);
    if (out && fclose(out)) ok = 0;
    free(z);
    return ok;
}

// -- vdag render

typedef struct camera {
    double eye[3], f[3], r[3], u[3], s, light[3];
    uint32_t w, h;
} camera;

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void normalize3(double *v) {
    double n = sqrt(dot3(v, v));
    v[0] /= n, v[1] /= n, v[2] /= n;
}

static void cross3(const double *a, const double *b, double *out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

typedef struct render_job {
    const vdag_file *file;
    camera cam;
    voxdag_ray_opts opts;
    int shadows;
    int lod_opaque; /* --lod-opaque: level-of-detail cells drawn whole, lit from the occupancy gradient */
    uint32_t side; /* samples per pixel: side x side */
    uint32_t levels;
    uint8_t *rgb;
    uint32_t tiles_x, tiles, next, done;
    int last_percent;
    int tty; /* progress on stderr, a terminal */
    pthread_mutex_t lock;
} render_job;

/* BLOCK_RAYS: --samples at most 8 x 8. LAYERS: cells a ray goes past at
   most, in pixels that cells cover in part (level of detail). */
enum { TILE = 32, BLOCK = 8, BLOCK_RAYS = BLOCK * BLOCK * 64, LAYERS = 8 };
/* A cell that a ray meets less than RUN_GAP of the last cell's chords past
   it continues that cell's run: the same surface, shown in the run's first
   cell's colour (a cell behind a surface is lit and shadowed as the inside). */
#define RUN_GAP 2.0

/* The unit eigenvector of the symmetric 3 x 3 matrix A for its least
   eigenvalue (cyclic Jacobi rotations; A is overwritten). */
static void least_eigenvector(double a[3][3], double out[3]) {
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    int sweep, p, q, k, least = 0;
    for (sweep = 0; sweep < 12 && !(fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]) <= 1e-12 * (fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]))); sweep++)
        for (p = 0; p < 2; p++)
            for (q = p + 1; q < 3; q++) {
                double theta, t, c, s;
                if (!(fabs(a[p][q]) > 1e-12 * (fabs(a[p][p]) + fabs(a[q][q])))) continue;
                theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
                t = (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
                c = 1 / sqrt(t * t + 1), s = t * c;
                for (k = 0; k < 3; k++) { /* A <- J^T A J, V <- V J */
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq, a[k][q] = s * akp + c * akq;
                }
                for (k = 0; k < 3; k++) {
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk, a[q][k] = s * apk + c * aqk;
                }
                for (k = 0; k < 3; k++) {
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq, v[k][q] = s * vkp + c * vkq;
                }
            }
    for (k = 1; k < 3; k++)
        if (a[k][k] < a[least][least]) least = k;
    for (k = 0; k < 3; k++) out[k] = v[k][least];
}

/* Neighbour I (0..26) of a 3^3 block of cells, x fastest: the index step
   along axis K, and its offset -1, 0 or 1 along K (13: the centre). */
static const int NEIGHBOUR_STRIDE[3] = {1, 3, 9};
static int neighbour_offset(int i, int k) { return i / NEIGHBOUR_STRIDE[k] % 3 - 1; }

/* Lighting of a level-of-detail cell that HIT stopped at: its voxels'
   faces, not the cell's box, as the supersampled full-detail picture sees
   them. A voxel surface with normal m is a staircase whose faces of axis k
   have areas in proportion to |m_k|, each seen in proportion to its facing
   the eye and lit as max(0, n_k . l); returns that mean, or FACE_LIT (the
   hit face's) where there is no normal. The normal comes from the voxel
   counts of the cell's 26 neighbours of the same level: by default the
   direction in which the occupied cells around it (the cell included,
   weighted by their counts) spread least, turned towards the eye, which
   holds for solids and one-voxel shells alike; with --lod-opaque the
   occupancy gradient, m_k = count(cell - e_k) - count(cell + e_k). */
static double cell_lit(const render_job *job, const voxdag_hit *hit, const double dir[3], double face_lit) {
    const double *l = job->cam.light;
    uint32_t size = 1u << (job->levels - hit->level), cell[27][3];
    uint64_t count[27];
    double m[3], num = 0, den = 0, total = 0, mean[3] = {0, 0, 0}, cov[3][3], facing = 0;
    int k, i, j;
    for (i = 0; i < 27; i++) /* wraps outside the grid: counted empty */
        for (k = 0; k < 3; k++) cell[i][k] = hit->xyz[k] + (uint32_t)neighbour_offset(i, k) * size;
    voxdag_cell_count_many(job->file->dag, hit->level, cell[0], 27, count, NULL);
    if (job->lod_opaque) {
        for (k = 0; k < 3; k++) m[k] = (double)count[13 - NEIGHBOUR_STRIDE[k]] - (double)count[13 + NEIGHBOUR_STRIDE[k]];
    } else {
        for (i = 0; i < 27; i++)
            for (total += (double)count[i], k = 0; k < 3; k++) mean[k] += (double)count[i] * neighbour_offset(i, k);
        for (k = 0; k < 3; k++) mean[k] /= total; /* total > 0: the cell is full */
        for (j = 0; j < 3; j++)
            for (k = 0; k < 3; k++)
                for (cov[j][k] = 0, i = 0; i < 27; i++)
                    cov[j][k] += (double)count[i] * (neighbour_offset(i, j) - mean[j]) * (neighbour_offset(i, k) - mean[k]);
        least_eigenvector(cov, m);
        for (k = 0; k < 3; k++) facing += m[k] * dir[k];
        for (k = 0; k < 3; k++) m[k] = facing > 0 ? -m[k] : m[k];
    }
    for (k = 0; k < 3; k++) {
        double n = m[k] < 0 ? -1 : 1, seen = fabs(m[k]) * (-dir[k] * n > 0 ? -dir[k] * n : 0);
        num += seen * (l[k] * n > 0 ? l[k] * n : 0);
        den += seen;
    }
    return den > 0 ? num / den : face_lit;
}

/* Coverage of a pixel by the cells along its ray. The pixel's footprint is
   a square of side FOOTPRINT x the pixel's size at the first hit, across
   the ray, holding FOOT x FOOT sub-rays parallel to it (at the centres of
   its sub-squares); *BLOCKED has a bit for each sub-ray some cell before
   has stopped. Marks the sub-rays that meet a full sub-cell of the
   level-of-detail cell HIT stopped at (its cells two levels finer: 4^3;
   2^3 one level above the voxels) and returns how many it newly stopped. */
enum { FOOT = 4, FOOT_ALL = (1 << FOOT * FOOT) - 1 };
#define FOOTPRINT 0.5
static uint32_t footprint_cover(const render_job *job, const voxdag_hit *hit, const voxdag_ray *ray, double side,
                                uint32_t *blocked) {
    uint32_t q = hit->level, down = job->levels - q < 2 ? job->levels - q : 2, n = 1u << down;
    uint32_t size = 1u << (job->levels - q - down), xyz[64][3], a, c, e, fresh = 0, i;
    uint64_t count[64];
    const double *d = ray->dir;
    double e1[3], e2[3], axis[3] = {0, 0, 0};
    int k, least = 0;
    for (a = 0; a < n; a++)
        for (c = 0; c < n; c++)
            for (e = 0; e < n; e++) {
                uint32_t *p = xyz[(e * n + c) * n + a];
                p[0] = hit->xyz[0] + a * size, p[1] = hit->xyz[1] + c * size, p[2] = hit->xyz[2] + e * size;
            }
    voxdag_cell_count_many(job->file->dag, q + down, xyz[0], n * n * n, count, NULL);
    for (k = 1; k < 3; k++) /* e1, e2: across the ray */
        if (fabs(d[k]) < fabs(d[least])) least = k;
    axis[least] = 1;
    cross3(d, axis, e1), normalize3(e1);
    cross3(d, e1, e2), normalize3(e2);
    for (i = 0; i < FOOT * FOOT; i++) {
        double o[3], t0 = -HUGE_VAL, t1 = HUGE_VAL, u = ((i % FOOT + 0.5) / FOOT - 0.5) * side,
                     v = ((i / FOOT + 0.5) / FOOT - 0.5) * side;
        int cell[3], step[3], m;
        if (*blocked >> i & 1) continue;
        for (m = 0; m < 3; m++) { /* the sub-ray in units of sub-cells, from the cell's corner; its span in the cell */
            o[m] = (ray->origin[m] + u * e1[m] + v * e2[m] - hit->xyz[m]) / size;
            if (d[m] != 0) {
                double ta = -o[m] / d[m], tb = ((double)n - o[m]) / d[m];
                if (ta > tb) { double x = ta; ta = tb, tb = x; }
                t0 = ta > t0 ? ta : t0, t1 = tb < t1 ? tb : t1;
            } else if (o[m] < 0 || o[m] >= n) {
                t0 = HUGE_VAL;
            }
        }
        if (!(t0 < t1)) continue;
        for (m = 0; m < 3; m++) {
            o[m] += t0 * d[m];
            cell[m] = (int)floor(o[m]);
            cell[m] = cell[m] < 0 ? 0 : cell[m] >= (int)n ? (int)n - 1 : cell[m];
            step[m] = d[m] > 0 ? 1 : -1;
        }
        for (;;) { /* through the sub-cells, from o */
            double next_t = HUGE_VAL;
            int next = 0;
            if (count[(cell[2] * n + cell[1]) * n + cell[0]]) {
                *blocked |= 1u << i, fresh++;
                break;
            }
            for (m = 0; m < 3; m++)
                if (d[m] != 0) {
                    double tm = ((double)cell[m] + (d[m] > 0) - o[m]) / d[m];
                    if (tm < next_t) next_t = tm, next = m;
                }
            cell[next] += step[next];
            if (cell[next] < 0 || cell[next] >= (int)n) break;
        }
    }
    return fresh;
}

/* Where RAY leaves the cell of side 2^(L - level) that HIT stopped at. */
static double cell_exit(const render_job *job, const voxdag_ray *ray, const voxdag_hit *hit) {
    double side = (double)(1u << (job->levels - hit->level)), t = HUGE_VAL;
    int k;
    for (k = 0; k < 3; k++)
        if (ray->dir[k] != 0) {
            double bound = hit->xyz[k] + (ray->dir[k] > 0 ? side : 0), tk = (bound - ray->origin[k]) / ray->dir[k];
            if (tk < t) t = tk;
        }
    return t;
}

/* The rays of a block of BLOCK x BLOCK pixels and their answers, traced
   together (voxdag_raycast_many, then voxdag_occluded_many for the shadow
   rays of the lit faces), in BLOCK x BLOCK tiles of samples so that
   neighbouring rays go together; then the rays of the samples that a cell
   covered only in part, past it (a layer), up to LAYERS times. */
typedef struct ray_block {
    voxdag_ray rays[BLOCK_RAYS], shadows[BLOCK_RAYS];
    voxdag_hit hits[BLOCK_RAYS];
    uint8_t got[BLOCK_RAYS], occluded[BLOCK_RAYS], front[BLOCK_RAYS];
    uint32_t x[BLOCK_RAYS], y[BLOCK_RAYS]; /* the sample's pixel in the block */
    uint32_t shadow_of[BLOCK_RAYS];       /* the ray whose hit casts shadow ray k */
    uint32_t sample[BLOCK_RAYS];          /* the sample whose ray is ray k of the layer */
    double factor[BLOCK_RAYS];
    /* per sample: its colour so far, the footprint's side and stopped
       sub-rays, the shaded colour of the first cell of the current run of
       adjacent cells, and where the ray entered and left the last cell */
    double sum[BLOCK_RAYS][3], side[BLOCK_RAYS], enter[BLOCK_RAYS], leave[BLOCK_RAYS];
    uint32_t blocked[BLOCK_RAYS];
    uint8_t color[BLOCK_RAYS][3];
} ray_block;

/* The ray through pixel (I, J) of a W x H picture of the view. */
static void sample_ray(const camera *c, uint32_t i, uint32_t j, double w, double h, voxdag_ray *ray) {
    double sx = (2 * (i + 0.5) / w - 1) * c->s * w / h, sy = (1 - 2 * (j + 0.5) / h) * c->s;
    int k;
    memset(ray, 0, sizeof *ray);
    for (k = 0; k < 3; k++) {
        ray->origin[k] = c->eye[k];
        ray->dir[k] = c->f[k] + sx * c->r[k] + sy * c->u[k];
    }
    normalize3(ray->dir);
    ray->t_max = HUGE_VAL;
}

/* The pixels [X0, X0 + BLOCK) x [Y0, Y0 + BLOCK) (those inside the picture):
   each averages its side x side samples of the view at side W x side H. */
static void render_block(const render_job *job, uint32_t x0, uint32_t y0, ray_block *b) {
    const camera *c = &job->cam;
    const voxdag *dag = job->file->dag;
    uint32_t n = job->side, tx, ty, a, k, count = 0, shadows = 0, samples, layer, sum[BLOCK][BLOCK][3];
    memset(sum, 0, sizeof sum);
    for (ty = 0; ty < n; ty++) /* samples in tiles of BLOCK x BLOCK */
        for (tx = 0; tx < n; tx++)
            for (k = 0; k < BLOCK * BLOCK; k++) {
                uint32_t i = n * x0 + BLOCK * tx + k % BLOCK, j = n * y0 + BLOCK * ty + k / BLOCK;
                if (i / n >= c->w || j / n >= c->h) continue;
                sample_ray(c, i, j, (double)n * c->w, (double)n * c->h, &b->rays[count]);
                b->x[count] = i / n - x0, b->y[count] = j / n - y0;
                count++;
            }
    samples = count;
    samples = count;
    for (k = 0; k < count; k++) {
        b->sample[k] = k, b->blocked[k] = 0;
        b->sum[k][0] = b->sum[k][1] = b->sum[k][2] = 0;
    }
    for (layer = 0; layer < LAYERS && count; layer++) {
        uint32_t next = 0;
        shadows = 0;
        voxdag_raycast_many(dag, b->rays, count, &job->opts, b->hits, b->got);
        for (k = 0; k < count; k++) { /* shading of the first cell of each run; shadow rays from the lit faces */
            const voxdag_hit *hit = &b->hits[k];
            uint32_t s = b->sample[k];
            b->factor[k] = 1;
            b->front[k] = !layer || !(hit->t < b->leave[s] + (b->leave[s] - b->enter[s]) * RUN_GAP);
            if (!b->got[k] || !b->front[k] || !(hit->normal[0] | hit->normal[1] | hit->normal[2])) continue;
            {
                double nv[3] = {hit->normal[0], hit->normal[1], hit->normal[2]}, lit = dot3(nv, c->light);
                voxdag_ray *shadow = &b->shadows[shadows];
                if (hit->level < job->levels) lit = cell_lit(job, hit, b->rays[k].dir, lit);
                b->factor[k] = AMBIENT + (1 - AMBIENT) * (lit > 0 ? lit : 0);
                if (!job->shadows || !(lit > 0)) continue;
                if (hit->level < job->levels) { /* past the cell's own staircase (lit above) */
                    voxdag_ray_from_hit(dag, &b->rays[k], hit, c->light, shadow);
                    shadow->t_min = (double)(1u << (job->levels - hit->level));
                    b->shadow_of[shadows++] = k;
                } else if (voxdag_ray_from_hit(dag, &b->rays[k], hit, c->light, shadow) > 0) {
                    b->shadow_of[shadows++] = k;
                }
            }
        }
        voxdag_occluded_many(dag, b->shadows, shadows, NULL, b->occluded);
        for (k = 0; k < shadows; k++)
            if (b->occluded[k]) b->factor[b->shadow_of[k]] = AMBIENT;
        for (k = 0; k < count; k++) { /* each cell's share of the footprint, in its run's colour */
            const voxdag_hit *hit = &b->hits[k];
            uint32_t s = b->sample[k], fresh = 0, left = b->blocked[s];
            const uint8_t *rgb = BACKGROUND;
            if (b->got[k]) {
                if (b->front[k]) {
                    vdag_hit_color(job->file, hit, b->color[s]);
                    for (a = 0; a < 3; a++) {
                        double v = b->color[s][a] * b->factor[k] + 0.5;
                        b->color[s][a] = (uint8_t)(v > 255 ? 255 : v);
                    }
                }
                rgb = b->color[s];
                if (!layer) b->side[s] = FOOTPRINT * job->opts.lod_factor * job->opts.lod_pixels * hit->t;
                if (!job->lod_opaque && hit->level < job->levels && layer + 1 < LAYERS)
                    fresh = footprint_cover(job, hit, &b->rays[k], b->side[s], &b->blocked[s]);
                else b->blocked[s] = FOOT_ALL; /* a voxel (or the last layer) stops the rest */
            } else {
                b->blocked[s] = FOOT_ALL;
            }
            if (b->blocked[s] == FOOT_ALL) /* the share still open before this cell */
                for (fresh = 0, a = 0; a < FOOT * FOOT; a++) fresh += !(left >> a & 1);
            for (a = 0; a < 3; a++) b->sum[s][a] += (double)fresh / (FOOT * FOOT) * rgb[a];
            if (b->blocked[s] != FOOT_ALL) { /* the rest of the footprint sees past the cell */
                b->enter[s] = hit->t, b->leave[s] = cell_exit(job, &b->rays[k], hit);
                b->rays[next] = b->rays[k], b->sample[next] = s;
                b->rays[next].t_min = b->leave[s] * (1 + 1e-12) + 1e-9; /* past the face, not on it */
                next++;
            }
        }
        count = next;
    }
    for (k = 0; k < samples; k++)
        for (a = 0; a < 3; a++) sum[b->y[k]][b->x[k]][a] += (uint32_t)(b->sum[k][a] + 0.5);
    for (ty = y0; ty < y0 + BLOCK && ty < c->h; ty++)
        for (tx = x0; tx < x0 + BLOCK && tx < c->w; tx++)
            for (a = 0; a < 3; a++)
                job->rgb[3 * ((size_t)ty * c->w + tx) + a] = (uint8_t)((sum[ty - y0][tx - x0][a] + n * n / 2) / (n * n));
}

static void *render_worker(void *arg) {
    render_job *job = (render_job *)arg;
    ray_block *block = (ray_block *)malloc(sizeof *block);
    if (!block) {
        fprintf(stderr, "render: out of memory\n");
        exit(1);
    }
    for (;;) {
        uint32_t tile, x0, y0, x, y;
        int percent;
        pthread_mutex_lock(&job->lock);
        tile = job->next++;
        pthread_mutex_unlock(&job->lock);
        if (tile >= job->tiles) break;
        x0 = tile % job->tiles_x * TILE, y0 = tile / job->tiles_x * TILE;
        for (y = y0; y < y0 + TILE && y < job->cam.h; y += BLOCK)
            for (x = x0; x < x0 + TILE && x < job->cam.w; x += BLOCK) render_block(job, x, y, block);
        pthread_mutex_lock(&job->lock);
        percent = (int)(100.0 * ++job->done / job->tiles);
        if (job->tty && percent / 10 != job->last_percent / 10) { /* in place, on a terminal only */
            job->last_percent = percent;
            fprintf(stderr, "\rrender: %3d%%", percent);
        }
        pthread_mutex_unlock(&job->lock);
    }
    free(block);
    return NULL;
}

/* Seconds on CLOCK (CLOCK_MONOTONIC: wall; CLOCK_PROCESS_CPUTIME_ID: the
   CPU time of all the process's threads). */
static double seconds_now(clockid_t clock) {
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Parses COUNT numbers from argv[*i + 1 ...]; advances *i. Returns 1 on success. */
static int parse_numbers(int argc, char **argv, int *i, double *out, int count) {
    int k;
    for (k = 0; k < count; k++) {
        char *end;
        if (*i + 1 >= argc) return 0;
        out[k] = strtod(argv[++*i], &end);
        if (*end || end == argv[*i] || !isfinite(out[k])) return 0;
    }
    return 1;
}

/* Parses "WxH", each 1..16384 in decimal digits (no sign, no wrap-around
   of long numbers). Returns 1 on success. */
static int parse_size(const char *s, uint32_t *w, uint32_t *h) {
    uint32_t v[2] = {0, 0};
    int k;
    for (k = 0; k < 2; k++) {
        if (*s < '0' || *s > '9') return 0;
        for (; *s >= '0' && *s <= '9'; s++)
            if ((v[k] = 10 * v[k] + (uint32_t)(*s - '0')) > 16384) return 0;
        if (!v[k] || *s++ != (k ? '\0' : 'x')) return 0;
    }
    *w = v[0], *h = v[1];
    return 1;
}

/* vdag render --gpu: the kernel's picture model (vdag_kernel.h) on the same
   camera, in one run. */
static int render_gpu(render_job *job, vdag_gpu_target target, double lod_pixels, unsigned threads, int beam, int quiet) {
    const camera *c = &job->cam;
    vdag_gpu_work w;
    vdag_gpu *g;
    uint32_t *out, *depths = NULL, i, blocks = ((c->w + 7) / 8) * ((c->h + 7) / 8);
    double secs = 0, beam_secs = 0, aspect = (double)c->w / c->h;
    char err[256];
    int k, rc = 0;
    memset(&w, 0, sizeof w);
    w.mode = VDAG_GPU_RENDER, w.count = c->w * c->h, w.width = c->w, w.height = c->h, w.shadows = job->shadows;
    for (k = 0; k < 3; k++) {
        w.eye[k] = (float)c->eye[k], w.f[k] = (float)c->f[k], w.light[k] = (float)c->light[k];
        w.r[k] = (float)(c->r[k] * c->s * aspect), w.u[k] = (float)(c->u[k] * c->s);
    }
    w.lod = (float)(job->opts.lod_factor * lod_pixels), w.ambient = (float)AMBIENT;
    w.inv_w = 1.0f / (float)c->w, w.inv_h = 1.0f / (float)c->h;
    out = (uint32_t *)malloc(sizeof *out * w.count);
    if (beam) depths = (uint32_t *)malloc(sizeof *depths * blocks);
    if (!out || (beam && !depths)) {
        free(out), free(depths);
        return vdag_fail("render: out of memory");
    }
    if (vdag_gpu_open(&g, target, job->file->dag, threads, err, sizeof err)) {
        free(out), free(depths);
        return vdag_fail("render --gpu: %s", err);
    }
    if (beam) { /* the beam pass: a safe start depth per 8x8 block */
        vdag_gpu_work bw = w;
        bw.mode = VDAG_GPU_BEAM, bw.count = blocks;
        if (vdag_gpu_run(g, &bw, NULL, 0, depths, blocks, 1, &beam_secs, err, sizeof err)) rc = vdag_fail("render --gpu: %s", err);
        w.beam_start = 1;
    }
    if (!rc && vdag_gpu_run(g, &w, depths, beam ? blocks : 0, out, w.count, 1, &secs, err, sizeof err))
        rc = vdag_fail("render --gpu: %s", err);
    secs += beam_secs;
    for (i = 0; !rc && i < w.count; i++)
        for (k = 0; k < 3; k++) job->rgb[3 * (size_t)i + k] = (uint8_t)(out[i] >> (8 * k));
    if (!rc && !quiet)
        fprintf(stderr, "render: %ux%u on %s in %.3f s%s%s, %.2f Mrays/s\n", c->w, c->h, vdag_gpu_device(g), secs,
                target == VDAG_GPU_EMULATE ? "" : " (GPU time)", beam ? " with the beam pass" : "",
                (double)w.count / (secs > 0 ? secs : 1e-9) * 1e-6);
    vdag_gpu_close(g);
    free(out), free(depths);
    return rc;
}

int vdag_cmd_render(int argc, char **argv) {
    static const char usage[] = "usage: vdag render FILE OUT.png [--size WxH] [--eye x y z] [--target x y z] "
                                "[--fov deg] [--threads T] [--shadows] [--light x y z] [--lod PIXELS [--lod-opaque]] [--samples N] [--quiet] "
                                "[--gpu | --gpu-emulate [--beam]]";
    render_job job;
    vdag_file f;
    voxdag_info info;
    double eye[3], target[3], fov = 50, lod = 0, threads_d = 0, up[3] = {0, 0, 1}, t0, cpu0, secs, cpu;
    double light[3] = {LIGHT[0], LIGHT[1], LIGHT[2]}, samples = 1;
    int have_eye = 0, have_target = 0, quiet = 0, gpu = -1, beam = 0, i, k;
    uint32_t box[6];
    unsigned threads, t;
    pthread_t tid[64];
    if (argc < 3) return vdag_fail(usage);
    memset(&job, 0, sizeof job);
    job.cam.w = 640, job.cam.h = 480;
    for (i = 3; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--size") && i + 1 < argc) {
            if (!parse_size(argv[++i], &job.cam.w, &job.cam.h))
                return vdag_fail("render: --size takes WxH, 1..16384 each");
        } else if (!strcmp(a, "--eye")) {
            if (!parse_numbers(argc, argv, &i, eye, 3)) return vdag_fail("render: --eye takes 3 numbers");
            have_eye = 1;
        } else if (!strcmp(a, "--target")) {
            if (!parse_numbers(argc, argv, &i, target, 3)) return vdag_fail("render: --target takes 3 numbers");
            have_target = 1;
        } else if (!strcmp(a, "--fov")) {
            if (!parse_numbers(argc, argv, &i, &fov, 1) || !(fov > 0 && fov < 180))
                return vdag_fail("render: --fov takes degrees in (0, 180)");
        } else if (!strcmp(a, "--threads")) {
            if (!parse_numbers(argc, argv, &i, &threads_d, 1) || threads_d < 0 || threads_d > 64 ||
                threads_d != floor(threads_d))
                return vdag_fail("render: --threads takes 0..64 (0: all processors)");
        } else if (!strcmp(a, "--lod")) {
            if (!parse_numbers(argc, argv, &i, &lod, 1) || lod < 0) return vdag_fail("render: --lod takes pixels >= 0");
        } else if (!strcmp(a, "--lod-opaque")) {
            job.lod_opaque = 1;
        } else if (!strcmp(a, "--shadows")) {
            job.shadows = 1;
        } else if (!strcmp(a, "--light")) {
            if (!parse_numbers(argc, argv, &i, light, 3) || dot3(light, light) == 0 || !(dot3(light, light) < HUGE_VAL))
                return vdag_fail("render: --light takes 3 numbers, a direction towards the light (not 0 0 0)");
        } else if (!strcmp(a, "--samples")) {
            if (!parse_numbers(argc, argv, &i, &samples, 1) || !(samples >= 1 && samples <= 64) ||
                floor(sqrt(samples)) * floor(sqrt(samples)) != samples)
                return vdag_fail("render: --samples takes a square number of rays per pixel: 1, 4, 9, ..., 64");
        } else if (!strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "--gpu")) {
            gpu = VDAG_GPU_GLSL;
        } else if (!strcmp(a, "--gpu-emulate")) {
            gpu = VDAG_GPU_EMULATE;
        } else if (!strcmp(a, "--beam")) {
            beam = 1;
        } else {
            return vdag_fail("render: unknown option '%s' (%s)", a, usage);
        }
    }
    if (gpu == VDAG_GPU_GLSL && threads_d > 0) return vdag_fail("render: --threads is for the CPU; --gpu takes none");
    if (beam && gpu < 0) return vdag_fail("render: --beam is a pass of the GPU kernel: add --gpu or --gpu-emulate");
    if (gpu >= 0 && samples > 1) return vdag_fail("render: --samples is for the CPU renderer; the GPU kernel takes one ray a pixel");
    {   /* the picture is a PNG: an OUT named otherwise would hold PNG bytes under another name */
        const char *slash = strrchr(argv[2], '/'), *dot = strrchr(slash ? slash : argv[2], '.');
        if (!dot || strlen(dot) != 4 || (dot[1] | 0x20) != 'p' || (dot[2] | 0x20) != 'n' || (dot[3] | 0x20) != 'g')
            return vdag_fail("render: %s: the picture is written as PNG; name it .png", argv[2]);
    }
    if (!vdag_check_output(argv[1], argv[2]) || !vdag_open(argv[1], &f)) return 1;
    voxdag_get_info(f.dag, &info);
    job.file = &f;
    job.tty = !quiet && isatty(2);
    job.levels = info.levels;
    job.cam.s = tan(fov * 3.14159265358979323846 / 360);
    if (!vdag_voxel_box(f.dag, box)) /* empty: the whole grid */
        for (k = 0; k < 3; k++) box[k] = 0, box[k + 3] = 1u << info.levels;
    if (!have_target)
        for (k = 0; k < 3; k++) target[k] = ((double)box[k] + box[k + 3]) / 2;
    if (!have_eye) { /* the bounding sphere of the occupied box fits the narrower field of view */
        double dir[3] = {1, -1.4, 0.9}, s = job.cam.s * (job.cam.w < job.cam.h ? (double)job.cam.w / job.cam.h : 1);
        double r = 0, dist;
        for (k = 0; k < 3; k++) r += ((double)box[k + 3] - box[k]) * ((double)box[k + 3] - box[k]) / 4;
        dist = sqrt(r) * sqrt(1 + 1 / (s * s));
        normalize3(dir);
        for (k = 0; k < 3; k++) eye[k] = target[k] + dist * dir[k];
    }
    for (k = 0; k < 3; k++) {
        job.cam.eye[k] = eye[k];
        job.cam.f[k] = target[k] - eye[k];
        job.cam.light[k] = light[k];
    }
    if (dot3(job.cam.f, job.cam.f) == 0) {
        vdag_close(&f);
        return vdag_fail("render: --eye and --target coincide");
    }
    normalize3(job.cam.f);
    normalize3(job.cam.light);
    if (fabs(job.cam.f[2]) > 0.999) up[1] = 1, up[2] = 0;
    cross3(job.cam.f, up, job.cam.r);
    normalize3(job.cam.r);
    cross3(job.cam.r, job.cam.f, job.cam.u);
    job.opts.want_index = 1;
    job.side = (uint32_t)floor(sqrt(samples));
    job.opts.lod_factor = 2 * job.cam.s / ((double)job.side * job.cam.h);
    job.opts.lod_pixels = lod;
    job.rgb = (uint8_t *)malloc(3 * (size_t)job.cam.w * job.cam.h);
    if (!job.rgb) {
        vdag_close(&f);
        return vdag_fail("render: out of memory");
    }
    if (gpu >= 0) {
        int rc = render_gpu(&job, (vdag_gpu_target)gpu, lod, threads_d > 0 ? (unsigned)threads_d : vdag_cpu_count(), beam,
                            quiet);
        if (!rc && !write_png(argv[2], job.rgb, job.cam.w, job.cam.h))
            rc = vdag_fail("render: cannot write %s (%s)", argv[2], errno ? strerror(errno) : "write error");
        free(job.rgb);
        vdag_close(&f);
        return rc;
    }
    job.tiles_x = (job.cam.w + TILE - 1) / TILE;
    job.tiles = job.tiles_x * ((job.cam.h + TILE - 1) / TILE);
    pthread_mutex_init(&job.lock, NULL);
    threads = threads_d > 0 ? (unsigned)threads_d : vdag_cpu_count();
    t0 = seconds_now(CLOCK_MONOTONIC);
    cpu0 = seconds_now(CLOCK_PROCESS_CPUTIME_ID);
    for (t = 0; t < threads; t++)
        if (pthread_create(&tid[t], NULL, render_worker, &job)) break;
    if (t == 0) render_worker(&job);
    while (t > 0) pthread_join(tid[--t], NULL);
    secs = seconds_now(CLOCK_MONOTONIC) - t0;
    cpu = seconds_now(CLOCK_PROCESS_CPUTIME_ID) - cpu0;
    pthread_mutex_destroy(&job.lock);
    if (!quiet) { /* primary rays: one a sample */
        double rays = (double)job.cam.w * job.cam.h * job.side * job.side;
        fprintf(stderr, "%srender: %ux%u in %.3f s (%.3f CPU-s), %.2f Mrays/s, %.2f Mrays/CPU-s (%u threads)\n",
                job.tty ? "\r" : "", job.cam.w, job.cam.h, secs, cpu, rays / (secs > 0 ? secs : 1e-9) * 1e-6,
                rays / (cpu > 0 ? cpu : 1e-9) * 1e-6, threads);
    }
    errno = 0;
    if (!write_png(argv[2], job.rgb, job.cam.w, job.cam.h)) {
        free(job.rgb);
        vdag_close(&f);
        return vdag_fail("render: cannot write %s (%s)", argv[2], errno ? strerror(errno) : "write error");
    }
    free(job.rgb);
    vdag_close(&f);
    return 0;
}
