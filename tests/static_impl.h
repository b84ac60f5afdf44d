/* A static copy of voxdag.h's implementation in this translation unit, for
   tests that reach its internals (voxdagi_* helpers, the VOXDAG_FILE_*
   layout macros that only the implementation part defines); the functions a
   unit does not call are not warned about. */
#ifndef VOXDAG_TEST_STATIC_IMPL_H
#define VOXDAG_TEST_STATIC_IMPL_H
#define VOXDAG_STATIC
#define VOXDAG_IMPLEMENTATION
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#include "voxdag.h"
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif
