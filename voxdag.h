/* voxdag.h (work in progress) */
#ifndef VOXDAG_H
#define VOXDAG_H
#define VOXDAG_VERSION_MAJOR 0
#endif
