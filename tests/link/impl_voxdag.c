/* The voxdag.h implementation alone in its translation unit. */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
