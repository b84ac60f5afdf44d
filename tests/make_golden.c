/* Writes the golden .vdag files, or the seed corpus of the load fuzz target.
     make_golden DIR          DIR/<name>.vdag for every golden scene (tests/golden.h)
     make_golden --seeds DIR  fuzz_load inputs: an option byte followed by a
                              golden file, as is or with bytes of its node and
                              brick sections changed (checksums resealed)
   Output is deterministic: the same files on every run. */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#include "golden.h"

#include <stdio.h>

static int write_file(const char *dir, const char *name, const uint8_t *head, size_t head_size,
                      const uint8_t *data, size_t size) {
    char path[4096];
    FILE *f;
    int ok;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "make_golden: cannot create %s\n", path);
        return 0;
    }
    ok = (!head_size || fwrite(head, 1, head_size, f) == head_size) && fwrite(data, 1, size, f) == size;
    ok = fclose(f) == 0 && ok;
    if (!ok) fprintf(stderr, "make_golden: cannot write %s\n", path);
    return ok;
}

/* Option bytes of the seeds (see tests/fuzz_load.c): resealed without and
   with copying, a node limit, a memory limit, a level limit, a failing
   allocator, and one without resealing. */
static const uint8_t seed_options[] = {0x02, 0x03, 0x26, 0x4A, 0x2E, 0x32, 0x00};

static int write_seeds(const char *dir, int kind, const uint8_t *img, size_t size) {
    char name[256];
    uint8_t *copy = (uint8_t *)malloc(size + 1);
    uint64_t r = 0xF00Du + (uint64_t)kind;
    size_t i;
    int ok = 1, k;
    for (i = 0; i < sizeof seed_options; i++) {
        snprintf(name, sizeof name, "seed_%s_%02x", golden_names[kind], seed_options[i]);
        ok &= write_file(dir, name, &seed_options[i], 1, img, size);
    }
    /* Mutations past the checksums: a changed byte in the node or brick data. */
    for (k = 0; k < 4 && size > GOLDEN_HEADER_SIZE; k++) {
        const uint8_t *e;
        uint64_t off, sz;
        memcpy(copy, img, size);
        e = golden_section(copy, size, k & 1 ? 3 : 2);
        if (!e) continue;
        off = golden_le(e + 8, 8), sz = golden_le(e + 16, 8);
        if (sz <= 8) continue; /* only padding */
        copy[off + golden_rand(&r) % (sz - 8)] ^= (uint8_t)(1u << (golden_rand(&r) % 8));
        golden_reseal(copy, size);
        snprintf(name, sizeof name, "seed_%s_mut%d", golden_names[kind], k);
        {
            uint8_t opt = 0x02;
            ok &= write_file(dir, name, &opt, 1, copy, size);
        }
    }
    free(copy);
    return ok;
}

int main(int argc, char **argv) {
    int seeds = argc == 3 && strcmp(argv[1], "--seeds") == 0, kind, ok = 1;
    const char *dir = argv[argc - 1];
    if (argc != 2 && !seeds) {
        fprintf(stderr, "usage: make_golden [--seeds] DIR\n");
        return 2;
    }
    for (kind = 0; kind < GOLDEN_COUNT; kind++) {
        voxdag *d = NULL;
        size_t size;
        const uint8_t *img;
        char name[256];
        if (golden_build(kind, NULL, &d) != VOXDAG_OK) {
            fprintf(stderr, "make_golden: cannot build %s\n", golden_names[kind]);
            return 1;
        }
        img = (const uint8_t *)voxdag_image(d, &size);
        if (seeds) {
            ok &= write_seeds(dir, kind, img, size);
        } else {
            snprintf(name, sizeof name, "%s.vdag", golden_names[kind]);
            ok &= write_file(dir, name, NULL, 0, img, size);
        }
        voxdag_free(d);
    }
    return ok ? 0 : 1;
}
