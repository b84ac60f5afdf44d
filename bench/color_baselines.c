/* Reimplementations of published colour-array codecs (see color_baselines.h),
   written from the papers' descriptions for measurement only. */
#include "color_baselines.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { KIND_ALG1, KIND_HDAG, KIND_DADO };

struct color_codec {
    int kind;
    size_t n;
    uint64_t bits;      /* compressed size as the paper's layout stores it */
    size_t blocks;
    uint32_t *start;    /* first element of each block */
    uint32_t *endpoint; /* alg1: two RGB565 endpoints per block */
    uint64_t *header;   /* hdag: the 64-bit block headers */
    uint32_t *first;    /* hdag: first block of each macro block; dado: palette of each block */
    uint64_t *offset;   /* hdag: weight bit offset of each macro block; dado: index bit offset */
    uint8_t *width;     /* dado: index bits of each block */
    uint8_t *stream;    /* weight or palette index bit stream */
    uint32_t *palettes; /* dado: material indices */
    uint8_t *materials; /* dado: RGB of each material */
};

// -- Shared pieces: bits, RGB565, line fits

static void put_bits(uint8_t *s, uint64_t pos, uint32_t v, unsigned n) {
    unsigned k;
    for (k = 0; k < n; k++, pos++)
        if ((v >> k) & 1) s[pos >> 3] |= (uint8_t)(1u << (pos & 7));
}

static uint32_t get_bits(const uint8_t *s, uint64_t pos, unsigned n) {
    uint32_t v = 0;
    unsigned k;
    for (k = 0; k < n; k++, pos++) v |= (uint32_t)((s[pos >> 3] >> (pos & 7)) & 1) << k;
    return v;
}

static unsigned expand5(unsigned q) { return q << 3 | q >> 2; }
static unsigned expand6(unsigned q) { return q << 2 | q >> 4; }

static unsigned to565(const double c[3]) {
    unsigned q[3], k;
    for (k = 0; k < 3; k++) {
        double v = c[k] < 0 ? 0 : c[k] > 255 ? 255 : c[k];
        unsigned top = k == 1 ? 63u : 31u;
        q[k] = (unsigned)(v * top / 255.0 + 0.5);
    }
    return q[0] | q[1] << 5 | q[2] << 11;
}

static void from565(unsigned v, int c[3]) {
    c[0] = (int)expand5(v & 31);
    c[1] = (int)expand6((v >> 5) & 63);
    c[2] = (int)expand5(v >> 11);
}

/* Element of a block with LEVELS weight levels: c0 + (c1 - c0) k / (levels - 1). */
static void lerp(const int c0[3], const int c1[3], unsigned k, unsigned levels, uint8_t out[3]) {
    unsigned i;
    for (i = 0; i < 3; i++) {
        double v = levels > 1 ? c0[i] + (double)(c1[i] - c0[i]) * k / (levels - 1) : c0[i];
        out[i] = (uint8_t)(v + 0.5);
    }
}

static int dist2(const uint8_t *a, const uint8_t *b) {
    int d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
}

/* Best weight of colour C between endpoints E0, E1; its squared error. */
static unsigned best_weight(const int e0[3], const int e1[3], unsigned levels, const uint8_t *c,
                            int *err) {
    double dot = 0, dd = 0, t;
    unsigned k, lo, hi, best = 0, i;
    int be = 1 << 30;
    for (i = 0; i < 3; i++) {
        dd += (double)(e1[i] - e0[i]) * (e1[i] - e0[i]);
        dot += (double)(c[i] - e0[i]) * (e1[i] - e0[i]);
    }
    t = dd > 0 ? dot / dd : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    k = (unsigned)(t * (levels - 1) + 0.5);
    lo = k ? k - 1 : 0;
    hi = k + 1 < levels ? k + 1 : levels - 1;
    for (k = lo; k <= hi; k++) {
        uint8_t d[3];
        int e;
        lerp(e0, e1, k, levels, d);
        e = dist2(c, d);
        if (e < be) be = e, best = k;
    }
    *err = be;
    return best;
}

typedef struct line_fit {
    unsigned ep[2]; /* RGB565 */
    double mse;     /* mean squared distance */
    int max_err;    /* largest squared distance */
} line_fit;

static void evaluate(const uint8_t *rgb, size_t n, unsigned levels, line_fit *f) {
    int e0[3], e1[3], err;
    double sum = 0;
    size_t i;
    from565(f->ep[0], e0);
    from565(f->ep[1], e1);
    f->max_err = 0;
    for (i = 0; i < n; i++) {
        best_weight(e0, e1, levels, rgb + 3 * i, &err);
        sum += err;
        if (err > f->max_err) f->max_err = err;
    }
    f->mse = sum / (double)n;
}

