/* The one translation unit holding the implementations used by the tests.
   voxcolor.h comes first, so voxdag_color decodes voxcolor colour sections. */
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
