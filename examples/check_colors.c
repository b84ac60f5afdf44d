/* vdag build --verify-colors: check_colors.h. The distance is computed here,
   not by the codec, so that an encoder that misjudges its own error is
   caught. */
#include "check_colors.h"

#include <math.h>
#include <stdlib.h>

/* One job: colours [BEGIN, END) of the slice that starts at colour BASE,
   against WANT; the largest squared distance (its first colour) and the
   colours over the bound (the first of them). */
typedef struct check_job {
    const voxcolor_view *view;
    const uint8_t *want;
    uint8_t *got;
    uint64_t base, worst, first_over, over, worst_d2;
    size_t begin, end;
    double limit, bound;
} check_job;

static void check_run(void *user, uint32_t index) {
    check_job *j = (check_job *)user + index;
    size_t i;
    j->worst_d2 = j->over = 0;
    j->worst = j->first_over = UINT64_MAX;
    voxcolor_view_get_range(j->view, j->base + j->begin, j->end - j->begin, j->got + 3 * j->begin);
    for (i = j->begin; i < j->end; i++) {
        const uint8_t *got = j->got + 3 * i, *want = j->want + 3 * i;
        int dr = (int)got[0] - want[0], dg = (int)got[1] - want[1], db = (int)got[2] - want[2];
        uint64_t d2 = (uint64_t)(dr * dr + dg * dg + db * db);
        if (d2 > j->worst_d2) j->worst_d2 = d2, j->worst = j->base + i;
        if ((double)d2 > j->limit && sqrt((double)d2) / 255.0 > j->bound) {
            if (!j->over) j->first_over = j->base + i;
            j->over++;
        }
    }
}

int vdag_check_colors_on(const voxcolor_view *view, FILE *raw, double bound,
                         void (*run)(void *user, void (*job)(void *job_user, uint32_t index), void *job_user,
                                     uint32_t count),
                         void *run_user, uint32_t threads, vdag_color_check *out) {
    enum { SLICE = 1 << 20, JOBS = 64 };
    uint8_t *want = (uint8_t *)malloc(3 * (size_t)SLICE), *got = (uint8_t *)malloc(3 * (size_t)SLICE);
    uint64_t done = 0, worst_d2 = 0;
    check_job job[JOBS];
    uint32_t jobs = run && threads > 1 ? (threads < JOBS ? threads : JOBS) : 1, t;
    int ok = want && got;
    out->max_error = 0;
    out->worst = 0;
    out->over = 0;
    out->first_over = UINT64_MAX;
    while (ok && done < view->count) {
        size_t k = view->count - done < SLICE ? (size_t)(view->count - done) : (size_t)SLICE;
        if (fread(want, 3, k, raw) != k) {
            ok = 0;
            break;
        }
        for (t = 0; t < jobs; t++) {
            check_job *j = &job[t];
            j->view = view, j->want = want, j->got = got, j->base = done;
            /* Squared distances above LIMIT are over the bound (in 8-bit units). */
            j->limit = bound * 255.0 * bound * 255.0, j->bound = bound;
            j->begin = k * t / jobs, j->end = k * (t + 1) / jobs;
        }
        if (jobs > 1) run(run_user, check_run, job, jobs);
        else check_run(job, 0);
        for (t = 0; t < jobs; t++) { /* in colour order: the first worst, the first over */
            if (job[t].worst_d2 > worst_d2) worst_d2 = job[t].worst_d2, out->worst = job[t].worst;
            if (job[t].over && !out->over) out->first_over = job[t].first_over;
            out->over += job[t].over;
        }
        done += k;
    }
    out->max_error = sqrt((double)worst_d2) / 255.0;
    free(want);
    free(got);
    return ok;
}

int vdag_check_colors(const voxcolor_view *view, FILE *raw, double bound, vdag_color_check *out) {
    return vdag_check_colors_on(view, raw, bound, NULL, NULL, 1, out);
}
