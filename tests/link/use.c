/* The program side of the link tests: declarations only, the
   implementations come from other translation units (C or C++). */
#include "voxdag.h"
#include "voxcolor.h"
#include "exercise.h"

int main(void) {
    return check_exercise("use") ? 1 : 0;
}
