/* The implementation side of the mixed-configuration link test
   (tests/check_all.sh): voxdag.h compiled with the configuration macros the
   command line gives, and the layouts this unit sees, for the other unit to
   compare with its own. */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"

#include <stddef.h>

size_t mixed_impl_layout(int what);
size_t mixed_impl_layout(int what) {
    switch (what) {
    case 0: return sizeof(voxdag_info);
    case 1: return offsetof(voxdag_info, file_bytes);
    case 2: return sizeof(voxdag_build_stats);
    case 3: return offsetof(voxdag_build_stats, peak_memory);
    case 4: return sizeof(voxdag_build_opts);
    case 5: return sizeof(voxdag_load_opts);
    case 6: return sizeof(voxdag_error);
    default: return 0;
    }
}
