/* A small Vulkan compute runner for the vdag tool and the tests: runs one
   SPIR-V compute shader over a few storage buffers and reads them back.
   The Vulkan loader is opened at run time (libvulkan.so.1, vulkan-1.dll),
   so the tool has no run-time package dependency; without a loader or a
   device, vdag_vk_open fails with a one-line reason. Built without
   VDAG_HAVE_VULKAN (no Vulkan headers at build time), every function exists
   and vdag_vk_open always fails. Targets Vulkan 1.1 with no extensions.
   A vdag_vk is used by one thread at a time. */
#ifndef VDAG_GPU_VULKAN_H
#define VDAG_GPU_VULKAN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Largest push-constant block vdag_vk_run takes, and most buffers per run. */
#define VDAG_VK_MAX_PUSH_BYTES 128
#define VDAG_VK_MAX_BUFFERS 16

typedef struct vdag_vk vdag_vk;

typedef struct vdag_vk_buffer {
    void *data;      /* uploaded before the dispatch; when read_back, overwritten with the buffer's content after it */
    uint64_t size;   /* bytes; a multiple of 4 */
    int read_back;
} vdag_vk_buffer;

/* Opens the loader, creates an instance and a device with a compute queue.
   The device is the first discrete GPU, else integrated, virtual, then CPU
   (lavapipe); the environment variable VDAG_VK_DEVICE=N picks physical
   device N instead. Returns 0 with *OUT set (release with vdag_vk_close), or
   nonzero with *OUT NULL and one line in ERR (when err_size > 0): no loader,
   no Vulkan device, or built without Vulkan. */
int vdag_vk_open(vdag_vk **out, char *err, size_t err_size);
/* Releases everything vdag_vk_open created; NULL is allowed. */
void vdag_vk_close(vdag_vk *vk);
/* The device's name (owned by VK; "" for NULL). */
const char *vdag_vk_device_name(const vdag_vk *vk);
/* 1 when the device is a CPU implementation (VK_PHYSICAL_DEVICE_TYPE_CPU, e.g. lavapipe). */
int vdag_vk_device_is_cpu(const vdag_vk *vk);
/* The largest storage buffer the device binds, in bytes (maxStorageBufferRange). */
uint64_t vdag_vk_max_storage_buffer(const vdag_vk *vk);

/* Runs compute shader SPIRV (SPIRV_BYTES bytes, entry point ENTRY, usually
   "main") with BUFFERS bound as storage buffers at set 0, bindings
   0..COUNT-1 (1 <= COUNT <= VDAG_VK_MAX_BUFFERS), PUSH (PUSH_BYTES <=
   VDAG_VK_MAX_PUSH_BYTES; NULL when 0) as push constants, GROUPS_X x
   GROUPS_Y workgroups. The dispatch is recorded REPEAT times (>= 1), each
   after the previous one's writes; *SECONDS (when not NULL) receives the GPU
   time of one dispatch from timestamp queries, the median over the repeats
   (0 when the queue has no timestamps). Returns 0, or nonzero with one line
   in ERR. The pipeline is kept for the next run with the same SPIRV pointer,
   size, entry, buffer count and push size (so SPIRV must not change while
   VK is open). Sizes are checked before anything is created or any data is read:
   a buffer larger than vdag_vk_max_storage_buffer is refused naming both
   sizes in MiB, so a DATA of NULL is never touched then. */
int vdag_vk_run(vdag_vk *vk, const uint32_t *spirv, size_t spirv_bytes, const char *entry,
                vdag_vk_buffer *buffers, unsigned count, const void *push, uint32_t push_bytes,
                uint32_t groups_x, uint32_t groups_y, uint32_t repeat, double *seconds,
                char *err, size_t err_size);

#ifdef __cplusplus
}
#endif
#endif