/* Fits N colours with RGB565 endpoints and LEVELS weights: endpoints at the
   extremes along the principal axis, then one least-squares refinement of
   the endpoints for the weights found; keeps the better by largest error,
   then by mean error. One colour: the RGB565 codes around it. */
static void fit_line(const uint8_t *rgb, size_t n, unsigned levels, line_fit *best) {
    double mean[3] = {0, 0, 0}, cov[3][3], v[3], lo[3], hi[3], tmin = 0, tmax = 0, vv;
    unsigned a, b, it;
    size_t i;
    line_fit ls;
    memset(cov, 0, sizeof cov);
    for (i = 0; i < n; i++)
        for (a = 0; a < 3; a++) mean[a] += rgb[3 * i + a] / (double)n;
    if (n == 1) { /* the codes just below and above each channel */
        for (a = 0; a < 3; a++) {
            double step = 255.0 / (a == 1 ? 63 : 31);
            lo[a] = floor(mean[a] / step) * step;
            hi[a] = lo[a] + step;
        }
        best->ep[0] = to565(lo);
        best->ep[1] = to565(hi);
        evaluate(rgb, n, levels, best);
        return;
    }
    for (i = 0; i < n; i++)
        for (a = 0; a < 3; a++)
            for (b = 0; b < 3; b++)
                cov[a][b] += (rgb[3 * i + a] - mean[a]) * (rgb[3 * i + b] - mean[b]);
    v[0] = cov[0][0] + 1e-9, v[1] = cov[1][1] + 1e-9, v[2] = cov[2][2] + 1e-9;
    for (it = 0; it < 8; it++) {
        double w[3], m = 0;
        for (a = 0; a < 3; a++) w[a] = cov[a][0] * v[0] + cov[a][1] * v[1] + cov[a][2] * v[2];
        for (a = 0; a < 3; a++) m = fabs(w[a]) > m ? fabs(w[a]) : m;
        if (m < 1e-12) break;
        for (a = 0; a < 3; a++) v[a] = w[a] / m;
    }
    vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    for (i = 0; i < n; i++) {
        double t = ((rgb[3 * i] - mean[0]) * v[0] + (rgb[3 * i + 1] - mean[1]) * v[1] +
                    (rgb[3 * i + 2] - mean[2]) * v[2]) / vv;
        tmin = t < tmin ? t : tmin;
        tmax = t > tmax ? t : tmax;
    }
    for (a = 0; a < 3; a++) lo[a] = mean[a] + tmin * v[a], hi[a] = mean[a] + tmax * v[a];
    best->ep[0] = to565(lo);
    best->ep[1] = to565(hi);
    evaluate(rgb, n, levels, best);
    /* Least squares for the weights of the first fit. */
    {
        double s00 = 0, s01 = 0, s11 = 0, r0[3] = {0, 0, 0}, r1[3] = {0, 0, 0}, det;
        int e0[3], e1[3], err;
        from565(best->ep[0], e0);
        from565(best->ep[1], e1);
        for (i = 0; i < n; i++) {
            double t = (double)best_weight(e0, e1, levels, rgb + 3 * i, &err) / (levels - 1), u = 1 - t;
            s00 += u * u, s01 += u * t, s11 += t * t;
            for (a = 0; a < 3; a++) r0[a] += u * rgb[3 * i + a], r1[a] += t * rgb[3 * i + a];
        }
        det = s00 * s11 - s01 * s01;
        if (fabs(det) < 1e-9) return;
        for (a = 0; a < 3; a++) {
            lo[a] = (s11 * r0[a] - s01 * r1[a]) / det;
            hi[a] = (s00 * r1[a] - s01 * r0[a]) / det;
        }
        ls.ep[0] = to565(lo);
        ls.ep[1] = to565(hi);
        evaluate(rgb, n, levels, &ls);
        if (ls.max_err < best->max_err || (ls.max_err == best->max_err && ls.mse < best->mse))
            *best = ls;
    }
}

static int threshold2(double max_error) {
    double x = max_error * 255.0;
    return x >= 442 ? 3 * 255 * 255 : (int)floor(x * x + 1e-9);
}

static color_codec *codec_new(int kind, size_t n) {
    color_codec *c = (color_codec *)calloc(1, sizeof *c);
    if (c) c->kind = kind, c->n = n;
    return c;
}

void color_codec_free(color_codec *c) {
    if (!c) return;
    free(c->start);
    free(c->endpoint);
    free(c->header);
    free(c->first);
    free(c->offset);
    free(c->width);
    free(c->stream);
    free(c->palettes);
    free(c->materials);
    free(c);
}

