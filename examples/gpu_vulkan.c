/* The Vulkan compute runner (gpu_vulkan.h). Every Vulkan function comes
   through vkGetInstanceProcAddr from the loader opened at run time, so the
   tool links no Vulkan library and runs where none is installed. */
#include "gpu_vulkan.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int vk_fail(char *err, size_t err_size, const char *fmt, ...) {
    va_list ap;
    if (err_size) {
        va_start(ap, fmt);
        vsnprintf(err, err_size, fmt, ap);
        va_end(ap);
    }
    return 1;
}

#ifndef VDAG_HAVE_VULKAN

/* -- Built without Vulkan */

struct vdag_vk {
    int unused;
};

int vdag_vk_open(vdag_vk **out, char *err, size_t err_size) {
    if (out) *out = NULL;
    return vk_fail(err, err_size, "this vdag was built without Vulkan support (needs the Vulkan headers at build time)");
}
void vdag_vk_close(vdag_vk *vk) {
    (void)vk;
}
const char *vdag_vk_device_name(const vdag_vk *vk) {
    (void)vk;
    return "";
}
int vdag_vk_device_is_cpu(const vdag_vk *vk) {
    (void)vk;
    return 0;
}
uint64_t vdag_vk_max_storage_buffer(const vdag_vk *vk) {
    (void)vk;
    return 0;
}
int vdag_vk_run(vdag_vk *vk, const uint32_t *spirv, size_t spirv_bytes, const char *entry, vdag_vk_buffer *buffers,
                unsigned count, const void *push, uint32_t push_bytes, uint32_t groups_x, uint32_t groups_y,
                uint32_t repeat, double *seconds, char *err, size_t err_size) {
    (void)vk, (void)spirv, (void)spirv_bytes, (void)entry, (void)buffers, (void)count, (void)push;
    (void)push_bytes, (void)groups_x, (void)groups_y, (void)repeat;
    if (seconds) *seconds = 0;
    return vk_fail(err, err_size, "this vdag was built without Vulkan support (needs the Vulkan headers at build time)");
}

#else

#define VK_NO_PROTOTYPES
#include <vulkan/vulkan.h>

/* -- Loader */

#ifdef _WIN32
/* The two Win32 calls, declared here rather than through <windows.h>. */
__declspec(dllimport) void *__stdcall LoadLibraryA(const char *name);
__declspec(dllimport) void *__stdcall GetProcAddress(void *module, const char *name);
__declspec(dllimport) int __stdcall FreeLibrary(void *module);
#define VK_LOADER_NAME "vulkan-1.dll"
static void *vk_lib_open(void) {
    return LoadLibraryA(VK_LOADER_NAME);
}
static void *vk_lib_sym(void *lib, const char *name) {
    return GetProcAddress(lib, name);
}
static void vk_lib_close(void *lib) {
    FreeLibrary(lib);
}
#else
#include <dlfcn.h>
#define VK_LOADER_NAME "libvulkan.so.1"
static void *vk_lib_open(void) {
    return dlopen(VK_LOADER_NAME, RTLD_NOW | RTLD_LOCAL);
}
static void *vk_lib_sym(void *lib, const char *name) {
    return dlsym(lib, name);
}
static void vk_lib_close(void *lib) {
    dlclose(lib);
}
#endif

/* The functions used, loaded by name: instance-level ones through
   vkGetInstanceProcAddr, device-level ones through vkGetDeviceProcAddr
   (which skips the loader's dispatch). */
#define VK_INSTANCE_FUNCS(X)                                                                                          \
    X(vkDestroyInstance)                                                                                              \
    X(vkEnumeratePhysicalDevices)                                                                                     \
    X(vkGetPhysicalDeviceProperties)                                                                                  \
    X(vkGetPhysicalDeviceMemoryProperties)                                                                            \
    X(vkGetPhysicalDeviceQueueFamilyProperties)                                                                       \
    X(vkCreateDevice)                                                                                                 \
    X(vkGetDeviceProcAddr)
