/* The one translation unit holding the implementations used by the tests. */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"