uint64_t color_codec_bits(const color_codec *c) { return c->bits; }

/* Last block in [lo, hi) whose start is <= I. */
static size_t find_block(const uint32_t *start, size_t lo, size_t hi, size_t i) {
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (start[mid] <= i) lo = mid;
        else hi = mid;
    }
    return lo;
}

// -- Dolonius et al. 2017, Algorithm 1

#define ALG1_LEVELS 8 /* 3-bit weights */

/* Algorithm 1's Eval: the mean squared error of the fitted block, or -1 when
   a colour misses the bound. */
static double alg1_eval(const uint8_t *rgb, size_t first, size_t end, int thr2) {
    line_fit f;
    fit_line(rgb + 3 * first, end - first, ALG1_LEVELS, &f);
    return f.max_err <= thr2 ? f.mse : -1;
}

color_codec *color_alg1_encode(const uint8_t *rgb, size_t n, double max_error) {
    color_codec *c = codec_new(KIND_ALG1, n);
    int thr2 = threshold2(max_error), merged;
    /* Blocks live at the index of their first element: a doubly linked list. */
    uint32_t *end = (uint32_t *)malloc(n * sizeof *end);
    int64_t *prev = (int64_t *)malloc(n * sizeof *prev), *next = (int64_t *)malloc(n * sizeof *next);
    uint8_t *changed = (uint8_t *)malloc(n), *changed_now = (uint8_t *)malloc(n);
    size_t i, b;
    int64_t k;
    if (!c || !end || !prev || !next || !changed || !changed_now) goto fail;
    for (i = 0; i < n; i++) {
        end[i] = (uint32_t)i + 1;
        prev[i] = (int64_t)i - 1;
        next[i] = i + 1 < n ? (int64_t)i + 1 : -1;
        changed[i] = 1;
    }
    do {
        merged = 0;
        memset(changed_now, 0, n);
        k = n ? next[0] : -1; /* the second block (the first keeps index 0) */
        while (k >= 0) {
            int64_t l = prev[k], r = next[k], at = k;
            double lm = -1, rm = -1;
            /* A pair is only worth evaluating again if a side changed. */
            if (l >= 0 && (changed[l] || changed[k])) lm = alg1_eval(rgb, (size_t)l, end[k], thr2);
            if (r >= 0 && (changed[r] || changed[k])) rm = alg1_eval(rgb, (size_t)k, end[r], thr2);
            if (lm >= 0 || rm >= 0) {
                if (lm >= 0 && (rm < 0 || lm <= rm)) { /* merge into the left block */
                    end[l] = end[k];
                    next[l] = r;
                    if (r >= 0) prev[r] = l;
                    at = l;
                } else { /* absorb the right block */
                    end[k] = end[r];
                    next[k] = next[r];
                    if (next[r] >= 0) prev[next[r]] = k;
                }
                changed_now[at] = 1;
                merged = 1;
            }
            k = next[at] >= 0 ? next[next[at]] : -1;
        }
        memcpy(changed, changed_now, n);
    } while (merged);

    /* The layout: per block a 32-bit start and two RGB565 endpoints; 3-bit weights. */
    for (k = n ? 0 : -1, c->blocks = 0; k >= 0; k = next[k]) c->blocks++;
    c->start = (uint32_t *)malloc((c->blocks + 1) * sizeof *c->start);
    c->endpoint = (uint32_t *)malloc((c->blocks + 1) * sizeof *c->endpoint);
    c->stream = (uint8_t *)calloc(3 * n / 8 + 8, 1);
    if (!c->start || !c->endpoint || !c->stream) goto fail;
    for (k = n ? 0 : -1, b = 0; k >= 0; k = next[k], b++) {
        line_fit f;
        int e0[3], e1[3], err;
        fit_line(rgb + 3 * k, end[k] - (size_t)k, ALG1_LEVELS, &f);
        c->start[b] = (uint32_t)k;
        c->endpoint[b] = f.ep[0] | f.ep[1] << 16;
        from565(f.ep[0], e0);
        from565(f.ep[1], e1);
        for (i = (size_t)k; i < end[k]; i++)
            put_bits(c->stream, 3 * i, best_weight(e0, e1, ALG1_LEVELS, rgb + 3 * i, &err), 3);
    }
    c->bits = 64 * (uint64_t)c->blocks + 3 * (uint64_t)n;
    free(end), free(prev), free(next), free(changed), free(changed_now);
    return c;
fail:
    free(end), free(prev), free(next), free(changed), free(changed_now);
    color_codec_free(c);
    return NULL;
}

