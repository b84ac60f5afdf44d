/* The GPU path of the vdag tool: see gpu.h. */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gpu.h"
#include "gpu_vulkan.h"
#include "voxdag_gpu.h"

/* The kernel's C build reads and writes plain word arrays. */
typedef struct vdag_kernel_io {
    const uint32_t *in;
    uint32_t *out;
} vdag_kernel_io;
#define VDAG_KERNEL_IN(io, i) ((io).in[i])
#define VDAG_KERNEL_OUT(io, i, v) ((io).out[i] = (v))
#include "shaders/vdag_kernel.h"

#ifdef VDAG_HAVE_VULKAN
/* SPIR-V arrays made by the Makefile's shader rules ($(BUILD)/shaders). */
#include "vdag_kernel_glsl.h"
#include "vdag_kernel_hlsl.h"
#endif

#define VDAG_GPU_GROUP 64u /* the kernel's local size */

struct vdag_gpu {
    vdag_gpu_target target;
    vdag_vk *vk;
    uint32_t *image; /* the file, padded to whole words */
    size_t image_words;
    voxdag_gpu_buf buf;
    unsigned threads;
};

int vdag_gpu_load(vdag_gpu *g, const voxdag *dag, char *err, size_t err_size) {
    size_t size;
    const void *img = voxdag_image(dag, &size);
    uint32_t *words;
    if ((uint64_t)size >= (uint64_t)1 << 32)
        return snprintf(err, err_size, "the GPU traversal addresses files below 4 GiB; this one has %.1f GiB",
                        (double)size / (1u << 30)), 1;
    if (g->vk && ((uint64_t)size + 3) / 4 * 4 > vdag_vk_max_storage_buffer(g->vk))
        return snprintf(err, err_size, "%s binds storage buffers of at most %llu MiB; this file needs %llu MiB",
                        vdag_vk_device_name(g->vk), (unsigned long long)(vdag_vk_max_storage_buffer(g->vk) >> 20),
                        (unsigned long long)(((uint64_t)size + (1u << 20) - 1) >> 20)), 1;
    words = (uint32_t *)calloc(size ? (size + 3) / 4 : 1, 4);
    if (!words) return snprintf(err, err_size, "out of memory"), 1;
    memcpy(words, img, size); /* the file's little-endian words, as the GPU reads them */
    free(g->image);
    g->image = words, g->image_words = (size + 3) / 4;
    g->buf.bytes = (const unsigned char *)img, g->buf.size = size;
    return 0;
}

int vdag_gpu_open(vdag_gpu **out, vdag_gpu_target target, const voxdag *dag, unsigned threads, char *err,
                  size_t err_size) {
    vdag_gpu *g = (vdag_gpu *)calloc(1, sizeof *g);
    *out = NULL;
    if (!g) return snprintf(err, err_size, "out of memory"), 1;
    g->target = target;
    g->threads = threads ? threads : 1;
    if ((target != VDAG_GPU_EMULATE && vdag_vk_open(&g->vk, err, err_size)) || vdag_gpu_load(g, dag, err, err_size)) {
        vdag_gpu_close(g);
        return 1;
    }
    *out = g;
    return 0;
}

void vdag_gpu_close(vdag_gpu *g) {
    if (!g) return;
    vdag_vk_close(g->vk);
    free(g->image);
    free(g);
}

const char *vdag_gpu_device(const vdag_gpu *g) {
    return g->vk ? vdag_vk_device_name(g->vk) : "the GPU kernel's C build on the CPU";
}

int vdag_gpu_is_cpu(const vdag_gpu *g) { return !g->vk || vdag_vk_device_is_cpu(g->vk); }

// -- The emulation: the kernel's C build over the CPU's threads

typedef struct emulation {
    const vdag_gpu *g;
    const vdag_kernel_params *p;
    vdag_kernel_io io;
    uint32_t next;
    pthread_mutex_t lock;
} emulation;

