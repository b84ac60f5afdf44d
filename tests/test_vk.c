/* The Vulkan compute runner (examples/gpu_vulkan.c) on the machine's device
   (lavapipe where there is no GPU), under AddressSanitizer and
   UndefinedBehaviorSanitizer (make test): the smoke shader in GLSL and HLSL
   (tests/shaders/vk_smoke.*) over 1,000,003 elements against the same
   computation in C, an oversized buffer refused before its data is read,
   and VDAG_VK_DEVICE naming a device that does not exist. When Vulkan
   cannot be opened this fails, unless the environment variable
   VOXDAG_TEST_SKIP lists "gpu". Prints "N passed, N failed". */
#define _POSIX_C_SOURCE 200112L /* setenv */
#include "examples/gpu_vulkan.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tally.h"

#ifdef VDAG_HAVE_VULKAN
/* SPIR-V arrays made by the Makefile's shader rules ($(BUILD)/shaders). */
#include "vk_smoke_glsl.h"
#include "vk_smoke_hlsl.h"
#endif

#define N 1000003u
#define GROUP 64u

static int skip_allowed(void) {
    const char *s = getenv("VOXDAG_TEST_SKIP");
    char words[256];
    char *w;
    if (!s) return 0;
    snprintf(words, sizeof words, "%s", s);
    for (w = strtok(words, ", "); w; w = strtok(NULL, ", "))
        if (!strcmp(w, "gpu") || !strcmp(w, "all")) return 1;
    return 0;
}

#ifdef VDAG_HAVE_VULKAN
/* Runs one smoke shader over N elements and compares every output. */
static void smoke(vdag_vk *vk, const char *name, const uint32_t *spirv, size_t bytes) {
    uint32_t *in = (uint32_t *)malloc(N * sizeof(uint32_t));
    uint32_t *out = (uint32_t *)malloc(N * sizeof(uint32_t));
    uint32_t push[3], i, bad = 0;
    /* Two rows of workgroups, so that the grid's second axis is used too. */
    uint32_t row = (N + 2 * GROUP - 1) / (2 * GROUP);
    vdag_vk_buffer b[2];
    double seconds = -1;
    char err[256] = "";
    int rc;
    if (!in || !out) {
        check(0, "out of memory", 0);
        free(in), free(out);
        return;
    }
    for (i = 0; i < N; i++) in[i] = i * 2654435761u ^ (i >> 7);
    memset(out, 0xab, N * sizeof(uint32_t));
    push[0] = 12345, push[1] = N, push[2] = row;
    memset(b, 0, sizeof b);
    b[0].data = in, b[0].size = N * sizeof(uint32_t);
    b[1].data = out, b[1].size = N * sizeof(uint32_t), b[1].read_back = 1;
    rc = vdag_vk_run(vk, spirv, bytes, "main", b, 2, push, sizeof push, row, 2, 3, &seconds, err, sizeof err);
    if (rc) fprintf(stderr, "%s: %s\n", name, err);
    check(rc == 0, name, 0);
    check(seconds >= 0 && seconds < 60, "dispatch time in range", 0);
    for (i = 0; i < N && rc == 0; i++)
        if (out[i] != in[i] * 3u + push[0] && bad++ < 5) fprintf(stderr, "%s: element %u is %u\n", name, i, out[i]);
    check(rc == 0 && bad == 0, "every element is in * 3 + add", bad);
    printf("%s: %u elements, %.3f ms per dispatch\n", name, N, seconds * 1e3);
    /* The input buffer, not marked read_back, is left as it was. */
    check(in[1] == (1u * 2654435761u ^ 0u), "input buffer untouched", 0);
    free(in);
    free(out);
}

/* A buffer above the device's limit is refused with both sizes, before any
   data is read (DATA is NULL here). */