static void alg1_get(const color_codec *c, size_t i, uint8_t out[3]) {
    size_t b = find_block(c->start, 0, c->blocks, i);
    int e0[3], e1[3];
    from565(c->endpoint[b] & 0xffff, e0);
    from565(c->endpoint[b] >> 16, e1);
    lerp(e0, e1, get_bits(c->stream, 3 * i, 3), ALG1_LEVELS, out);
}

// -- HashDAG's 64-bit-header layout

#define HDAG_MACRO 16384
#define HDAG_SINGLE 0xffffu /* weight offset marking a single-colour block */

/* 1 when colours [0, n) fit one block of width W (0: one colour) within THR2. */
static int hdag_fits(const uint8_t *rgb, size_t n, unsigned w, int thr2, line_fit *f) {
    if (w == 0) {
        double mid[3];
        unsigned a;
        size_t i;
        int lo[3] = {255, 255, 255}, hi[3] = {0, 0, 0};
        for (i = 0; i < n; i++)
            for (a = 0; a < 3; a++) {
                lo[a] = rgb[3 * i + a] < lo[a] ? rgb[3 * i + a] : lo[a];
                hi[a] = rgb[3 * i + a] > hi[a] ? rgb[3 * i + a] : hi[a];
            }
        for (a = 0; a < 3; a++) mid[a] = (lo[a] + hi[a]) / 2.0;
        f->ep[0] = f->ep[1] = to565(mid);
        evaluate(rgb, n, 1, f);
    } else {
        fit_line(rgb, n, 1u << w, f);
    }
    return f->max_err <= thr2;
}

/* Longest block from RGB of width W (at least 1 colour): doubling, then
   bisection. */
static size_t hdag_longest(const uint8_t *rgb, size_t left, unsigned w, int thr2) {
    size_t ok = 1, bad = 0, len = 2;
    line_fit f;
    while (len <= left && hdag_fits(rgb, len, w, thr2, &f)) ok = len, len *= 2;
    bad = len <= left ? len : left + 1;
    while (bad - ok > 1) {
        size_t mid = ok + (bad - ok) / 2;
        if (hdag_fits(rgb, mid, w, thr2, &f)) ok = mid;
        else bad = mid;
    }
    return ok;
}

typedef struct hdag_block {
    uint32_t start, len;
    unsigned w; /* 0: single colour */
    line_fit f;
} hdag_block;

color_codec *color_hdag_encode(const uint8_t *rgb, size_t n, double max_error) {
    color_codec *c = codec_new(KIND_HDAG, n);
    int thr2 = threshold2(max_error);
    size_t macros = (n + HDAG_MACRO - 1) / HDAG_MACRO, cap = 0, m;
    hdag_block *cand = (hdag_block *)malloc(HDAG_MACRO * sizeof *cand);
    uint64_t bitpos = 0;
    if (!c || !cand) goto fail;
    c->first = (uint32_t *)malloc((macros + 1) * sizeof *c->first);
    c->offset = (uint64_t *)malloc((macros + 1) * sizeof *c->offset);
    c->stream = (uint8_t *)calloc(4 * n / 8 + 16, 1);
    if (!c->first || !c->offset || !c->stream) goto fail;
    for (m = 0; m < macros; m++) {
        size_t base = m * HDAG_MACRO, size = n - base < HDAG_MACRO ? n - base : HDAG_MACRO;
        uint64_t best_bits = UINT64_MAX;
        unsigned w, best_w = 0;
        /* The cheapest segmentation over the weight widths 0..4. */
        for (w = 0; w <= 4; w++) {
            size_t pos = 0, count = 0;
            uint64_t bits = 0;
            while (pos < size) {
                size_t len = hdag_longest(rgb + 3 * (base + pos), size - pos, w, thr2);
                line_fit single;
                bits += 64;
                if (w && !hdag_fits(rgb + 3 * (base + pos), len, 0, thr2, &single)) bits += w * len;
                pos += len;
                count++;
            }
            if (bits < best_bits) best_bits = bits, best_w = w;
        }
        /* Redo the winner and store it. */
        c->first[m] = (uint32_t)c->blocks;
        c->offset[m] = bitpos;
        {
            size_t pos = 0, count = 0, b;
            while (pos < size) {
                hdag_block *h = &cand[count++];
                line_fit single;
                h->start = (uint32_t)pos;
                h->len = (uint32_t)hdag_longest(rgb + 3 * (base + pos), size - pos, best_w, thr2);
                h->w = best_w;
                if (best_w == 0 || hdag_fits(rgb + 3 * (base + pos), h->len, 0, thr2, &single)) {
                    if (best_w) h->f = single;
                    else hdag_fits(rgb + 3 * (base + pos), h->len, 0, thr2, &h->f);
                    h->w = 0;
                } else {
                    fit_line(rgb + 3 * (base + pos), h->len, 1u << best_w, &h->f);
                }
                pos += h->len;
            }
            if (c->blocks + count > cap) {
                cap = 2 * (c->blocks + count);
                c->header = (uint64_t *)realloc(c->header, cap * sizeof *c->header);
                c->start = (uint32_t *)realloc(c->start, cap * sizeof *c->start);
                if (!c->header || !c->start) goto fail;
            }
            for (b = 0; b < count; b++) {
                hdag_block *h = &cand[b];
                uint64_t rel = bitpos - c->offset[m];
                int e0[3], e1[3], err;
                size_t i;
                c->start[c->blocks] = (uint32_t)(base + h->start);
                c->header[c->blocks++] = h->start | (uint64_t)(h->w ? h->w - 1 : 0) << 14 |
                                         (uint64_t)(h->w ? rel : HDAG_SINGLE) << 16 |
                                         (uint64_t)h->f.ep[0] << 32 | (uint64_t)h->f.ep[1] << 48;
                if (!h->w) continue;
                from565(h->f.ep[0], e0);
                from565(h->f.ep[1], e1);
                for (i = 0; i < h->len; i++, bitpos += h->w)
                    put_bits(c->stream, bitpos,
                             best_weight(e0, e1, 1u << h->w, rgb + 3 * (base + h->start + i), &err),
                             h->w);
            }
        }
    }
    c->first[macros] = (uint32_t)c->blocks;
    c->bits = 64 * (uint64_t)c->blocks + bitpos + 64 * (uint64_t)macros;
    free(cand);
    return c;
fail:
    free(cand);
    color_codec_free(c);
    return NULL;
}

