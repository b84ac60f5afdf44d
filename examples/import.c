/* Scene importers for the vdag tool (see import.h). One section per format on
   top of shared helpers: error messages, growable arrays, a text cursor and a
   bounds-checked binary reader. Every size read from a file is checked
   against the bytes that remain before anything is allocated for it. */
#define _POSIX_C_SOURCE 200809L /* fileno, fstat, open, fdopen */
#include "import.h"

#include <sys/stat.h>
#include <errno.h>
#ifdef _WIN32
#include <stdlib.h> /* _fullpath */
#else
#include <fcntl.h>
#include <unistd.h>
#endif
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Every allocation goes through VDAG_IMPORT_REALLOC: realloc, unless the
   program names its own (the importer fuzz target fails each allocation in
   turn through it); blocks are released with free. */
#ifdef VDAG_IMPORT_REALLOC
void *VDAG_IMPORT_REALLOC(void *ptr, size_t size);
#else
#define VDAG_IMPORT_REALLOC realloc
#endif

// -- Errors and limits

/* Larger coordinate magnitudes are rejected so that bounding boxes and their
   extents stay finite. */
#define VI_MAX_COORD 1e30
/* Point tests allowed for triangulating the concave polygons of one file
   (ear clipping is quadratic in a polygon's corners): past it, polygons are
   fan-triangulated with a warning. About a second of work. */
#define VI_EAR_BUDGET ((uint64_t)1 << 28)
/* "No index" in 32-bit index fields. */
#define VI_NONE UINT32_MAX

#if defined(__GNUC__)
#define VI_PRINTF __attribute__((format(printf, 2, 3)))
#else
#define VI_PRINTF
#endif

typedef unsigned long long vi_ull; /* for printf */

typedef struct vi_ctx {
    const char *format;   /* message prefix: "ply", "vox", ... */
    char *err;
    size_t err_size;
    const char *base_dir; /* resolves .mtl and texture paths; NULL: no file access */
    vdag_import_limits limits; /* every field set */
    uint64_t ear_budget;  /* point tests left for triangulating concave polygons */
    uint64_t polys_bad;   /* polygons fan-triangulated: degenerate or self-intersecting */
    uint64_t polys_costly; /* polygons fan-triangulated: past ear_budget */
    struct vi_defer *defer; /* textures decoded in batches on limits.run; NULL: at once */
} vi_ctx;

/* C for one import: the message target and LIMITS with defaults filled in. */
static void vi_ctx_init(vi_ctx *c, const char *format, char *err, size_t err_size,
                        const vdag_import_limits *limits) {
    c->format = format;
    c->err = err;
    c->err_size = err_size;
    c->base_dir = NULL;
    c->ear_budget = VI_EAR_BUDGET;
    c->polys_bad = c->polys_costly = 0;
    c->defer = NULL;
    memset(&c->limits, 0, sizeof c->limits);
    if (limits) c->limits = *limits;
    if (!c->limits.max_input_bytes) c->limits.max_input_bytes = VDAG_IMPORT_MAX_INPUT_BYTES;
    if (!c->limits.max_points) c->limits.max_points = VDAG_IMPORT_MAX_POINTS;
    if (!c->limits.max_vertices) c->limits.max_vertices = VDAG_IMPORT_MAX_VERTICES;
    if (!c->limits.max_triangles) c->limits.max_triangles = VDAG_IMPORT_MAX_TRIANGLES;
    if (!c->limits.max_texture_pixels) c->limits.max_texture_pixels = VDAG_IMPORT_MAX_TEXTURE_PIXELS;
    if (!c->limits.max_vox_voxels) c->limits.max_vox_voxels = VDAG_IMPORT_MAX_VOX_VOXELS;
}

/* Writes "FORMAT: message" to the caller's buffer; returns 0 so that parsers
   can `return vi_fail(...)`. */
static int vi_fail(vi_ctx *c, const char *fmt, ...) VI_PRINTF;
static int vi_fail(vi_ctx *c, const char *fmt, ...) {
    va_list ap;
    int n;
    if (!c->err_size) return 0;
    n = snprintf(c->err, c->err_size, "%s: ", c->format);
    if (n < 0 || (size_t)n >= c->err_size) return 0;
    va_start(ap, fmt);
    vsnprintf(c->err + n, c->err_size - (size_t)n, fmt, ap);
    va_end(ap);
    return 0;
}

/* Prints "vdag: warning: FORMAT: message" on stderr unless the limits ask
   for quiet: for what an import tolerates or leaves out. */
