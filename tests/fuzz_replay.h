/* Replay main shared by the fuzz targets: runs LLVMFuzzerTestOneInput on
   every file named on the command line (directories: every file inside) and
   prints "N passed, N failed". Include it after the target, in the build
   without libFuzzer.

   Sweeps, before the file names: with --sweep each file also runs cut at
   every length (as exact-size copies, so that ASan sees any over-read) and
   with every byte patched to +1, -1, 0x00 and 0xff; --sweep-full patches
   every byte to each of its 255 other values instead. Both also run each
   file with allocation N failing, for every N in turn, when the target
   defines FUZZ_ALLOC_SWEEP with these two variables:
     static long fuzz_fail_at = -1; the allocation to fail (-1: the target's
                                    own choice)
     static long fuzz_alloc_calls;  allocations the last run counted
   The targets' own checks (clean errors, nothing held at the end) apply to
   every run. */
#ifndef VOXDAG_FUZZ_REPLAY_H
#define VOXDAG_FUZZ_REPLAY_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Runs an exact-size copy of DATA[0..SIZE). */
static void replay_copy(const uint8_t *data, size_t size) {
    uint8_t *copy = (uint8_t *)malloc(size ? size : 1);
    if (size) memcpy(copy, data, size);
    LLVMFuzzerTestOneInput(copy, size);
    free(copy);
}

/* SWEEP: 0 none, 1 the four patches, 2 every byte value. */
static void replay_sweep(const uint8_t *data, size_t size, int sweep) {
    static const int patch[4] = {1, -1, 0x100, 0x1FF}; /* +1, -1, set 0, set 0xff */
    uint8_t *m = (uint8_t *)malloc(size ? size : 1);
    size_t i;
    int k;
    for (i = 0; i < size; i++) replay_copy(data, i);
    if (size) memcpy(m, data, size);
    for (i = 0; i < size; i++) {
        for (k = 0; k < (sweep == 2 ? 256 : 4); k++) {
            uint8_t v = sweep == 2 ? (uint8_t)k
                        : patch[k] == 0x100 ? 0
                        : patch[k] == 0x1FF ? 0xFF
                                            : (uint8_t)(data[i] + patch[k]);
            if (v == data[i]) continue;
            m[i] = v;
            LLVMFuzzerTestOneInput(m, size);
        }
        m[i] = data[i];
    }
    free(m);
#ifdef FUZZ_ALLOC_SWEEP
    for (fuzz_fail_at = 0;; fuzz_fail_at++) {
        fuzz_alloc_calls = 0;
        replay_copy(data, size);
        if (fuzz_alloc_calls <= fuzz_fail_at) break; /* no allocation failed */
    }
    fuzz_fail_at = -1;
#endif
}

static int replay_file(const char *path, int sweep) {
    FILE *f = fopen(path, "rb");
    uint8_t *buf;
    long size;
    if (!f) return 0;
    if (fseek(f, 0, SEEK_END) || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) {
        fclose(f);
        return 0;
    }
    buf = (uint8_t *)malloc(size > 0 ? (size_t)size : 1);
    if (fread(buf, 1, (size_t)size, f) != (size_t)size) {
        fclose(f);
        free(buf);
        return 0;
    }
    fclose(f);
    replay_copy(buf, (size_t)size);
    if (sweep) replay_sweep(buf, (size_t)size, sweep);
    free(buf);
    return 1;
}

int main(int argc, char **argv) {
    int passed = 0, failed = 0, sweep = 0, i;
    for (i = 1; i < argc; i++) {
        DIR *d;
        struct dirent *e;
        if (!strcmp(argv[i], "--sweep") || !strcmp(argv[i], "--sweep-full")) {
            sweep = argv[i][7] ? 2 : 1;
            continue;
        }
        d = opendir(argv[i]);
        if (!d) {
            if (replay_file(argv[i], sweep)) passed++;
            else failed++, fprintf(stderr, "cannot read %s\n", argv[i]);
            continue;
        }
        while ((e = readdir(d)) != NULL) {
            char path[4096];
            if (e->d_name[0] == '.') continue;
            snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
            if (replay_file(path, sweep)) passed++;
            else failed++, fprintf(stderr, "cannot read %s\n", path);
        }
        closedir(d);
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}

#endif