static void *emulate_worker(void *arg) {
    emulation *e = (emulation *)arg;
    for (;;) {
        uint32_t first, i;
        pthread_mutex_lock(&e->lock);
        first = e->next;
        e->next = first + 4096 < e->p->count ? first + 4096 : e->p->count;
        pthread_mutex_unlock(&e->lock);
        if (first >= e->p->count) return NULL;
        for (i = first; i < first + 4096 && i < e->p->count; i++) vdag_kernel_run(e->g->buf, e->io, *e->p, i);
    }
}

static double wall_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void emulate(const vdag_gpu *g, const vdag_kernel_params *p, const uint32_t *in, uint32_t *out) {
    emulation e;
    pthread_t tid[64];
    unsigned t, n = g->threads < 64 ? g->threads : 64;
    e.g = g, e.p = p, e.io.in = in, e.io.out = out, e.next = 0;
    pthread_mutex_init(&e.lock, NULL);
    for (t = 0; t < n; t++)
        if (pthread_create(&tid[t], NULL, emulate_worker, &e)) break;
    if (t == 0) emulate_worker(&e);
    while (t > 0) pthread_join(tid[--t], NULL);
    pthread_mutex_destroy(&e.lock);
}

/* The push constants for W. */
static vdag_kernel_params kernel_params(const vdag_gpu_work *w) {
    vdag_kernel_params p;
    memset(&p, 0, sizeof p);
    p.mode = (uint32_t)w->mode, p.count = w->count, p.width = w->width, p.height = w->height;
    p.flags = (w->shadows ? VDAG_KERNEL_SHADOWS : 0u) | (w->beam_start ? VDAG_KERNEL_BEAM_START : 0u);
    p.eye_x = w->eye[0], p.eye_y = w->eye[1], p.eye_z = w->eye[2], p.lod = w->lod;
    p.f_x = w->f[0], p.f_y = w->f[1], p.f_z = w->f[2], p.inv_w = w->inv_w;
    p.r_x = w->r[0], p.r_y = w->r[1], p.r_z = w->r[2], p.inv_h = w->inv_h;
    p.u_x = w->u[0], p.u_y = w->u[1], p.u_z = w->u[2], p.ambient = w->ambient;
    p.l_x = w->light[0], p.l_y = w->light[1], p.l_z = w->light[2];
    return p;
}

int vdag_gpu_run(vdag_gpu *g, const vdag_gpu_work *w, const uint32_t *in, size_t in_words, uint32_t *out,
                 size_t out_words, uint32_t repeat, double *seconds, char *err, size_t err_size) {
    vdag_kernel_params params = kernel_params(w), *p = &params;
    uint32_t groups = (p->count + VDAG_GPU_GROUP - 1) / VDAG_GPU_GROUP, gx = groups < 32768 ? groups : 32768;
    uint32_t k;
    static const uint32_t none = 0;
    p->row = VDAG_GPU_GROUP * (gx ? gx : 1);
    if (g->target == VDAG_GPU_EMULATE) {
        double t0 = wall_seconds();
        for (k = 0; k < (repeat ? repeat : 1); k++) emulate(g, p, in ? in : &none, out);
        if (seconds) *seconds = (wall_seconds() - t0) / (repeat ? repeat : 1);
        return 0;
    }
    {
        vdag_vk_buffer b[3];
        const uint32_t *spirv = NULL;
        size_t spirv_bytes = 0;
#ifdef VDAG_HAVE_VULKAN
        spirv = g->target == VDAG_GPU_HLSL ? vdag_kernel_hlsl : vdag_kernel_glsl;
        spirv_bytes = g->target == VDAG_GPU_HLSL ? sizeof vdag_kernel_hlsl : sizeof vdag_kernel_glsl;
#endif
        memset(b, 0, sizeof b);
        b[0].data = g->image, b[0].size = (uint64_t)g->image_words * 4;
        b[1].data = (void *)(in ? in : &none), b[1].size = 4 * (uint64_t)(in_words ? in_words : 1);
        b[2].data = out, b[2].size = 4 * (uint64_t)out_words, b[2].read_back = 1;
        return vdag_vk_run(g->vk, spirv, spirv_bytes, "main", b, 3, p, (uint32_t)sizeof *p, gx ? gx : 1,
                           gx ? (groups + gx - 1) / gx : 1, repeat ? repeat : 1, seconds, err, err_size);
    }
}
