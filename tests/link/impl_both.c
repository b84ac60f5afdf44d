/* Both implementations in one translation unit, after both headers were
   included once without them (as through another header). */
#include "voxcolor.h"
#include "voxdag.h"

#define VOXDAG_IMPLEMENTATION
#define VOXCOLOR_IMPLEMENTATION
#include "voxdag.h"
#include "voxcolor.h"