static void hdag_get(const color_codec *c, size_t i, uint8_t out[3]) {
    size_t m = i / HDAG_MACRO, b = find_block(c->start, c->first[m], c->first[m + 1], i);
    uint64_t h = c->header[b];
    int e0[3], e1[3];
    unsigned w = (unsigned)((h >> 14) & 3) + 1, rel = (unsigned)((h >> 16) & 0xffff);
    from565((unsigned)(h >> 32) & 0xffff, e0);
    if (rel == HDAG_SINGLE) {
        out[0] = (uint8_t)e0[0], out[1] = (uint8_t)e0[1], out[2] = (uint8_t)e0[2];
        return;
    }
    from565((unsigned)(h >> 48), e1);
    lerp(e0, e1, get_bits(c->stream, c->offset[m] + rel + w * (i - c->start[b]), w), 1u << w, out);
}

// -- Dado et al. 2016: quantization and palette compression

typedef struct dado_box {
    size_t lo, hi; /* range of unique colours */
} dado_box;

static int cmp_u32(const void *a, const void *b) {
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static int sort_channel; /* for cmp_channel (qsort has no context) */
static int cmp_channel(const void *a, const void *b) {
    unsigned x = (*(const uint32_t *)a >> (8 * sort_channel)) & 255;
    unsigned y = (*(const uint32_t *)b >> (8 * sort_channel)) & 255;
    return x < y ? -1 : x > y;
}

/* Median cut of the unique colours U[0..u) (0xRRGGBB... as b<<16|g<<8|r)
   into at most K boxes; BOX_OF receives each unique colour's box, RGB the
   mean colour of each box. Returns the number of boxes. */
static size_t median_cut(uint32_t *u, size_t count, size_t k, uint32_t *box_of, uint8_t *rgb) {
    dado_box *boxes = (dado_box *)malloc(k * sizeof *boxes);
    size_t nb = 1, b, i;
    boxes[0].lo = 0, boxes[0].hi = count;
    while (nb < k) {
        size_t pick = k, best = 0;
        int axis = 0;
        for (b = 0; b < nb; b++) {
            unsigned lo[3] = {255, 255, 255}, hi[3] = {0, 0, 0}, a;
            if (boxes[b].hi - boxes[b].lo < 2) continue;
            for (i = boxes[b].lo; i < boxes[b].hi; i++)
                for (a = 0; a < 3; a++) {
                    unsigned v = (u[i] >> (8 * a)) & 255;
                    lo[a] = v < lo[a] ? v : lo[a];
                    hi[a] = v > hi[a] ? v : hi[a];
                }
            for (a = 0; a < 3; a++)
                if (hi[a] - lo[a] + 1 > best || pick == k) {
                    if (hi[a] - lo[a] + 1 <= best && pick != k) continue;
                    best = hi[a] - lo[a] + 1, pick = b, axis = (int)a;
                }
        }
        if (pick == k || best <= 1) break;
        sort_channel = axis;
        qsort(u + boxes[pick].lo, boxes[pick].hi - boxes[pick].lo, sizeof *u, cmp_channel);
        {
            size_t mid = boxes[pick].lo + (boxes[pick].hi - boxes[pick].lo) / 2;
            boxes[nb].lo = mid, boxes[nb].hi = boxes[pick].hi;
            boxes[pick].hi = mid;
            nb++;
        }
    }
    for (b = 0; b < nb; b++) {
        double s[3] = {0, 0, 0};
        unsigned a;
        for (i = boxes[b].lo; i < boxes[b].hi; i++) {
            box_of[i] = (uint32_t)b;
            for (a = 0; a < 3; a++) s[a] += (u[i] >> (8 * a)) & 255;
        }
        for (a = 0; a < 3; a++) rgb[3 * b + a] = (uint8_t)(s[a] / (double)(boxes[b].hi - boxes[b].lo) + 0.5);
    }
    free(boxes);
    return nb;
}

typedef struct dado_state {
    const uint32_t *m; /* material index per element */
    size_t lambda;
    unsigned index_bits; /* ceil(log2 lambda) */
    uint32_t *count;     /* per material, zero between uses */
    /* The result: blocks in any order, sorted at the end. */
    size_t blocks, cap;
    uint32_t *bstart, *bend;
    uint8_t *bw;
} dado_state;

static uint64_t dado_memory(size_t len, unsigned w, unsigned index_bits) {
    return (uint64_t)len * w + ((uint64_t)1 << w) * index_bits + 96;
}

static int dado_add(dado_state *s, size_t first, size_t end, unsigned w) {
    if (s->blocks == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 1024;
        s->bstart = (uint32_t *)realloc(s->bstart, s->cap * sizeof *s->bstart);
        s->bend = (uint32_t *)realloc(s->bend, s->cap * sizeof *s->bend);
        s->bw = (uint8_t *)realloc(s->bw, s->cap);
        if (!s->bstart || !s->bend || !s->bw) return 0;
    }
    s->bstart[s->blocks] = (uint32_t)first;
    s->bend[s->blocks] = (uint32_t)end;
    s->bw[s->blocks++] = (uint8_t)w;
    return 1;
}

/* Largest block in [i, j) with at most LIMIT distinct materials (two
   pointers). */
static void dado_largest(dado_state *s, size_t i, size_t j, size_t limit, size_t *bi, size_t *bj) {
    size_t l = i, r, distinct = 0;
    *bi = *bj = i;
    for (r = i; r < j; r++) {
        if (s->count[s->m[r]]++ == 0) distinct++;
        while (distinct > limit)
            if (--s->count[s->m[l++]] == 0) distinct--;
        if (r + 1 - l > *bj - *bi) *bi = l, *bj = r + 1;
    }
    for (; l < j; l++) s->count[s->m[l]]--;
}

/* Phase 2 (FindRemainingBlocks): from I, the block of 1..256 distinct
   materials with the least memory per element, repeatedly. */
static int dado_remaining(dado_state *s, size_t i, size_t j) {
    while (i < j) {
        size_t len[9], r = i, distinct = 0, k;
        unsigned w, best_w = 0;
        double best = 1e300;
        for (w = 0; w <= 8; w++) {
            while (r < j && (s->count[s->m[r]] || distinct < ((size_t)1 << w)))
                if (s->count[s->m[r++]]++ == 0) distinct++;
            len[w] = r - i;
        }
        for (k = i; k < r; k++) s->count[s->m[k]] = 0;
        for (w = 0; w <= 8; w++) {
            double per = (double)dado_memory(len[w], w, s->index_bits) / (double)len[w];
            if (per < best) best = per, best_w = w;
        }
        if (!dado_add(s, i, i + len[best_w], best_w)) return 0;
        i += len[best_w];
    }
    return 1;
}

/* Phase 1 (FindLargeBlocks) with an explicit stack of ranges. */
static int dado_large(dado_state *s, size_t n) {
    size_t *stack = (size_t *)malloc(2 * (n + 1) * sizeof *stack), top = 0;
    int ok = 1;
    stack[top++] = 0, stack[top++] = n;
    while (top && ok) {
        size_t j = stack[--top], i = stack[--top], bi = 0, bj = 0;
        unsigned w;
        if (j <= i) continue;
        for (w = 0; w < 4; w++) {
            dado_largest(s, i, j, (size_t)1 << w, &bi, &bj);
            if (dado_memory(bj - bi, w, s->index_bits) < (uint64_t)(bj - bi) * (w + 1)) break;
        }
        if (w == 4) {
            ok = dado_remaining(s, i, j);
            continue;
        }
        ok = dado_add(s, bi, bj, w);
        stack[top++] = i, stack[top++] = bi;
        stack[top++] = bj, stack[top++] = j;
    }
    free(stack);
    return ok;
}

static int cmp_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Index of KEY among the sorted keys in the high halves of PAIRS[0..n). */
static size_t find_pair(const uint64_t *pairs, size_t n, uint32_t key) {
    size_t lo = 0, hi = n;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if ((uint32_t)(pairs[mid] >> 32) <= key) lo = mid;
        else hi = mid;
    }
    return lo;
}

