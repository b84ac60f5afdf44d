/* voxcolor.h (work in progress) */
#ifndef VOXCOLOR_H
#define VOXCOLOR_H
#define VOXCOLOR_VERSION_MAJOR 0
#endif