static void oversized(vdag_vk *vk, const uint32_t *spirv, size_t bytes) {
    uint64_t limit = vdag_vk_max_storage_buffer(vk);
    uint32_t small[4] = {0, 0, 0, 0}, push[3] = {0, 0, 1};
    vdag_vk_buffer b[2];
    char err[256] = "", want[64];
    int rc;
    memset(b, 0, sizeof b);
    b[0].data = small, b[0].size = sizeof small;
    b[1].data = NULL, b[1].size = (limit + 4 + (1u << 20)) & ~(uint64_t)3;
    rc = vdag_vk_run(vk, spirv, bytes, "main", b, 2, push, sizeof push, 1, 1, 1, NULL, err, sizeof err);
    printf("oversized: %s\n", err);
    check(rc != 0, "oversized buffer refused", 0);
    snprintf(want, sizeof want, "at most %llu MiB", (unsigned long long)(limit >> 20));
    check(strstr(err, "the GPU allows storage buffers of") && strstr(err, want) && strstr(err, "this one needs"),
          "oversized message names both sizes", 0);
    /* Bad arguments: one line each, nothing run. */
    b[1].data = small, b[1].size = sizeof small;
    err[0] = 0;
    check(vdag_vk_run(vk, spirv, bytes, "main", b, 2, push, sizeof push, 1, 1, 0, NULL, err, sizeof err) && *err,
          "repeat 0 refused", 0);
    err[0] = 0;
    check(vdag_vk_run(vk, spirv, 16, "main", b, 2, push, sizeof push, 1, 1, 1, NULL, err, sizeof err) && *err,
          "short SPIR-V refused", 0);
    err[0] = 0;
    check(vdag_vk_run(vk, spirv, bytes, "main", b, 2, push, 132, 1, 1, 1, NULL, err, sizeof err) && *err,
          "132 push bytes refused", 0);
    err[0] = 0;
    check(vdag_vk_run(vk, spirv, bytes, "mai", b, 2, push, sizeof push, 1, 1, 1, NULL, err, sizeof err) &&
              strstr(err, "no compute entry point \"mai\""),
          "unknown entry point refused", 0);
    printf("unknown entry point: %s\n", err);
}
#endif

int main(void) {
    vdag_vk *vk = NULL;
    char err[256] = "";
    if (vdag_vk_open(&vk, err, sizeof err)) {
        if (skip_allowed()) {
            printf("SKIP gpu: %s (allowed by VOXDAG_TEST_SKIP)\n", err);
            printf("0 passed, 0 failed\n");
            return 0;
        }
        fprintf(stderr, "FAIL gpu: cannot open Vulkan: %s (tests/deps.sh installs the packages; "
                        "VOXDAG_TEST_SKIP=gpu allows the skip)\n", err);
        printf("0 passed, 1 failed\n");
        return 1;
    }
    printf("device: %s%s, storage buffers up to %llu bytes\n", vdag_vk_device_name(vk),
           vdag_vk_device_is_cpu(vk) ? " (CPU)" : "", (unsigned long long)vdag_vk_max_storage_buffer(vk));
    check(*vdag_vk_device_name(vk) != 0, "device has a name", 0);
    check(vdag_vk_max_storage_buffer(vk) >= (1u << 27), "storage buffers of at least 128 MiB (Vulkan minimum)", 0);
#ifdef VDAG_HAVE_VULKAN
    smoke(vk, "glsl", vk_smoke_glsl, sizeof vk_smoke_glsl);
    smoke(vk, "hlsl", vk_smoke_hlsl, sizeof vk_smoke_hlsl);
    oversized(vk, vk_smoke_glsl, sizeof vk_smoke_glsl);
#endif
    vdag_vk_close(vk);

    /* A device number past the end names the count. */
    {
        vdag_vk *none = NULL;
        int rc;
        setenv("VDAG_VK_DEVICE", "99", 1);
        rc = vdag_vk_open(&none, err, sizeof err);
        printf("device 99: %s\n", err);
        check(rc != 0 && none == NULL, "VDAG_VK_DEVICE=99 fails", 0);
        check(strstr(err, "VDAG_VK_DEVICE=99") && strstr(err, "Vulkan device"), "VDAG_VK_DEVICE=99 message", 0);
        setenv("VDAG_VK_DEVICE", "0", 1);
        rc = vdag_vk_open(&none, err, sizeof err);
        check(rc == 0 && none != NULL, "VDAG_VK_DEVICE=0 opens", 0);
        vdag_vk_close(none);
        unsetenv("VDAG_VK_DEVICE");
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed != 0;
}