static void vi_warn(vi_ctx *c, const char *fmt, ...) VI_PRINTF;
static void vi_warn(vi_ctx *c, const char *fmt, ...) {
    va_list ap;
    if (c->limits.quiet) return;
    fprintf(stderr, "vdag: warning: %s: ", c->format);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

// -- Growable arrays

typedef struct vi_buf {
    void *data;
    size_t count, cap; /* in elements */
} vi_buf;

/* Appends N elements of ELEM bytes to B and returns them (uninitialised), or
   NULL after reporting the failure. Capacity doubles, so memory only grows
   with what the parser has already read. */
static void *vi_push(vi_ctx *c, vi_buf *b, size_t elem, size_t n) {
    if (!b->data || n > b->cap - b->count) {
        size_t cap = b->cap ? b->cap : 16;
        void *p;
        while (n > cap - b->count) {
            if (cap > SIZE_MAX / 2) return vi_fail(c, "out of memory"), (void *)NULL;
            cap *= 2;
        }
        if (cap > SIZE_MAX / elem) return vi_fail(c, "out of memory"), (void *)NULL;
        p = VDAG_IMPORT_REALLOC(b->data, cap * elem);
        if (!p) return vi_fail(c, "out of memory"), (void *)NULL;
        b->data = p;
        b->cap = cap;
    }
    b->count += n;
    return (char *)b->data + (b->count - n) * elem;
}

static void vi_buf_free(vi_buf *b) {
    free(b->data);
    b->data = NULL;
    b->count = b->cap = 0;
}

/* COUNT elements of ELEM bytes, with the product checked; NULL after
   reporting the failure. */
static void *vi_alloc(vi_ctx *c, size_t count, size_t elem) {
    void *p;
    if (elem && count > SIZE_MAX / elem) return vi_fail(c, "out of memory"), (void *)NULL;
    p = VDAG_IMPORT_REALLOC(NULL, count && elem ? count * elem : 1);
    if (!p) vi_fail(c, "out of memory");
    return p;
}

// -- Text input: lines, tokens, numbers

typedef struct vi_span {
    const char *s, *e;
} vi_span;

typedef struct vi_text {
    const char *p, *end;
    uint64_t line; /* number of the current line, from 1 */
} vi_text;

static int vi_is_space(char ch) {
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n' || ch == '\v' || ch == '\f';
}

/* Moves to the next line of T; LINE gets its text up to any '#' comment.
   Returns 0 at the end of the input. */
static int vi_line(vi_text *t, vi_span *line) {
    const char *nl, *hash;
    if (t->p == t->end) return 0;
    nl = (const char *)memchr(t->p, '\n', (size_t)(t->end - t->p));
    line->s = t->p;
    line->e = nl ? nl : t->end;
    t->p = nl ? nl + 1 : t->end;
    t->line++;
    hash = (const char *)memchr(line->s, '#', (size_t)(line->e - line->s));
    if (hash) line->e = hash;
    return 1;
}

/* Pops the next whitespace-separated token of LINE into TOK; 0 if none. */
static int vi_tok(vi_span *line, vi_span *tok) {
    const char *s = line->s;
    while (s < line->e && vi_is_space(*s)) s++;
    tok->s = s;
    while (s < line->e && !vi_is_space(*s)) s++;
    tok->e = s;
    line->s = s;
    return tok->s < tok->e;
}

/* Pops the next token of T across line ends (counting them); 0 at the end. */
static int vi_word(vi_text *t, vi_span *tok) {
    while (t->p < t->end && vi_is_space(*t->p)) {
        if (*t->p == '\n') t->line++;
        t->p++;
    }
    tok->s = t->p;
    while (t->p < t->end && !vi_is_space(*t->p)) t->p++;
    tok->e = t->p;
    return tok->s < tok->e;
}

/* SPAN without leading and trailing white space. */
static vi_span vi_trim(vi_span span) {
    while (span.s < span.e && vi_is_space(*span.s)) span.s++;
    while (span.e > span.s && vi_is_space(span.e[-1])) span.e--;
    return span;
}

static size_t vi_len(vi_span span) { return (size_t)(span.e - span.s); }

static int vi_is(vi_span tok, const char *word) {
    size_t n = strlen(word);
    return vi_len(tok) == n && memcmp(tok.s, word, n) == 0;
}

/* Like vi_is, ignoring ASCII case. */
static int vi_is_nocase(vi_span tok, const char *word) {
    size_t i, n = strlen(word);
    if (vi_len(tok) != n) return 0;
    for (i = 0; i < n; i++) {
        char a = tok.s[i], b = word[i];
        if (a >= 'A' && a <= 'Z') a = (char)(a - 'A' + 'a');
        if (b >= 'A' && b <= 'Z') b = (char)(b - 'A' + 'a');
        if (a != b) return 0;
    }
    return 1;
}

/* Parses TOK as a number (strtod syntax, so "nan" and "inf" pass: callers
   check ranges); 0 if it is not one. */
static int vi_real(vi_span tok, double *out) {
    char buf[128], *end;
    size_t n = vi_len(tok);
    if (n == 0 || n >= sizeof buf) return 0;
    memcpy(buf, tok.s, n);
    buf[n] = 0;
    *out = strtod(buf, &end);
    return end == buf + n;
}

/* 1 if TOK is written as a decimal integer: an optional sign, then digits. */
static int vi_integer_syntax(vi_span tok) {
    const char *s = tok.s;
    if (s < tok.e && (*s == '-' || *s == '+')) s++;
    if (s == tok.e) return 0;
    for (; s < tok.e; s++)
        if (*s < '0' || *s > '9') return 0;
    return 1;
}

/* Parses TOK as a decimal integer with an optional sign and a magnitude of at
   most 2^62; 0 otherwise (a larger one is refused before it could wrap). */
static int vi_int(vi_span tok, int64_t *out) {
    const uint64_t max = (uint64_t)1 << 62;
    const char *s = tok.s;
    uint64_t v = 0;
    int neg = 0;
    if (s < tok.e && (*s == '-' || *s == '+')) neg = *s++ == '-';
    if (s == tok.e) return 0;
    for (; s < tok.e; s++) {
        uint64_t d = (uint64_t)(*s - '0');
        if (*s < '0' || *s > '9' || v > (max - d) / 10) return 0;
        v = v * 10 + d;
    }
    *out = neg ? -(int64_t)v : (int64_t)v;
    return 1;
}

// -- Binary input: one bounds-checked cursor, either byte order

typedef struct vi_reader {
    const uint8_t *data;
    size_t size, pos;
    int big_endian;
} vi_reader;

/* The next N bytes (moving past them), or NULL when fewer remain. */
static const uint8_t *vi_take(vi_reader *r, size_t n) {
    const uint8_t *p;
    if (r->size - r->pos < n) return NULL;
    p = r->data + r->pos;
    r->pos += n;
    return p;
}

/* Unsigned integer of N <= 8 bytes at B, big- or little-endian. */
static uint64_t vi_uint(const uint8_t *b, size_t n, int big_endian) {
    uint64_t v = 0;
    size_t i;
    for (i = 0; i < n; i++) v |= (uint64_t)b[big_endian ? n - 1 - i : i] << (8 * i);
    return v;
}

static int vi_u32(vi_reader *r, uint32_t *v) {
    const uint8_t *b = vi_take(r, 4);
    if (b) *v = (uint32_t)vi_uint(b, 4, r->big_endian);
    return b != NULL;
}

/* Two's complement value of U, a BITS-bit (< 64) unsigned integer. */
static int64_t vi_signed(uint64_t u, unsigned bits) {
    return u >> (bits - 1) ? (int64_t)u - ((int64_t)1 << bits) : (int64_t)u;
}

static int vi_i32(vi_reader *r, int32_t *v) {
    uint32_t u;
    if (!vi_u32(r, &u)) return 0;
    *v = (int32_t)vi_signed(u, 32);
    return 1;
}

// -- Shared checks and scene assembly

/* A coordinate or texture coordinate from a file: finite and in range. */
static int vi_coord_ok(double v) { return fabs(v) <= VI_MAX_COORD; }

/* Colour channel V scaled by SCALE to 0..255 (clamped); 0 if V is NaN. */
static int vi_channel(double v, double scale, uint8_t *out) {
    if (v != v) return 0;
    v *= scale;
    *out = (uint8_t)(v <= 0 ? 0 : v >= 255 ? 255 : v + 0.5);
    return 1;
}

/* Appends the fan triangulation of polygon POLY (N corners of ELEM bytes) to
   TRIS, three corners per triangle. */
static int vi_fan(vi_ctx *c, vi_buf *tris, const void *poly, size_t n, size_t elem) {
    const char *p = (const char *)poly;
    size_t i;
    for (i = 1; i + 1 < n; i++) {
        char *t = (char *)vi_push(c, tris, elem, 3);
        if (!t) return 0;
        memcpy(t, p, elem);
        memcpy(t + elem, p + i * elem, elem);
        memcpy(t + 2 * elem, p + (i + 1) * elem, elem);
    }
    return 1;
}

// -- Polygons

/* Twice the signed area of 2D triangle ABC: positive when counter-clockwise. */
static double vi_cross2(const double *a, const double *b, const double *c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* 1 if 2D segments AB and CD cross, each one's ends strictly on either side
   of the other's line. */
static int vi_crosses(const double *a, const double *b, const double *c, const double *d) {
    double d1 = vi_cross2(a, b, c), d2 = vi_cross2(a, b, d), d3 = vi_cross2(c, d, a), d4 = vi_cross2(c, d, b);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/* Ear clipping of the counter-clockwise 2D polygon XY (N corners): appends
   triangles of corners from POLY (ELEM bytes each) to TRIS. Returns 1 on
   success, 0 if the polygon is not simple or no ear is found (TRIS may hold
   part of the triangles), -1 past the work budget, -2 on allocation failure.
   NEXT and PREV hold N entries of scratch. */
static int vi_ears(vi_ctx *c, vi_buf *tris, const char *poly, size_t n, size_t elem, const double *xy, size_t *next,
                   size_t *prev) {
    size_t i, j, left = n, misses = 0;
    /* Simple: no two edges cross. */
    if ((uint64_t)n * n / 2 > c->ear_budget) return -1;
    c->ear_budget -= (uint64_t)n * n / 2;
    for (i = 0; i < n; i++)
        for (j = i + 2; j < n; j++)
            if ((i || j + 1 < n) && vi_crosses(&xy[2 * i], &xy[2 * (i + 1)], &xy[2 * j], &xy[2 * ((j + 1) % n)]))
                return 0;
    for (i = 0; i < n; i++) {
        next[i] = (i + 1) % n;
        prev[i] = (i + n - 1) % n;
    }
    for (i = 0; left >= 3;) {
        size_t p = prev[i], q = next[i];
        const double *a = &xy[2 * p], *b = &xy[2 * i], *d = &xy[2 * q];
        double cr = vi_cross2(a, b, d);
        int ear = left == 3 || cr > 0 ||
                  (cr == 0 && (b[0] - a[0]) * (d[0] - b[0]) + (b[1] - a[1]) * (d[1] - b[1]) > 0); /* straight on */
        if (ear && cr > 0 && left > 3)
            for (j = next[q]; j != p; j = next[j]) {
                const double *e = &xy[2 * j];
                if (!c->ear_budget) return -1;
                c->ear_budget--;
                if ((e[0] == a[0] && e[1] == a[1]) || (e[0] == b[0] && e[1] == b[1]) || (e[0] == d[0] && e[1] == d[1]))
                    continue;
                if (vi_cross2(a, b, e) >= 0 && vi_cross2(b, d, e) >= 0 && vi_cross2(d, a, e) >= 0) {
                    ear = 0;
                    break;
                }
            }
        if (ear) {
            char *t = (char *)vi_push(c, tris, elem, 3);
            if (!t) return -2;
            memcpy(t, poly + p * elem, elem);
            memcpy(t + elem, poly + i * elem, elem);
            memcpy(t + 2 * elem, poly + q * elem, elem);
            if (left == 3) return 1;
            next[p] = q;
            prev[q] = p;
            left--;
            i = p; /* P may have become an ear */
            misses = 0;
        } else {
            if (++misses > left) return 0;
            i = q;
        }
    }
    return 1;
}

/* Appends a triangulation of polygon POLY (N corners of ELEM bytes) to TRIS,
   three corners per triangle, N - 2 triangles in all. A corner's vertex is
   its uint32 (ELEM 4) or the high half of its uint64 (ELEM 8), a position in
   POS (3 per vertex); POS NULL: the fan. Polygons are projected onto the
   plane of the axis their Newell normal leans on most; convex ones get the
   fan (from the first corner), others ear clipping. A polygon that is
   degenerate (no normal) or self-intersecting in that plane, or that would
   take the file past VI_EAR_BUDGET, gets the fan and is counted for a
   warning (vi_poly_warn). Returns 0 only on allocation failure. */
static int vi_poly(vi_ctx *c, vi_buf *tris, const void *poly, size_t n, size_t elem, const double *pos) {
    const char *p = (const char *)poly;
    double nrm[3] = {0, 0, 0}, *xy = NULL, turn = 0, s;
    size_t *link = NULL, i, before = tris->count;
    int axis, u, w, convex = 1, r;
    if (n <= 3 || !pos) return vi_fan(c, tris, poly, n, elem);
#define VI_CORNER(k) (pos + 3 * (size_t)(elem == 4 ? *(const uint32_t *)(const void *)(p + (k) * elem) \
                                                   : (uint32_t)(*(const uint64_t *)(const void *)(p + (k) * elem) >> 32)))
    for (i = 0; i < n; i++) { /* Newell's normal */
        const double *a = VI_CORNER(i), *b = VI_CORNER((i + 1) % n);
        nrm[0] += (a[1] - b[1]) * (a[2] + b[2]);
        nrm[1] += (a[2] - b[2]) * (a[0] + b[0]);
        nrm[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    axis = fabs(nrm[0]) >= fabs(nrm[1]) && fabs(nrm[0]) >= fabs(nrm[2]) ? 0 : fabs(nrm[1]) >= fabs(nrm[2]) ? 1 : 2;
    if (!(fabs(nrm[axis]) > 0) || !(fabs(nrm[axis]) < HUGE_VAL)) {
        c->polys_bad++;
        return vi_fan(c, tris, poly, n, elem);
    }
    u = (axis + 1) % 3;
    w = (axis + 2) % 3;
    s = nrm[axis] > 0 ? 1 : -1; /* flips the first coordinate: counter-clockwise */
    if (n > SIZE_MAX / (2 * sizeof(double) + 2 * sizeof(size_t)) ||
        !(xy = (double *)VDAG_IMPORT_REALLOC(NULL, n * (2 * sizeof(double) + 2 * sizeof(size_t)))))
        return vi_fail(c, "out of memory");
    link = (size_t *)(void *)(xy + 2 * n);
    for (i = 0; i < n; i++) {
        const double *a = VI_CORNER(i);
        xy[2 * i] = s * a[u];
        xy[2 * i + 1] = a[w];
    }
#undef VI_CORNER
    for (i = 0; i < n && convex; i++) { /* left turns only, once around */
        const double *a = &xy[2 * ((i + n - 1) % n)], *b = &xy[2 * i], *d = &xy[2 * ((i + 1) % n)];
        double e0 = b[0] - a[0], e1 = b[1] - a[1], f0 = d[0] - b[0], f1 = d[1] - b[1];
        double cr = e0 * f1 - e1 * f0;
        convex = cr >= 0;
        turn += atan2(cr, e0 * f0 + e1 * f1);
    }
    if (convex && fabs(turn - 2 * 3.14159265358979323846) < 1) {
        free(xy);
        return vi_fan(c, tris, poly, n, elem);
    }
    r = vi_ears(c, tris, p, n, elem, xy, link, link + n);
    free(xy);
    if (r == -2) return 0;
    if (r == 1) return 1;
    if (r == 0) c->polys_bad++;
    else c->polys_costly++;
    tris->count = before;
    return vi_fan(c, tris, poly, n, elem);
}

/* Notes in LATE (pairs of size_t) that the polygon of N corners whose fan
   starts at corner FIRST of TRIS was triangulated before its positions were
   read; a no-op for triangles. Returns 0 only on allocation failure. */
static int vi_poly_note(vi_ctx *c, vi_buf *late, size_t first, size_t n) {
    size_t *l;
    if (n <= 3) return 1;
    if (!(l = (size_t *)vi_push(c, late, sizeof *l, 2))) return 0;
    l[0] = first;
    l[1] = n;
    return 1;
}

/* Triangulates again, by vi_poly with positions POS, the polygons that
   vi_poly_note listed in LATE: each fan gives back its polygon (the first
   triangle's corners, then each later triangle's last corner) and is
   overwritten in place. Every corner must be in range of POS. Returns 0
   only on allocation failure. */
static int vi_poly_late(vi_ctx *c, vi_buf *tris, size_t elem, const vi_buf *late, const double *pos) {
    vi_buf poly = {NULL, 0, 0};
    size_t i, j;
    int ok = 1;
    for (i = 0; ok && i < late->count; i += 2) {
        const size_t *l = (const size_t *)late->data + i;
        char *q;
        poly.count = 0;
        if (!(q = (char *)vi_push(c, &poly, elem, l[1]))) ok = 0;
        for (j = 0; ok && j < l[1]; j++)
            memcpy(q + j * elem, (const char *)tris->data + (l[0] + (j < 3 ? j : 3 * (j - 2) + 2)) * elem, elem);
        j = tris->count;
        if (ok && (ok = vi_poly(c, tris, q, l[1], elem, pos)) != 0) {
            memcpy((char *)tris->data + l[0] * elem, (const char *)tris->data + j * elem, (tris->count - j) * elem);
            tris->count = j;
        }
    }
    vi_buf_free(&poly);
    return ok;
}

/* The warning for the polygons vi_poly fan-triangulated as a fallback. */
static void vi_poly_warn(vi_ctx *c) {
    if (c->polys_bad)
        vi_warn(c, "%llu polygon%s degenerate or self-intersecting; fan-triangulated", (vi_ull)c->polys_bad,
                c->polys_bad == 1 ? " was" : "s were");
    if (c->polys_costly)
        vi_warn(c, "%llu concave polygon%s past the triangulation work limit; fan-triangulated",
                (vi_ull)c->polys_costly, c->polys_costly == 1 ? "" : "s");
}

/* A mesh without faces is a point cloud: its vertices become the points. */
static void vi_as_points(vdag_scene *s) {
    s->point_count = s->vertex_count;
    s->points = s->positions;
    s->point_rgb = s->vertex_rgb;
    s->points_are_voxels = 0;
    free(s->uv);
    s->uv = NULL;
    s->positions = NULL;
    s->vertex_rgb = NULL;
    s->vertex_count = 0;
}

/* Gives S the triangles in TRIS (three uint32 corners each), taking the
   memory; without any, S is a point cloud. */
static void vi_set_triangles(vdag_scene *s, vi_buf *tris) {
    if (!tris->count) {
        vi_as_points(s);
        return;
    }
    s->triangle_count = tris->count / 3;
    s->indices = (uint32_t *)tris->data;
    tris->data = NULL;
}

/* Sets T to the text DATA, past a UTF-8 byte order mark. Text in UTF-16
   (a UTF-16 byte order mark, or a NUL byte among the first two) is refused
   with a message that says so. */
static int vi_text_start(vi_ctx *c, const char *data, size_t size, vi_text *t) {
    const unsigned char *u = (const unsigned char *)data;
    t->p = data;
    t->end = data + size;
    t->line = 0;
    if (size >= 3 && u[0] == 0xEF && u[1] == 0xBB && u[2] == 0xBF) t->p += 3;
    else if (size >= 2 && ((u[0] == 0xFF && u[1] == 0xFE) || (u[0] == 0xFE && u[1] == 0xFF) || !u[0] || !u[1]))
        return vi_fail(c, "the file is UTF-16 text (or binary); save it as UTF-8 or ASCII");
    return 1;
}

// -- .xyz: voxels ("x y z" or "x y z r g b"), or a point cloud

/* Every value is read as a number; the file is a voxel list when every
   coordinate is written as an integer, else a point cloud. The first data
   line decides the number of values (3 or 6): every other line must agree.
   In a voxel list the 4th-6th values are colours (integers 0..255, else an
   error); in a point cloud they are colours when every one of them is an
   integer 0..255, else they are ignored (normals, as point-set tools write). */
static int vi_parse_xyz(vi_ctx *c, vi_text *t, vdag_scene *out) {
    vi_buf pts = {NULL, 0, 0}, extra = {NULL, 0, 0};
    int fields = 0, integral = 1, extra_rgb = 1;
    uint64_t first_line = 0, bad_voxel_line = 0, bad_colour_line = 0;
    vi_span line, tok;
    size_t i;
    while (vi_line(t, &line)) {
        double v[6], *p;
        int k, n = 0;
        while (vi_tok(&line, &tok)) {
            if (n == 6) goto too_many;
            if (!vi_real(tok, &v[n]) || !vi_coord_ok(v[n])) {
                vi_fail(c, "line %llu: value %d is not a finite number", (vi_ull)t->line, n + 1);
                goto fail;
            }
            if (!vi_integer_syntax(tok)) {
                if (n < 3) integral = 0;
                else extra_rgb = 0;
            }
            n++;
        }
        if (n == 0) continue;
        if (n != 3 && n != 6) goto too_many;
        if (!fields) {
            fields = n;
            first_line = t->line;
        } else if (n != fields) {
            vi_fail(c, "line %llu: %d values, but line %llu has %d (colours go on every line or none)",
                    (vi_ull)t->line, n, (vi_ull)first_line, fields);
            goto fail;
        }
        for (k = 0; k < 3; k++) {
            if (!vi_coord_ok(v[k])) {
                vi_fail(c, "line %llu: coordinate is not finite or too large", (vi_ull)t->line);
                goto fail;
            }
            if (!bad_voxel_line && (v[k] < 0 || v[k] > (double)UINT32_MAX)) bad_voxel_line = t->line;
        }
        for (k = 3; k < n; k++)
            if (!(v[k] >= 0 && v[k] <= 255 && v[k] == floor(v[k]))) {
                extra_rgb = 0;
                if (!bad_colour_line) bad_colour_line = t->line;
            }
        if (!(p = (double *)vi_push(c, &pts, sizeof(double), 3))) goto fail;
        memcpy(p, v, 3 * sizeof *p);
        if (n == 6) {
            if (!(p = (double *)vi_push(c, &extra, sizeof(double), 3))) goto fail;
            memcpy(p, v + 3, 3 * sizeof *p);
        }
    }
    if (integral && bad_voxel_line) {
        vi_fail(c, "line %llu: coordinate outside 0..4294967295", (vi_ull)bad_voxel_line);
        goto fail;
    }
    if (integral && bad_colour_line) {
        vi_fail(c, "line %llu: colour outside 0..255", (vi_ull)bad_colour_line);
        goto fail;
    }
    if (extra.count && extra_rgb) {
        if (!(out->point_rgb = (uint8_t *)vi_alloc(c, extra.count, 1))) goto fail;
        for (i = 0; i < extra.count; i++) out->point_rgb[i] = (uint8_t)((const double *)extra.data)[i];
    }
    vi_buf_free(&extra);
    out->points_are_voxels = integral;
    out->point_count = pts.count / 3;
    out->points = (double *)pts.data;
    return 1;
too_many:
    vi_fail(c, "line %llu: expected \"x y z\" or \"x y z r g b\"", (vi_ull)t->line);
fail:
    vi_buf_free(&pts);
    vi_buf_free(&extra);
    return 0;
}

// -- .ply: ASCII and binary, vertices (points or mesh) and faces

enum { VI_I8, VI_U8, VI_I16, VI_U16, VI_I32, VI_U32, VI_F32, VI_F64, VI_TYPE_COUNT };

static const struct {
    const char *name, *alias;
    unsigned size;
} vi_ply_types[VI_TYPE_COUNT] = {
    {"char", "int8", 1},    {"uchar", "uint8", 1}, {"short", "int16", 2},   {"ushort", "uint16", 2},
    {"int", "int32", 4},    {"uint", "uint32", 4}, {"float", "float32", 4}, {"double", "float64", 8},
};

/* What a property means to the importer. */
enum { VI_SKIP, VI_X, VI_Y, VI_Z, VI_R, VI_G, VI_B, VI_U, VI_V, VI_ROLE_COUNT, VI_CORNERS = VI_ROLE_COUNT };

typedef struct vi_ply_prop {
    vi_span name;
    int type;
    int count_type; /* list length type, or -1 for a scalar */
    int role;
} vi_ply_prop;

typedef struct vi_ply_elem {
    vi_span name;
    uint64_t count;
    size_t first, props; /* its properties in the property array */
} vi_ply_elem;

typedef struct vi_ply {
    vi_ctx *c;
    int ascii;
    vi_text text;  /* ASCII body */
    vi_reader bin; /* binary body */
    uint64_t vertex_count;
} vi_ply;

static int vi_ply_type(vi_span tok) {
    int i;
    for (i = 0; i < VI_TYPE_COUNT; i++)
        if (vi_is(tok, vi_ply_types[i].name) || vi_is(tok, vi_ply_types[i].alias)) return i;
    return -1;
}

static int vi_ply_truncated(vi_ply *p) {
    if (p->ascii) return vi_fail(p->c, "line %llu: file ends early", (vi_ull)p->text.line);
    return vi_fail(p->c, "byte %llu: file ends early", (vi_ull)p->bin.pos);
}

/* Reads one value of TYPE from the body. */
static int vi_ply_value(vi_ply *p, int type, double *v) {
    const uint8_t *b;
    uint64_t u;
    if (p->ascii) {
        vi_span tok;
        if (!vi_word(&p->text, &tok)) return vi_ply_truncated(p);
        if (!vi_real(tok, v)) return vi_fail(p->c, "line %llu: not a number", (vi_ull)p->text.line);
        return 1;
    }
    if (!(b = vi_take(&p->bin, vi_ply_types[type].size))) return vi_ply_truncated(p);
    u = vi_uint(b, vi_ply_types[type].size, p->bin.big_endian);
    switch (type) {
    case VI_I8: *v = (double)vi_signed(u, 8); break;
    case VI_I16: *v = (double)vi_signed(u, 16); break;
    case VI_I32: *v = (double)vi_signed(u, 32); break;
    case VI_F32: {
        uint32_t w = (uint32_t)u;
        float f;
        memcpy(&f, &w, 4);
        *v = f;
        break;
    }
    case VI_F64: memcpy(v, &u, 8); break;
    default: *v = (double)u; break;
    }
    return 1;
}

/* Where the current value is, for messages. */
static vi_ull vi_ply_where(const vi_ply *p) { return p->ascii ? (vi_ull)p->text.line : (vi_ull)p->bin.pos; }

/* Reads one item of element E: scalars go to VALS by role, the corner list
   (role VI_CORNERS) to POLY, checked against the vertex count. */
static int vi_ply_item(vi_ply *p, const vi_ply_prop *props, const vi_ply_elem *e, double *vals, vi_buf *poly) {
    const char *where = p->ascii ? "line" : "byte";
    size_t j;
    poly->count = 0;
    for (j = 0; j < e->props; j++) {
        const vi_ply_prop *q = &props[e->first + j];
        double v, n, k;
        if (q->count_type < 0) {
            if (!vi_ply_value(p, q->type, &v)) return 0;
            vals[q->role] = v;
            continue;
        }
        if (!vi_ply_value(p, q->count_type, &n)) return 0;
        if (!(n >= 0 && n <= 4294967295.0 && n == floor(n)))
            return vi_fail(p->c, "%s %llu: bad list length", where, vi_ply_where(p));
        for (k = 0; k < n; k++) {
            if (!vi_ply_value(p, q->type, &v)) return 0;
            if (q->role != VI_CORNERS) continue;
            if (!(v >= 0 && v < (double)p->vertex_count && v == floor(v)))
                return vi_fail(p->c, "%s %llu: vertex index out of range", where, vi_ply_where(p));
            if (!vi_push(p->c, poly, sizeof(uint32_t), 1)) return 0;
            ((uint32_t *)poly->data)[poly->count - 1] = (uint32_t)v;
        }
    }
    return 1;
}

/* Fewest bytes one item of E takes in the body. */
static uint64_t vi_ply_min_bytes(const vi_ply *p, const vi_ply_prop *props, const vi_ply_elem *e) {
    uint64_t n = 0;
    size_t j;
    for (j = 0; j < e->props; j++) {
        const vi_ply_prop *q = &props[e->first + j];
        n += p->ascii ? 2 : vi_ply_types[q->count_type < 0 ? q->type : q->count_type].size;
    }
    return n;
}

/* Parses the header into ELEMS and PROPS, leaving P at the body. */
static int vi_ply_header(vi_ply *p, vi_text *t, vi_buf *elems, vi_buf *props) {
    vi_ctx *c = p->c;
    vi_span line, tok;
    int format = 0;
    if (!vi_line(t, &line) || !vi_tok(&line, &tok) || !vi_is(tok, "ply") || vi_tok(&line, &tok))
        return vi_fail(c, "not a PLY file (no \"ply\" line)");
    for (;;) {
        if (!vi_line(t, &line)) return vi_fail(c, "header has no end_header line");
        if (!vi_tok(&line, &tok) || vi_is(tok, "comment") || vi_is(tok, "obj_info")) continue;
        if (vi_is(tok, "end_header")) break;
        if (vi_is(tok, "format")) {
            if (!vi_tok(&line, &tok)) return vi_fail(c, "line %llu: format has no name", (vi_ull)t->line);
            p->ascii = vi_is(tok, "ascii");
            p->bin.big_endian = vi_is(tok, "binary_big_endian");
            if (!p->ascii && !p->bin.big_endian && !vi_is(tok, "binary_little_endian"))
                return vi_fail(c, "line %llu: unknown format", (vi_ull)t->line);
            format = 1;
        } else if (vi_is(tok, "element")) {
            vi_ply_elem *e = (vi_ply_elem *)vi_push(c, elems, sizeof *e, 1);
            int64_t count;
            if (!e) return 0;
            if (!vi_tok(&line, &e->name) || !vi_tok(&line, &tok) || !vi_int(tok, &count) || count < 0)
                return vi_fail(c, "line %llu: expected \"element NAME COUNT\"", (vi_ull)t->line);
            e->count = (uint64_t)count;
            e->first = props->count;
            e->props = 0;
        } else if (vi_is(tok, "property")) {
            vi_ply_prop *q;
            if (!elems->count) return vi_fail(c, "line %llu: property before any element", (vi_ull)t->line);
            if (!(q = (vi_ply_prop *)vi_push(c, props, sizeof *q, 1))) return 0;
            ((vi_ply_elem *)elems->data)[elems->count - 1].props++;
            q->count_type = -1;
            q->role = VI_SKIP;
            if (!vi_tok(&line, &tok)) return vi_fail(c, "line %llu: property has no type", (vi_ull)t->line);
            if (vi_is(tok, "list")) {
                if (!vi_tok(&line, &tok) || (q->count_type = vi_ply_type(tok)) < 0 || q->count_type >= VI_F32)
                    return vi_fail(c, "line %llu: list length type must be an integer type", (vi_ull)t->line);
                if (!vi_tok(&line, &tok)) return vi_fail(c, "line %llu: list has no item type", (vi_ull)t->line);
            }
            if ((q->type = vi_ply_type(tok)) < 0)
                return vi_fail(c, "line %llu: unknown property type", (vi_ull)t->line);
            if (!vi_tok(&line, &q->name)) return vi_fail(c, "line %llu: property has no name", (vi_ull)t->line);
        } else { /* e.g. a comment without its keyword, as some exporters write */
            vi_warn(c, "line %llu: unknown header line skipped", (vi_ull)t->line);
        }
    }
    if (!format) return vi_fail(c, "header has no format line");
    p->text = *t;
    p->text.line++; /* the body starts on the line after end_header */
    p->bin.data = (const uint8_t *)t->p;
    p->bin.size = (size_t)(t->end - t->p);
    return 1;
}

/* Role of a vertex property, by its conventional names. */
static int vi_ply_vertex_role(vi_span name) {
    static const struct {
        const char *name;
        int role;
    } names[] = {
        {"x", VI_X}, {"y", VI_Y}, {"z", VI_Z},
        {"red", VI_R}, {"green", VI_G}, {"blue", VI_B},
        {"diffuse_red", VI_R}, {"diffuse_green", VI_G}, {"diffuse_blue", VI_B},
        {"s", VI_U}, {"t", VI_V}, {"u", VI_U}, {"v", VI_V},
        {"texture_u", VI_U}, {"texture_v", VI_V}, {"texture_s", VI_U}, {"texture_t", VI_V},
    };
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; i++)
        if (vi_is(name, names[i].name)) return names[i].role;
    return VI_SKIP;
}

/* Scale that brings a colour property of TYPE to 0..255. */
static double vi_ply_colour_scale(int type) {
    return type >= VI_F32 ? 255.0 : type == VI_U16 ? 1.0 / 257.0 : 1.0;
}

static int vi_parse_ply(vi_ctx *c, vi_text *t, vdag_scene *out) {
    vi_ply p;
    vi_buf elems = {NULL, 0, 0}, props = {NULL, 0, 0}, poly = {NULL, 0, 0}, tris = {NULL, 0, 0};
    vi_buf late = {NULL, 0, 0}; /* faces read before the vertices: size_t first corner in tris, corner count */
    vi_ply_elem *vertex = NULL, *face = NULL;
    int have_pos = 0;
    vi_ply_prop *prop;
    double colour_scale = 1.0;
    int has[VI_ROLE_COUNT] = {0};
    size_t i, j;
    int ok = 0;
    memset(&p, 0, sizeof p);
    p.c = c;
    if (!vi_ply_header(&p, t, &elems, &props)) goto done;
    prop = (vi_ply_prop *)props.data;

    /* Find the vertex and face elements and give their properties roles. */
    for (i = 0; i < elems.count; i++) {
        vi_ply_elem *e = &((vi_ply_elem *)elems.data)[i];
        if (!vertex && vi_is(e->name, "vertex")) vertex = e;
        else if (!face && vi_is(e->name, "face")) face = e;
    }
    if (!vertex) {
        vi_fail(c, "no vertex element");
        goto done;
    }
    for (j = 0; j < vertex->props; j++) {
        vi_ply_prop *q = &prop[vertex->first + j];
        if (q->count_type >= 0 || has[vi_ply_vertex_role(q->name)]) continue;
        q->role = vi_ply_vertex_role(q->name);
        has[q->role] = 1;
        if (q->role == VI_R) colour_scale = vi_ply_colour_scale(q->type);
    }
    if (!has[VI_X] || !has[VI_Y] || !has[VI_Z]) {
        vi_fail(c, "vertex element lacks scalar x, y or z");
        goto done;
    }
    if (face) {
        for (j = 0; j < face->props; j++) {
            vi_ply_prop *q = &prop[face->first + j];
            if (q->count_type >= 0 && (vi_is(q->name, "vertex_indices") || vi_is(q->name, "vertex_index"))) {
                q->role = VI_CORNERS;
                break;
            }
        }
        if (j == face->props) {
            vi_fail(c, "face element has no vertex_indices list");
            goto done;
        }
    }

    /* Size the vertex arrays once the body is known to be large enough. */
    {
        uint64_t min = vi_ply_min_bytes(&p, prop, vertex);
        uint64_t avail = p.ascii ? (uint64_t)(t->end - p.text.p) + 1 : (uint64_t)p.bin.size;
        if (vertex->count > avail / min) {
            vi_fail(c, "header declares more vertices than the file holds");
            goto done;
        }
        if (vertex->count >= VI_NONE) {
            vi_fail(c, "more than 4294967294 vertices");
            goto done;
        }
    }
    p.vertex_count = vertex->count;
    out->vertex_count = (size_t)vertex->count;
    if (!(out->positions = (double *)vi_alloc(c, out->vertex_count, 3 * sizeof(double)))) goto done;
    if (has[VI_R] && has[VI_G] && has[VI_B] &&
        !(out->vertex_rgb = (uint8_t *)vi_alloc(c, out->vertex_count, 3)))
        goto done;
    if (has[VI_U] && has[VI_V] && !(out->uv = (float *)vi_alloc(c, out->vertex_count, 2 * sizeof(float))))
        goto done;

    /* Read the body element by element. */
    for (i = 0; i < elems.count; i++) {
        const vi_ply_elem *e = &((const vi_ply_elem *)elems.data)[i];
        uint64_t k;
        if (!e->props) continue;
        if (e != vertex && e != face && !p.ascii) {
            /* Skip fixed-size elements whole; lists need item by item. */
            for (j = 0; j < e->props && prop[e->first + j].count_type < 0; j++) {}
            if (j == e->props) {
                uint64_t min = vi_ply_min_bytes(&p, prop, e);
                if (e->count > (uint64_t)(p.bin.size - p.bin.pos) / min) {
                    vi_ply_truncated(&p);
                    goto done;
                }
                p.bin.pos += (size_t)(e->count * min);
                continue;
            }
        }
        for (k = 0; k < e->count; k++) {
            double vals[VI_ROLE_COUNT];
            if (!vi_ply_item(&p, prop, e, vals, &poly)) goto done;
            if (e == face) {
                if (!have_pos && !vi_poly_note(c, &late, tris.count, poly.count)) goto done;
                if (!vi_poly(c, &tris, poly.data, poly.count, sizeof(uint32_t), have_pos ? out->positions : NULL))
                    goto done;
            } else if (e == vertex) {
                double *pos = &out->positions[3 * k];
                for (j = 0; j < 3; j++) {
                    pos[j] = vals[VI_X + j];
                    if (!vi_coord_ok(pos[j])) {
                        vi_fail(c, "vertex %llu: coordinate is not finite or too large", (vi_ull)k);
                        goto done;
                    }
                }
                if (out->vertex_rgb)
                    for (j = 0; j < 3; j++)
                        if (!vi_channel(vals[VI_R + j], colour_scale, &out->vertex_rgb[3 * k + j])) {
                            vi_fail(c, "vertex %llu: colour is NaN", (vi_ull)k);
                            goto done;
                        }
                if (out->uv)
                    for (j = 0; j < 2; j++) {
                        if (!vi_coord_ok(vals[VI_U + j])) {
                            vi_fail(c, "vertex %llu: texture coordinate is not finite or too large", (vi_ull)k);
                            goto done;
                        }
                        out->uv[2 * k + j] = (float)vals[VI_U + j];
                    }
            }
        }
        have_pos |= e == vertex;
    }
    if (!vi_poly_late(c, &tris, sizeof(uint32_t), &late, out->positions)) goto done;
    vi_set_triangles(out, &tris);
    ok = 1;
done:
    vi_buf_free(&late);
    vi_buf_free(&elems);
    vi_buf_free(&props);
    vi_buf_free(&poly);
    vi_buf_free(&tris);
    return ok;
}

// -- .off: [ST][C][N]OFF header, counts, vertices, polygons

/* Moves to the next line holding a token and pops that token into TOK. */
static int vi_data_line(vi_text *t, vi_span *line, vi_span *tok) {
    while (vi_line(t, line))
        if (vi_tok(line, tok)) return 1;
    return 0;
}

/* Colours are 0..1 floats when written with a point or an exponent, else
   0..255 integers (decided per vertex line). */
static int vi_off_colour(vi_span *line, uint8_t rgb[3]) {
    vi_span tok[3];
    double v[3], scale = 1.0;
    int i;
    for (i = 0; i < 3; i++) {
        if (!vi_tok(line, &tok[i]) || !vi_real(tok[i], &v[i])) return 0;
        if (memchr(tok[i].s, '.', vi_len(tok[i])) || memchr(tok[i].s, 'e', vi_len(tok[i])) ||
            memchr(tok[i].s, 'E', vi_len(tok[i])))
            scale = 255.0;
    }
    for (i = 0; i < 3; i++)
        if (!vi_channel(v[i], scale, &rgb[i])) return 0;
    return 1;
}

static int vi_parse_off(vi_ctx *c, vi_text *t, vdag_scene *out) {
    vi_buf poly = {NULL, 0, 0}, tris = {NULL, 0, 0};
    vi_span line, tok, kw;
    int has_c = 0, has_n = 0, ok = 0;
    int64_t nv, nf, i, j, k;
    if (!vi_data_line(t, &line, &kw)) return vi_fail(c, "empty file");
    if (vi_len(kw) >= 2 && !memcmp(kw.s, "ST", 2)) kw.s += 2; /* texture coordinates: ignored */
    if (kw.s < kw.e && *kw.s == 'C') has_c = 1, kw.s++;
    if (kw.s < kw.e && *kw.s == 'N') has_n = 1, kw.s++;
    if (!vi_is(kw, "OFF")) return vi_fail(c, "not an OFF file (header must be [ST][C][N]OFF)");
    /* The counts follow on the header line or on the next one. */
    if (!vi_tok(&line, &tok) && !vi_data_line(t, &line, &tok)) return vi_fail(c, "no vertex and face counts");
    if (vi_is(tok, "BINARY")) return vi_fail(c, "binary OFF is not supported");
    if (!vi_int(tok, &nv) || !vi_tok(&line, &tok) || !vi_int(tok, &nf) || nv < 0 || nf < 0)
        return vi_fail(c, "line %llu: expected vertex and face counts", (vi_ull)t->line);
    /* A vertex takes at least "0 0 0\n". */
    if ((uint64_t)nv > ((uint64_t)(t->end - t->p) + 1) / 6)
        return vi_fail(c, "header declares more vertices than the file holds");
    if (nv >= (int64_t)VI_NONE) return vi_fail(c, "more than 4294967294 vertices");
    out->vertex_count = (size_t)nv;
    if (!(out->positions = (double *)vi_alloc(c, out->vertex_count, 3 * sizeof(double)))) return 0;
    if (has_c && !(out->vertex_rgb = (uint8_t *)vi_alloc(c, out->vertex_count, 3))) return 0;
    for (i = 0; i < nv; i++) {
        double *p = &out->positions[3 * i];
        if (!vi_data_line(t, &line, &tok))
            return vi_fail(c, "file ends after %llu of %llu vertices", (vi_ull)i, (vi_ull)nv);
        for (j = 0; j < 3; j++) {
            if ((j && !vi_tok(&line, &tok)) || !vi_real(tok, &p[j]))
                return vi_fail(c, "line %llu: expected x y z", (vi_ull)t->line);
            if (!vi_coord_ok(p[j]))
                return vi_fail(c, "line %llu: coordinate is not finite or too large", (vi_ull)t->line);
        }
        for (j = 0; has_n && j < 3; j++) vi_tok(&line, &tok);
        if (has_c && !vi_off_colour(&line, &out->vertex_rgb[3 * i]))
            return vi_fail(c, "line %llu: expected a colour r g b", (vi_ull)t->line);
    }
    for (i = 0; i < nf; i++) {
        int64_t n;
        if (!vi_data_line(t, &line, &tok)) {
            vi_fail(c, "file ends after %llu of %llu faces", (vi_ull)i, (vi_ull)nf);
            goto done;
        }
        if (!vi_int(tok, &n) || n < 0) {
            vi_fail(c, "line %llu: bad corner count", (vi_ull)t->line);
            goto done;
        }
        poly.count = 0;
        for (j = 0; j < n; j++) { /* anything after the corners (a face colour) is ignored */
            uint32_t *q;
            if (!vi_tok(&line, &tok) || !vi_int(tok, &k) || k < 0 || k >= nv) {
                vi_fail(c, "line %llu: missing or out-of-range vertex index", (vi_ull)t->line);
                goto done;
            }
            if (!(q = (uint32_t *)vi_push(c, &poly, sizeof *q, 1))) goto done;
            *q = (uint32_t)k;
        }
        if (!vi_poly(c, &tris, poly.data, poly.count, sizeof(uint32_t), out->positions)) goto done;
    }
    vi_set_triangles(out, &tris);
    ok = 1;
done:
    vi_buf_free(&poly);
    vi_buf_free(&tris);
    return ok;
}

// -- .stl: binary and ASCII triangle soups

/* ASCII: "solid [name]", then facets "facet normal nx ny nz", "outer loop",
   three or more "vertex x y z" lines, "endloop", "endfacet", and
   "endsolid [name]"; several solids may follow each other. Keywords in any
   case; normals are ignored; polygons of more than three vertices are
   fan-triangulated. */
static int vi_parse_stl_ascii(vi_ctx *c, vi_text *t, vi_buf *pos, vi_buf *tris) {
    enum { SOLID, FACET, LOOP, VERTEX, ENDFACET } want = SOLID;
    vi_span line, kw, tok;
    uint32_t first = 0, corners = 0;
    while (vi_line(t, &line)) {
        if (!vi_tok(&line, &kw)) continue;
        if (want == SOLID) {
            if (!vi_is_nocase(kw, "solid"))
                return vi_fail(c, "line %llu: expected \"solid\"", (vi_ull)t->line);
            want = FACET;
        } else if (want == FACET) {
            if (vi_is_nocase(kw, "endsolid")) {
                want = SOLID;
            } else if (!vi_is_nocase(kw, "facet")) {
                return vi_fail(c, "line %llu: expected \"facet\" or \"endsolid\"", (vi_ull)t->line);
            } else {
                want = LOOP;
            }
        } else if (want == LOOP) {
            if (!vi_is_nocase(kw, "outer") || !vi_tok(&line, &tok) || !vi_is_nocase(tok, "loop"))
                return vi_fail(c, "line %llu: expected \"outer loop\"", (vi_ull)t->line);
            want = VERTEX;
            corners = 0;
            first = (uint32_t)(pos->count / 3);
        } else if (want == VERTEX && vi_is_nocase(kw, "vertex")) {
            double *p;
            int k;
            if (pos->count / 3 >= VI_NONE - 1) return vi_fail(c, "more than 4294967294 vertices");
            if (!(p = (double *)vi_push(c, pos, sizeof *p, 3))) return 0;
            for (k = 0; k < 3; k++)
                if (!vi_tok(&line, &tok) || !vi_real(tok, &p[k]) || !vi_coord_ok(p[k]))
                    return vi_fail(c, "line %llu: expected \"vertex x y z\" with finite numbers", (vi_ull)t->line);
            if (++corners >= 3) {
                uint32_t *q = (uint32_t *)vi_push(c, tris, sizeof *q, 3);
                if (!q) return 0;
                q[0] = first;
                q[1] = first + corners - 2;
                q[2] = first + corners - 1;
            }
        } else if (want == VERTEX) {
            if (!vi_is_nocase(kw, "endloop"))
                return vi_fail(c, "line %llu: expected \"vertex\" or \"endloop\"", (vi_ull)t->line);
            if (corners < 3) return vi_fail(c, "line %llu: a facet with fewer than 3 vertices", (vi_ull)t->line);
            want = ENDFACET;
        } else {
            if (!vi_is_nocase(kw, "endfacet")) return vi_fail(c, "line %llu: expected \"endfacet\"", (vi_ull)t->line);
            want = FACET;
        }
    }
    if (want != SOLID) return vi_fail(c, "file ends inside a solid (no \"endsolid\")");
    return 1;
}

static vi_span vi_first5(const char *p) {
    vi_span s;
    s.s = p;
    s.e = p + 5;
    return s;
}

/* Binary: an 80-byte header, a u32 triangle count, then per triangle a
   normal (ignored), three vertices (f32 x y z each) and a u16 attribute
   (ignored), little-endian. A file of exactly that size is binary even
   when its header starts with "solid" (as some exporters write); any other
   file starting with "solid" is ASCII. Bytes after the last triangle get a
   warning. */
static int vi_parse_stl(vi_ctx *c, const uint8_t *data, size_t size, vdag_scene *out) {
    vi_buf pos = {NULL, 0, 0}, tris = {NULL, 0, 0};
    uint64_t n = size >= 84 ? vi_uint(data + 80, 4, 0) : 0;
    vi_text t;
    int ok = 0;
    size_t i, k;
    t.p = (const char *)data;
    t.end = t.p + size;
    t.line = 0;
    if (size >= 3 && !memcmp(data, "\xEF\xBB\xBF", 3)) t.p += 3; /* a UTF-8 byte order mark */
    if (size >= 84 && (uint64_t)size - 84 == 50 * n) {
        /* binary, exact size */
    } else if (t.end - t.p >= 5 && vi_is_nocase(vi_first5(t.p), "solid")) {
        if (!vi_parse_stl_ascii(c, &t, &pos, &tris)) goto done;
        goto mesh;
    } else if (size < 84) {
        return vi_fail(c, "not an STL file (no \"solid\" and shorter than a binary header)");
    } else if ((uint64_t)size - 84 < 50 * n) {
        return vi_fail(c, "binary header declares %llu triangles, the file holds %llu", (vi_ull)n,
                       (vi_ull)((size - 84) / 50));
    } else {
        vi_warn(c, "%llu bytes after the last of %llu triangles ignored", (vi_ull)(size - 84 - 50 * n), (vi_ull)n);
    }
    if (3 * n >= VI_NONE) return vi_fail(c, "more than 4294967294 vertices");
    if (!(out->positions = (double *)vi_alloc(c, (size_t)n, 9 * sizeof(double))) ||
        !(out->indices = (uint32_t *)vi_alloc(c, (size_t)n, 3 * sizeof(uint32_t))))
        goto done;
    for (i = 0; i < 3 * (size_t)n; i++) {
        const uint8_t *v = data + 84 + 50 * (i / 3) + 12 + 12 * (i % 3);
        for (k = 0; k < 3; k++) {
            uint32_t w = (uint32_t)vi_uint(v + 4 * k, 4, 0);
            float f;
            memcpy(&f, &w, 4);
            if (!vi_coord_ok(f)) {
                vi_fail(c, "triangle %llu: coordinate is not finite or too large", (vi_ull)(i / 3));
                goto done;
            }
            out->positions[3 * i + k] = f;
        }
        out->indices[i] = (uint32_t)i;
    }
    out->vertex_count = 3 * (size_t)n;
    out->triangle_count = (size_t)n;
    return 1;
mesh:
    out->vertex_count = pos.count / 3;
    out->positions = (double *)pos.data;
    pos.data = NULL;
    out->triangle_count = tris.count / 3;
    out->indices = (uint32_t *)tris.data;
    tris.data = NULL;
    ok = 1;
done:
    vi_buf_free(&pos);
    vi_buf_free(&tris);
    return ok;
}

// -- Hash map: 64-bit hash → 32-bit index, equality decided by the caller

typedef struct vi_map_slot {
    uint64_t hash;
    uint32_t index; /* entry index + 1; 0: empty slot */
} vi_map_slot;

typedef struct vi_map {
    vi_map_slot *slots;
    size_t cap, count; /* cap: a power of two */
} vi_map;

/* Finds the entry with hash H for which SAME(CTX, index) holds. If there is
   none, adds NEXT as a new entry (unless NEXT is VI_NONE). *INDEX receives
   the entry found or added, or VI_NONE. Returns 0 only on allocation failure. */
static int vi_map_find(vi_ctx *c, vi_map *m, uint64_t h, int (*same)(const void *ctx, uint32_t index),
                       const void *ctx, uint32_t next, uint32_t *index) {
    size_t i;
    if ((m->count + 1) * 2 > m->cap) {
        size_t cap = m->cap ? m->cap * 2 : 64, k;
        vi_map_slot *slots = (vi_map_slot *)vi_alloc(c, cap, sizeof *slots);
        if (!slots) return 0;
        memset(slots, 0, cap * sizeof *slots);
        for (k = 0; k < m->cap; k++) {
            if (!m->slots[k].index) continue;
            for (i = m->slots[k].hash & (cap - 1); slots[i].index; i = (i + 1) & (cap - 1)) {}
            slots[i] = m->slots[k];
        }
        free(m->slots);
        m->slots = slots;
        m->cap = cap;
    }
    for (i = h & (m->cap - 1); m->slots[i].index; i = (i + 1) & (m->cap - 1))
        if (m->slots[i].hash == h && same(ctx, m->slots[i].index - 1)) {
            *index = m->slots[i].index - 1;
            return 1;
        }
    *index = next;
    if (next != VI_NONE) {
        m->slots[i].hash = h;
        m->slots[i].index = next + 1;
        m->count++;
    }
    return 1;
}

static uint64_t vi_hash_bytes(vi_span s) { /* FNV-1a */
    uint64_t h = 14695981039346656037ull;
    for (; s.s < s.e; s.s++) h = (h ^ (uint8_t)*s.s) * 1099511628211ull;
    return h;
}

static uint64_t vi_hash_u64(uint64_t x) { /* splitmix64 finaliser */
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

// -- Files and paths

/* 1 when the caller lets the import read PATH (limits.on_file), else 0
   with a message. */
static int vi_may_read(vi_ctx *c, const char *path) {
    if (!c->limits.on_file || c->limits.on_file(c->limits.on_file_user, path)) return 1;
    return vi_fail(c, "%s: not read (refused by the caller)", path);
}

/* Reads F to its end into *DATA (malloc'd) and *SIZE: at most MAX bytes
   (else an error naming WHAT, the limit); KNOWN (or -1) reserves the size. */
static int vi_read_stream(vi_ctx *c, FILE *f, long known, uint64_t max, const char *what, char **data,
                          size_t *size) {
    enum { CHUNK = 1 << 16 };
    vi_buf b = {NULL, 0, 0};
    int ok = 1, too_big = 0;
    /* Reserve the size when it is known, so that big files are not copied. */
    if (known > 0 && (unsigned long)known < SIZE_MAX - CHUNK) {
        too_big = (uint64_t)known > max;
        ok = !too_big && vi_push(c, &b, 1, (size_t)known + CHUNK) != NULL;
        b.count = 0;
    }
    while (ok) {
        char *chunk = (char *)vi_push(c, &b, 1, CHUNK);
        size_t got;
        if (!(ok = chunk != NULL)) break;
        got = fread(chunk, 1, CHUNK, f);
        b.count -= CHUNK - got;
        if ((too_big = b.count > max) != 0) ok = 0;
        if (got < CHUNK) break;
    }
    if (too_big) vi_fail(c, "file larger than %s (%llu)", what, (vi_ull)max);
    if (ok && ferror(f)) ok = vi_fail(c, "cannot read the file (%s)", strerror(errno));
    if (!ok) {
        vi_buf_free(&b);
        return 0;
    }
    *data = (char *)b.data;
    *size = b.count;
    return 1;
}

/* Reads the whole file at PATH into *DATA (malloc'd) and *SIZE. */
static int vi_read_file(vi_ctx *c, const char *path, char **data, size_t *size) {
    FILE *f = fopen(path, "rb");
    long known = -1;
    struct stat st;
    int ok;
    if (!f) return vi_fail(c, "cannot open the file (%s)", strerror(errno));
    if (!fstat(fileno(f), &st) && S_ISDIR(st.st_mode)) {
        fclose(f);
        return vi_fail(c, "is a directory, not a file");
    }
    if (!fseek(f, 0, SEEK_END)) known = ftell(f);
    rewind(f);
    ok = vi_read_stream(c, f, known, c->limits.max_input_bytes, "max_input_bytes", data, size);
    fclose(f);
    return ok;
}

/* The identity of an open file, so that one file named under several
   spellings is read once: its device and inode, or (Windows, where these
   are not kept) its full path. */
typedef struct vi_file_id {
    uint64_t dev, ino;
    char *full; /* malloc'd; NULL but on Windows */
} vi_file_id;

static int vi_same_file(const vi_file_id *a, const vi_file_id *b) {
    if (a->full || b->full) return a->full && b->full && !strcmp(a->full, b->full);
    return a->dev == b->dev && a->ino == b->ino;
}

/* Opens side file PATH (a material library or a texture) for reading, into
   *F with its identity in ID and its size in *SIZE. Only a regular file of
   at most VDAG_IMPORT_MAX_SIDE_FILE_BYTES (and max_input_bytes) is opened:
   the check comes before any read, and a FIFO is never waited on (POSIX:
   opened without blocking, then checked through its descriptor). Returns
   1; -1 when PATH cannot be opened (the reason in WHY); 0 when it is
   refused or on an allocation failure (a message naming PATH in C). */
static uint64_t vi_side_max(const vi_ctx *c) {
    return c->limits.max_input_bytes < VDAG_IMPORT_MAX_SIDE_FILE_BYTES ? c->limits.max_input_bytes
                                                                      : VDAG_IMPORT_MAX_SIDE_FILE_BYTES;
}

static int vi_open_side(vi_ctx *c, const char *path, FILE **f, vi_file_id *id, uint64_t *size, char *why,
                        size_t why_size) {
    uint64_t max = vi_side_max(c);
    vi_ctx named = *c;
    int regular;
#ifdef _WIN32
    struct _stat64 st;
#else
    struct stat st;
    int fd;
#endif
    named.format = path;
    *f = NULL;
    memset(id, 0, sizeof *id);
#ifdef _WIN32
    /* No FIFOs in Windows' file system; devices (NUL, CON) are not regular. */
    if (_stat64(path, &st)) {
        snprintf(why, why_size, "%s: cannot open the file (%s)", path, strerror(errno));
        return -1;
    }
    regular = (st.st_mode & _S_IFMT) == _S_IFREG;
#else
    if ((fd = open(path, O_RDONLY | O_NONBLOCK)) < 0) {
        snprintf(why, why_size, "%s: cannot open the file (%s)", path, strerror(errno));
        return -1;
    }
    if (fstat(fd, &st)) {
        snprintf(why, why_size, "%s: cannot read the file (%s)", path, strerror(errno));
        close(fd);
        return -1;
    }
    regular = S_ISREG(st.st_mode) != 0;
#endif
    if (!regular || st.st_size < 0 || (uint64_t)st.st_size > max) {
#ifndef _WIN32
        close(fd);
#endif
        if (!regular)
            return vi_fail(&named, "not a regular file (a directory, FIFO or device): material libraries "
                                   "and textures are read only from regular files");
        return vi_fail(&named, "file larger than %llu bytes, the most read from a material library or texture",
                       (vi_ull)max);
    }
    *size = (uint64_t)st.st_size;
#ifdef _WIN32
    if (!(id->full = _fullpath(NULL, path, 0))) return vi_fail(c, "out of memory");
    if (!(*f = fopen(path, "rb"))) {
        free(id->full);
        id->full = NULL;
        snprintf(why, why_size, "%s: cannot open the file (%s)", path, strerror(errno));
        return -1;
    }
#else
    id->dev = (uint64_t)st.st_dev;
    id->ino = (uint64_t)st.st_ino;
    /* O_NONBLOCK has no effect on reads of a regular file. */
    if (!(*f = fdopen(fd, "rb"))) {
        close(fd);
        return vi_fail(c, "out of memory");
    }
#endif
    return 1;
}

/* Reads side file PATH whole into *DATA (malloc'd) and *SIZE, as
   vi_open_side allows; returns as it does. */
static int vi_read_side(vi_ctx *c, const char *path, char **data, size_t *size, char *why, size_t why_size) {
    FILE *f;
    vi_file_id id;
    uint64_t known;
    vi_ctx named = *c;
    int ok = vi_open_side(c, path, &f, &id, &known, why, why_size);
    if (ok <= 0) return ok;
    free(id.full);
    named.format = path;
    /* The limit holds also for a file that grows while it is read. */
    ok = vi_read_stream(&named, f, (long)known, vi_side_max(c), "VDAG_IMPORT_MAX_SIDE_FILE_BYTES", data, size);
    fclose(f);
    return ok;
}

/* Directory part of PATH ("." if none), malloc'd. */
static char *vi_dirname(vi_ctx *c, const char *path) {
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) + (slash == path) : 1;
    char *d = (char *)vi_alloc(c, n + 1, 1);
    if (!d) return NULL;
    memcpy(d, slash ? path : ".", n);
    d[n] = 0;
    return d;
}

/* FILE (named inside a file in DIR) as a path, malloc'd; '\' reads as '/'. */
static char *vi_path(vi_ctx *c, const char *dir, vi_span file) {
    size_t dn = strlen(dir), fn = vi_len(file), i;
    char *p = (char *)vi_alloc(c, dn + fn + 2, 1);
    if (!p) return NULL;
    if (fn && (file.s[0] == '/' || file.s[0] == '\\')) dn = 0;
    memcpy(p, dir, dn);
    if (dn) p[dn++] = '/';
    for (i = 0; i < fn; i++) p[dn + i] = file.s[i] == '\\' ? '/' : file.s[i];
    p[dn + fn] = 0;
    return p;
}

// -- .mtl: material libraries (newmtl, Kd, map_Kd)

typedef struct vi_mtl {
    vi_span name, map; /* map: texture file, empty if none */
    uint8_t rgb[3];
} vi_mtl;

/* map_Kd options that take arguments: ARGS of them, then up to MORE numbers. */
static const struct {
    const char *name;
    int args, more;
} vi_map_options[] = {
    {"-blendu", 1, 0}, {"-blendv", 1, 0}, {"-bm", 1, 0}, {"-boost", 1, 0}, {"-cc", 1, 0},
    {"-clamp", 1, 0}, {"-imfchan", 1, 0}, {"-mm", 2, 0}, {"-texres", 1, 0}, {"-type", 1, 0},
    {"-o", 1, 2}, {"-s", 1, 2}, {"-t", 1, 2},
};

/* The file name of a map_Kd line (LINE: what follows the keyword): options
   skipped; the rest of the line is the name, spaces included. */
static int vi_map_file(vi_span line, vi_span *file) {
    const size_t n = sizeof vi_map_options / sizeof vi_map_options[0];
    for (;;) {
        vi_span here = line, tok;
        size_t i;
        int a;
        if (!vi_tok(&line, &tok)) return 0;
        for (i = 0; i < n && !vi_is(tok, vi_map_options[i].name); i++) {}
        if (i == n) {
            *file = vi_trim(here);
            return 1;
        }
        for (a = 0; a < vi_map_options[i].args; a++)
            if (!vi_tok(&line, &tok)) return 0;
        for (a = 0; a < vi_map_options[i].more; a++) {
            vi_span before = line;
            double d;
            if (!vi_tok(&line, &tok) || !vi_real(tok, &d)) {
                line = before;
                break;
            }
        }
    }
}

/* Parses a material library into MTLS (spans into T's bytes). */
static int vi_mtl_parse(vi_ctx *c, vi_text *t, vi_buf *mtls) {
    vi_mtl *m = NULL;
    vi_span line, kw, tok;
    while (vi_line(t, &line)) {
        if (!vi_tok(&line, &kw)) continue;
        if (vi_is(kw, "newmtl")) {
            if (!(m = (vi_mtl *)vi_push(c, mtls, sizeof *m, 1))) return 0;
            m->name = vi_trim(line);
            m->map.s = m->map.e = line.e;
            m->rgb[0] = m->rgb[1] = m->rgb[2] = 255;
        } else if (vi_is_nocase(kw, "Kd")) {
            double v[3];
            int n = 0, i;
            if (!m) return vi_fail(c, "line %llu: Kd before newmtl", (vi_ull)t->line);
            while (n < 3 && vi_tok(&line, &tok) && vi_real(tok, &v[n])) n++;
            if (n == 1) v[1] = v[2] = v[0];
            for (i = 0; i < 3; i++)
                if ((n != 1 && n != 3) || !vi_channel(v[i], 255.0, &m->rgb[i]))
                    return vi_fail(c, "line %llu: Kd needs 1 or 3 numbers", (vi_ull)t->line);
        } else if (vi_is_nocase(kw, "map_Kd")) {
            if (!m) return vi_fail(c, "line %llu: map_Kd before newmtl", (vi_ull)t->line);
            if (!vi_map_file(line, &m->map)) return vi_fail(c, "line %llu: map_Kd has no file", (vi_ull)t->line);
        }
    }
    return 1;
}

/* Textures loaded so far, by file identity, so that each file is read (and
   counted against max_texture_pixels) once however it is named; by the
   name too, so that a name seen before needs no system call. */
typedef struct vi_tex {
    char *path;     /* the name as resolved by vi_path */
    vi_file_id id;  /* valid when opened */
    int opened;
    int32_t image;  /* -1: could not be decoded */
} vi_tex;

typedef struct vi_texcache {
    vi_buf entries; /* vi_tex */
    uint64_t pixels; /* of the textures decoded so far */
} vi_texcache;

static void vi_tex_free(vi_texcache *cache) {
    size_t i;
    for (i = 0; i < cache->entries.count; i++) {
        free(((vi_tex *)cache->entries.data)[i].path);
        free(((vi_tex *)cache->entries.data)[i].id.full);
    }
    vi_buf_free(&cache->entries);
    cache->pixels = 0;
}

/* Textures decoded in batches on the caller's threads (limits.run): each
   texture met gets a provisional image, -2 - N for the Nth, resolved once
   the import is done (vi_defer_resolve); the batch is decoded when it holds
   limits.threads textures, and at the end (vi_defer_flush), in order as
   vi_texture would: the same images, warnings, pixel budget and errors. */
typedef struct vi_defer_tex {
    FILE *f;        /* open at the image's first byte; NULL once decoded */
    char *path;
    vdag_image img;
    uint64_t max_pixels;
    int got;        /* vdag_image_load_file's result */
    char why[512];
} vi_defer_tex;

typedef struct vi_defer {
    vi_buf batch;   /* vi_defer_tex */
    vi_buf images;  /* int32_t per texture met: its image, or -1 */
    uint64_t pixels; /* of the textures decoded so far */
} vi_defer;

static void vi_defer_job(void *user, uint32_t index) {
    vi_defer_tex *t = (vi_defer_tex *)((vi_buf *)user)->data + index;
    t->got = vdag_image_load_file(t->f, t->path, t->max_pixels, &t->img, t->why, sizeof t->why);
    fclose(t->f);
    t->f = NULL;
}

/* Drops the batch: files closed, images and names freed. */
static void vi_defer_drop(vi_defer *d) {
    size_t i;
    for (i = 0; i < d->batch.count; i++) {
        vi_defer_tex *t = (vi_defer_tex *)d->batch.data + i;
        if (t->f) fclose(t->f);
        vdag_image_free(&t->img);
        free(t->path);
    }
    d->batch.count = 0;
}

/* Decodes the batch on the caller's threads and adds its images to S in
   order. Returns 0 after reporting a failure. */
static int vi_defer_flush(vi_ctx *c, vdag_scene *s) {
    vi_defer *d = c->defer;
    size_t i;
    int ok = 1;
    if (!d->batch.count) return 1;
    for (i = 0; i < d->batch.count; i++)
        ((vi_defer_tex *)d->batch.data)[i].max_pixels = c->limits.max_texture_pixels - d->pixels;
    c->limits.run(c->limits.run_user, vi_defer_job, &d->batch, (uint32_t)d->batch.count);
    for (i = 0; ok && i < d->batch.count; i++) {
        vi_defer_tex *t = (vi_defer_tex *)d->batch.data + i;
        int32_t *image = (int32_t *)vi_push(c, &d->images, sizeof *image, 1);
        uint64_t pixels = (uint64_t)t->img.width * t->img.height;
        if (!image) {
            ok = 0;
        } else if (t->got < 0 || (t->got > 0 && pixels > c->limits.max_texture_pixels - d->pixels)) {
            vi_ctx named = *c;
            named.format = t->path;
            ok = vi_fail(&named, "a %lux%lu texture takes the textures past max_texture_pixels (%llu) pixels in all "
                                 "(vdag build --max-texture-pixels N)",
                         (unsigned long)t->img.width, (unsigned long)t->img.height,
                         (vi_ull)c->limits.max_texture_pixels);
        } else if (t->got) {
            vdag_image *grown = (vdag_image *)VDAG_IMPORT_REALLOC(s->images, (s->image_count + 1) * sizeof *grown);
            if (!grown) {
                ok = vi_fail(c, "out of memory");
            } else {
                s->images = grown;
                s->images[s->image_count] = t->img;
                memset(&t->img, 0, sizeof t->img);
                *image = (int32_t)s->image_count++;
                d->pixels += pixels;
            }
        } else {
            if (!c->limits.quiet) fprintf(stderr, "vdag: warning: %s; using the material colour\n", t->why);
            *image = -1;
        }
    }
    vi_defer_drop(d);
    return ok;
}

/* Replaces the provisional images of S's materials by the decoded ones. */
static void vi_defer_resolve(const vi_defer *d, vdag_scene *s) {
    size_t i;
    for (i = 0; i < s->material_count; i++) {
        int32_t *image = &s->materials[i].image;
        if (*image <= -2 && (size_t)(-2 - (int64_t)*image) < d->images.count)
            *image = ((const int32_t *)d->images.data)[-2 - (int64_t)*image];
    }
}

/* Sets *IMAGE to the scene image of texture FILE (named in a file in DIR),
   decoding it on first use; -1, with a warning, if it cannot be opened or
   decoded, or -1 when the caller skips textures: the material then keeps its
   Kd colour. A texture that is not a regular file or is too large, or whose
   pixels would take the textures past max_texture_pixels, is an error. */
static int vi_texture(vi_ctx *c, vdag_scene *s, vi_texcache *cache, const char *dir, vi_span file, int32_t *image) {
    char *path, why[512];
    vi_tex *e, *all;
    vdag_image img;
    size_t i;
    uint64_t bytes;
    FILE *f;
    int got;
    *image = -1;
    if (c->limits.skip_textures) return 1;
    if (!(path = vi_path(c, dir, file))) return 0;
    all = (vi_tex *)cache->entries.data;
    for (i = 0; i < cache->entries.count; i++)
        if (!strcmp(all[i].path, path)) {
            free(path);
            *image = all[i].image;
            return 1;
        }
    if (!(e = (vi_tex *)vi_push(c, &cache->entries, sizeof *e, 1))) {
        free(path);
        return 0;
    }
    memset(e, 0, sizeof *e);
    e->path = path;
    e->image = -1;
    if (!vi_may_read(c, path)) return 0;
    if ((got = vi_open_side(c, path, &f, &e->id, &bytes, why, sizeof why)) <= 0) {
        if (got < 0 && !c->limits.quiet) fprintf(stderr, "vdag: warning: %s; using the material colour\n", why);
        return got < 0;
    }
    e->opened = 1;
    all = (vi_tex *)cache->entries.data;
    for (i = 0; i + 1 < cache->entries.count; i++)
        if (all[i].opened && vi_same_file(&all[i].id, &e->id)) {
            fclose(f);
            *image = e->image = all[i].image;
            return 1;
        }
    if (c->defer) { /* decoded with its batch; a provisional image until then */
        vi_defer *d = c->defer;
        vi_defer_tex *t = (vi_defer_tex *)vi_push(c, &d->batch, sizeof *t, 1);
        size_t n = strlen(path) + 1;
        if (!t) {
            fclose(f);
            return 0;
        }
        memset(t, 0, sizeof *t);
        t->f = f;
        if (!(t->path = (char *)vi_alloc(c, n, 1))) return 0; /* the batch closes F */
        memcpy(t->path, path, n);
        *image = e->image = -2 - (int32_t)(d->images.count + d->batch.count - 1);
        return d->batch.count < c->limits.threads || vi_defer_flush(c, s);
    }
    got = vdag_image_load_file(f, path, c->limits.max_texture_pixels - cache->pixels, &img, why, sizeof why);
    fclose(f);
    if (got < 0) {
        vi_ctx named = *c;
        named.format = path;
        return vi_fail(&named, "a %lux%lu texture takes the textures past max_texture_pixels (%llu) pixels in all "
                               "(vdag build --max-texture-pixels N)",
                       (unsigned long)img.width, (unsigned long)img.height, (vi_ull)c->limits.max_texture_pixels);
    }
    if (got) {
        vdag_image *grown = (vdag_image *)VDAG_IMPORT_REALLOC(s->images, (s->image_count + 1) * sizeof *grown);
        if (!grown) {
            vdag_image_free(&img);
            return vi_fail(c, "out of memory");
        }
        s->images = grown;
        s->images[s->image_count] = img;
        e->image = (int32_t)s->image_count++;
        cache->pixels += (uint64_t)img.width * img.height;
    } else {
        if (!c->limits.quiet) fprintf(stderr, "vdag: warning: %s; using the material colour\n", why);
    }
    *image = e->image;
    return 1;
}

/* A material library on its own: every material, in file order. */
static int vi_parse_mtl(vi_ctx *c, vi_text *t, vdag_scene *out) {
    vi_buf mtls = {NULL, 0, 0};
    vi_texcache cache = {{NULL, 0, 0}, 0};
    size_t i;
    int ok = vi_mtl_parse(c, t, &mtls);
    if (ok && !(out->materials = (vdag_material *)vi_alloc(c, mtls.count, sizeof *out->materials))) ok = 0;
    for (i = 0; ok && i < mtls.count; i++) {
        const vi_mtl *m = &((const vi_mtl *)mtls.data)[i];
        memcpy(out->materials[i].rgb, m->rgb, 3);
        out->materials[i].image = -1;
        out->material_count = i + 1;
        if (c->base_dir && vi_len(m->map)) ok = vi_texture(c, out, &cache, c->base_dir, m->map, &out->materials[i].image);
    }
    vi_buf_free(&mtls);
    vi_tex_free(&cache);
    return ok;
}

// -- .obj: v (optional colour), vt, f, usemtl, mtllib

typedef struct vi_obj {
    vi_ctx *c;
    vi_buf pos, rgb, vt; /* per "v" line (3 doubles, 3 bytes), per "vt" line (2 floats) */
    vi_buf corners;      /* uint64 per triangle corner: v << 32 | vt (VI_NONE: none) */
    vi_buf tri_mat;      /* int32 per triangle */
    vi_buf poly;         /* corners of the face being read */
    vi_buf late;         /* faces naming vertices not yet read (vi_poly_note) */
    vi_buf names;        /* vi_span per material named by usemtl, first use first */
    vi_map name_map;
    vi_buf mtllibs;      /* vi_span per mtllib line */
    uint8_t *defined;    /* per name: 1 when a material library read defines it */
    int any_rgb, any_vt;
    int32_t material;    /* current material, or -1 */
} vi_obj;

typedef struct vi_name_key {
    const vi_span *names;
    vi_span name;
} vi_name_key;

static int vi_same_name(const void *ctx, uint32_t index) {
    const vi_name_key *k = (const vi_name_key *)ctx;
    vi_span a = k->names[index];
    return vi_len(a) == vi_len(k->name) && !memcmp(a.s, k->name.s, vi_len(a));
}

typedef struct vi_corner_key {
    const uint64_t *keys;
    uint64_t key;
} vi_corner_key;

static int vi_same_corner(const void *ctx, uint32_t index) {
    const vi_corner_key *k = (const vi_corner_key *)ctx;
    return k->keys[index] == k->key;
}

/* Resolves index TOK (from 1, or negative: back from the COUNT elements read
   so far) to one from 0. Forward references are checked at the end. */
static int vi_obj_ref(vi_span tok, size_t count, uint32_t *out) {
    int64_t k;
    if (!vi_int(tok, &k) || k == 0) return 0;
    if (k < 0) {
        if ((uint64_t)-k > count) return 0;
        *out = (uint32_t)(count - (size_t)-k);
        return 1;
    }
    if (k >= (int64_t)VI_NONE) return 0;
    *out = (uint32_t)(k - 1);
    return 1;
}

static int vi_obj_vertex(vi_obj *o, vi_span line, uint64_t lineno) {
    double v[6], *p;
    uint8_t *q;
    int n = 0, i;
    vi_span tok;
    while (n < 6 && vi_tok(&line, &tok))
        if (!vi_real(tok, &v[n++])) return vi_fail(o->c, "line %llu: not a number", (vi_ull)lineno);
    if (n < 3) return vi_fail(o->c, "line %llu: v needs x y z", (vi_ull)lineno);
    for (i = 0; i < 3; i++)
        if (!vi_coord_ok(v[i])) return vi_fail(o->c, "line %llu: coordinate is not finite or too large", (vi_ull)lineno);
    if (o->pos.count / 3 >= VI_NONE - 1) return vi_fail(o->c, "more than 4294967294 vertices");
    if (!(p = (double *)vi_push(o->c, &o->pos, sizeof *p, 3)) || !(q = (uint8_t *)vi_push(o->c, &o->rgb, 1, 3)))
        return 0;
    memcpy(p, v, 3 * sizeof *p);
    memset(q, 255, 3);
    if (n == 6) { /* "v x y z r g b": a colour, 0..1 */
        o->any_rgb = 1;
        for (i = 0; i < 3; i++)
            if (!vi_channel(v[3 + i], 255.0, &q[i])) return vi_fail(o->c, "line %llu: colour is NaN", (vi_ull)lineno);
    }
    return 1;
}

static int vi_obj_texcoord(vi_obj *o, vi_span line, uint64_t lineno) {
    double v[2] = {0, 0};
    float *p;
    int n = 0;
    vi_span tok;
    while (n < 2 && vi_tok(&line, &tok))
        if (!vi_real(tok, &v[n++])) return vi_fail(o->c, "line %llu: not a number", (vi_ull)lineno);
    if (!n) return vi_fail(o->c, "line %llu: vt needs u", (vi_ull)lineno);
    if (!vi_coord_ok(v[0]) || !vi_coord_ok(v[1]))
        return vi_fail(o->c, "line %llu: texture coordinate is not finite or too large", (vi_ull)lineno);
    if (o->vt.count / 2 >= VI_NONE - 1) return vi_fail(o->c, "more than 4294967294 texture coordinates");
    if (!(p = (float *)vi_push(o->c, &o->vt, sizeof *p, 2))) return 0;
    p[0] = (float)v[0];
    p[1] = (float)v[1];
    return 1;
}

/* "f v v/vt v//vn v/vt/vn ...": a polygon, triangulated by vi_poly. */
static int vi_obj_face(vi_obj *o, vi_span line, uint64_t lineno) {
    vi_span tok;
    int32_t *m;
    size_t i;
    o->poly.count = 0;
    while (vi_tok(&line, &tok)) {
        const char *slash = (const char *)memchr(tok.s, '/', vi_len(tok));
        vi_span vpart = tok, tpart;
        uint32_t v, t = VI_NONE;
        uint64_t *q;
        tpart.s = tpart.e = tok.e;
        if (slash) {
            vpart.e = slash;
            tpart.s = slash + 1;
            slash = (const char *)memchr(tpart.s, '/', vi_len(tpart));
            if (slash) tpart.e = slash;
        }
        if (!vi_obj_ref(vpart, o->pos.count / 3, &v) || (vi_len(tpart) && !vi_obj_ref(tpart, o->vt.count / 2, &t)))
            return vi_fail(o->c, "line %llu: bad face corner", (vi_ull)lineno);
        if (t != VI_NONE) o->any_vt = 1;
        if (!(q = (uint64_t *)vi_push(o->c, &o->poly, sizeof *q, 1))) return 0;
        *q = (uint64_t)v << 32 | t;
    }
    if (o->poly.count < 3) return 1; /* a point or a line: nothing to voxelize */
    for (i = 0; i < o->poly.count && ((const uint64_t *)o->poly.data)[i] >> 32 < o->pos.count / 3; i++) {}
    if (i < o->poly.count && !vi_poly_note(o->c, &o->late, o->corners.count, o->poly.count)) return 0;
    if (!vi_poly(o->c, &o->corners, o->poly.data, o->poly.count, sizeof(uint64_t),
                 i < o->poly.count ? NULL : (const double *)o->pos.data))
        return 0;
    if (!(m = (int32_t *)vi_push(o->c, &o->tri_mat, sizeof *m, o->poly.count - 2))) return 0;
    for (i = 0; i + 2 < o->poly.count; i++) m[i] = o->material;
    return 1;
}

static int vi_obj_usemtl(vi_obj *o, vi_span name) {
    vi_name_key key;
    uint32_t index;
    key.names = (const vi_span *)o->names.data;
    key.name = name;
    if (o->names.count >= INT32_MAX) return vi_fail(o->c, "too many materials");
    if (!vi_map_find(o->c, &o->name_map, vi_hash_bytes(name), vi_same_name, &key, (uint32_t)o->names.count, &index))
        return 0;
    if (index == o->names.count) {
        vi_span *s = (vi_span *)vi_push(o->c, &o->names, sizeof *s, 1);
        if (!s) return 0;
        *s = name;
    }
    o->material = (int32_t)index;
    return 1;
}

static int vi_obj_read(vi_obj *o, vi_text *t) {
    vi_span line, kw;
    while (vi_line(t, &line)) {
        int ok = 1;
        if (!vi_tok(&line, &kw)) continue;
        if (vi_is(kw, "v")) ok = vi_obj_vertex(o, line, t->line);
        else if (vi_is(kw, "vt")) ok = vi_obj_texcoord(o, line, t->line);
        else if (vi_is(kw, "f")) ok = vi_obj_face(o, line, t->line);
        else if (vi_is(kw, "usemtl")) ok = vi_obj_usemtl(o, vi_trim(line));
        else if (vi_is(kw, "mtllib")) {
            vi_span *s = (vi_span *)vi_push(o->c, &o->mtllibs, sizeof *s, 1);
            if (s) *s = vi_trim(line);
            ok = s != NULL;
        }
        if (!ok) return 0;
    }
    return 1;
}

/* Checks the face corners and builds the vertex arrays: one vertex per
   distinct (v, vt) pair when the faces use texture coordinates. */
static int vi_obj_mesh(vi_obj *o, vdag_scene *out) {
    vi_ctx *c = o->c;
    const uint64_t *corner = (const uint64_t *)o->corners.data;
    size_t npos = o->pos.count / 3, nvt = o->vt.count / 2, n = o->corners.count, i;
    vi_map map = {NULL, 0, 0};
    vi_buf keys = {NULL, 0, 0};
    int ok = 0;
    for (i = 0; i < n; i++) {
        uint32_t v = (uint32_t)(corner[i] >> 32), t = (uint32_t)corner[i];
        if (v >= npos)
            return vi_fail(c, "a face uses vertex %llu of %llu", (vi_ull)v + 1, (vi_ull)npos);
        if (t != VI_NONE && t >= nvt)
            return vi_fail(c, "a face uses texture coordinate %llu of %llu", (vi_ull)t + 1, (vi_ull)nvt);
    }
    if (!vi_poly_late(c, &o->corners, sizeof(uint64_t), &o->late, (const double *)o->pos.data)) return 0;
    corner = (const uint64_t *)o->corners.data;
    if (!n || !o->any_vt) { /* the "v" lines are the vertices */
        out->vertex_count = npos;
        out->positions = (double *)o->pos.data;
        o->pos.data = NULL;
        if (o->any_rgb) {
            out->vertex_rgb = (uint8_t *)o->rgb.data;
            o->rgb.data = NULL;
        }
        if (!n) {
            vi_as_points(out);
            return 1;
        }
    }
    if (!(out->indices = (uint32_t *)vi_alloc(c, n, sizeof(uint32_t)))) return 0;
    out->triangle_count = n / 3;
    if (!o->any_vt) {
        for (i = 0; i < n; i++) out->indices[i] = (uint32_t)(corner[i] >> 32);
        return 1;
    }
    for (i = 0; i < n; i++) {
        vi_corner_key key;
        uint32_t index;
        key.keys = (const uint64_t *)keys.data;
        key.key = corner[i];
        if (keys.count >= VI_NONE - 1) {
            vi_fail(c, "more than 4294967294 vertices");
            goto done;
        }
        if (!vi_map_find(c, &map, vi_hash_u64(corner[i]), vi_same_corner, &key, (uint32_t)keys.count, &index))
            goto done;
        if (index == keys.count) {
            uint64_t *k = (uint64_t *)vi_push(c, &keys, sizeof *k, 1);
            if (!k) goto done;
            *k = corner[i];
        }
        out->indices[i] = index;
    }
    out->vertex_count = keys.count;
    if (!(out->positions = (double *)vi_alloc(c, keys.count, 3 * sizeof(double))) ||
        !(out->uv = (float *)vi_alloc(c, keys.count, 2 * sizeof(float))) ||
        (o->any_rgb && !(out->vertex_rgb = (uint8_t *)vi_alloc(c, keys.count, 3))))
        goto done;
    for (i = 0; i < keys.count; i++) {
        uint64_t k = ((const uint64_t *)keys.data)[i];
        uint32_t v = (uint32_t)(k >> 32), t = (uint32_t)k;
        memcpy(&out->positions[3 * i], &((const double *)o->pos.data)[3 * (size_t)v], 3 * sizeof(double));
        if (out->vertex_rgb) memcpy(&out->vertex_rgb[3 * i], &((const uint8_t *)o->rgb.data)[3 * (size_t)v], 3);
        out->uv[2 * i] = t == VI_NONE ? 0.0f : ((const float *)o->vt.data)[2 * (size_t)t];
        out->uv[2 * i + 1] = t == VI_NONE ? 0.0f : ((const float *)o->vt.data)[2 * (size_t)t + 1];
    }
    ok = 1;
done:
    free(map.slots);
    vi_buf_free(&keys);
    return ok;
}

/* Applies material library FILE (named in the .obj) to the used materials.
   Returns 1 when done, 0 on an error, -1 when the file cannot be read. */
static int vi_obj_mtllib(vi_obj *o, vdag_scene *out, vi_texcache *cache, vi_span file, char *why, size_t why_size) {
    vi_ctx sub = *o->c;
    vi_buf mtls = {NULL, 0, 0};
    char *path = vi_path(o->c, o->c->base_dir, file), *data = NULL, *dir = NULL;
    size_t size, i;
    vi_text t;
    int ok = 0;
    if (!path) return 0;
    if (!vi_may_read(o->c, path)) {
        free(path);
        return 0;
    }
    sub.format = path; /* messages name the library */
    if ((ok = vi_read_side(&sub, path, &data, &size, why, why_size)) <= 0) {
        free(path);
        return ok;
    }
    ok = 0;
    if (!vi_text_start(&sub, data, size, &t) || !(dir = vi_dirname(&sub, path)) || !vi_mtl_parse(&sub, &t, &mtls))
        goto done;
    for (i = 0; i < mtls.count; i++) {
        const vi_mtl *m = &((const vi_mtl *)mtls.data)[i];
        vi_name_key key;
        uint32_t index;
        key.names = (const vi_span *)o->names.data;
        key.name = m->name;
        if (!vi_map_find(&sub, &o->name_map, vi_hash_bytes(m->name), vi_same_name, &key, VI_NONE, &index)) goto done;
        if (index == VI_NONE) continue;
        o->defined[index] = 1;
        memcpy(out->materials[index].rgb, m->rgb, 3);
        if (vi_len(m->map) && !vi_texture(&sub, out, cache, dir, m->map, &out->materials[index].image)) goto done;
    }
    ok = 1;
done:
    vi_buf_free(&mtls);
    free(data);
    free(dir);
    free(path);
    return ok;
}

/* vi_obj_mtllib, where a library that cannot be read only gets a warning. */
static int vi_obj_mtllib_or_warn(vi_obj *o, vdag_scene *out, vi_texcache *cache, vi_span file) {
    char why[512];
    int r = vi_obj_mtllib(o, out, cache, file, why, sizeof why);
    if (r < 0 && !o->c->limits.quiet) fprintf(stderr, "vdag: warning: %s; its materials stay white\n", why);
    return r != 0;
}

/* One warning for the names given to usemtl that no material library read
   defines (they stay white), naming the first few. */
static void vi_obj_undefined_warn(vi_obj *o) {
    enum { SHOWN = 4 };
    char list[4 * 64 + 16];
    size_t i, n = 0, at = 0;
    for (i = 0; i < o->names.count; i++) {
        vi_span name = ((const vi_span *)o->names.data)[i];
        size_t len = vi_len(name);
        if (o->defined[i]) continue;
        if (n < SHOWN && at < sizeof list) {
            int w = snprintf(list + at, sizeof list - at, "%s\"%.*s\"%s", n ? ", " : "",
                             (int)(len > 48 ? 48 : len), name.s, len > 48 ? "..." : "");
            if (w > 0) at += (size_t)w;
        }
        n++;
    }
    if (!n) return;
    if (at > sizeof list - 1) at = sizeof list - 1;
    list[at] = 0;
    vi_warn(o->c, "usemtl names %llu material%s that no material library defines (white): %s%s%s", (vi_ull)n,
            n == 1 ? "" : "s", list, n > SHOWN ? ", ..." : "", o->mtllibs.count ? "" : " (no mtllib line)");
}

/* One material per name given to usemtl: white until a library says more.
   An mtllib line names one file, spaces included, or else several. */
static int vi_obj_materials(vi_obj *o, vdag_scene *out) {
    vi_texcache cache = {{NULL, 0, 0}, 0};
    size_t i;
    int ok = 1;
    if (!o->names.count || !out->triangle_count) return 1;
    out->triangle_material = (int32_t *)o->tri_mat.data;
    o->tri_mat.data = NULL;
    if (!(o->defined = (uint8_t *)vi_alloc(o->c, o->names.count, 1))) return 0;
    memset(o->defined, 0, o->names.count);
    if (!(out->materials = (vdag_material *)vi_alloc(o->c, o->names.count, sizeof *out->materials))) return 0;
    out->material_count = o->names.count;
    for (i = 0; i < o->names.count; i++) {
        memset(out->materials[i].rgb, 255, 3);
        out->materials[i].image = -1;
    }
    for (i = 0; ok && o->c->base_dir && i < o->mtllibs.count; i++) {
        vi_span line = ((const vi_span *)o->mtllibs.data)[i], rest = line, file;
        char why[512];
        int several = vi_tok(&rest, &file) && vi_tok(&rest, &file);
        ok = several ? vi_obj_mtllib(o, out, &cache, line, why, sizeof why) : -1;
        if (ok < 0) { /* one file per token */
            ok = 1;
            for (rest = line; ok && vi_tok(&rest, &file);) ok = vi_obj_mtllib_or_warn(o, out, &cache, file);
        }
    }
    vi_tex_free(&cache);
    if (ok) vi_obj_undefined_warn(o);
    return ok;
}

static int vi_parse_obj(vi_ctx *c, vi_text *t, vdag_scene *out) {
    vi_obj o;
    int ok;
    memset(&o, 0, sizeof o);
    o.c = c;
    o.material = -1;
    ok = vi_obj_read(&o, t) && vi_obj_mesh(&o, out) && vi_obj_materials(&o, out);
    vi_buf_free(&o.pos);
    vi_buf_free(&o.rgb);
    vi_buf_free(&o.vt);
    vi_buf_free(&o.corners);
    vi_buf_free(&o.late);
    vi_buf_free(&o.tri_mat);
    vi_buf_free(&o.poly);
    vi_buf_free(&o.names);
    vi_buf_free(&o.mtllibs);
    free(o.defined);
    free(o.name_map.slots);
    return ok;
}

// -- .vox: MagicaVoxel, versions 150 and 200

/* Most nodes visited while expanding the scene graph, whose shared nodes
   could otherwise expand exponentially (or forever, in a cycle). */
#define VI_VOX_MAX_STEPS ((uint64_t)1 << 22)

/* Integer transform: p -> m p + t, m a signed permutation matrix. */
typedef struct vi_xform {
    int m[3][3];
    int64_t t[3];
} vi_xform;

typedef struct vi_vox_model {
    uint32_t size[3], count;
    uint32_t solid; /* voxels of a colour index other than 0 */
    const uint8_t *voxels; /* count * (x, y, z, colour index) */
} vi_vox_model;

typedef struct vi_vox_node {
    int32_t id;              /* first, so vi_i32_order sorts nodes by id */
    char kind;               /* 'T' transform, 'G' group, 'S' shape */
    int hidden;              /* "_hidden" set on the node */
    int32_t layer;           /* T: its layer */
    uint32_t child_count;    /* T: 1, G: any, S: 0 */
    const uint8_t *children; /* child node ids, int32 each */
    int32_t model;           /* S: the model it shows, or -1 */
    vi_xform xf;             /* T: its transform in the first frame */
} vi_vox_node;

typedef struct vi_vox_visit {
    int32_t node;
    uint64_t depth;
    vi_xform xf;
} vi_vox_visit;

static const char vi_empty[] = "";

static int32_t vi_le_i32(const uint8_t *b) { return (int32_t)vi_signed(vi_uint(b, 4, 0), 32); }

static void vi_identity(vi_xform *x) {
    memset(x, 0, sizeof *x);
    x->m[0][0] = x->m[1][1] = x->m[2][2] = 1;
}

/* A then B: p -> a.m (b.m p + b.t) + a.t. */
static vi_xform vi_compose(const vi_xform *a, const vi_xform *b) {
    vi_xform r;
    int i, j, k;
    for (i = 0; i < 3; i++) {
        r.t[i] = a->t[i];
        for (j = 0; j < 3; j++) {
            r.m[i][j] = 0;
            for (k = 0; k < 3; k++) r.m[i][j] += a->m[i][k] * b->m[k][j];
            r.t[i] += a->m[i][j] * b->t[j];
        }
    }
    return r;
}

/* MagicaVoxel's default palette; entry K is colour index K + 1. First a
   6x6x6 cube of the channel values FF, CC, 99, 66, 33, 00 (blue varying
   fastest, red slowest, black left out), then ten-step ramps of red, green,
   blue and grey through the remaining multiples of 0x11, EE down to 11. */
static void vi_vox_default_palette(uint8_t pal[256][3]) {
    int k;
    for (k = 0; k < 215; k++) {
        pal[k][0] = (uint8_t)(255 - 51 * (k / 36));
        pal[k][1] = (uint8_t)(255 - 51 * (k / 6 % 6));
        pal[k][2] = (uint8_t)(255 - 51 * (k % 6));
    }
    for (k = 0; k < 40; k++) {
        int step = k % 10, ramp = k / 10;
        uint8_t v = (uint8_t)(0x11 * (14 - step - step / 2));
        pal[215 + k][0] = ramp == 0 || ramp == 3 ? v : 0;
        pal[215 + k][1] = ramp == 1 || ramp == 3 ? v : 0;
        pal[215 + k][2] = ramp == 2 || ramp == 3 ? v : 0;
    }
    pal[255][0] = pal[255][1] = pal[255][2] = 0;
}

static int vi_vox_string(vi_reader *r, vi_span *s) {
    uint32_t n;
    const uint8_t *b;
    if (!vi_u32(r, &n) || !(b = vi_take(r, n))) return 0;
    s->s = (const char *)b;
    s->e = s->s + n;
    return 1;
}

/* Reads a DICT (string pairs); the values of the NKEYS KEYS go to VALUES,
   empty when absent. */
static int vi_vox_dict(vi_reader *r, const char *const *keys, vi_span *values, size_t nkeys) {
    uint32_t n, i;
    size_t k;
    for (k = 0; k < nkeys; k++) values[k].s = values[k].e = vi_empty;
    if (!vi_u32(r, &n)) return 0;
    for (i = 0; i < n; i++) {
        vi_span key, value;
        if (!vi_vox_string(r, &key) || !vi_vox_string(r, &value)) return 0;
        for (k = 0; k < nkeys; k++)
            if (vi_is(key, keys[k])) values[k] = value;
    }
    return 1;
}

/* Frame attribute "_r": bits 0-1 and 2-3 give the column of the non-zero
   entry of rows 0 and 1 (row 2 takes the one left), bits 4-6 make rows 0-2
   negative. */
static int vi_vox_rotation(vi_span s, int m[3][3]) {
    int64_t r;
    int c0, c1;
    vi_span tok;
    if (!vi_tok(&s, &tok) || !vi_int(tok, &r) || r < 0 || r > 255) return 0;
    c0 = (int)(r & 3);
    c1 = (int)(r >> 2 & 3);
    if (c0 > 2 || c1 > 2 || c0 == c1) return 0;
    memset(m, 0, 9 * sizeof m[0][0]);
    m[0][c0] = r & 16 ? -1 : 1;
    m[1][c1] = r & 32 ? -1 : 1;
    m[2][3 - c0 - c1] = r & 64 ? -1 : 1;
    return 1;
}

/* Frame attribute "_t": "x y z", 32-bit integers. */
static int vi_vox_translation(vi_span s, int64_t t[3]) {
    vi_span tok;
    int i;
    for (i = 0; i < 3; i++)
        if (!vi_tok(&s, &tok) || !vi_int(tok, &t[i]) || t[i] < INT32_MIN || t[i] > INT32_MAX) return 0;
    return 1;
}

/* Reads the attribute DICT of a node or layer: is "_hidden" set? */
static int vi_vox_hidden(vi_reader *r, int *hidden) {
    static const char *const key[] = {"_hidden"};
    vi_span value;
    if (!vi_vox_dict(r, key, &value, 1)) return 0;
    *hidden = vi_is(vi_trim(value), "1");
    return 1;
}

/* Parses an nTRN, nGRP or nSHP chunk body. */
static int vi_vox_node_chunk(vi_reader *r, char kind, vi_vox_node *n) {
    static const char *const frame_keys[] = {"_r", "_t"};
    vi_span frame[2];
    uint32_t count, frames;
    int32_t reserved;
    memset(n, 0, sizeof *n);
    n->kind = kind;
    n->model = -1;
    vi_identity(&n->xf);
    if (!vi_i32(r, &n->id) || !vi_vox_hidden(r, &n->hidden)) return 0;
    if (kind == 'T') {
        n->child_count = 1;
        if (!(n->children = vi_take(r, 4)) || !vi_i32(r, &reserved) || !vi_i32(r, &n->layer) || !vi_u32(r, &frames))
            return 0;
        if (!frames) return 1; /* only the first frame (of an animation) counts */
        if (!vi_vox_dict(r, frame_keys, frame, 2)) return 0;
        if (vi_len(frame[0]) && !vi_vox_rotation(frame[0], n->xf.m)) return 0;
        if (vi_len(frame[1]) && !vi_vox_translation(frame[1], n->xf.t)) return 0;
        return 1;
    }
    if (!vi_u32(r, &count)) return 0;
    if (kind == 'G') {
        if (count > (r->size - r->pos) / 4) return 0;
        n->child_count = count;
        n->children = vi_take(r, (size_t)count * 4);
        return 1;
    }
    return !count || (vi_i32(r, &n->model) && vi_vox_dict(r, NULL, NULL, 0));
}

/* Orders int32 values, or structs that start with one. */
static int vi_i32_order(const void *a, const void *b) {
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

static int64_t vi_floor_half(int64_t x) { return x >= 0 ? x / 2 : -((1 - x) / 2); }

/* Appends the voxels of model M placed by XF. In a scene graph (CENTRED) a
   model's centre sits at its node's origin: voxel v covers the cell whose
   centre is xf(v + 1/2 - size/2), rounded down where it lands on a corner.
   Outside one, voxels keep their model coordinates. Axes stay MagicaVoxel's
   (z up), the vdag tool's convention too. */
static int vi_vox_place(vi_ctx *c, const vi_vox_model *m, const vi_xform *xf, int centred,
                        const uint8_t pal[256][3], vi_buf *pts, vi_buf *rgb) {
    uint32_t i;
    if (m->count > c->limits.max_points || pts->count / 3 > c->limits.max_points - m->count)
        return vi_fail(c, "scene holds more than max_points (%llu) voxels", (vi_ull)c->limits.max_points);
    for (i = 0; i < m->count; i++) {
        const uint8_t *b = m->voxels + 4 * (size_t)i;
        int64_t w[3], d[3];
        double *p;
        uint8_t *q;
        int a;
        if (!b[3]) continue; /* colour index 0 marks an empty voxel */
        if (b[0] >= m->size[0] || b[1] >= m->size[1] || b[2] >= m->size[2])
            return vi_fail(c, "a voxel lies outside its model's size");
        for (a = 0; a < 3; a++) { /* d: twice the voxel centre, from the model centre */
            d[a] = 2 * (int64_t)b[a] + 1 - (int64_t)m->size[a];
            w[a] = b[a];
        }
        for (a = 0; centred && a < 3; a++)
            w[a] = xf->t[a] + vi_floor_half(xf->m[a][0] * d[0] + xf->m[a][1] * d[1] + xf->m[a][2] * d[2]);
        if (!(p = (double *)vi_push(c, pts, sizeof *p, 3)) || !(q = (uint8_t *)vi_push(c, rgb, 1, 3))) return 0;
        p[0] = (double)w[0];
        p[1] = (double)w[1];
        p[2] = (double)w[2];
        memcpy(q, pal[b[3] - 1], 3);
    }
    return 1;
}

/* Walks the scene graph from node 0, placing each shape's model; hidden
   nodes, and transforms on hidden layers (HIDDEN: sorted ids), are left out
   with what lies below them, as MagicaVoxel leaves them out of exports.
   Without PTS it only counts what it would place: the voxels the models
   list (in *LISTED, refused past max_vox_voxels) and the solid ones among
   them (in *SOLID). */
static int vi_vox_walk(vi_ctx *c, const vi_buf *nodes, const vi_buf *hidden, const vi_buf *models,
                       const uint8_t pal[256][3], vi_buf *pts, vi_buf *rgb, uint64_t *listed, uint64_t *solid) {
    const vi_vox_node *all = (const vi_vox_node *)nodes->data;
    vi_buf stack = {NULL, 0, 0};
    vi_vox_visit *v;
    uint64_t steps = 1;
    int ok = 0;
    if (!(v = (vi_vox_visit *)vi_push(c, &stack, sizeof *v, 1))) return 0;
    v->node = 0;
    v->depth = 0;
    vi_identity(&v->xf);
    while (stack.count) {
        vi_vox_visit at = ((const vi_vox_visit *)stack.data)[--stack.count];
        vi_vox_node key;
        const vi_vox_node *n;
        uint32_t i;
        key.id = at.node;
        n = (const vi_vox_node *)bsearch(&key, all, nodes->count, sizeof key, vi_i32_order);
        if (!n) {
            vi_fail(c, "scene graph refers to missing node %ld", (long)at.node);
            goto done;
        }
        if (at.depth > nodes->count) {
            vi_fail(c, "scene graph has a cycle");
            goto done;
        }
        if (n->hidden || (n->kind == 'T' && hidden->count &&
                          bsearch(&n->layer, hidden->data, hidden->count, sizeof n->layer, vi_i32_order)))
            continue;
        if (n->kind == 'S') {
            if (n->model >= 0 && (size_t)n->model >= models->count) {
                vi_fail(c, "shape node %ld shows missing model %ld", (long)n->id, (long)n->model);
                goto done;
            }
            if (n->model < 0) continue;
            if (!pts) {
                const vi_vox_model *m = &((const vi_vox_model *)models->data)[n->model];
                *listed += m->count;
                *solid += m->solid;
                if (*listed > c->limits.max_vox_voxels) {
                    vi_fail(c, "scene graph places more than max_vox_voxels (%llu) voxels "
                               "(vdag build --max-vox-voxels N)", (vi_ull)c->limits.max_vox_voxels);
                    goto done;
                }
            } else if (!vi_vox_place(c, &((const vi_vox_model *)models->data)[n->model], &at.xf, 1, pal, pts, rgb)) {
                goto done;
            }
            continue;
        }
        if (n->kind == 'T') at.xf = vi_compose(&at.xf, &n->xf);
        for (i = 0; i < n->child_count; i++) {
            if (++steps > VI_VOX_MAX_STEPS) {
                vi_fail(c, "scene graph expands to more than %llu nodes", (vi_ull)VI_VOX_MAX_STEPS);
                goto done;
            }
            if (!(v = (vi_vox_visit *)vi_push(c, &stack, sizeof *v, 1))) goto done;
            v->node = vi_le_i32(n->children + 4 * (size_t)i);
            v->depth = at.depth + 1;
            v->xf = at.xf;
        }
    }
    ok = 1;
done:
    vi_buf_free(&stack);
    return ok;
}

/* Gives PTS and RGB room for SOLID voxels, exactly (none for none);
   refused past max_points. */
static int vi_vox_reserve(vi_ctx *c, uint64_t solid, vi_buf *pts, vi_buf *rgb) {
    if (solid > c->limits.max_points)
        return vi_fail(c, "scene holds more than max_points (%llu) voxels", (vi_ull)c->limits.max_points);
    if (!solid) return 1;
    if (solid > SIZE_MAX / 3 || !(pts->data = vi_alloc(c, (size_t)solid * 3, sizeof(double))) ||
        !(rgb->data = vi_alloc(c, (size_t)solid * 3, 1)))
        return solid > SIZE_MAX / 3 ? vi_fail(c, "out of memory") : 0;
    pts->cap = rgb->cap = (size_t)solid * 3;
    return 1;
}

static int vi_parse_vox(vi_ctx *c, const uint8_t *data, size_t size, vdag_scene *out) {
    vi_reader r;
    vi_buf models = {NULL, 0, 0}, nodes = {NULL, 0, 0}, hidden = {NULL, 0, 0}, pts = {NULL, 0, 0}, rgb = {NULL, 0, 0};
    const uint8_t *b, *palette = NULL;
    size_t palette_entries = 0;
    uint8_t pal[256][3];
    uint32_t version, n, m, size_xyz[3];
    uint64_t listed = 0, solid = 0;
    int have_size = 0, ok = 0;
    size_t end, i;
    r.data = data;
    r.size = size;
    r.pos = 0;
    r.big_endian = 0;
    if (!(b = vi_take(&r, 4)) || memcmp(b, "VOX ", 4)) return vi_fail(c, "not a MagicaVoxel file (no \"VOX \")");
    if (!vi_u32(&r, &version) || !(b = vi_take(&r, 4)) || memcmp(b, "MAIN", 4) || !vi_u32(&r, &n) ||
        !vi_u32(&r, &m) || !vi_take(&r, n))
        return vi_fail(c, "no MAIN chunk");
    if (m > r.size - r.pos) return vi_fail(c, "MAIN chunk runs past the end of the file");
    end = r.pos + m;

    /* Chunks inside MAIN, in order; SIZE comes before its XYZI. */
    while (r.pos < end) {
        size_t at = r.pos;
        const uint8_t *id;
        vi_reader body;
        if (end - r.pos < 12) {
            vi_fail(c, "byte %llu: truncated chunk header", (vi_ull)at);
            goto done;
        }
        id = vi_take(&r, 4);
        vi_u32(&r, &n);
        vi_u32(&r, &m);
        if (n > end - r.pos || m > end - r.pos - n) {
            vi_fail(c, "byte %llu: chunk runs past the end of MAIN", (vi_ull)at);
            goto done;
        }
        body = r;
        body.data = r.data + r.pos;
        body.size = n;
        body.pos = 0;
        r.pos += (size_t)n + m; /* children of chunks inside MAIN are not used */
        if (!memcmp(id, "SIZE", 4)) {
            if (!vi_u32(&body, &size_xyz[0]) || !vi_u32(&body, &size_xyz[1]) || !vi_u32(&body, &size_xyz[2])) {
                vi_fail(c, "byte %llu: SIZE chunk too short", (vi_ull)at);
                goto done;
            }
            have_size = 1;
        } else if (!memcmp(id, "XYZI", 4)) {
            vi_vox_model *model;
            uint32_t count;
            if (!have_size) {
                vi_fail(c, "byte %llu: XYZI chunk without a SIZE chunk before it", (vi_ull)at);
                goto done;
            }
            if (!vi_u32(&body, &count) || count > (body.size - body.pos) / 4) {
                vi_fail(c, "byte %llu: XYZI chunk holds fewer voxels than it declares", (vi_ull)at);
                goto done;
            }
            if (models.count >= INT32_MAX || !(model = (vi_vox_model *)vi_push(c, &models, sizeof *model, 1))) {
                if (models.count >= INT32_MAX) vi_fail(c, "too many models");
                goto done;
            }
            memcpy(model->size, size_xyz, sizeof size_xyz);
            model->count = count;
            model->voxels = vi_take(&body, (size_t)count * 4);
            for (model->solid = 0, i = 0; i < count; i++) {
                const uint8_t *v = model->voxels + 4 * i;
                model->solid += v[3] != 0;
                if (v[3] && (v[0] >= size_xyz[0] || v[1] >= size_xyz[1] || v[2] >= size_xyz[2])) {
                    /* checked here too, as a model may not be placed (one frame of several) */
                    vi_fail(c, "byte %llu: a voxel lies outside its model's size", (vi_ull)at);
                    goto done;
                }
            }
            have_size = 0;
        } else if (!memcmp(id, "RGBA", 4)) { /* 256 entries; shorter ones, as some tools write, are padded */
            palette = body.data;
            palette_entries = body.size / 4 < 256 ? body.size / 4 : 256;
            if (palette_entries < 255) /* entry 255 is never used (colour indices are 1..255) */
                vi_warn(c, "byte %llu: RGBA chunk of %llu bytes (1024 expected); the missing entries are "
                           "MagicaVoxel's default colours", (vi_ull)at, (vi_ull)body.size);
        } else if (!memcmp(id, "nTRN", 4) || !memcmp(id, "nGRP", 4) || !memcmp(id, "nSHP", 4)) {
            vi_vox_node *node = (vi_vox_node *)vi_push(c, &nodes, sizeof *node, 1);
            if (!node) goto done;
            if (!vi_vox_node_chunk(&body, (char)(id[1] == 'T' ? 'T' : id[1] == 'G' ? 'G' : 'S'), node)) {
                vi_fail(c, "byte %llu: malformed %.4s chunk", (vi_ull)at, (const char *)id);
                goto done;
            }
        } else if (!memcmp(id, "LAYR", 4)) {
            int32_t layer;
            int is_hidden;
            if (!vi_i32(&body, &layer) || !vi_vox_hidden(&body, &is_hidden)) {
                vi_fail(c, "byte %llu: malformed LAYR chunk", (vi_ull)at);
                goto done;
            }
            if (is_hidden) {
                int32_t *h = (int32_t *)vi_push(c, &hidden, sizeof *h, 1);
                if (!h) goto done;
                *h = layer;
            }
        } /* else PACK, MATL, MATT, rOBJ, rCAM, NOTE, IMAP, ...: not needed */
    }

    /* Colour index k + 1 is palette entry k. */
    vi_vox_default_palette(pal);
    for (i = 0; palette && i < palette_entries; i++) memcpy(pal[i], palette + 4 * i, 3);
    if (nodes.count && c->limits.vox_model) {
        vi_fail(c, "model %llu asked for, but the file has a scene graph, which places its models",
                (vi_ull)c->limits.vox_model);
        goto done;
    }
    if (nodes.count) {
        const vi_vox_node *sorted = (const vi_vox_node *)nodes.data;
        qsort(nodes.data, nodes.count, sizeof(vi_vox_node), vi_i32_order);
        for (i = 1; i < nodes.count; i++)
            if (sorted[i].id == sorted[i - 1].id) {
                vi_fail(c, "two scene graph nodes have the id %ld", (long)sorted[i].id);
                goto done;
            }
        if (hidden.count) qsort(hidden.data, hidden.count, sizeof(int32_t), vi_i32_order);
        /* Counted first, so that a scene graph that instances a model many
           times is refused before anything is placed, and the voxels kept
           get memory once, of their exact size. */
        if (!vi_vox_walk(c, &nodes, &hidden, &models, (const uint8_t(*)[3])pal, NULL, NULL, &listed, &solid) ||
            !vi_vox_reserve(c, solid, &pts, &rgb) ||
            !vi_vox_walk(c, &nodes, &hidden, &models, (const uint8_t(*)[3])pal, &pts, &rgb, &listed, &solid))
            goto done;
    } else { /* no scene graph: one model (of several, animation frames) at the origin */
        vi_xform id;
        vi_identity(&id);
        if (models.count > 1 || c->limits.vox_model) {
            if (c->limits.vox_model >= models.count) {
                vi_fail(c, "model %llu asked for, but the file holds %llu model%s (numbered from 0)",
                        (vi_ull)c->limits.vox_model, (vi_ull)models.count, models.count == 1 ? "" : "s");
                goto done;
            }
            vi_warn(c, "%llu models and no scene graph (animation frames?): model %llu imported; "
                       "--vox-model N (0..%llu) picks another",
                    (vi_ull)models.count, (vi_ull)c->limits.vox_model, (vi_ull)models.count - 1);
        }
        if (models.count) {
            const vi_vox_model *model = (const vi_vox_model *)models.data + c->limits.vox_model;
            if (!vi_vox_reserve(c, model->solid, &pts, &rgb) ||
                !vi_vox_place(c, model, &id, 0, (const uint8_t(*)[3])pal, &pts, &rgb))
                goto done;
        }
    }

    /* Shift so that the smallest coordinate on each axis is 0. */
    {
        double lo[3] = {0, 0, 0}, *p = (double *)pts.data;
        size_t count = pts.count / 3, a;
        for (i = 0; i < count; i++)
            for (a = 0; a < 3; a++)
                if (!i || p[3 * i + a] < lo[a]) lo[a] = p[3 * i + a];
        for (i = 0; i < count; i++)
            for (a = 0; a < 3; a++) p[3 * i + a] -= lo[a];
        out->points_are_voxels = 1;
        out->point_count = count;
        out->points = p;
        out->point_rgb = (uint8_t *)rgb.data;
        pts.data = rgb.data = NULL;
    }
    ok = 1;
done:
    vi_buf_free(&models);
    vi_buf_free(&nodes);
    vi_buf_free(&hidden);
    vi_buf_free(&pts);
    vi_buf_free(&rgb);
    return ok;
}

// -- .spm and .ac: game scenes (their own file, sharing the helpers above)

#include "import_scene.c"

// -- Entry points

enum { VI_XYZ, VI_PLY, VI_OBJ, VI_OFF, VI_VOX, VI_MTL, VI_SPM, VI_AC, VI_STL, VI_FORMAT_COUNT };
static const char *const vi_formats[VI_FORMAT_COUNT] = {"xyz", "ply", "obj", "off", "vox", "mtl", "spm", "ac", "stl"};

static int vi_format(const char *ext) {
    vi_span s;
    int i;
    s.s = ext;
    s.e = ext + strlen(ext);
    for (i = 0; i < VI_FORMAT_COUNT; i++)
        if (vi_is_nocase(s, vi_formats[i])) return i;
    return -1;
}

/* Parses DATA as FORMAT into OUT (zeroed first; freed on failure). */
static int vi_import(vi_ctx *c, int format, const char *data, size_t size, vdag_scene *out) {
    vi_text t;
    vi_defer defer;
    int ok;
    memset(out, 0, sizeof *out);
    if (c->err_size) c->err[0] = 0;
    memset(&defer, 0, sizeof defer);
    if (c->limits.run && c->limits.threads > 1 && !c->limits.skip_textures &&
        (format == VI_SPM || format == VI_OBJ || format == VI_MTL))
        c->defer = &defer; /* the formats whose materials hold the images */
    switch (format) { /* text formats: past a UTF-8 byte order mark, UTF-16 refused */
    case VI_XYZ: ok = vi_text_start(c, data, size, &t) && vi_parse_xyz(c, &t, out); break;
    case VI_PLY: ok = vi_text_start(c, data, size, &t) && vi_parse_ply(c, &t, out); break;
    case VI_OBJ: ok = vi_text_start(c, data, size, &t) && vi_parse_obj(c, &t, out); break;
    case VI_OFF: ok = vi_text_start(c, data, size, &t) && vi_parse_off(c, &t, out); break;
    case VI_VOX: ok = vi_parse_vox(c, (const uint8_t *)data, size, out); break;
    case VI_MTL: ok = vi_text_start(c, data, size, &t) && vi_parse_mtl(c, &t, out); break;
    case VI_SPM: ok = vi_parse_spm(c, (const uint8_t *)data, size, out); break;
    case VI_AC: ok = vi_text_start(c, data, size, &t) && vi_parse_ac(c, &t, out); break;
    case VI_STL: ok = vi_parse_stl(c, (const uint8_t *)data, size, out); break;
    default: ok = vi_fail(c, "unknown format (expected .xyz, .ply, .obj, .off, .stl, .vox, .mtl, .spm or .ac)"); break;
    }
    if (c->defer) {
        if (ok && (ok = vi_defer_flush(c, out))) vi_defer_resolve(&defer, out);
        vi_defer_drop(&defer);
        vi_buf_free(&defer.batch);
        vi_buf_free(&defer.images);
        c->defer = NULL;
    }
    if (ok) vi_poly_warn(c);
    if (ok && out->point_count > c->limits.max_points)
        ok = vi_fail(c, "more than max_points (%llu) points", (vi_ull)c->limits.max_points);
    if (ok && out->vertex_count > c->limits.max_vertices)
        ok = vi_fail(c, "more than max_vertices (%llu) vertices", (vi_ull)c->limits.max_vertices);
    if (ok && out->triangle_count > c->limits.max_triangles)
        ok = vi_fail(c, "more than max_triangles (%llu) triangles", (vi_ull)c->limits.max_triangles);
    if (!ok) vdag_scene_free(out);
    return ok;
}

int vdag_import_memory(const char *ext, const void *data, size_t size, const char *base_dir,
                       const vdag_import_limits *limits, vdag_scene *out, char *err, size_t err_size) {
    vi_ctx c;
    int format = vi_format(ext);
    vi_ctx_init(&c, format < 0 ? ext : vi_formats[format], err, err_size, limits);
    c.base_dir = base_dir;
    if (size > c.limits.max_input_bytes) {
        memset(out, 0, sizeof *out);
        return vi_fail(&c, "input larger than max_input_bytes (%llu)", (vi_ull)c.limits.max_input_bytes);
    }
    return vi_import(&c, format, size ? (const char *)data : vi_empty, size, out);
}

int vdag_import_file(const char *path, const vdag_import_limits *limits, vdag_scene *out, char *err,
                     size_t err_size) {
    const char *slash = strrchr(path, '/'), *dot = strrchr(slash ? slash : path, '.');
    char *data = NULL, *dir = NULL;
    size_t size = 0;
    vi_ctx c;
    int ok;
    vi_ctx_init(&c, path, err, err_size, limits); /* messages start with the file name */
    memset(out, 0, sizeof *out);
    ok = vi_may_read(&c, path) && vi_read_file(&c, path, &data, &size) &&
         (c.base_dir = dir = vi_dirname(&c, path)) != NULL &&
         vi_import(&c, dot ? vi_format(dot + 1) : -1, data ? data : vi_empty, size, out);
    free(data);
    free(dir);
    return ok;
}

void vdag_scene_free(vdag_scene *scene) {
    size_t i;
    if (!scene) return;
    free(scene->points);
    free(scene->point_rgb);
    free(scene->positions);
    free(scene->vertex_rgb);
    free(scene->uv);
    free(scene->indices);
    free(scene->triangle_material);
    free(scene->materials);
    for (i = 0; i < scene->image_count; i++) vdag_image_free(&scene->images[i]);
    free(scene->images);
    memset(scene, 0, sizeof *scene);
}
