/* Helpers shared by the importer tests: a growing byte buffer, imports that
   check the failure contract, and the truncation / byte-patch sweep. */
#ifndef VDAG_IMPORT_TEST_H
#define VDAG_IMPORT_TEST_H

#include <stdarg.h>
#include <stdio.h>
#include <unistd.h> /* dup, dup2: the includer defines _POSIX_C_SOURCE */
#include "test.h"
#include "examples/import.h"

typedef struct bytes {
    uint8_t *p;
    size_t n, cap;
} bytes;

static inline void put(bytes *b, const void *data, size_t n) {
    if (!n) return;
    if (b->n + n > b->cap) {
        b->cap = (b->n + n) * 2 + 64;
        b->p = (uint8_t *)realloc(b->p, b->cap);
    }
    memcpy(b->p + b->n, data, n);
    b->n += n;
}

static inline void putf(bytes *b, const char *fmt, ...) {
    char line[1024];
    va_list ap;
    int n;
    va_start(ap, fmt);
    n = vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    put(b, line, (size_t)n);
}

/* An unsigned integer of N bytes in either byte order. */
static inline void put_uint(bytes *b, uint64_t v, int n, int big_endian) {
    uint8_t tmp[8];
    int i;
    for (i = 0; i < n; i++) tmp[big_endian ? n - 1 - i : i] = (uint8_t)(v >> (8 * i));
    put(b, tmp, (size_t)n);
}

static inline void put_le32(bytes *b, int64_t v) { put_uint(b, (uint64_t)v, 4, 0); }

/* Imports DATA; a failure must leave a one-line message and an empty scene. */
static inline int import(const char *ext, const bytes *data, vdag_scene *s, char *err, size_t err_size) {
    vdag_import_limits quiet;
    int ok;
    memset(&quiet, 0, sizeof quiet);
    quiet.quiet = 1; /* sweeps would repeat the warnings of what is tolerated */
    ok = vdag_import_memory(ext, data->p, data->n, NULL, &quiet, s, err, err_size);
    if (!ok) {
        CHECK_MSG(err[0] && !strchr(err, '\n'), "bad message \"%s\"", err);
        CHECK(!s->points && !s->positions && !s->indices && !s->point_count && !s->triangle_count);
    }
    return ok;
}

/* Imports DATA as EXT with warnings on, returning what went to stderr in
   WARN (truncated to WARN_SIZE); the result goes to S (freed by the caller
   when the import succeeded). */
static inline int import_warnings(const char *ext, const bytes *data, vdag_scene *s, char *err, size_t err_size, char *warn,
                           size_t warn_size) {
    FILE *tmp = tmpfile();
    int saved = dup(2), ok;
    size_t n = 0;
    warn[0] = 0;
    CHECK(tmp != NULL && saved >= 0);
    if (!tmp || saved < 0) return 0;
    fflush(stderr);
    dup2(fileno(tmp), 2);
    ok = vdag_import_memory(ext, data->p, data->n, NULL, NULL, s, err, err_size);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    rewind(tmp);
    n = fread(warn, 1, warn_size - 1, tmp);
    warn[n] = 0;
    fclose(tmp);
    return ok;
}

/* Imports DATA expecting a failure whose message contains WANT. */
static inline void expect_error(const char *ext, const bytes *data, const char *want) {
    vdag_scene s;
    char err[256];
    if (import(ext, data, &s, err, sizeof err)) {
        CHECK_MSG(0, "%s file accepted; expected an error with \"%s\"", ext, want);
        vdag_scene_free(&s);
        return;
    }
    CHECK_MSG(strstr(err, want) != NULL, "message \"%s\" lacks \"%s\"", err, want);
}

static inline void expect_error_text(const char *ext, const char *text, const char *want) {
    bytes b = {NULL, 0, 0};
    put(&b, text, strlen(text));
    expect_error(ext, &b, want);
    free(b.p);
}

/* Every proper prefix of a file fails (STRICT) or at least returns cleanly;
   every byte patched (test_patch) returns cleanly. */
static inline void sweep(const char *ext, const bytes *data, int strict) {
    bytes cut = {NULL, 0, 0};
    vdag_scene s;
    char err[256];
    size_t n, i;
    int k;
    for (n = 0; n < data->n; n++) {
        cut.n = 0;
        put(&cut, data->p, n); /* an exact-size copy, so ASan sees over-reads */
        if (import(ext, &cut, &s, err, sizeof err)) {
            CHECK_MSG(!strict, "%s cut to %zu of %zu bytes accepted", ext, n, data->n);
            vdag_scene_free(&s);
        }
    }
    for (i = 0; i < data->n; i++)
        for (k = 0; k < test_patch_count(); k++) {
            if (test_patch(data->p[i], k) == data->p[i]) continue;
            cut.n = 0;
            put(&cut, data->p, data->n);
            cut.p[i] = test_patch(data->p[i], k);
            if (import(ext, &cut, &s, err, sizeof err)) vdag_scene_free(&s);
        }
    free(cut.p);
}

#endif