static const dado_state *dado_sorting; /* for cmp_block (qsort has no context) */
static int cmp_block(const void *a, const void *b) {
    uint32_t x = dado_sorting->bstart[*(const uint32_t *)a];
    uint32_t y = dado_sorting->bstart[*(const uint32_t *)b];
    return x < y ? -1 : x > y;
}

/* Palettes are stored once (identical lists shared): an open hash table of
   (offset, length) into the palette array. */
typedef struct dado_palettes {
    uint32_t *data;
    size_t size, cap;
    uint64_t *slot; /* offset << 20 | length, 0 = empty (offset starts at 1) */
    size_t slots;
} dado_palettes;

static uint32_t dado_palette(dado_palettes *p, const uint32_t *list, size_t len, int *added) {
    uint64_t h = 1469598103934665603ull;
    size_t i, at;
    for (i = 0; i < len; i++) h = (h ^ list[i]) * 1099511628211ull;
    for (at = (size_t)(h % p->slots);; at = (at + 1) % p->slots) {
        uint64_t v = p->slot[at];
        if (!v) break;
        if ((v & 0xfffff) == len && !memcmp(p->data + (v >> 20), list, len * sizeof *list)) {
            *added = 0;
            return (uint32_t)(v >> 20);
        }
    }
    if (p->size + len > p->cap) {
        p->cap = 2 * (p->size + len);
        p->data = (uint32_t *)realloc(p->data, p->cap * sizeof *p->data);
    }
    memcpy(p->data + p->size, list, len * sizeof *list);
    p->slot[at] = (uint64_t)p->size << 20 | len;
    p->size += len;
    *added = 1;
    return (uint32_t)(p->slot[at] >> 20);
}

