/* vdag build --verify-colors: check_colors.h. The distance is computed here,
   not by the codec, so that an encoder that misjudges its own error is
   caught. */
#include "check_colors.h"

#include <math.h>
#include <stdlib.h>

int vdag_check_colors(const voxcolor_view *view, FILE *raw, double bound, vdag_color_check *out) {
    enum { SLICE = 1 << 20 };
    uint8_t *want = (uint8_t *)malloc(3 * (size_t)SLICE), *got = (uint8_t *)malloc(3 * (size_t)SLICE);
    uint64_t done = 0, worst_d2 = 0;
    /* Squared distances above this are over the bound (in 8-bit units). */
    double limit = bound * 255.0 * bound * 255.0;
    int ok = want && got;
    out->max_error = 0;
    out->worst = 0;
    out->over = 0;
    out->first_over = UINT64_MAX;
    while (ok && done < view->count) {
        size_t k = view->count - done < SLICE ? (size_t)(view->count - done) : (size_t)SLICE, i;
        if (fread(want, 3, k, raw) != k) {
            ok = 0;
            break;
        }
        voxcolor_view_get_range(view, done, k, got);
        for (i = 0; i < k; i++) {
            int dr = (int)got[3 * i] - want[3 * i], dg = (int)got[3 * i + 1] - want[3 * i + 1],
                db = (int)got[3 * i + 2] - want[3 * i + 2];
            uint64_t d2 = (uint64_t)(dr * dr + dg * dg + db * db);
            if (d2 > worst_d2) worst_d2 = d2, out->worst = done + i;
            if ((double)d2 > limit && sqrt((double)d2) / 255.0 > bound) {
                if (!out->over) out->first_over = done + i;
                out->over++;
            }
        }
        done += k;
    }
    out->max_error = sqrt((double)worst_d2) / 255.0;
    free(want);
    free(got);
    return ok;
}