#define VK_DEVICE_FUNCS(X)                                                                                            \
    X(vkDestroyDevice)                                                                                                \
    X(vkGetDeviceQueue)                                                                                               \
    X(vkCreateBuffer)                                                                                                 \
    X(vkDestroyBuffer)                                                                                                \
    X(vkGetBufferMemoryRequirements)                                                                                  \
    X(vkAllocateMemory)                                                                                               \
    X(vkFreeMemory)                                                                                                   \
    X(vkBindBufferMemory)                                                                                             \
    X(vkMapMemory)                                                                                                    \
    X(vkUnmapMemory)                                                                                                  \
    X(vkCreateShaderModule)                                                                                           \
    X(vkDestroyShaderModule)                                                                                          \
    X(vkCreateDescriptorSetLayout)                                                                                    \
    X(vkDestroyDescriptorSetLayout)                                                                                   \
    X(vkCreatePipelineLayout)                                                                                         \
    X(vkDestroyPipelineLayout)                                                                                        \
    X(vkCreateComputePipelines)                                                                                       \
    X(vkDestroyPipeline)                                                                                              \
    X(vkCreateDescriptorPool)                                                                                         \
    X(vkDestroyDescriptorPool)                                                                                        \
    X(vkAllocateDescriptorSets)                                                                                       \
    X(vkUpdateDescriptorSets)                                                                                         \
    X(vkCreateQueryPool)                                                                                              \
    X(vkDestroyQueryPool)                                                                                             \
    X(vkGetQueryPoolResults)                                                                                          \
    X(vkCreateCommandPool)                                                                                            \
    X(vkDestroyCommandPool)                                                                                           \
    X(vkAllocateCommandBuffers)                                                                                       \
    X(vkBeginCommandBuffer)                                                                                           \
    X(vkEndCommandBuffer)                                                                                             \
    X(vkCmdBindPipeline)                                                                                              \
    X(vkCmdBindDescriptorSets)                                                                                        \
    X(vkCmdPushConstants)                                                                                             \
    X(vkCmdResetQueryPool)                                                                                            \
    X(vkCmdWriteTimestamp)                                                                                            \
    X(vkCmdDispatch)                                                                                                  \
    X(vkCmdPipelineBarrier)                                                                                           \
    X(vkCreateFence)                                                                                                  \
    X(vkDestroyFence)                                                                                                 \
    X(vkWaitForFences)                                                                                                \
    X(vkQueueSubmit)

#define VK_DECLARE(name) PFN_##name name;

struct vdag_vk {
    void *lib;
    PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr;
    VK_INSTANCE_FUNCS(VK_DECLARE)
    VK_DEVICE_FUNCS(VK_DECLARE)
    VkInstance instance;
    VkPhysicalDevice physical;
    VkDevice device;
    VkQueue queue;
    uint32_t family;
    uint32_t timestamp_bits; /* the queue family's timestampValidBits; 0: no timestamps */
    VkPhysicalDeviceProperties props;
    VkPhysicalDeviceMemoryProperties memory;
    /* The pipeline of the last run, kept for the next one with the same
       shader and interface (creating one compiles the shader). */
    const uint32_t *cached_spirv;
    size_t cached_bytes;
    char cached_entry[64];
    unsigned cached_count;
    uint32_t cached_push;
    VkShaderModule module;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
};

static const char *vk_result_name(VkResult r) {
    switch (r) {
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_FRAGMENTED_POOL: return "VK_ERROR_FRAGMENTED_POOL";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_ERROR_INVALID_SHADER_NV: return "VK_ERROR_INVALID_SHADER_NV";
    case -13: return "VK_ERROR_UNKNOWN"; /* by number: older headers lack the name */
    default: return "an unknown VkResult";
    }
}

/* Names the call that failed and why, for every VkResult checked. */
static int vk_call_fail(char *err, size_t err_size, const char *call, VkResult r) {
    return vk_fail(err, err_size, "Vulkan: %s failed (%s, %d)", call, vk_result_name(r), (int)r);
}

/* Loads one function; a loader or driver without it cannot run us. */
static int vk_load(void *slot, void *fn, const char *name, char *err, size_t err_size) {
    if (!fn) return vk_fail(err, err_size, "Vulkan: the loader or driver lacks %s", name);
    /* A function pointer read back from a data pointer: memcpy is the
       conversion that ISO C accepts (dlsym returns void *). */
    memcpy(slot, &fn, sizeof fn);
    return 0;
}

static void *vk_instance_fn(vdag_vk *vk, const char *name) {
    PFN_vkVoidFunction f = vk->vkGetInstanceProcAddr(vk->instance, name);
    void *p;
    memcpy(&p, &f, sizeof p);
    return p;
}
static void *vk_device_fn(vdag_vk *vk, const char *name) {
    PFN_vkVoidFunction f = vk->vkGetDeviceProcAddr(vk->device, name);
    void *p;
    memcpy(&p, &f, sizeof p);
    return p;
}

/* -- Device choice */