color_codec *color_dado_encode(const uint8_t *rgb, size_t n, uint32_t colors) {
    color_codec *c = codec_new(KIND_DADO, n);
    uint32_t *key = (uint32_t *)malloc((n + 1) * sizeof *key), *u = NULL, *box_of = NULL;
    uint32_t *m = NULL, *order = NULL, *list = NULL;
    uint64_t *pairs = NULL, index_pos = 0, palette_bits = 0, index_bits_total = 0;
    size_t unique = 0, i, b;
    dado_state s;
    dado_palettes pal;
    memset(&s, 0, sizeof s);
    memset(&pal, 0, sizeof pal);
    if (!c || !key || !n) goto fail;
    for (i = 0; i < n; i++) key[i] = rgb[3 * i] | (uint32_t)rgb[3 * i + 1] << 8 | (uint32_t)rgb[3 * i + 2] << 16;
    u = (uint32_t *)malloc(n * sizeof *u);
    box_of = (uint32_t *)malloc(n * sizeof *box_of);
    m = (uint32_t *)malloc(n * sizeof *m);
    pairs = (uint64_t *)malloc(n * sizeof *pairs);
    c->materials = (uint8_t *)malloc(3 * n);
    if (!u || !box_of || !m || !pairs || !c->materials) goto fail;
    memcpy(u, key, n * sizeof *u);
    qsort(u, n, sizeof *u, cmp_u32);
    for (i = 0; i < n; i++)
        if (!unique || u[unique - 1] != u[i]) u[unique++] = u[i];
    /* The material array: median-cut boxes (Dado et al. use a clustering in
       CIELAB; any quantizer to K colours serves the layout), or the colours. */
    if (colors && colors < unique) {
        s.lambda = median_cut(u, unique, colors, box_of, c->materials);
    } else {
        s.lambda = unique;
        for (i = 0; i < unique; i++) {
            box_of[i] = (uint32_t)i;
            c->materials[3 * i] = (uint8_t)u[i];
            c->materials[3 * i + 1] = (uint8_t)(u[i] >> 8);
            c->materials[3 * i + 2] = (uint8_t)(u[i] >> 16);
        }
    }
    for (i = 0; i < unique; i++) pairs[i] = (uint64_t)u[i] << 32 | box_of[i];
    qsort(pairs, unique, sizeof *pairs, cmp_u64);
    for (i = 0; i < n; i++) m[i] = (uint32_t)pairs[find_pair(pairs, unique, key[i])];
    for (s.index_bits = 1; ((size_t)1 << s.index_bits) < s.lambda; s.index_bits++) {}
    s.m = m;
    s.count = (uint32_t *)calloc(s.lambda, sizeof *s.count);
    if (!s.count || !dado_large(&s, n)) goto fail;

    /* Blocks in order; palettes shared; the index stream. */
    order = (uint32_t *)malloc(s.blocks * sizeof *order);
    list = (uint32_t *)malloc(256 * sizeof *list);
    pal.slots = 4 * s.blocks + 1;
    pal.slot = (uint64_t *)calloc(pal.slots, sizeof *pal.slot);
    pal.size = 1;
    pal.cap = 1024;
    pal.data = (uint32_t *)malloc(pal.cap * sizeof *pal.data);
    c->blocks = s.blocks;
    c->start = (uint32_t *)malloc(s.blocks * sizeof *c->start);
    c->first = (uint32_t *)malloc(s.blocks * sizeof *c->first);
    c->offset = (uint64_t *)malloc(s.blocks * sizeof *c->offset);
    c->width = (uint8_t *)malloc(s.blocks);
    c->stream = (uint8_t *)calloc(n + 8, 1);
    if (!order || !list || !pal.slot || !pal.data || !c->start || !c->first || !c->offset ||
        !c->width || !c->stream)
        goto fail;
    for (b = 0; b < s.blocks; b++) order[b] = (uint32_t)b;
    dado_sorting = &s;
    qsort(order, s.blocks, sizeof *order, cmp_block);
    for (b = 0; b < s.blocks; b++) {
        size_t first = s.bstart[order[b]], end = s.bend[order[b]], len = 0, k;
        unsigned w = s.bw[order[b]];
        int added;
        for (i = first; i < end; i++) {
            if (s.count[m[i]]) continue;
            s.count[m[i]] = 1;
            list[len++] = m[i];
        }
        for (k = 0; k < len; k++) s.count[list[k]] = 0;
        qsort(list, len, sizeof *list, cmp_u32);
        c->start[b] = (uint32_t)first;
        c->width[b] = (uint8_t)w;
        c->offset[b] = index_pos;
        c->first[b] = dado_palette(&pal, list, len, &added);
        if (added) palette_bits += ((uint64_t)1 << w) * s.index_bits;
        for (i = first; i < end && w; i++, index_pos += w) {
            size_t lo = 0, hi = len;
            while (hi - lo > 1) {
                size_t mid = (lo + hi) / 2;
                if (list[mid] <= m[i]) lo = mid;
                else hi = mid;
            }
            put_bits(c->stream, index_pos, (uint32_t)lo, w);
        }
        index_bits_total += (uint64_t)w * (end - first);
    }
    c->palettes = pal.data;
    pal.data = NULL;
    /* Indices, palettes, a 96-bit directory entry per block (start, palette,
       index offset) and the 24-bit material array. */
    c->bits = index_bits_total + palette_bits + 96 * (uint64_t)s.blocks + 24 * (uint64_t)s.lambda;
    free(key), free(u), free(box_of), free(m), free(pairs), free(order), free(list);
    free(s.bstart), free(s.bend), free(s.bw), free(s.count), free(pal.slot);
    return c;
fail:
    free(key), free(u), free(box_of), free(m), free(pairs), free(order), free(list);
    free(s.bstart), free(s.bend), free(s.bw), free(s.count), free(pal.slot), free(pal.data);
    color_codec_free(c);
    return NULL;
}

static void dado_get(const color_codec *c, size_t i, uint8_t out[3]) {
    size_t b = find_block(c->start, 0, c->blocks, i);
    unsigned w = c->width[b];
    uint32_t k = w ? get_bits(c->stream, c->offset[b] + (uint64_t)w * (i - c->start[b]), w) : 0;
    memcpy(out, c->materials + 3 * (size_t)c->palettes[c->first[b] + k], 3);
}

void color_codec_get(const color_codec *c, size_t i, uint8_t out[3]) {
    if (c->kind == KIND_ALG1) alg1_get(c, i, out);
    else if (c->kind == KIND_HDAG) hdag_get(c, i, out);
    else dado_get(c, i, out);
}
