/* The program side of the mixed-configuration link test: compiled with other
   configuration macros (another VOXDAG_MAX_LEVELS, NO_ switches) than the
   implementation it is linked with (tests/link/mixed_impl.c), it builds a
   scene, takes its build statistics and info into structs on its own stack
   (AddressSanitizer catches a write past them) and checks every value and
   every layout against the implementation's. */
#include "voxdag.h"

#include <stdio.h>
#include <string.h>

size_t mixed_impl_layout(int what);

int main(void) {
    static const char *const names[7] = {"sizeof voxdag_info", "offsetof voxdag_info.file_bytes",
        "sizeof voxdag_build_stats", "offsetof voxdag_build_stats.peak_memory", "sizeof voxdag_build_opts",
        "sizeof voxdag_load_opts", "sizeof voxdag_error"};
    size_t mine[7];
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag *d = NULL;
    voxdag_build_stats stats;
    voxdag_info info;
    uint32_t xyz[3 * 64], i, bad = 0;
    size_t image = 0;
    uint64_t nodes = 0;
    int k;
    mine[0] = sizeof(voxdag_info), mine[1] = offsetof(voxdag_info, file_bytes);
    mine[2] = sizeof(voxdag_build_stats), mine[3] = offsetof(voxdag_build_stats, peak_memory);
    mine[4] = sizeof(voxdag_build_opts), mine[5] = sizeof(voxdag_load_opts), mine[6] = sizeof(voxdag_error);
    for (i = 0; i < 64; i++) xyz[3 * i] = i, xyz[3 * i + 1] = (i * 7) % 64, xyz[3 * i + 2] = (i * 13) % 64;
    memset(&o, 0, sizeof o);
    o.levels = 6;
    o.compare_structures = 1;
    memset(&stats, 0, sizeof stats);
    memset(&info, 0, sizeof info);
    if (voxdag_builder_create(&o, &b, NULL) != VOXDAG_OK || voxdag_builder_add(b, xyz, NULL, 64, NULL) != VOXDAG_OK ||
        voxdag_builder_finish(b, &d, &stats, NULL) != VOXDAG_OK) {
        printf("mixed: the build failed\n");
        return 1;
    }
    voxdag_get_info(d, &info);
    voxdag_image(d, &image);
    for (i = 0; i + 1 < info.levels; i++) nodes += info.nodes[i];
    if (stats.levels != 6 || stats.voxels != 64 || stats.peak_memory == 0 || stats.nodes[0] != 1 ||
        stats.svo_nodes[4] == 0 || stats.full_nodes[4] != stats.nodes[4])
        printf("mixed: wrong build stats (levels %u, voxels %llu, peak %llu)\n", stats.levels,
               (unsigned long long)stats.voxels, (unsigned long long)stats.peak_memory), bad++;
    if (info.levels != 6 || info.voxels != 64 || info.file_bytes != image || info.nodes[0] != 1 ||
        info.nodes[4] != stats.nodes[4] || nodes == 0 || info.has_bounds != 0)
        printf("mixed: wrong info (levels %u, voxels %llu, file %llu of %lu bytes)\n", info.levels,
               (unsigned long long)info.voxels, (unsigned long long)info.file_bytes, (unsigned long)image), bad++;
    for (k = 0; k < 7; k++)
        if (mine[k] != mixed_impl_layout(k))
            printf("mixed: layout mismatch: %s is %lu here, %lu in the implementation\n", names[k],
                   (unsigned long)mine[k], (unsigned long)mixed_impl_layout(k)), bad++;
    voxdag_free(d);
    printf("mixed: VOXDAG_MAX_LEVELS %d here, %u checks failed\n", VOXDAG_MAX_LEVELS, bad);
    return bad != 0;
}
