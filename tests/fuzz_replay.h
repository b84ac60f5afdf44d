/* Replay main shared by the fuzz targets: runs LLVMFuzzerTestOneInput on
   every file named on the command line (directories: every file inside) and
   prints "N passed, N failed". Include it after the target, in the build
   without libFuzzer. */
#ifndef VOXDAG_FUZZ_REPLAY_H
#define VOXDAG_FUZZ_REPLAY_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

static int replay_file(const char *path) {
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
    LLVMFuzzerTestOneInput(buf, (size_t)size);
    free(buf);
    return 1;
}

int main(int argc, char **argv) {
    int passed = 0, failed = 0, i;
    for (i = 1; i < argc; i++) {
        DIR *d = opendir(argv[i]);
        struct dirent *e;
        if (!d) {
            if (replay_file(argv[i])) passed++;
            else failed++, fprintf(stderr, "cannot read %s\n", argv[i]);
            continue;
        }
        while ((e = readdir(d)) != NULL) {
            char path[4096];
            if (e->d_name[0] == '.') continue;
            snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
            if (replay_file(path)) passed++;
            else failed++, fprintf(stderr, "cannot read %s\n", path);
        }
        closedir(d);
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}

#endif
