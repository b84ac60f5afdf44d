/* The streaming colour check of `vdag build --verify-colors`: every colour a
   voxcolor stream decodes to, compared with the raw colours it was encoded
   from, a slice at a time (bounded memory whatever the count). */
#ifndef VDAG_CHECK_COLORS_H
#define VDAG_CHECK_COLORS_H

#include <stdint.h>
#include <stdio.h>
#include "voxcolor.h"

typedef struct vdag_color_check {
    double max_error;    /* largest |decoded - raw|_2 / 255 over all colours */
    uint64_t worst;      /* the first colour with that error (0 when none) */
    uint64_t over;       /* colours whose error exceeds the bound */
    uint64_t first_over; /* the first of them; UINT64_MAX when none */
} vdag_color_check;

/* Decodes VIEW's view->count colours in order and compares each with the
   next raw RGB8 colour read from RAW (3 bytes each, from its current
   position). A colour is over BOUND when its Euclidean RGB distance / 255
   exceeds it. Returns 1 with OUT filled, or 0 when RAW ends early or cannot
   be read, or out of memory (OUT then undefined). */
int vdag_check_colors(const voxcolor_view *view, FILE *raw, double bound, vdag_color_check *out);

/* vdag_check_colors with each slice decoded and compared in THREADS jobs:
   RUN (NULL: the calling thread) calls JOB(JOB_USER, i) once for every i in
   [0, COUNT), on any threads, and returns when all have returned. The
   result is the same whatever THREADS. */
int vdag_check_colors_on(const voxcolor_view *view, FILE *raw, double bound,
                         void (*run)(void *user, void (*job)(void *job_user, uint32_t index), void *job_user,
                                     uint32_t count),
                         void *run_user, uint32_t threads, vdag_color_check *out);

#endif
