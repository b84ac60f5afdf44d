/* Both implementations with internal linkage (VOXDAG_STATIC, VOXCOLOR_STATIC).
   Compiled twice with different STATIC_UNIT names and linked together with
   static_main.c: the two copies must not clash. */
#define VOXDAG_STATIC
#define VOXCOLOR_STATIC
#define VOXDAG_IMPLEMENTATION
#define VOXCOLOR_IMPLEMENTATION
#include "voxdag.h"
#include "voxcolor.h"
#include "exercise.h"

int STATIC_UNIT(void);
int STATIC_UNIT(void) {
    return check_exercise("static unit");
}