static int vk_type_rank(VkPhysicalDeviceType t) {
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
    }
}

/* The first queue family with compute, preferring one without graphics (an
   async compute queue runs beside a display's work); UINT32_MAX when none. */
static uint32_t vk_compute_family(vdag_vk *vk, VkPhysicalDevice pd, uint32_t *timestamp_bits) {
    VkQueueFamilyProperties q[64];
    uint32_t n = 64, i, best = UINT32_MAX;
    vk->vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, q);
    for (i = 0; i < n; i++) {
        if (!(q[i].queueFlags & VK_QUEUE_COMPUTE_BIT) || q[i].queueCount == 0) continue;
        if (best == UINT32_MAX || !(q[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)) best = i;
        if (!(q[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)) break;
    }
    *timestamp_bits = best == UINT32_MAX ? 0 : q[best].timestampValidBits;
    return best;
}

static int vk_pick_device(vdag_vk *vk, char *err, size_t err_size) {
    VkPhysicalDevice pds[32];
    uint32_t n = 32, i, family = UINT32_MAX, bits = 0;
    int best = -1, best_rank = -1;
    const char *env = getenv("VDAG_VK_DEVICE");
    VkResult r = vk->vkEnumeratePhysicalDevices(vk->instance, &n, pds);
    if (r != VK_SUCCESS && r != VK_INCOMPLETE) return vk_call_fail(err, err_size, "vkEnumeratePhysicalDevices", r);
    if (n == 0) return vk_fail(err, err_size, "Vulkan: no Vulkan device found (the loader found no driver with a device)");
    if (env && *env) {
        char *end;
        unsigned long k = strtoul(env, &end, 10);
        VkPhysicalDeviceProperties p;
        if (*end || end == env)
            return vk_fail(err, err_size, "VDAG_VK_DEVICE=%s: not a device number (0..%u)", env, n - 1);
        if (k >= n)
            return vk_fail(err, err_size, "VDAG_VK_DEVICE=%s: there %s only %u Vulkan device%s (0..%u)", env,
                           n == 1 ? "is" : "are", n, n == 1 ? "" : "s", n - 1);
        vk->vkGetPhysicalDeviceProperties(pds[k], &p);
        if (p.apiVersion < VK_API_VERSION_1_1)
            return vk_fail(err, err_size, "VDAG_VK_DEVICE=%s: %s supports only Vulkan %u.%u; 1.1 is needed", env,
                           p.deviceName, VK_VERSION_MAJOR(p.apiVersion), VK_VERSION_MINOR(p.apiVersion));
        family = vk_compute_family(vk, pds[k], &bits);
        if (family == UINT32_MAX)
            return vk_fail(err, err_size, "VDAG_VK_DEVICE=%s: %s has no compute queue", env, p.deviceName);
        best = (int)k;
    } else {
        for (i = 0; i < n; i++) {
            VkPhysicalDeviceProperties p;
            uint32_t f, b;
            vk->vkGetPhysicalDeviceProperties(pds[i], &p);
            if (p.apiVersion < VK_API_VERSION_1_1) continue;
            f = vk_compute_family(vk, pds[i], &b);
            if (f == UINT32_MAX || vk_type_rank(p.deviceType) <= best_rank) continue;
            best = (int)i, best_rank = vk_type_rank(p.deviceType), family = f, bits = b;
        }
        if (best < 0)
            return vk_fail(err, err_size, "Vulkan: none of the %u Vulkan devices has Vulkan 1.1 and a compute queue", n);
    }
    vk->physical = pds[best];
    vk->family = family;
    vk->timestamp_bits = bits;
    vk->vkGetPhysicalDeviceProperties(vk->physical, &vk->props);
    vk->vkGetPhysicalDeviceMemoryProperties(vk->physical, &vk->memory);
    /* Timestamps also need timestampPeriod; some drivers report 0 bits on
       compute queues, and then the time stays 0. */
    if (vk->props.limits.timestampPeriod <= 0) vk->timestamp_bits = 0;
    return 0;
}

/* -- Open and close */

int vdag_vk_open(vdag_vk **out, char *err, size_t err_size) {
    vdag_vk *vk;
    PFN_vkCreateInstance create_instance = NULL;
    PFN_vkEnumerateInstanceVersion instance_version = NULL;
    VkApplicationInfo app;
    VkInstanceCreateInfo ici;
    VkDeviceQueueCreateInfo qci;
    VkDeviceCreateInfo dci;
    float priority = 1.0f;
    uint32_t version = 0;
    VkResult r;
    if (!out) return vk_fail(err, err_size, "vdag_vk_open: OUT is NULL");
    *out = NULL;
    vk = (vdag_vk *)calloc(1, sizeof *vk);
    if (!vk) return vk_fail(err, err_size, "vdag_vk_open: out of memory");
    vk->lib = vk_lib_open();
    if (!vk->lib) {
        free(vk);
        return vk_fail(err, err_size, "Vulkan: no loader found (cannot open %s; install a Vulkan driver and loader)",
                       VK_LOADER_NAME);
    }
    if (vk_load(&vk->vkGetInstanceProcAddr, vk_lib_sym(vk->lib, "vkGetInstanceProcAddr"), "vkGetInstanceProcAddr",
                err, err_size))
        goto fail;
    /* Global functions are looked up with a NULL instance. */
    if (vk_load(&create_instance, vk_instance_fn(vk, "vkCreateInstance"), "vkCreateInstance", err, err_size)) goto fail;
    /* A 1.0 loader lacks vkEnumerateInstanceVersion. */
    if (vk_load(&instance_version, vk_instance_fn(vk, "vkEnumerateInstanceVersion"), "vkEnumerateInstanceVersion", err,
                err_size)) {
        vk_fail(err, err_size, "Vulkan: the loader supports only Vulkan 1.0; 1.1 is needed");
        goto fail;
    }
    r = instance_version(&version);
    if (r != VK_SUCCESS) {
        vk_call_fail(err, err_size, "vkEnumerateInstanceVersion", r);
        goto fail;
    }
    if (version < VK_API_VERSION_1_1) {
        vk_fail(err, err_size, "Vulkan: the loader supports only Vulkan 1.0; 1.1 is needed");
        goto fail;
    }
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "vdag";
    app.pEngineName = "voxdag";
    app.apiVersion = VK_API_VERSION_1_1;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &app;
    r = create_instance(&ici, NULL, &vk->instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER) {
        vk_fail(err, err_size, "Vulkan: no Vulkan device (the loader found no driver that supports Vulkan 1.1)");
        goto fail;
    }
    if (r != VK_SUCCESS) {
        vk_call_fail(err, err_size, "vkCreateInstance", r);
        goto fail;
    }
#define VK_LOAD_INSTANCE(name) \
    if (vk_load(&vk->name, vk_instance_fn(vk, #name), #name, err, err_size)) goto fail;
    VK_INSTANCE_FUNCS(VK_LOAD_INSTANCE)
    if (vk_pick_device(vk, err, err_size)) goto fail;
    memset(&qci, 0, sizeof qci);
    qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qci.queueFamilyIndex = vk->family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    memset(&dci, 0, sizeof dci);
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    r = vk->vkCreateDevice(vk->physical, &dci, NULL, &vk->device);
    if (r != VK_SUCCESS) {
        vk_call_fail(err, err_size, "vkCreateDevice", r);
        goto fail;
    }
#define VK_LOAD_DEVICE(name) \
    if (vk_load(&vk->name, vk_device_fn(vk, #name), #name, err, err_size)) goto fail;
    VK_DEVICE_FUNCS(VK_LOAD_DEVICE)
    vk->vkGetDeviceQueue(vk->device, vk->family, 0, &vk->queue);
    *out = vk;
    return 0;
fail:
    vdag_vk_close(vk);
    return 1;
}

static void vk_pipeline_free(vdag_vk *vk);

void vdag_vk_close(vdag_vk *vk) {
    if (!vk) return;
    if (vk->device) vk_pipeline_free(vk);
    if (vk->device && vk->vkDestroyDevice) vk->vkDestroyDevice(vk->device, NULL);
    if (vk->instance && vk->vkDestroyInstance) vk->vkDestroyInstance(vk->instance, NULL);
    if (vk->lib) vk_lib_close(vk->lib);
    free(vk);
}

const char *vdag_vk_device_name(const vdag_vk *vk) {
    return vk ? vk->props.deviceName : "";
}
int vdag_vk_device_is_cpu(const vdag_vk *vk) {
    return vk && vk->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
}
uint64_t vdag_vk_max_storage_buffer(const vdag_vk *vk) {
    return vk ? vk->props.limits.maxStorageBufferRange : 0;
}

/* -- Run */

/* Everything one run creates; vk_run_free releases what was made. */
typedef struct vk_run_state {
    VkBuffer buffer[VDAG_VK_MAX_BUFFERS];
    VkDeviceMemory memory[VDAG_VK_MAX_BUFFERS];
    void *mapped[VDAG_VK_MAX_BUFFERS];
    VkDescriptorPool pool;
    VkQueryPool queries;
    VkCommandPool commands;
    VkFence fence;
    uint64_t *stamps;
} vk_run_state;

static void vk_run_free(vdag_vk *vk, vk_run_state *s) {
    unsigned i;
    VkDevice d = vk->device;
    /* Destroying a command pool frees its command buffers, and a descriptor
       pool its sets. */
    if (s->fence) vk->vkDestroyFence(d, s->fence, NULL);
    if (s->commands) vk->vkDestroyCommandPool(d, s->commands, NULL);
    if (s->queries) vk->vkDestroyQueryPool(d, s->queries, NULL);
    if (s->pool) vk->vkDestroyDescriptorPool(d, s->pool, NULL);
    for (i = 0; i < VDAG_VK_MAX_BUFFERS; i++) {
        if (s->mapped[i]) vk->vkUnmapMemory(d, s->memory[i]);
        if (s->buffer[i]) vk->vkDestroyBuffer(d, s->buffer[i], NULL);
        if (s->memory[i]) vk->vkFreeMemory(d, s->memory[i], NULL);
    }
    free(s->stamps);
}

static void vk_pipeline_free(vdag_vk *vk) {
    VkDevice d = vk->device;
    if (vk->pipeline) vk->vkDestroyPipeline(d, vk->pipeline, NULL);
    if (vk->layout) vk->vkDestroyPipelineLayout(d, vk->layout, NULL);
    if (vk->set_layout) vk->vkDestroyDescriptorSetLayout(d, vk->set_layout, NULL);
    if (vk->module) vk->vkDestroyShaderModule(d, vk->module, NULL);
    vk->pipeline = VK_NULL_HANDLE, vk->layout = VK_NULL_HANDLE;
    vk->set_layout = VK_NULL_HANDLE, vk->module = VK_NULL_HANDLE;
    vk->cached_spirv = NULL;
}

/* 1 when SPIRV declares a compute entry point named ENTRY. Checked here
   because naming one that is absent is undefined behaviour in Vulkan (a
   driver may crash instead of failing). */
static int vk_has_entry(const uint32_t *spirv, size_t words, const char *entry) {
    size_t i = 5, len = strlen(entry);
    while (i < words) {
        uint32_t n = spirv[i] >> 16, op = spirv[i] & 0xffff;
        if (n == 0 || n > words - i) return 0;
        /* OpEntryPoint (15): execution model, function id, name. GLCompute is 5. */
        if (op == 15 && n > 3 && spirv[i + 1] == 5 && (n - 3) * 4 > len &&
            !memcmp(spirv + i + 3, entry, len + 1))
            return 1;
        i += n;
    }
    return 0;
}

/* Checks the arguments against the API and the device's limits; reads no
   buffer data, so an oversized buffer can be described without memory. */
static int vk_run_check(const vdag_vk *vk, const uint32_t *spirv, size_t spirv_bytes, const char *entry,
                        const vdag_vk_buffer *buffers, unsigned count, const void *push, uint32_t push_bytes,
                        uint32_t groups_x, uint32_t groups_y, uint32_t repeat, char *err, size_t err_size) {
    const VkPhysicalDeviceLimits *l = &vk->props.limits;
    unsigned i;
    if (!spirv || spirv_bytes < 20 || spirv_bytes % 4 || spirv[0] != 0x07230203u)
        return vk_fail(err, err_size, "vdag_vk_run: SPIRV is not a SPIR-V module (NULL, short, or wrong magic)");
    if (!entry || !*entry) return vk_fail(err, err_size, "vdag_vk_run: no entry point name");
    if (!vk_has_entry(spirv, spirv_bytes / 4, entry))
        return vk_fail(err, err_size, "vdag_vk_run: the shader has no compute entry point \"%s\"", entry);
    if (count == 0 || count > VDAG_VK_MAX_BUFFERS || !buffers)
        return vk_fail(err, err_size, "vdag_vk_run: %u buffers; 1 to %d are allowed", count, VDAG_VK_MAX_BUFFERS);
    if (count > l->maxPerStageDescriptorStorageBuffers)
        return vk_fail(err, err_size, "the GPU binds at most %u storage buffers per shader; this run has %u",
                       l->maxPerStageDescriptorStorageBuffers, count);
    if (push_bytes > VDAG_VK_MAX_PUSH_BYTES || push_bytes % 4 || (push_bytes && !push))
        return vk_fail(err, err_size, "vdag_vk_run: %u push-constant bytes; a multiple of 4 up to %d, with PUSH set",
                       push_bytes, VDAG_VK_MAX_PUSH_BYTES);
    if (push_bytes > l->maxPushConstantsSize)
        return vk_fail(err, err_size, "the GPU allows at most %u push-constant bytes; this run has %u",
                       l->maxPushConstantsSize, push_bytes);
    if (groups_x == 0 || groups_y == 0 || groups_x > l->maxComputeWorkGroupCount[0] ||
        groups_y > l->maxComputeWorkGroupCount[1])
        return vk_fail(err, err_size, "vdag_vk_run: %u x %u workgroups; the GPU allows 1..%u x 1..%u", groups_x,
                       groups_y, l->maxComputeWorkGroupCount[0], l->maxComputeWorkGroupCount[1]);
    if (repeat == 0) return vk_fail(err, err_size, "vdag_vk_run: REPEAT is 0");
    for (i = 0; i < count; i++) {
        uint64_t size = buffers[i].size;
        if (size > l->maxStorageBufferRange)
            /* The limit rounded down and the need up: never "at most 128; needs 128". */
            return vk_fail(err, err_size, "the GPU allows storage buffers of at most %llu MiB; this one needs %llu MiB",
                           (unsigned long long)(l->maxStorageBufferRange >> 20),
                           (unsigned long long)((size >> 20) + ((size & 0xfffff) != 0)));
        if (size == 0 || size % 4)
            return vk_fail(err, err_size, "vdag_vk_run: buffer %u has %llu bytes; a nonzero multiple of 4 is needed",
                           i, (unsigned long long)size);
        if (!buffers[i].data) return vk_fail(err, err_size, "vdag_vk_run: buffer %u has no data", i);
        if ((uint64_t)(size_t)size != size)
            return vk_fail(err, err_size, "vdag_vk_run: buffer %u is larger than this process can address", i);
    }
    return 0;
}

/* A memory type of TYPE_BITS with every flag in WANT; UINT32_MAX when none. */
static uint32_t vk_memory_type(const vdag_vk *vk, uint32_t type_bits, VkMemoryPropertyFlags want) {
    uint32_t i;
    for (i = 0; i < vk->memory.memoryTypeCount; i++)
        if ((type_bits >> i & 1) && (vk->memory.memoryTypes[i].propertyFlags & want) == want) return i;
    return UINT32_MAX;
}

static int vk_cmp_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

#define VK_CHECK(call, name)                                    \
    do {                                                        \
        VkResult r_ = (call);                                   \
        if (r_ != VK_SUCCESS) {                                 \
            vk_call_fail(err, err_size, name, r_);              \
            goto done;                                          \
        }                                                       \
    } while (0)

int vdag_vk_run(vdag_vk *vk, const uint32_t *spirv, size_t spirv_bytes, const char *entry, vdag_vk_buffer *buffers,
                unsigned count, const void *push, uint32_t push_bytes, uint32_t groups_x, uint32_t groups_y,
                uint32_t repeat, double *seconds, char *err, size_t err_size) {
    vk_run_state s;
    VkDevice d;
    VkDescriptorSetLayoutBinding bindings[VDAG_VK_MAX_BUFFERS];
    VkDescriptorBufferInfo infos[VDAG_VK_MAX_BUFFERS];
    VkWriteDescriptorSet writes[VDAG_VK_MAX_BUFFERS];
    VkDescriptorSetLayoutCreateInfo dslci;
    VkPushConstantRange range;
    VkPipelineLayoutCreateInfo plci;
    VkShaderModuleCreateInfo smci;
    VkComputePipelineCreateInfo cpci;
    VkDescriptorPoolSize pool_size;
    VkDescriptorPoolCreateInfo dpci;
    VkDescriptorSetAllocateInfo dsai;
    VkDescriptorSet set;
    VkQueryPoolCreateInfo qpci;
    VkCommandPoolCreateInfo cpoolci;
    VkCommandBufferAllocateInfo cbai;
    VkCommandBuffer cb;
    VkCommandBufferBeginInfo cbbi;
    VkMemoryBarrier barrier;
    VkFenceCreateInfo fci;
    VkSubmitInfo si;
    int timed, status = 1;
    unsigned i;
    uint32_t k;
    if (seconds) *seconds = 0;
    if (!vk) return vk_fail(err, err_size, "vdag_vk_run: VK is NULL");
    if (vk_run_check(vk, spirv, spirv_bytes, entry, buffers, count, push, push_bytes, groups_x, groups_y, repeat,
                     err, err_size))
        return 1;
    memset(&s, 0, sizeof s);
    d = vk->device;
    timed = seconds && vk->timestamp_bits;

    /* Buffers in host-visible, coherent memory: mapped, filled and read
       back directly (no staging copies, no flushes). */
    for (i = 0; i < count; i++) {
        VkBufferCreateInfo bci;
        VkMemoryRequirements req;
        VkMemoryAllocateInfo mai;
        uint32_t type;
        memset(&bci, 0, sizeof bci);
        bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
        bci.size = buffers[i].size;
        bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        VK_CHECK(vk->vkCreateBuffer(d, &bci, NULL, &s.buffer[i]), "vkCreateBuffer");
        vk->vkGetBufferMemoryRequirements(d, s.buffer[i], &req);
        type = vk_memory_type(vk, req.memoryTypeBits,
                              VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        if (type == UINT32_MAX) {
            vk_fail(err, err_size, "Vulkan: no host-visible, coherent memory for a storage buffer");
            goto done;
        }
        memset(&mai, 0, sizeof mai);
        mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
        mai.allocationSize = req.size;
        mai.memoryTypeIndex = type;
        VK_CHECK(vk->vkAllocateMemory(d, &mai, NULL, &s.memory[i]), "vkAllocateMemory");
        VK_CHECK(vk->vkBindBufferMemory(d, s.buffer[i], s.memory[i], 0), "vkBindBufferMemory");
        VK_CHECK(vk->vkMapMemory(d, s.memory[i], 0, VK_WHOLE_SIZE, 0, &s.mapped[i]), "vkMapMemory");
        memcpy(s.mapped[i], buffers[i].data, (size_t)buffers[i].size);
    }

    if (vk->cached_spirv != spirv || vk->cached_bytes != spirv_bytes || strcmp(vk->cached_entry, entry) ||
        vk->cached_count != count || vk->cached_push != push_bytes) {
        vk_pipeline_free(vk);
        memset(&smci, 0, sizeof smci);
        smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
        smci.codeSize = spirv_bytes;
        smci.pCode = spirv;
        VK_CHECK(vk->vkCreateShaderModule(d, &smci, NULL, &vk->module), "vkCreateShaderModule");

        memset(bindings, 0, sizeof bindings);
        for (i = 0; i < count; i++) {
            bindings[i].binding = i;
            bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            bindings[i].descriptorCount = 1;
            bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        }
        memset(&dslci, 0, sizeof dslci);
        dslci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
        dslci.bindingCount = count;
        dslci.pBindings = bindings;
        VK_CHECK(vk->vkCreateDescriptorSetLayout(d, &dslci, NULL, &vk->set_layout), "vkCreateDescriptorSetLayout");

        memset(&range, 0, sizeof range);
        range.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        range.size = push_bytes;
        memset(&plci, 0, sizeof plci);
        plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
        plci.setLayoutCount = 1;
        plci.pSetLayouts = &vk->set_layout;
        plci.pushConstantRangeCount = push_bytes ? 1 : 0;
        plci.pPushConstantRanges = &range;
        VK_CHECK(vk->vkCreatePipelineLayout(d, &plci, NULL, &vk->layout), "vkCreatePipelineLayout");

        memset(&cpci, 0, sizeof cpci);
        cpci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
        cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        cpci.stage.module = vk->module;
        cpci.stage.pName = entry;
        cpci.layout = vk->layout;
        VK_CHECK(vk->vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &cpci, NULL, &vk->pipeline), "vkCreateComputePipelines");
        if (strlen(entry) < sizeof vk->cached_entry) { /* else never reused */
            vk->cached_spirv = spirv, vk->cached_bytes = spirv_bytes, vk->cached_count = count;
            vk->cached_push = push_bytes;
            memcpy(vk->cached_entry, entry, strlen(entry) + 1);
        }
    }

    pool_size.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    pool_size.descriptorCount = count;
    memset(&dpci, 0, sizeof dpci);
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = 1;
    dpci.poolSizeCount = 1;
    dpci.pPoolSizes = &pool_size;
    VK_CHECK(vk->vkCreateDescriptorPool(d, &dpci, NULL, &s.pool), "vkCreateDescriptorPool");
    memset(&dsai, 0, sizeof dsai);
    dsai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dsai.descriptorPool = s.pool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &vk->set_layout;
    VK_CHECK(vk->vkAllocateDescriptorSets(d, &dsai, &set), "vkAllocateDescriptorSets");
    memset(writes, 0, sizeof writes);
    for (i = 0; i < count; i++) {
        infos[i].buffer = s.buffer[i];
        infos[i].offset = 0;
        infos[i].range = VK_WHOLE_SIZE;
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstSet = set;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    vk->vkUpdateDescriptorSets(d, count, writes, 0, NULL);

    if (timed) {
        s.stamps = (uint64_t *)malloc(sizeof(uint64_t) * 2 * (size_t)repeat);
        if (!s.stamps) {
            vk_fail(err, err_size, "vdag_vk_run: out of memory");
            goto done;
        }
        memset(&qpci, 0, sizeof qpci);
        qpci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
        qpci.queryType = VK_QUERY_TYPE_TIMESTAMP;
        qpci.queryCount = 2 * repeat;
        VK_CHECK(vk->vkCreateQueryPool(d, &qpci, NULL, &s.queries), "vkCreateQueryPool");
    }

    memset(&cpoolci, 0, sizeof cpoolci);
    cpoolci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    cpoolci.queueFamilyIndex = vk->family;
    VK_CHECK(vk->vkCreateCommandPool(d, &cpoolci, NULL, &s.commands), "vkCreateCommandPool");
    memset(&cbai, 0, sizeof cbai);
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = s.commands;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    VK_CHECK(vk->vkAllocateCommandBuffers(d, &cbai, &cb), "vkAllocateCommandBuffers");
    memset(&cbbi, 0, sizeof cbbi);
    cbbi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vk->vkBeginCommandBuffer(cb, &cbbi), "vkBeginCommandBuffer");
    if (timed) vk->vkCmdResetQueryPool(cb, s.queries, 0, 2 * repeat);
    vk->vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, vk->pipeline);
    vk->vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, vk->layout, 0, 1, &set, 0, NULL);
    if (push_bytes) vk->vkCmdPushConstants(cb, vk->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes, push);
    memset(&barrier, 0, sizeof barrier);
    barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    for (k = 0; k < repeat; k++) {
        /* Each dispatch waits for the previous one's writes: repeats then
           neither overlap (their times stay apart) nor race on the buffers. */
        if (k > 0) {
            barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
            barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
            vk->vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                                     &barrier, 0, NULL, 0, NULL);
        }
        /* The start is stamped once earlier compute work has finished (a
           top-of-pipe stamp could be written while the previous dispatch
           still runs, adding its tail to this one's time). */
        if (timed) vk->vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, s.queries, 2 * k);
        vk->vkCmdDispatch(cb, groups_x, groups_y, 1);
        if (timed) vk->vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries, 2 * k + 1);
    }
    /* The shader's writes made visible to the host's reads of the mapping. */
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vk->vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                             NULL, 0, NULL);
    VK_CHECK(vk->vkEndCommandBuffer(cb), "vkEndCommandBuffer");

    memset(&fci, 0, sizeof fci);
    fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VK_CHECK(vk->vkCreateFence(d, &fci, NULL, &s.fence), "vkCreateFence");
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    VK_CHECK(vk->vkQueueSubmit(vk->queue, 1, &si, s.fence), "vkQueueSubmit");
    VK_CHECK(vk->vkWaitForFences(d, 1, &s.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");

    if (timed) {
        uint64_t mask = vk->timestamp_bits >= 64 ? UINT64_MAX : ((uint64_t)1 << vk->timestamp_bits) - 1;
        VK_CHECK(vk->vkGetQueryPoolResults(d, s.queries, 0, 2 * repeat, sizeof(uint64_t) * 2 * (size_t)repeat,
                                           s.stamps, sizeof(uint64_t),
                                           VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                 "vkGetQueryPoolResults");
        /* Durations in ticks (masked: the counter may wrap), sorted in place. */
        for (k = 0; k < repeat; k++) s.stamps[k] = (s.stamps[2 * k + 1] - s.stamps[2 * k]) & mask;
        qsort(s.stamps, repeat, sizeof(uint64_t), vk_cmp_u64);
        *seconds = (double)s.stamps[repeat / 2] * (double)vk->props.limits.timestampPeriod * 1e-9;
    }
    for (i = 0; i < count; i++)
        if (buffers[i].read_back) memcpy(buffers[i].data, s.mapped[i], (size_t)buffers[i].size);
    status = 0;
done:
    vk_run_free(vk, &s);
    return status;
}

#endif
