/* Shared pieces of the vdag tool's subcommands. */
#ifndef VDAG_CLI_H
#define VDAG_CLI_H

#include <stdint.h>
#include "voxdag.h"
#include "voxcolor.h"

/* A loaded .vdag file with its colour decoder. */
typedef struct vdag_file {
    voxdag *dag;
    int has_colors;         /* RGB8 or voxcolor colours present */
    unsigned levels;        /* L: the grid is 2^L voxels a side */
    voxcolor_view colors;   /* valid when the colour section is a voxcolor stream */
} vdag_file;

/* Loads and validates PATH. Returns 1, or 0 after printing a one-line reason. */
int vdag_open(const char *path, vdag_file *f);
void vdag_close(vdag_file *f);

/* Colour of voxel INDEX (white when the file has no colours). Thread-safe. */
void vdag_voxel_color(const vdag_file *f, uint64_t index, uint8_t rgb[3]);

/* Colour of what a ray hit: the voxel's (HIT->index, so the ray needs
   want_index), or at a level-of-detail cell the mean of its voxels
   (voxdag_cell_color); white when the file has no colours. Thread-safe. */
void vdag_hit_color(const vdag_file *f, const voxdag_hit *hit, uint8_t rgb[3]);

/* The box of the occupied voxels, BOX = x0 y0 z0 x1 y1 z1 in grid units,
   half-open; all zero when the DAG has no voxel (the file's voxel box).
   Returns 1 when it has one. */
int vdag_voxel_box(const voxdag *dag, uint32_t box[6]);

/* Checks that OUT may be written: not a directory, not the file IN (also
   under another name: same device and inode), and in a folder that exists,
   is a directory and is writable (checked before the work, which may take
   minutes). Returns 1, or 0 after printing why, naming the folder. IN may
   be NULL. */
int vdag_check_output(const char *in, const char *out);

/* When ARGV (a command's arguments, ARGV[0] its name) holds --help or -h:
   prints COMMAND's usage, options and defaults on stdout and returns 1. */
int vdag_help(const char *command, int argc, char **argv);

/* Prints "vdag: MESSAGE" on stderr; returns 1 (the failing exit status). */
int vdag_fail(const char *fmt, ...);

/* Number of online processors (at least 1). */
unsigned vdag_cpu_count(void);

/* Subcommands implemented outside vdag.c. */
int vdag_cmd_rays(int argc, char **argv);
int vdag_cmd_render(int argc, char **argv);

#endif
