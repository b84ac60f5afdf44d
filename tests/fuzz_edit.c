/* Fuzz target for the editor: random operations on random scenes, every
   answer compared with the brute-force model of tests/edit_model.h. The
   first input byte selects the options, the second the scene, the rest are
   the operations (each number an operation needs is the next byte; past
   the end, zeros):
     bits 0-1  levels 2..5
     bits 2-3  symmetry: none, reflect, full (3: full)
     bit 4     colours
     bit 5     the allocator fails at allocation 16 * (the second byte)
   After each operation the editor must agree with the model (voxels,
   indices, colours, lookups, rays, and the commit byte for byte with a
   fresh build); an edit may fail only with VOXDAG_ERR_OUT_OF_MEMORY where
   an allocation failed, and then changes nothing. Nothing is held after
   voxdag_editor_free. Any violation aborts.

   Built with -DFUZZ_LIBFUZZER and -fsanitize=fuzzer this is a libFuzzer
   target (make fuzz-edit). Otherwise main() replays the files and folders
   given on the command line (make test replays tests/data/fuzz/edit). */
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#include "count_alloc.h"
#include "fuzz_require.h"
#include "edit_model.h"

#include <stdio.h>

#define FUZZ_MAX_STEPS 64 /* operations a run applies at most */

/* Allocation failure sweeps of the replay main (fuzz_replay.h). */
#define FUZZ_ALLOC_SWEEP
static long fuzz_fail_at = -1, fuzz_alloc_calls;

typedef struct bytes {
    const uint8_t *p;
    size_t n, at;
} bytes;

static uint64_t next_bytes(void *user) {
    bytes *b = (bytes *)user;
    return b->at < b->n ? b->p[b->at++] : 0;
}

/* The rays of the comparisons come from a generator (splitmix64), not from
   the input, which holds the operations. */
static uint64_t next_mix(void *user) {
    uint64_t z = (*(uint64_t *)user += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    static const voxdag_symmetry groups[4] = {VOXDAG_SYMMETRY_NONE, VOXDAG_SYMMETRY_REFLECT, VOXDAG_SYMMETRY_FULL,
                                              VOXDAG_SYMMETRY_FULL};
    count_alloc ca;
    voxdag_editor_opts o;
    voxdag_editor *ed = NULL;
    voxdag *start;
    edit_src src, rays;
    uint64_t ray_state = 1;
    bytes in;
    history h;
    model m;
    uint32_t levels, salt = 7, scene;
    voxdag_symmetry sym;
    int colors, failing, step, wrong = 0;
    size_t c;
    voxdag_status st;
    if (size < 2) return 0;
    levels = 2 + (data[0] & 3u);
    sym = groups[data[0] >> 2 & 3];
    colors = data[0] >> 4 & 1;
    failing = data[0] >> 5 & 1;
    scene = data[1];
    in.p = data + 2;
    in.n = size - 2;
    in.at = 0;
    src.next = next_bytes;
    src.user = &in;
    rays.next = next_mix;
    rays.user = &ray_state;
    model_init(&m, levels);
    for (c = 0; c < m.cells; c++) /* the scene: a pattern picked by the second byte */
        if ((c * 2654435761u >> (scene & 7)) % 5 < (scene >> 3 & 3)) m.full[c] = 1, m.rgb[c] = colors ? (uint32_t)(c * 40503u) & 0xFFFFFF : 0;
    start = model_build(&m, sym, colors, NULL);
    require(start != NULL, "the scene's build failed");
    memset(&o, 0, sizeof o);
    o.allocator = ca_start(&ca, fuzz_fail_at >= 0 ? fuzz_fail_at : failing ? 16 * (long)scene : -1);
    history_init(&h, &m);
    st = voxdag_editor_create(start, &o, &ed, NULL);
    voxdag_free(start);
    require(st == VOXDAG_OK || (st == VOXDAG_ERR_OUT_OF_MEMORY && ca.fail_at >= 0), "create failed");
    for (step = 0; ed && step < FUZZ_MAX_STEPS && in.at < in.n; step++) {
        const char *why;
        long calls = ca.calls, armed;
        st = edit_step(ed, &h, colors, &src, &salt, &wrong);
        require(!wrong, "undo or redo answered wrongly");
        require(st == VOXDAG_OK || (st == VOXDAG_ERR_OUT_OF_MEMORY && ca.fail_at >= calls && ca.fail_at < ca.calls),
                "an edit failed without a failing allocation");
        armed = ca.fail_at >= ca.calls ? ca.fail_at : -1; /* the failure is still ahead */
        ca.fail_at = -1; /* the comparison (a commit) neither counts nor fails */
        why = edit_compare(ed, &h.state[h.done], sym, colors, NULL, &rays, 1);
        ca.fail_at = armed;
        if (why) fprintf(stderr, "step %d: %s\n", step, why);
        require(!why, "the editor differs from the model");
    }
    voxdag_editor_free(ed);
    history_free(&h);
    fuzz_alloc_calls = ca.calls;
    require(ca.held == 0 && !ca.bad_free, "memory held after voxdag_editor_free, or a bad free");
    return 0;
}

#ifndef FUZZ_LIBFUZZER
#include "fuzz_replay.h"
#endif
