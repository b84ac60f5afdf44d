/* The voxcolor.h implementation alone in its translation unit. */
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"
