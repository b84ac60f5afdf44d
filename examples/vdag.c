/* vdag: build, inspect, query and render .vdag files.

   vdag build IN OUT.vdag [--levels L] [--up x|y|z] [--symmetry none|reflect|full]
              [--no-symmetry] [--color-error E] [--raw-colors] [--color-bits W|auto]
              [--color-effort smallest|fast] [--verify-colors] [--no-colors] [--no-lod-colors]
              [--no-alpha-test] [--chunk-levels C] [--threads T] [--max-memory MIB] [--max-texture-pixels N]
              [--max-vox-voxels N] [--vox-model N] [--allow-empty] [--force] [--stats] [--timings]
              [--quiet]
   vdag info FILE [--json]
   vdag validate FILE
   vdag lookup FILE x y z
   vdag rays FILE            (rays on stdin)
   vdag render FILE OUT.png [--size WxH] [--eye x y z] [--target x y z] [--fov deg] [--threads T]
   vdag export-voxels FILE
   vdag edit IN.vdag OUT.vdag [--color-error E]   (operations on stdin)
   vdag gen SCENE OUT.xyz [--levels L]   (built-in scenes: demo)

   Progress and diagnostics go to stderr; stdout carries only documented
   output. Exit status 0 on success, 1 with a one-line message otherwise. */
#define _POSIX_C_SOURCE 200809L
/* voxcolor.h first: voxdag.h's implementation then decodes voxcolor colours
   (voxdag_color, and the level-of-detail means voxdag_with_colors writes). */
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <pthread.h>
#include <unistd.h>
#ifdef _WIN32
#include <io.h>
#endif

#include "check_colors.h"
#include "cli.h"
#include "import.h"

// -- Shared helpers (cli.h)

int vdag_fail(const char *fmt, ...) {
    va_list ap;
    fputs("vdag: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    return 1;
}

unsigned vdag_cpu_count(void) {
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > 64 ? 64 : (unsigned)n;
}

int vdag_check_output(const char *in, const char *out) {
    struct stat a, b;
    char dir[4096];
    const char *slash = strrchr(out, '/');
    size_t n = slash ? (size_t)(slash - out) + (slash == out) : 1; /* "/x": "/"; "x": "." */
    if (!stat(out, &b) && S_ISDIR(b.st_mode)) return !vdag_fail("%s: is a directory, not a file to write", out);
    if (in && !stat(in, &a) && !stat(out, &b) && a.st_dev == b.st_dev && a.st_ino == b.st_ino)
        return !vdag_fail("%s: is the input file %s; refusing to write over it", out, in);
    /* The folder that will hold OUT (and the save's temporary beside it):
       checked now, not after a build of minutes. */
    if (n >= sizeof dir) return !vdag_fail("%s: the path is too long", out);
    memcpy(dir, slash ? out : ".", n);
    dir[n] = 0;
    if (stat(dir, &b))
        return !vdag_fail("%s: cannot write into the folder %s (%s)", out, dir, strerror(errno));
    if (!S_ISDIR(b.st_mode)) return !vdag_fail("%s: cannot write into the folder %s (not a directory)", out, dir);
#ifdef _WIN32
    if (_access(dir, 2)) /* <io.h>: 2 = write */
#else
    if (access(dir, W_OK | X_OK))
#endif
        return !vdag_fail("%s: cannot write into the folder %s (%s)", out, dir, strerror(errno));
    return 1;
}

int vdag_open(const char *path, vdag_file *f) {
    voxdag_error err;
    voxdag_info info;
    const void *payload;
    size_t size;
    struct stat fs;
    memset(f, 0, sizeof *f);
    if (stat(path, &fs)) return !vdag_fail("%s: cannot open (%s)", path, strerror(errno));
    if (S_ISDIR(fs.st_mode)) return !vdag_fail("%s: is a directory, not a .vdag file", path);
    errno = 0;
    if (voxdag_load_file(path, NULL, &f->dag, &err) != VOXDAG_OK) {
        if (err.status == VOXDAG_ERR_IO && errno)
            return !vdag_fail("%s: %s (%s: %s)", path, voxdag_status_string(err.status), err.message, strerror(errno));
        if (err.byte_offset != UINT64_MAX)
            return !vdag_fail("%s: %s (%s at byte %llu)", path, voxdag_status_string(err.status), err.message,
                              (unsigned long long)err.byte_offset);
        return !vdag_fail("%s: %s (%s)", path, voxdag_status_string(err.status), err.message);
    }
    voxdag_get_info(f->dag, &info);
    f->levels = info.levels;
    switch (voxdag_colors(f->dag, &payload, &size)) {
    case VOXDAG_COLORS_RGB8: f->has_colors = 1; break;
    case VOXDAG_COLORS_VOXCOLOR: {
        voxcolor_status st = voxcolor_view_init(&f->colors, payload, size, NULL);
        if (st != VOXCOLOR_OK || f->colors.count != info.voxels) {
            vdag_close(f);
            return !vdag_fail("%s: corrupt colour section (%s)", path,
                              st != VOXCOLOR_OK ? voxcolor_status_string(st) : "colour count differs from voxel count");
        }
        f->has_colors = 1;
        break;
    }
    default: break;
    }
    return 1;
}

void vdag_close(vdag_file *f) {
    voxdag_free(f->dag);
    memset(f, 0, sizeof *f);
}

void vdag_voxel_color(const vdag_file *f, uint64_t index, uint8_t rgb[3]) {
    if (f->colors.count) voxcolor_view_get(&f->colors, index, rgb);
    else if (!voxdag_color(f->dag, index, rgb)) rgb[0] = rgb[1] = rgb[2] = 255;
}

void vdag_hit_color(const vdag_file *f, const voxdag_hit *hit, uint8_t rgb[3]) {
    if (hit->level == f->levels) vdag_voxel_color(f, hit->index, rgb);
    else if (voxdag_cell_color(f->dag, hit, rgb) <= 0) rgb[0] = rgb[1] = rgb[2] = 255;
}

int vdag_voxel_box(const voxdag *dag, uint32_t box[6]) {
    voxdag_info in;
    voxdag_get_info(dag, &in);
    memcpy(box, in.voxel_box, sizeof in.voxel_box);
    return in.voxels > 0;
}

// -- Help: every command, every option with its default and units

static const struct {
    const char *name, *text;
} help_texts[] = {
    {"build",
     "usage: vdag build IN OUT.vdag [options]\n"
     "Builds a .vdag file from IN: .xyz (voxels \"x y z [r g b]\", integers; with decimal\n"
     "coordinates a point cloud), .ply, .obj (+ .mtl, textures PNG/JPEG/TGA/BMP/PNM), .off,\n"
     ".stl, .vox, .spm, .ac. Meshes and point clouds are fitted into the 2^L grid by their\n"
     "bounding box; voxel lists keep their coordinates. OUT may not be IN, nor a file the\n"
     "build reads (.mtl libraries, textures); its folder must exist and be writable (checked\n"
     "before the build). An input that is no model (an image, an archive, a .vdag, an .mtl,\n"
     "an empty file, a file without triangles or points) is refused, saying what it looks like.\n"
     "  --levels L         grid of 2^L voxels per axis, 2..21 (default: 10 for meshes; point\n"
     "                     clouds: the largest L up to 10 whose voxel is at least the median\n"
     "                     nearest-neighbour spacing, printed; voxel lists: the smallest grid\n"
     "                     that holds them)\n"
     "  --up x|y|z         the input's up axis, turned to +z (default: what the exporter named\n"
     "                     in the file writes (Blender), else y for .obj .ply .off, z for .stl\n"
     "                     .xyz .vox .spm .ac; the axis and why are printed)\n"
     "  --symmetry G       share subtrees equal up to: none (identical only), reflect (the 8\n"
     "                     reflections) or full (all 48 cube symmetries) (default: full)\n"
     "  --no-symmetry      the same as --symmetry none (default: full symmetry)\n"
     "  --color-error E    compress colours with voxcolor, each within E (RGB distance / 255,\n"
     "                     0 = lossless) (default: 0, lossless voxcolor: runs of one colour\n"
     "                     cost next to nothing); an E above sqrt(3) = 1.732 warns: every\n"
     "                     colour is within it\n"
     "  --raw-colors       store colours raw, 24 bits each (RGB8), instead of voxcolor; not\n"
     "                     with the other colour options (default: voxcolor, lossless)\n"
     "  --color-bits W|auto  voxcolor weight bits 1..4 (default: auto)\n"
     "  --color-effort smallest|fast  colour encoder effort: fast searches one endpoint precision,\n"
     "                     a little larger near e_t 0.02-0.04 (default: smallest)\n"
     "  --verify-colors    after compressing, decode every colour and compare it with the\n"
     "                     raw colour; fail when one is off by more than E (default: off)\n"
     "  --no-colors        drop colours (default: keep them); textures are still read for the\n"
     "                     alpha test, the voxels stay the same\n"
     "  --no-lod-colors    write no level-of-detail colour section (default: write it: the mean\n"
     "                     colour of cells of more than 64 voxels, about 1-25% of the colours)\n"
     "  --timings          print each phase's wall and CPU seconds at the end (read, voxelize,\n"
     "                     reduce, encode, colours, colour check, colour attach, save): the\n"
     "                     process's CPU and the building thread's (main CPU)\n"},
    {"build", /* the rest (a C99 string holds at most 4095 characters; vdag_help prints both) */
     "  --no-alpha-test    texels of any alpha make voxels (default: a texel with alpha below one\n"
     "                     half makes none, as renderers discard it; foliage keeps its holes)\n"
     "  --solid            meshes: fill the inside too (default: the surface only): voxels whose\n"
     "                     centre the mesh encloses (nonzero winding number); a mesh with open\n"
     "                     edges is refused, with their count\n"
     "  --chunk-levels C   voxelize meshes in chunks of 2^C voxels per axis, 2..8 (default:\n"
     "                     chosen from the mesh: 5 for coloured meshes under 65536 triangles, else 8)\n"
     "  --threads T        worker threads, >= 1 (default: the processors online)\n"
     "  --max-memory MIB   the most memory the builder may hold, in MiB (2^20 bytes), >= 1;\n"
     "                     a build that needs more stops with a limit error (default: no limit)\n"
     "  --max-texture-pixels N  the most pixels of all textures together (each file counted\n"
     "                     once), >= 1; a scene past it is refused (default: 268435456, 2^28)\n"
     "  --max-vox-voxels N the most voxels a .vox scene graph may place (a model once per\n"
     "                     shape showing it), >= 1; past it the file is refused (default:\n"
     "                     2147483648, 2^31)\n"
     "  --vox-model N      a .vox of several models and no scene graph (animation frames):\n"
     "                     import model N, from 0; past the last, or with a scene graph, an\n"
     "                     error (default: 0, with a warning that names the model count)\n"
     "  --allow-empty      build an empty scene from an empty input, or one without triangles\n"
     "                     and points, with a warning (default: refused)\n"
     "  --force            build even when the estimate exceeds the machine's memory (default:\n"
     "                     refuse; an estimate is printed before builds of over 10^7 voxels)\n"
     "  --stats            also count the nodes per level under all three symmetry groups\n"
     "                     (three times the work) (default: off)\n"
     "  --quiet            warnings and errors only (default: progress and a summary on stderr)\n"},
    {"info", "usage: vdag info FILE [--json]\n"
             "Prints levels, voxels, nodes and bytes per level, bits per voxel, colours, the grid's world\n"
             "box (the source's units) and the box of the occupied voxels (grid units, half-open).\n"
             "  --json   one JSON object instead of the text (default: text)\n"},
    {"validate", "usage: vdag validate FILE\nExit status 0 when FILE is a valid .vdag file, else 1 with a one-line reason.\n"},
    {"lookup", "usage: vdag lookup FILE x y z\n"
               "Prints \"0\" when voxel (x, y, z) is empty, else \"1 INDEX R G B\". Coordinates are\n"
               "grid units: integers 0..2^L-1; a voxel outside the grid is an error (exit 1).\n"},
    {"rays", "usage: vdag rays FILE [--gpu | --gpu-emulate]\n"
             "Reads rays from stdin, one a line \"ox oy oz dx dy dz\" (numbers, grid units: the grid\n"
             "spans [0, 2^L)^3), prints a line a ray: \"miss\", or \"hit T X Y Z NX NY NZ INDEX R G B\"\n"
             "(T: distance along the ray in units of |d|; N: the entry face normal).\n"
             "  --gpu          trace on the GPU through Vulkan (voxdag_gpu.h, float32: numbers are\n"
             "                 rounded to float; answers differ from the exact ones only at near-ties)\n"
             "  --gpu-emulate  the same float32 traversal compiled for the CPU (same answers as --gpu)\n"},
    {"render", "usage: vdag render FILE OUT.png [options]\n"
               "Ray traces a shaded picture, z up, into a PNG file: OUT must end in .png (any case),\n"
               "may not be FILE, and its folder must exist and be writable.\n"
               "  --size WxH        picture size, 1..16384 each (default: 640x480)\n"
               "  --eye x y z       camera position, grid units (default: a three-quarter view from\n"
               "                    +x, -y, above, far enough that the occupied voxels fit)\n"
               "  --target x y z    point looked at, grid units (default: the occupied voxels' centre)\n"
               "  --fov deg         vertical field of view in degrees, (0, 180) (default: 50)\n"
               "  --shadows         shadows towards the light (default: off)\n"
               "  --light x y z     direction towards the light, any length but 0 (default: 0.5 0.3 0.8)\n"
               "  --lod PIXELS      stop at cells smaller than PIXELS pixels, or samples with --samples\n"
               "                    (default: 0, full detail)\n"
               "  --samples N       antialiasing: N = n^2 rays a pixel (1, 4, 9, ..., 64) on an n x n grid,\n"
               "                    averaged: the n times larger picture's n x n blocks (default: 1; CPU)\n"
               "  --threads T       threads, 0..64, 0 = the processors online (default: 0)\n"
               "  --quiet           no progress or timing on stderr\n"
               "  --gpu             render on the GPU through Vulkan (voxdag_gpu.h, float32; every option\n"
               "                    but --threads and --samples; level of detail by depth along the\n"
               "                    view axis)\n"
               "  --gpu-emulate     the GPU picture computed on the CPU (the same pixels as --gpu)\n"
               "  --beam            with --gpu or --gpu-emulate: a first pass finds, per 8x8 block of\n"
               "                    pixels, a depth before which none of its rays meets a voxel, where\n"
               "                    the rays then start (the same picture)\n"},
    {"export-voxels", "usage: vdag export-voxels FILE\n"
                      "Prints every voxel as \"x y z r g b\" (grid units), in voxel-index order.\n"},
    {"edit", "usage: vdag edit IN.vdag OUT.vdag [--color-error E]\n"
             "Applies the operations on stdin, one a line, to IN's voxels and writes OUT (the same bytes as\n"
             "building the final voxels). Integers in grid units (signed; shapes are clipped to the grid),\n"
             "colours 0..255; boxes are half-open [X0, X1) per axis; a sphere holds the voxels with\n"
             "(2x+1-2CX)^2 + (2y+1-2CY)^2 + (2z+1-2CZ)^2 <= 4 RADIUS^2:\n"
             "  set X Y Z [R G B]                 clear X Y Z\n"
             "  fill-box X0 Y0 Z0 X1 Y1 Z1 [R G B] carve-box X0 Y0 Z0 X1 Y1 Z1\n"
             "  fill-sphere CX CY CZ RADIUS [R G B] carve-sphere CX CY CZ RADIUS\n"
             "  paint-box X0 Y0 Z0 X1 Y1 Z1 R G B  paint-sphere CX CY CZ RADIUS R G B\n"
             "  copy-box X0 Y0 Z0 X1 Y1 Z1 DX DY DZ  (the box's voxels, empty ones too, moved by D)\n"
             "  undo   redo\n"
             "A fill with a colour recolours the voxels already in its shape too; without one, new voxels\n"
             "are white. Every operation line is one edit of the history. Blank lines and # comments are\n"
             "ignored; a line that does not parse stops it with its number, and nothing is written.\n"
             "  --color-error E   required when IN's colours are voxcolor: OUT's are compressed within E\n"
             "                    (untouched voxels stay within E of IN's decoded colours); raw RGB8\n"
             "                    colours stay raw\n"},
    {"gen", "usage: vdag gen demo OUT.xyz [--levels L]\n"
            "Writes the built-in demo scene as a voxel list.\n"
            "  --levels L   grid of 2^L voxels per axis, 4..10 (default: 7)\n"},
};

int vdag_help(const char *command, int argc, char **argv) {
    size_t i;
    int k;
    for (k = 1; k < argc; k++)
        if (!strcmp(argv[k], "--help") || !strcmp(argv[k], "-h")) break;
    if (k == argc) return 0;
    for (i = 0; i < sizeof help_texts / sizeof help_texts[0]; i++)
        if (!strcmp(help_texts[i].name, command)) fputs(help_texts[i].text, stdout);
    return 1;
}

static double now_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* A batch of jobs on threads made for it: JOB(USER, i) for every i in
   [0, COUNT). */
typedef struct job_batch {
    void (*job)(void *user, uint32_t index);
    void *user;
    uint32_t count, next;
    pthread_mutex_t lock;
} job_batch;

static void *job_batch_work(void *arg) {
    job_batch *b = (job_batch *)arg;
    for (;;) {
        uint32_t i;
        pthread_mutex_lock(&b->lock);
        i = b->next < b->count ? b->next++ : b->count;
        pthread_mutex_unlock(&b->lock);
        if (i == b->count) return NULL;
        b->job(b->user, i);
    }
}

/* vdag_import_limits.run: COUNT jobs on up to *USER threads (the calling one
   too, which does them all when no thread can be made); returns when all
   are done. */
static void run_jobs(void *user, void (*job)(void *job_user, uint32_t index), void *job_user, uint32_t count) {
    pthread_t tid[64];
    uint32_t threads = *(const uint32_t *)user, t = 0;
    job_batch b;
    b.job = job, b.user = job_user, b.count = count, b.next = 0;
    pthread_mutex_init(&b.lock, NULL);
    while (t + 1 < threads && t + 1 < count && t < 64 && !pthread_create(&tid[t], NULL, job_batch_work, &b)) t++;
    job_batch_work(&b);
    while (t > 0) pthread_join(tid[--t], NULL);
    pthread_mutex_destroy(&b.lock);
}

static int parse_u32(const char *s, uint32_t *out) {
    char *end;
    unsigned long v;
    errno = 0;
    v = strtoul(s, &end, 10);
    if (errno || end == s || *end || v > 0xFFFFFFFFul || s[0] == '-') return 0;
    *out = (uint32_t)v;
    return 1;
}

/* A count 1..2^64-1 in decimal; 0 for anything else (a sign, trailing text,
   a number past 2^64 - 1). */
static int parse_count(const char *s, uint64_t *out) {
    char *end;
    unsigned long long v;
    errno = 0;
    if (s[0] < '0' || s[0] > '9') return 0;
    v = strtoull(s, &end, 10);
    if (errno || end == s || *end || !v) return 0;
    *out = (uint64_t)v;
    return 1;
}

static int parse_double(const char *s, double *out) {
    char *end;
    *out = strtod(s, &end);
    return end != s && !*end && isfinite(*out);
}

// -- vdag build

/* The --symmetry and info name of a group. */
static const char *symmetry_name(voxdag_symmetry s) {
    return s == VOXDAG_SYMMETRY_NONE ? "none" : s == VOXDAG_SYMMETRY_REFLECT ? "reflect" : "full";
}

/* --timings: wall and CPU seconds of each phase of a build. A phase lasts
   from its first report to the next phase's; phases that alternate (a mesh
   is voxelized and reduced chunk by chunk) add up. The CPU seconds are the
   whole process's, so CPU / wall is the phase's parallelism; main CPU is
   the building thread's alone (on 2 threads, main CPU less the rest is
   what that thread did alone: a measure that other processes on the
   machine do not skew). */
enum { PHASES = 12 };
typedef struct phase_times {
    const char *name[PHASES];
    double wall[PHASES], cpu[PHASES], main[PHASES]; /* MAIN: the building thread's CPU */
    int count, current; /* current: the running phase, -1 none */
    double wall0, cpu0, main0; /* when it last started */
} phase_times;

static double cpu_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Ends the running phase and starts NAME (a string that outlives P; NULL:
   none). */
/* CPU seconds of the calling thread. */
static double thread_cpu_seconds(void) {
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void phase_enter(phase_times *p, const char *name) {
    double wall = now_seconds(), cpu = cpu_seconds(), main = thread_cpu_seconds();
    int i;
    if (p->current >= 0) {
        p->wall[p->current] += wall - p->wall0, p->cpu[p->current] += cpu - p->cpu0;
        p->main[p->current] += main - p->main0;
    }
    p->wall0 = wall, p->cpu0 = cpu, p->main0 = main, p->current = -1;
    if (!name) return;
    for (i = 0; i < p->count && strcmp(p->name[i], name); i++) continue;
    if (i == PHASES) return; /* more phases than slots: the rest go uncounted */
    if (i == p->count) p->name[p->count++] = name;
    p->current = i;
}

static void phase_print(const phase_times *p) {
    double wall = 0, cpu = 0, main = 0;
    int i;
    fprintf(stderr, "vdag: timings      wall s    CPU s  CPU/wall  main CPU s\n");
    for (i = 0; i < p->count; i++) {
        fprintf(stderr, "vdag:   %-13s %8.3f %8.3f %6.2f %8.3f\n", p->name[i], p->wall[i], p->cpu[i],
                p->wall[i] > 0 ? p->cpu[i] / p->wall[i] : 0.0, p->main[i]);
        wall += p->wall[i], cpu += p->cpu[i], main += p->main[i];
    }
    fprintf(stderr, "vdag:   %-13s %8.3f %8.3f %6.2f %8.3f\n", "total", wall, cpu, wall > 0 ? cpu / wall : 0.0, main);
}

typedef struct build_args {
    const char *in, *out;
    uint32_t levels, threads;
    voxdag_symmetry symmetry;
    int no_colors, stats;
    int compress;           /* voxcolor (the default); 0: --raw-colors, RGB8 */
    const char *color_option; /* the last colour-compression option given, for the clash with --raw-colors */
    int no_alpha_test;      /* --no-alpha-test: texels of any alpha make voxels */
    int verify_colors;      /* --verify-colors */
    int no_lod_colors;      /* --no-lod-colors */
    int timings;            /* --timings: print PHASES at the end */
    phase_times phases;
    double color_error;
    uint32_t color_bits; /* 0: auto */
    voxcolor_effort color_effort;
    struct color_spill *spill;
    double t0;              /* when the command started */
    size_t input_items;     /* triangles or points read */
    char up;                /* the input's up axis: 'x', 'y', 'z'; 0: the format's default */
    const char *last_stage; /* progress printed last */
    int last_percent;
    int tty, line_open;     /* stderr is a terminal; a progress line is open on it */
    int quiet;              /* --quiet: warnings and errors only */
    int force;              /* --force: build even past the machine's memory */
    int allow_empty;        /* --allow-empty: an input without triangles or points builds */
    uint32_t chunk_levels;  /* --chunk-levels; 0: chosen from the mesh */
    int solid;              /* --solid: meshes filled inside */
    uint32_t max_memory;    /* --max-memory in MiB; 0: no limit */
    uint64_t max_texture_pixels; /* --max-texture-pixels; 0: the importer's default */
    uint64_t max_vox_voxels;     /* --max-vox-voxels; 0: the importer's default */
    uint32_t vox_model;          /* --vox-model; 0: the first */
} build_args;

/* Progress of a build: on a terminal, one line per stage updated in place
   at each whole percent; elsewhere (logs, pipes) a plain line when a stage
   starts and at each quarter; nothing with --quiet. */
static void progress(void *user, const char *stage, double fraction) {
    build_args *a = (build_args *)user;
    int percent = (int)(100 * fraction), new_stage = !a->last_stage || strcmp(a->last_stage, stage) != 0;
    if (a->phases.current < 0 || strcmp(a->phases.name[a->phases.current], stage)) phase_enter(&a->phases, stage);
    if (a->quiet || (!new_stage && a->last_percent == percent)) return;
    if (!a->tty && !new_stage && percent / 25 == a->last_percent / 25) return;
    if (a->tty) fprintf(stderr, "%svdag: %s %3d%% (%.1f s)", a->line_open ? (new_stage ? "\n" : "\r") : "", stage,
                        percent, now_seconds() - a->t0);
    else fprintf(stderr, "vdag: %s %3d%% (%.1f s)\n", stage, percent, now_seconds() - a->t0);
    a->line_open = a->tty;
    a->last_stage = stage;
    a->last_percent = percent;
}

/* Ends a progress line left open on a terminal. */
static void progress_end(build_args *a) {
    if (a->line_open) fputc('\n', stderr);
    a->line_open = 0;
}

/* The tool's axes are z up (x right, y away from a viewer in front):
   renders, the default camera and every built file use them. A file's up
   axis is turned to +z by a rotation: y up: (x, y, z) -> (x, -z, y); x up:
   (x, y, z) -> (y, z, x). The axis is --up when given; else an exporter's
   convention that the file names (up_marks); else the default of its
   format: formats whose usual exporters write y up (.obj, .ply, .off)
   default to y; .stl (CAD and 3D printing), .xyz and .vox default to z;
   .spm and .ac are turned to z up by the importer and default to z. */

/* PATH's extension after the last '.', or "" when it has none. */
static const char *path_ext(const char *path) {
    const char *slash = strrchr(path, '/'), *dot = strrchr(slash ? slash : path, '.');
    return dot ? dot + 1 : "";
}

/* Extension EXT is NAME (lower case), in any case. */
static int ext_is(const char *ext, const char *name) {
    while (*ext && (*ext | 0x20) == *name) ext++, name++;
    return !*ext && !*name;
}

static char default_up(const char *path) {
    const char *ext = path_ext(path);
    return ext_is(ext, "obj") || ext_is(ext, "ply") || ext_is(ext, "off") ? 'y' : 'z';
}

/* Exporters whose default axes are known, by the comment they write: a
   line in the file's first 4 KiB (.ply: in its header, before end_header)
   that begins with MARK gives UP. Only conventions read
   from the exporters' own sources are listed; a file without one keeps its
   format's default (3ds Max's OBJ exporter, for one, writes y or z up as its
   "Flip YZ-axis" option says, which the file does not record). */
static const struct {
    const char *ext, *mark;
    char up;
} up_marks[] = {
    {"obj", "# Blender", 'y'},                         /* Blender's OBJ exporters: forward -Z, up Y */
    {"ply", "comment Created by Blender", 'z'},        /* Blender's PLY add-on (to 3.5): forward Y, up Z */
    {"ply", "comment Created in Blender version", 'y'}, /* Blender 3.6 and later: forward -Z, up Y */
};

/* The up axis of the file at PATH when its first 4 KiB name an exporter of
   up_marks, else 0; WHY (WHY_SIZE bytes, at least 4) receives the line that
   names it, its first 72 bytes and "..." when longer, with '"' and bytes
   outside printable ASCII as '?'. */
static char file_up(const char *path, char *why, size_t why_size) {
    char buf[4097], *line, *next;
    const char *ext = path_ext(path);
    size_t n, i, k;
    struct stat st;
    FILE *f;
    if (stat(path, &st) || !S_ISREG(st.st_mode) || !(f = fopen(path, "rb"))) return 0; /* read once only */
    n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    line = buf;
    if (n >= 3 && !memcmp(buf, "\xef\xbb\xbf", 3)) line += 3; /* a UTF-8 byte order mark */
    for (; line < buf + n; line = next + 1) {
        next = line + strcspn(line, "\r\n");
        if (next >= buf + n) break; /* a line cut at 4 KiB, or the end: not read */
        *next = 0;
        if (ext_is(ext, "ply") && !strncmp(line, "end_header", 10)) break;
        for (i = 0; i < sizeof up_marks / sizeof up_marks[0]; i++) {
            if (!ext_is(ext, up_marks[i].ext) || strncmp(line, up_marks[i].mark, strlen(up_marks[i].mark))) continue;
            for (k = 0; line[k] && k + 4 < why_size && k < 72; k++)
                why[k] = line[k] >= 0x20 && line[k] < 0x7f && line[k] != '"' ? line[k] : '?';
            strcpy(why + k, line[k] ? "..." : "");
            return up_marks[i].up;
        }
    }
    return 0;
}

/* Sets A->up (unless --up gave it) and prints it with the reason. */
static void choose_up(build_args *a) {
    char line[80] = "";
    const char *ext = path_ext(a->in);
    if (a->up) {
        if (!a->quiet) fprintf(stderr, "vdag: up axis: %c (--up)\n", a->up);
        return;
    }
    a->up = file_up(a->in, line, sizeof line);
    if (a->up) {
        if (!a->quiet) fprintf(stderr, "vdag: up axis: %c (from the file: \"%s\"; --up overrides)\n", a->up, line);
        return;
    }
    a->up = default_up(a->in);
    if (!a->quiet) {
        size_t k;
        for (k = 0; ext[k] && k < 8; k++)
            line[k] = ext[k] >= 'A' && ext[k] <= 'Z' ? (char)(ext[k] + 32) : ext[k] > 0x20 && ext[k] < 0x7f ? ext[k] : '?';
        line[k] = 0;
        fprintf(stderr, "vdag: up axis: %c (default for .%s; --up overrides)\n", a->up, line);
    }
}

/* Turns N points (3 doubles each) so that axis UP becomes +z. Voxels
   (integer cells) flip an axis as max - v, so they stay cells >= 0. */
static void turn_up(double *p, size_t n, char up, int voxels) {
    double top = 0;
    size_t i;
    if (up == 'z') return;
    for (i = 0; voxels && up == 'y' && i < n; i++)
        if (p[3 * i + 2] > top) top = p[3 * i + 2];
    for (i = 0; i < n; i++) {
        double x = p[3 * i], y = p[3 * i + 1], z = p[3 * i + 2];
        if (up == 'y') {
            p[3 * i + 1] = voxels ? top - z : -z;
            p[3 * i + 2] = y;
        } else {
            p[3 * i] = y;
            p[3 * i + 1] = z;
            p[3 * i + 2] = x;
        }
    }
}

/* The level of a point cloud (float points, no triangles) built without
   --levels: the largest L up to 10 (the default of meshes) whose voxel,
   the bounding box's largest extent / 2^L as scene_to_grid fits it, is at
   least the cloud's spacing (point_spacing), so that two points that far
   apart fall in the same or in touching voxels (they differ by at most one
   voxel on each axis); at least 2. */
#define CLOUD_SAMPLES 2000  /* points whose nearest neighbour is searched */
#define CLOUD_WORK 65536    /* cells and points one search visits at most */
#define CLOUD_MAX_LEVELS 10 /* the default level of meshes, never exceeded */

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The median distance from a point to its nearest other point (a duplicate,
   at distance 0, is none), over every (N / CLOUD_SAMPLES)-th point (all of
   them up to CLOUD_SAMPLES), each searched against all N points through a
   uniform grid of about N cells (4 bytes a point and 4 a cell) in rings of
   cells around it. A search stops after CLOUD_WORK cells and points with
   the nearest found, so clusters and outliers stay cheap; the answer depends
   on the points alone. *USED receives the samples that found a neighbour
   (the median is over them; 0 when none did, and the result is 0);
   *EXTENT the bounding box's largest extent. Returns -1 when out of
   memory. */
static double point_spacing(const double *p, size_t n, size_t *used, double *extent) {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, side, *nearest, median = 0;
    uint32_t dim[3], *start, *order, g;
    size_t i, k, cells, samples, step;
    *used = 0;
    *extent = 0;
    for (i = 0; i < 3 * n; i++) {
        if (p[i] < lo[i % 3]) lo[i % 3] = p[i];
        if (p[i] > hi[i % 3]) hi[i % 3] = p[i];
    }
    for (k = 0; k < 3; k++)
        if (n && hi[k] - lo[k] > *extent) *extent = hi[k] - lo[k];
    if (n < 2 || n > UINT32_MAX || !(*extent > 0)) return 0;
    g = (uint32_t)ceil(cbrt((double)n));
    side = *extent / g;
    for (cells = 1, k = 0; k < 3; k++) {
        double d = floor((hi[k] - lo[k]) / side) + 1;
        dim[k] = d > g ? g : (uint32_t)d;
        cells *= dim[k];
    }
    samples = n < CLOUD_SAMPLES ? n : CLOUD_SAMPLES;
    start = (uint32_t *)calloc(cells + 1, sizeof *start);
    order = (uint32_t *)malloc(n * sizeof *order);
    nearest = (double *)malloc(samples * sizeof *nearest);
    if (!start || !order || !nearest) {
        free(start), free(order), free(nearest);
        return -1;
    }
#define CLOUD_CELL(q, k) \
    ((q)[k] - lo[k] >= dim[k] * side ? dim[k] - 1 : (uint32_t)(((q)[k] - lo[k]) / side))
#define CLOUD_INDEX(q) (((size_t)CLOUD_CELL(q, 2) * dim[1] + CLOUD_CELL(q, 1)) * dim[0] + CLOUD_CELL(q, 0))
    for (i = 0; i < n; i++) start[CLOUD_INDEX(p + 3 * i) + 1]++;
    for (k = 0; k < cells; k++) start[k + 1] += start[k];
    for (i = 0; i < n; i++) order[start[CLOUD_INDEX(p + 3 * i)]++] = (uint32_t)i;
    for (k = cells; k > 0; k--) start[k] = start[k - 1]; /* each cell's first point again */
    start[0] = 0;
    step = n / samples;
    for (i = 0; i < samples; i++) {
        const double *q = p + 3 * (i * step);
        long c[3], r, x, y, z, reach = 0, work = 0;
        double best = HUGE_VAL;
        for (k = 0; k < 3; k++) {
            c[k] = (long)CLOUD_CELL(q, k);
            if ((long)dim[k] > reach) reach = dim[k];
        }
        /* Ring r: the cells r away (Chebyshev) from q's own. Its points are
           at least (r - 1) SIDE from q: the search stops before it once the
           nearest found is that close. */
        for (r = 0; r <= reach && work < CLOUD_WORK && !(best <= (double)(r - 1) * side * ((double)(r - 1) * side)); r++)
            for (z = c[2] - r; z <= c[2] + r; z++)
                for (y = c[1] - r; y <= c[1] + r; y++)
                    for (x = c[0] - r; x <= c[0] + r;
                         x += r && z != c[2] - r && z != c[2] + r && y != c[1] - r && y != c[1] + r ? 2 * r : 1) {
                        size_t cell, j;
                        work++;
                        if (x < 0 || y < 0 || z < 0 || x >= (long)dim[0] || y >= (long)dim[1] || z >= (long)dim[2])
                            continue;
                        cell = ((size_t)z * dim[1] + (size_t)y) * dim[0] + (size_t)x;
                        for (j = start[cell]; j < start[cell + 1] && work < CLOUD_WORK; j++, work++) {
                            const double *o = p + 3 * (size_t)order[j];
                            double d = (o[0] - q[0]) * (o[0] - q[0]) + (o[1] - q[1]) * (o[1] - q[1]) +
                                       (o[2] - q[2]) * (o[2] - q[2]);
                            if (d > 0 && d < best) best = d;
                        }
                    }
        if (best < HUGE_VAL) nearest[(*used)++] = sqrt(best);
    }
#undef CLOUD_CELL
#undef CLOUD_INDEX
    if (*used) {
        qsort(nearest, *used, sizeof *nearest, cmp_double);
        median = nearest[*used / 2];
    }
    free(start), free(order), free(nearest);
    return median;
}

/* Chooses A->levels for a point cloud built without --levels and prints
   it with the spacing it comes from. Returns 1 when out of memory. */
static int choose_cloud_levels(const vdag_scene *sc, build_args *a) {
    size_t used;
    double extent, spacing = point_spacing(sc->points, sc->point_count, &used, &extent);
    if (spacing < 0) return vdag_fail("out of memory");
    a->levels = 2;
    while (a->levels < CLOUD_MAX_LEVELS && spacing > 0 && extent / (double)(1u << (a->levels + 1)) >= spacing)
        a->levels++;
    if (!spacing) a->levels = CLOUD_MAX_LEVELS;
    if (a->quiet) return 0;
    if (spacing > 0)
        fprintf(stderr, "vdag: point cloud: median spacing %.3g (of %zu sampled points), extent %.3g: --levels %u "
                        "(voxels of %.3g; override with --levels)\n", spacing, used, extent, a->levels,
                extent / (double)(1u << a->levels));
    else
        fprintf(stderr, "vdag: point cloud: no sampled point has a distinct neighbour near it: --levels %u (override with "
                        "--levels)\n", a->levels);
    return 0;
}

/* Points to grid voxels: integer voxels as they are, point clouds and mesh
   vertices fitted into the 2^L grid by their bounding box. */
static int scene_to_grid(const vdag_scene *sc, build_args *a, uint32_t **xyz_out, double bounds[6]) {
    size_t i;
    int k;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, extent = 0, scale;
    uint32_t *xyz, n;
    for (i = 0; i < sc->point_count; i++)
        for (k = 0; k < 3; k++) {
            double v = sc->points[3 * i + k];
            if (v < lo[k]) lo[k] = v;
            if (v > hi[k]) hi[k] = v;
        }
    if (sc->points_are_voxels) {
        double top = 0;
        for (k = 0; k < 3; k++)
            if (sc->point_count && hi[k] > top) top = hi[k];
        if (!a->levels) {
            a->levels = 2;
            while (a->levels < VOXDAG_MAX_LEVELS && (double)(1u << a->levels) <= top) a->levels++;
        }
        if (top >= (double)(1u << a->levels))
            return vdag_fail("%s: coordinate %.0f does not fit --levels %u", a->in, top, a->levels);
    } else if (!a->levels) {
        a->levels = 10;
    }
    n = 1u << a->levels;
    for (k = 0; k < 3; k++) {
        if (!sc->point_count) lo[k] = hi[k] = 0;
        if (hi[k] - lo[k] > extent) extent = hi[k] - lo[k];
    }
    scale = extent > 0 ? n / extent : 1;
    for (k = 0; k < 3; k++) {
        bounds[k] = sc->points_are_voxels ? 0 : lo[k];
        bounds[k + 3] = sc->points_are_voxels ? n : lo[k] + n / scale;
    }
    xyz = (uint32_t *)malloc(3 * sc->point_count * sizeof *xyz + 1);
    if (!xyz) return vdag_fail("out of memory");
    for (i = 0; i < 3 * sc->point_count; i++) {
        double v = sc->points[i];
        if (!sc->points_are_voxels) {
            v = floor((v - lo[i % 3]) * scale);
            if (v > n - 1) v = n - 1;
        }
        xyz[i] = (uint32_t)v;
    }
    *xyz_out = xyz;
    return 0;
}

/* The texel of a point on a mesh triangle (nearest texel, wrapping; uv
   origin at the bottom left, rows top down): its index in *IM, or SIZE_MAX
   when the triangle has no texture. */
static size_t mesh_texel(const vdag_scene *sc, size_t tri, const double bary[3], const vdag_image **im) {
    const uint32_t *v = sc->indices + 3 * tri;
    int32_t m = sc->triangle_material ? sc->triangle_material[tri] : -1;
    double u = 0, w = 0;
    long px, py;
    int c;
    if (!(m >= 0 && (size_t)m < sc->material_count && sc->uv && sc->materials[m].image >= 0 &&
          (size_t)sc->materials[m].image < sc->image_count))
        return SIZE_MAX;
    *im = &sc->images[sc->materials[m].image];
    for (c = 0; c < 3; c++) {
        u += bary[c] * sc->uv[2 * (size_t)v[c]];
        w += bary[c] * sc->uv[2 * (size_t)v[c] + 1];
    }
    u -= floor(u);
    w -= floor(w);
    px = (long)(u * (*im)->width);
    py = (long)((1 - w) * (*im)->height);
    if (px >= (long)(*im)->width) px = (long)(*im)->width - 1;
    if (py >= (long)(*im)->height) py = (long)(*im)->height - 1;
    if (px < 0) px = 0;
    if (py < 0) py = 0;
    return (size_t)py * (*im)->width + (size_t)px;
}

/* The alpha test: a point whose texel has alpha below one half (< 128 of
   255) makes no voxel, as the scenes' own renderers discard it. */
static int mesh_keep(void *user, size_t tri, const double bary[3]) {
    const vdag_image *im = NULL;
    size_t texel = mesh_texel((const vdag_scene *)user, tri, bary, &im);
    return texel == SIZE_MAX || !im->alpha || im->alpha[texel] >= 128;
}

/* Colour of a point on a mesh triangle: the material's texture (mesh_texel)
   tinted by the interpolated vertex colours; without a texture, the vertex
   colours, else the material's Kd (white without one). */
static void mesh_color(void *user, size_t tri, const double bary[3], uint8_t rgb[3]) {
    const vdag_scene *sc = (const vdag_scene *)user;
    const uint32_t *v = sc->indices + 3 * tri;
    int32_t m = sc->triangle_material ? sc->triangle_material[tri] : -1;
    const vdag_image *im = NULL;
    size_t texel = mesh_texel(sc, tri, bary, &im);
    int k, c;
    if (texel != SIZE_MAX) {
        memcpy(rgb, im->rgb + 3 * texel, 3);
    } else if (m >= 0 && (size_t)m < sc->material_count && !sc->vertex_rgb) {
        memcpy(rgb, sc->materials[m].rgb, 3);
    } else {
        rgb[0] = rgb[1] = rgb[2] = 255;
    }
    if (sc->vertex_rgb) {
        for (k = 0; k < 3; k++) {
            double x = 0;
            for (c = 0; c < 3; c++) x += bary[c] * sc->vertex_rgb[3 * (size_t)v[c] + k];
            x = x * rgb[k] / 255.0;
            rgb[k] = (uint8_t)(x + 0.5 > 255 ? 255 : x + 0.5);
        }
    }
}

/* Mesh vertices in grid units: the bounding box fitted into the 2^L grid
   with one uniform scale; BOUNDS receives the grid's world-space box. */
static double *mesh_to_grid(const vdag_scene *sc, uint32_t levels, double bounds[6]) {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, extent = 0, scale;
    double *grid = (double *)malloc(3 * sc->vertex_count * sizeof *grid + 1);
    size_t i;
    int k;
    if (!grid) return NULL;
    for (i = 0; i < 3 * sc->vertex_count; i++) {
        if (sc->positions[i] < lo[i % 3]) lo[i % 3] = sc->positions[i];
        if (sc->positions[i] > hi[i % 3]) hi[i % 3] = sc->positions[i];
    }
    for (k = 0; k < 3; k++)
        if (hi[k] - lo[k] > extent) extent = hi[k] - lo[k];
    scale = extent > 0 ? (double)(1u << levels) / extent : 1;
    for (i = 0; i < 3 * sc->vertex_count; i++) grid[i] = (sc->positions[i] - lo[i % 3]) * scale;
    for (k = 0; k < 3; k++) {
        bounds[k] = lo[k];
        bounds[k + 3] = lo[k] + (double)(1u << levels) / scale;
    }
    return grid;
}

static void print_build_summary(const voxdag *dag, const voxdag_build_stats *st, double seconds) {
    voxdag_info info;
    uint32_t l;
    voxdag_get_info(dag, &info);
    fprintf(stderr, "vdag: %llu voxels, L=%u, %.2f s, peak %.1f MiB\n", (unsigned long long)info.voxels,
            info.levels, seconds, st->peak_memory / 1048576.0);
    int all = st->svdag_nodes[0] && st->reflect_nodes[0] && st->full_nodes[0];
    fprintf(stderr, "vdag: level      nodes        svo%s\n", all ? "      svdag    reflect       full" : "");
    for (l = 0; l + 1 < info.levels; l++) {
        fprintf(stderr, "vdag: %5u %10llu %10llu", l, (unsigned long long)st->nodes[l],
                (unsigned long long)st->svo_nodes[l]);
        if (all)
            fprintf(stderr, " %10llu %10llu %10llu", (unsigned long long)st->svdag_nodes[l],
                    (unsigned long long)st->reflect_nodes[l], (unsigned long long)st->full_nodes[l]);
        fputc('\n', stderr);
    }
    fprintf(stderr, "vdag: geometry %llu bytes (%.3f bits/voxel), colours %llu bytes, file %llu bytes\n",
            (unsigned long long)(info.node_bytes + info.brick_bytes),
            info.voxels ? 8.0 * (double)(info.node_bytes + info.brick_bytes) / (double)info.voxels : 0.0,
            (unsigned long long)info.color_bytes, (unsigned long long)info.file_bytes);
}

/* The builder's colours go to a temporary file as they are reduced (the
   builder's memory then does not grow with them) and come back once the
   geometry is done: 3 bytes a voxel, in $TMPDIR (else /tmp), removed when
   closed. */
typedef struct color_spill {
    FILE *f; /* NULL: the build has no colours */
    uint64_t n;
    const char *dir;
} color_spill;

/* BYTES of temporary disk as text: bytes under 1 KiB, KiB under 1 MiB (a
   small spill is not "0.0 MiB"), else MiB. */
static const char *spill_size(double bytes, char buf[32]) {
    if (bytes < 1024.0) snprintf(buf, 32, "%.0f bytes", bytes);
    else if (bytes < 1048576.0) snprintf(buf, 32, "%.1f KiB", bytes / 1024.0);
    else snprintf(buf, 32, "%.1f MiB", bytes / 1048576.0);
    return buf;
}

/* Opens S's file: created and unlinked at once, so that nothing is left
   behind whatever happens. */
static int spill_open(color_spill *s) {
    char path[4096];
    int fd;
    s->dir = getenv("TMPDIR");
    if (!s->dir || !*s->dir) s->dir = "/tmp";
    if (snprintf(path, sizeof path, "%s/vdag-colors-XXXXXX", s->dir) >= (int)sizeof path) return 0;
    fd = mkstemp(path);
    if (fd < 0) return 0;
    unlink(path);
    if (!(s->f = fdopen(fd, "w+b"))) close(fd);
    return s->f != NULL;
}

/* Voxels a mesh voxelizes to, about: each triangle's area times the sum of
   its normal's absolute components (the voxel columns it crosses along each
   axis), in grid units. Shared edges make it a little high. */
static double mesh_voxel_estimate(const double *grid, const uint32_t *indices, size_t triangles) {
    double sum = 0;
    size_t t;
    for (t = 0; t < triangles; t++) {
        const double *a = grid + 3 * (size_t)indices[3 * t], *b = grid + 3 * (size_t)indices[3 * t + 1],
                     *c = grid + 3 * (size_t)indices[3 * t + 2];
        double u[3], v[3], n[3];
        int k;
        for (k = 0; k < 3; k++) u[k] = b[k] - a[k], v[k] = c[k] - a[k];
        n[0] = u[1] * v[2] - u[2] * v[1];
        n[1] = u[2] * v[0] - u[0] * v[2];
        n[2] = u[0] * v[1] - u[1] * v[0];
        /* |n| is twice the area; area * (|nx| + |ny| + |nz|) / |n|. */
        sum += 0.5 * (fabs(n[0]) + fabs(n[1]) + fabs(n[2]));
    }
    return sum;
}

/* The volume a closed mesh encloses, in grid units (|the sum of the signed
   volumes of the tetrahedra from the origin to each triangle|); for the
   voxels of a solid build. */
static double mesh_volume_estimate(const double *grid, const uint32_t *indices, size_t triangles) {
    double sum = 0;
    size_t t;
    for (t = 0; t < triangles; t++) {
        const double *a = grid + 3 * (size_t)indices[3 * t], *b = grid + 3 * (size_t)indices[3 * t + 1],
                     *c = grid + 3 * (size_t)indices[3 * t + 2];
        sum += a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) +
               a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    return fabs(sum) / 6;
}

static int spill_colors(void *user, const uint8_t *rgb, size_t n) {
    color_spill *s = (color_spill *)user;
    s->n += n;
    return fwrite(rgb, 3, n, s->f) != n;
}

/* A voxcolor stream written into a buffer that grows. */
typedef struct grow_buf {
    uint8_t *data;
    size_t size, cap;
} grow_buf;

static int write_grow(void *user, uint64_t offset, const void *bytes, size_t size) {
    grow_buf *g = (grow_buf *)user;
    uint64_t end = offset + size;
    if (end > g->cap) {
        size_t cap = g->cap ? g->cap : 1u << 20;
        uint8_t *p;
        while (cap < end) cap *= 2;
        if (!(p = (uint8_t *)realloc(g->data, cap))) return 0;
        g->data = p;
        g->cap = cap;
    }
    memcpy(g->data + offset, bytes, size);
    if (end > g->size) g->size = (size_t)end;
    return 1;
}

/* Compresses the spilled colours, read back a slice at a time, into G. */
static int encode_spill(FILE *f, uint64_t n, const build_args *a, grow_buf *g) {
    enum { SLICE = 1 << 20 };
    voxcolor_encode_opts o;
    voxcolor_encoder *enc = (voxcolor_encoder *)malloc(sizeof *enc);
    uint8_t *rgb = (uint8_t *)malloc(3 * SLICE);
    uint64_t done = 0;
    int ok = enc && rgb;
    memset(&o, 0, sizeof o);
    o.max_error = a->color_error;
    o.weight_bits = a->color_bits;
    o.effort = a->color_effort;
    o.threads = a->threads; /* whole pages of each slice in parallel */
    ok = ok && voxcolor_encoder_init(enc, n, &o, write_grow, g, NULL) == VOXCOLOR_OK;
    while (ok && done < n) {
        size_t k = n - done < SLICE ? (size_t)(n - done) : SLICE;
        ok = fread(rgb, 3, k, f) == k && voxcolor_encoder_push(enc, rgb, k) == VOXCOLOR_OK;
        done += k;
    }
    ok = ok && voxcolor_encoder_finish(enc, NULL) == g->size;
    free(enc);
    free(rgb);
    return ok;
}

/* --verify-colors: decodes the stream in G a slice at a time and compares
   every colour with the spilled raw one, before the spill is gone. Returns
   0, or 1 after printing why (a colour over e_t, or the check could not
   run). */
static int verify_spill(color_spill *spill, const grow_buf *g, const build_args *a) {
    voxcolor_view view;
    voxcolor_error verr;
    vdag_color_check c;
    double t0 = now_seconds();
    if (voxcolor_view_init(&view, g->data, g->size, &verr) != VOXCOLOR_OK)
        return vdag_fail("colour check: the compressed colours do not decode: %s (byte %llu)", verr.message,
                         (unsigned long long)verr.byte_offset);
    if (view.count != spill->n)
        return vdag_fail("colour check: the stream holds %llu colours, the spill %llu", (unsigned long long)view.count,
                         (unsigned long long)spill->n);
    rewind(spill->f);
    if (!vdag_check_colors_on(&view, spill->f, a->color_error, run_jobs, (void *)&a->threads, a->threads, &c))
        return vdag_fail("colour check: cannot read the raw colours back (or out of memory)");
    if (c.over)
        return vdag_fail("colour check FAILED: %llu of %llu colours are off by more than e_t %g (first: colour %llu; "
                         "max error %.6f at colour %llu)",
                         (unsigned long long)c.over, (unsigned long long)view.count, a->color_error,
                         (unsigned long long)c.first_over, c.max_error, (unsigned long long)c.worst);
    if (!a->quiet)
        fprintf(stderr, "vdag: colour check: all %llu colours decoded and compared with the raw ones: max error %.6f "
                        "<= e_t %g (%.2f s)\n",
                (unsigned long long)view.count, c.max_error, a->color_error, now_seconds() - t0);
    return 0;
}

/* Reads the spilled colours back and attaches them to *DAG: RGB8, or a
   voxcolor stream when COMPRESS is set (encoded as it is read, so only the
   stream is held). */
static int attach_colors(voxdag **dag, color_spill *spill, build_args *a) {
    uint64_t size = 3 * spill->n;
    voxdag *with = NULL;
    voxdag_error err;
    voxdag_build_opts o;
    double t0 = now_seconds();
    char text[32];
    int rc;
    memset(&o, 0, sizeof o);
    o.no_lod_colors = a->no_lod_colors;
    o.threads = a->threads; /* the level-of-detail means */
    if (!a->quiet && spill->n)
        fprintf(stderr, "vdag: colour spill: %s of temporary disk in %s (%llu colours)\n",
                spill_size((double)size, text), spill->dir, (unsigned long long)spill->n);
    phase_enter(&a->phases, "colours");
    rewind(spill->f);
    if (!a->compress) {
        uint8_t *rgb = (uint8_t *)malloc(size ? (size_t)size : 1);
        if (!rgb) return vdag_fail("out of memory for %llu colours", (unsigned long long)spill->n);
        if (fread(rgb, 1, (size_t)size, spill->f) != size) {
            free(rgb);
            return vdag_fail("cannot read back the colours");
        }
        phase_enter(&a->phases, "colour attach"); /* with the level-of-detail means */
        rc = voxdag_with_colors_opts(*dag, VOXDAG_COLORS_RGB8, rgb, (size_t)size, &o, &with, &err) != VOXDAG_OK;
        free(rgb);
    } else {
        grow_buf g;
        memset(&g, 0, sizeof g);
        if (!encode_spill(spill->f, spill->n, a, &g)) {
            free(g.data);
            return vdag_fail("colour compression failed (out of memory or the colours cannot be read back)");
        }
        if (!a->quiet)
            fprintf(stderr,
                    "vdag: colours %llu -> %zu bytes (%.1f%%, %.2f bits/colour, e_t %g, %s effort) in %.2f s on %u "
                    "thread%s\n",
                    (unsigned long long)size, g.size, size ? 100.0 * (double)g.size / (double)size : 0.0,
                    size ? 24.0 * (double)g.size / (double)size : 0.0, a->color_error,
                    a->color_effort == VOXCOLOR_EFFORT_FAST ? "fast" : "smallest", now_seconds() - t0, a->threads,
                    a->threads == 1 ? "" : "s");
        if (a->verify_colors) {
            phase_enter(&a->phases, "colour check");
            if (verify_spill(spill, &g, a)) {
                free(g.data);
                return 1;
            }
        }
        phase_enter(&a->phases, "colour attach"); /* with the level-of-detail means */
        rc = voxdag_with_colors_opts(*dag, VOXDAG_COLORS_VOXCOLOR, g.data, g.size, &o, &with, &err) != VOXDAG_OK;
        free(g.data);
    }
    if (rc) return vdag_fail("%s", err.message);
    voxdag_free(*dag);
    *dag = with;
    return 0;
}

/* Options of a build; its colours, if any, go to A's spill file, about
   VOXELS of them (an estimate, reported). */
static int build_opts(build_args *a, int colors, const double *bounds, double voxels, voxdag_build_opts *o) {
    struct statvfs fs;
    char text[32];
    double free_mib = -1; /* unknown */
    memset(o, 0, sizeof *o);
    o->levels = a->levels;
    o->symmetry = a->symmetry;
    o->colors = colors;
    o->compare_structures = a->stats;
    o->threads = a->threads;
    o->max_memory = (uint64_t)a->max_memory << 20;
    o->bounds = bounds;
    o->progress = progress;
    o->progress_user = a;
    if (!colors) return 0;
    if (!spill_open(a->spill))
        return vdag_fail("build: cannot create a temporary file for the colours in %s (set TMPDIR): %s", a->spill->dir,
                         strerror(errno));
    if (statvfs(a->spill->dir, &fs) == 0) free_mib = (double)fs.f_bavail * (double)fs.f_frsize / 1048576.0;
    if (!a->quiet && voxels > 0 && free_mib >= 0)
        fprintf(stderr, "vdag: colour spill: about %s of temporary disk in %s (estimate; %.0f MiB free there; "
                        "set TMPDIR to move it)\n", spill_size(3.0 * voxels, text), a->spill->dir, free_mib);
    else if (!a->quiet && voxels > 0)
        fprintf(stderr, "vdag: colour spill: about %s of temporary disk in %s (estimate; set TMPDIR to move it)\n",
                spill_size(3.0 * voxels, text), a->spill->dir);
    if (free_mib >= 0 && 3.0 * voxels / 1048576.0 > free_mib)
        fprintf(stderr, "vdag: warning: the colour spill may not fit in %s (about %.1f MiB, %.0f MiB free): set TMPDIR "
                        "to a larger disk\n", a->spill->dir, 3.0 * voxels / 1048576.0, free_mib);
    o->color_sink = spill_colors;
    o->color_sink_user = a->spill;
    return 0;
}

static int finish_build(build_args *a, voxdag_builder *b, int failed, voxdag_error *err, double t0);

/* A rough estimate of a mesh build, printed before a long one (more than
   10^7 voxels): the voxels from the mesh's area (mesh_voxel_estimate);
   memory 4 bytes a voxel up to 2048^3, then 3/4 of that per level more (the
   builder holds the unique nodes, which grow about 3x per level while the
   voxels grow 4x: on a game level its peak fell from 2.4 bytes a voxel at
   2048^3 to 0.3 at 65536^3), plus 3 a voxel for uncompressed colours;
   with --solid, the inside's voxels (mesh_volume_estimate) count for the
   colours only, as its nodes are shared all but next to the surface. Past
   the machine's memory the build needs --force. Returns 0 after printing
   why it stops. */
static int mesh_estimate(const build_args *a, const vdag_scene *sc, const double *grid, int colors) {
    double surface = mesh_voxel_estimate(grid, sc->indices, sc->triangle_count), per_voxel = 4, bytes, machine;
    double voxels = surface + (a->solid ? mesh_volume_estimate(grid, sc->indices, sc->triangle_count) : 0);
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    uint32_t l;
    for (l = 12; l <= a->levels; l++) per_voxel *= 0.75;
    bytes = surface * per_voxel + voxels * (colors && !a->compress ? 3 : 0); /* inside: shared nodes */
    machine = pages > 0 && page > 0 ? (double)pages * (double)page : 0;
    if (voxels > 1e7 && !a->quiet)
        fprintf(stderr, "vdag: estimate: about %.3g voxels and %.0f MiB (rough)\n", voxels, bytes / 1048576.0);
    if (machine > 0 && bytes > machine && !a->force)
        return !vdag_fail("build: the estimate (%.0f MiB) exceeds this machine's memory (%.0f MiB); "
                          "lower --levels, or add --force to try anyway", bytes / 1048576.0, machine / 1048576.0);
    return 1;
}

static int build_mesh(build_args *a, vdag_scene *sc, double t0) {
    double bounds[6], *grid;
    voxdag_build_opts o;
    voxdag_builder *b = NULL;
    voxdag_mesh mesh;
    voxdag_error err;
    size_t i;
    int colors = !a->no_colors && (sc->vertex_rgb || sc->material_count), rc;
    if (!a->levels) a->levels = 10;
    if (!a->quiet)
        fprintf(stderr, "vdag: voxelizing %zu triangles into %u^3 (%.1f s)\n", sc->triangle_count, 1u << a->levels,
                now_seconds() - t0);
    grid = mesh_to_grid(sc, a->levels, bounds);
    if (!grid) {
        vdag_scene_free(sc);
        return vdag_fail("out of memory");
    }
    if (build_opts(a, colors, bounds,
                   colors ? mesh_voxel_estimate(grid, sc->indices, sc->triangle_count) +
                                (a->solid ? mesh_volume_estimate(grid, sc->indices, sc->triangle_count) : 0)
                          : 0,
                   &o)) {
        free(grid);
        vdag_scene_free(sc);
        return 1;
    }
    /* Small coloured meshes in small chunks: a chunk holds a colour per voxel. */
    o.chunk_levels = a->chunk_levels ? a->chunk_levels : colors && sc->triangle_count < 65536 ? 5 : 8;
    if (!mesh_estimate(a, sc, grid, colors)) {
        free(grid);
        vdag_scene_free(sc);
        if (a->spill->f) fclose(a->spill->f);
        return 1;
    }
    memset(&mesh, 0, sizeof mesh);
    mesh.positions = grid;
    mesh.vertex_count = sc->vertex_count;
    mesh.indices = sc->indices;
    mesh.triangle_count = sc->triangle_count;
    mesh.color = colors ? mesh_color : NULL;
    mesh.user = sc;
    mesh.solid = a->solid;
    for (i = 0; !a->no_alpha_test && i < sc->image_count; i++)
        if (sc->images[i].alpha) mesh.keep = mesh_keep; /* some texel is not opaque */
    rc = voxdag_builder_create(&o, &b, &err) != VOXDAG_OK;
    if (!rc && voxdag_builder_add_mesh(b, &mesh, &err) != VOXDAG_OK) {
        uint64_t open = 0, first = 0;
        voxdag_error e2;
        voxdag_builder_free(b);
        rc = 1;
        progress_end(a);
        if (err.status == VOXDAG_ERR_NOT_CLOSED && voxdag_mesh_open_edges(&mesh, NULL, &open, &first, &e2) == VOXDAG_OK)
            fprintf(stderr,
                    "vdag: --solid: %s is not closed: %llu open edges (the first at triangle %llu, from 0); an "
                    "edge is open when its triangles do not use it as often each way (vertices at one position "
                    "are one vertex). Without --solid the surface builds.\n",
                    a->in, (unsigned long long)open, (unsigned long long)first);
    }
    rc = finish_build(a, b, rc, &err, t0);
    free(grid);
    vdag_scene_free(sc);
    return rc;
}

/* The output of a build, to refuse files the import reads (the input, its
   .mtl libraries, textures) as the output: the same device and inode. */
typedef struct output_guard {
    struct stat out; /* valid when exists */
    int exists;
    char clash[4096]; /* the file read that is the output, else "" */
} output_guard;

static int guard_read(void *user, const char *path) {
    output_guard *g = (output_guard *)user;
    struct stat st;
    if (g->exists && !stat(path, &st) && st.st_dev == g->out.st_dev && st.st_ino == g->out.st_ino) {
        snprintf(g->clash, sizeof g->clash, "%s", path);
        return 0;
    }
    return 1;
}

/* The extension of PATH compared with EXT (lower case, no dot), in any case. */
static int has_ext(const char *path, const char *ext) {
    const char *slash = strrchr(path, '/'), *dot = strrchr(slash ? slash : path, '.');
    if (!dot) return 0;
    for (dot++; *dot && (*dot | 0x20) == *ext; dot++, ext++) {}
    return !*dot && !*ext;
}

/* What the first bytes of an input say it is, when that is not a model the
   importers read: "" for anything else. HEAD holds the first N bytes of a
   regular file of SIZE bytes; TEXT is set when they hold no NUL byte. */
static const char *sniff_kind(const char *path, const uint8_t *head, size_t n, uint64_t size, int *text) {
    static const uint8_t png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    static const uint8_t vdag[8] = {0x89, 'V', 'D', 'A', 'G', '\r', '\n', 0x1A};
    size_t i;
    *text = !memchr(head, 0, n);
    if (!size) return "an empty file";
    if (n >= 8 && !memcmp(head, png, 8)) return "a PNG image";
    if (n >= 3 && head[0] == 0xFF && head[1] == 0xD8 && head[2] == 0xFF) return "a JPEG image";
    if (n >= 6 && (!memcmp(head, "GIF87a", 6) || !memcmp(head, "GIF89a", 6))) return "a GIF image";
    if (n >= 8 && !memcmp(head, vdag, 8)) return "a .vdag file (already built: vdag info reads it)";
    if (n >= 2 && head[0] == 0x1F && head[1] == 0x8B) return "gzip-compressed data (decompress it first)";
    if (n >= 4 && !memcmp(head, "PK\3\4", 4)) return "a zip archive (extract it first)";
    if (n >= 4 && !memcmp(head, "VOX ", 4) && !has_ext(path, "vox")) return "a MagicaVoxel .vox file (name it .vox)";
    /* Binary STL: an 80-byte header, a triangle count, 50 bytes a triangle. */
    if (n >= 84 && !has_ext(path, "stl") && !has_ext(path, "vox") && !has_ext(path, "spm") &&
        size == 84 + 50 * (uint64_t)(head[80] | head[81] << 8 | head[82] << 16 | (uint32_t)head[83] << 24))
        return "a binary STL mesh (80-byte header and a triangle count that matches its size; name it .stl)";
    /* A material library: its first keyword (after blank lines, comments
       and a UTF-8 byte order mark) is newmtl; or so named. */
    i = n >= 3 && !memcmp(head, "\xEF\xBB\xBF", 3) ? 3 : 0;
    while (i < n && (head[i] == ' ' || head[i] == '\t' || head[i] == '\r' || head[i] == '\n' || head[i] == '#')) {
        if (head[i] == '#')
            while (i < n && head[i] != '\n') i++;
        else i++;
    }
    if (has_ext(path, "mtl") || (*text && n - i >= 7 && !memcmp(head + i, "newmtl", 6) && (head[i + 6] == ' ' || head[i + 6] == '\t')))
        return "a material library (.mtl), which holds no geometry: build the .obj that names it in mtllib";
    return "";
}

/* Refuses an input that is not a model (an image, an archive, a .vdag, a
   material library, an empty file unless ALLOW_EMPTY) before importing it,
   saying what it looks like. Returns 1 to go on, or 0 after printing why.
   *TEXT receives whether the first bytes are text (no NUL byte). */
static int check_input(const char *path, int allow_empty, int *text) {
    uint8_t head[4096];
    struct stat st;
    size_t n;
    const char *kind;
    FILE *f;
    *text = 0;
    if (stat(path, &st) || !S_ISREG(st.st_mode)) return 1; /* the importer says why */
    if (!(f = fopen(path, "rb"))) return 1;
    n = fread(head, 1, sizeof head, f);
    fclose(f);
    kind = sniff_kind(path, head, n, (uint64_t)st.st_size, text);
    if (!*kind || (allow_empty && !st.st_size)) return 1;
    if (!st.st_size) return !vdag_fail("%s: not a model: an empty file (--allow-empty builds an empty scene)", path);
    return !vdag_fail("%s: not a model: it looks like %s", path, kind);
}

static int cmd_build(int argc, char **argv) {
    build_args a;
    color_spill spill;
    vdag_scene sc;
    vdag_import_limits limits;
    output_guard guard;
    char msg[256];
    voxdag_build_opts o;
    voxdag_builder *b;
    voxdag_error err;
    uint32_t *xyz = NULL;
    double bounds[6], t0 = now_seconds();
    size_t i;
    int k, rc, text;
    memset(&a, 0, sizeof a);
    memset(&spill, 0, sizeof spill);
    a.spill = &spill;
    a.compress = 1; /* lossless voxcolor (color_error 0) unless --raw-colors */
    a.t0 = t0;
    a.phases.current = -1;
    phase_enter(&a.phases, "read");
    a.threads = vdag_cpu_count();
    a.tty = isatty(2);
    for (k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "--levels") && k + 1 < argc) {
            if (!parse_u32(argv[++k], &a.levels) || a.levels < 2 || a.levels > VOXDAG_MAX_LEVELS)
                return vdag_fail("build: --levels takes 2..%d", VOXDAG_MAX_LEVELS);
        } else if (!strcmp(argv[k], "--threads") && k + 1 < argc) {
            if (!parse_u32(argv[++k], &a.threads) || !a.threads) return vdag_fail("build: --threads takes a count >= 1");
        } else if (!strcmp(argv[k], "--up") && k + 1 < argc) {
            k++;
            if (strlen(argv[k]) != 1 || !strchr("xyz", argv[k][0])) return vdag_fail("build: --up takes x, y or z");
            a.up = argv[k][0];
        } else if (!strcmp(argv[k], "--chunk-levels") && k + 1 < argc) {
            if (!parse_u32(argv[++k], &a.chunk_levels) || a.chunk_levels < 2 || a.chunk_levels > 8)
                return vdag_fail("build: --chunk-levels takes 2..8");
        } else if (!strcmp(argv[k], "--max-memory") && k + 1 < argc) {
            if (!parse_u32(argv[++k], &a.max_memory) || !a.max_memory)
                return vdag_fail("build: --max-memory takes MiB >= 1");
        } else if (!strcmp(argv[k], "--max-texture-pixels") && k + 1 < argc) {
            if (!parse_count(argv[++k], &a.max_texture_pixels))
                return vdag_fail("build: --max-texture-pixels takes a pixel count >= 1");
        } else if (!strcmp(argv[k], "--max-vox-voxels") && k + 1 < argc) {
            if (!parse_count(argv[++k], &a.max_vox_voxels))
                return vdag_fail("build: --max-vox-voxels takes a voxel count >= 1");
        } else if (!strcmp(argv[k], "--vox-model") && k + 1 < argc) {
            if (!parse_u32(argv[++k], &a.vox_model)) return vdag_fail("build: --vox-model takes a model number >= 0");
        } else if (!strcmp(argv[k], "--force")) {
            a.force = 1;
        } else if (!strcmp(argv[k], "--allow-empty")) {
            a.allow_empty = 1;
        } else if (!strcmp(argv[k], "--quiet")) {
            a.quiet = 1;
        } else if (!strcmp(argv[k], "--no-colors")) {
            a.no_colors = 1;
        } else if (!strcmp(argv[k], "--timings")) {
            a.timings = 1;
        } else if (!strcmp(argv[k], "--no-lod-colors")) {
            a.no_lod_colors = 1;
        } else if (!strcmp(argv[k], "--solid")) {
            a.solid = 1;
        } else if (!strcmp(argv[k], "--no-alpha-test")) {
            a.no_alpha_test = 1;
        } else if (!strcmp(argv[k], "--no-symmetry")) {
            a.symmetry = VOXDAG_SYMMETRY_NONE;
        } else if (!strcmp(argv[k], "--symmetry") && k + 1 < argc) {
            k++;
            for (a.symmetry = VOXDAG_SYMMETRY_NONE; a.symmetry <= VOXDAG_SYMMETRY_FULL;
                 a.symmetry = (voxdag_symmetry)(a.symmetry + 1))
                if (!strcmp(argv[k], symmetry_name(a.symmetry))) break;
            if (a.symmetry > VOXDAG_SYMMETRY_FULL) return vdag_fail("build: --symmetry takes none, reflect or full");
        } else if (!strcmp(argv[k], "--stats")) {
            a.stats = 1;
        } else if (!strcmp(argv[k], "--color-error") && k + 1 < argc) {
            if (!parse_double(argv[++k], &a.color_error) || a.color_error < 0)
                return vdag_fail("build: --color-error takes a number >= 0");
            a.color_option = "--color-error";
        } else if (!strcmp(argv[k], "--raw-colors")) {
            a.compress = 0;
        } else if (!strcmp(argv[k], "--color-effort") && k + 1 < argc) {
            k++;
            if (!strcmp(argv[k], "smallest")) a.color_effort = VOXCOLOR_EFFORT_SMALLEST;
            else if (!strcmp(argv[k], "fast")) a.color_effort = VOXCOLOR_EFFORT_FAST;
            else return vdag_fail("build: --color-effort takes smallest or fast");
            a.color_option = "--color-effort";
        } else if (!strcmp(argv[k], "--verify-colors")) {
            a.verify_colors = 1;
            a.color_option = "--verify-colors";
        } else if (!strcmp(argv[k], "--color-bits") && k + 1 < argc) {
            k++;
            if (!strcmp(argv[k], "auto")) a.color_bits = 0;
            else if (!parse_u32(argv[k], &a.color_bits) || a.color_bits < 1 || a.color_bits > 4)
                return vdag_fail("build: --color-bits takes 1..4 or auto");
            a.color_option = "--color-bits";
        } else if (argv[k][0] == '-' && argv[k][1]) {
            return vdag_fail("build: unknown option %s", argv[k]);
        } else if (!a.in) {
            a.in = argv[k];
        } else if (!a.out) {
            a.out = argv[k];
        } else {
            return vdag_fail("build: too many arguments");
        }
    }
    if (!a.in || !a.out) return vdag_fail("usage: vdag build IN OUT.vdag [--levels L] [--symmetry G] ...");
    if (!a.compress && a.color_option)
        return vdag_fail("build: --raw-colors stores colours uncompressed: %s is for voxcolor colours", a.color_option);
    if (a.color_error > sqrt(3.0)) /* the distance from black to white */
        fprintf(stderr, "vdag: warning: --color-error %g is above sqrt(3) = 1.732, the largest RGB distance / 255: "
                        "every colour is within it\n", a.color_error);
    if (!vdag_check_output(a.in, a.out)) return 1;
    if (!check_input(a.in, a.allow_empty, &text)) return 1;
    if (!a.quiet) fprintf(stderr, "vdag: reading %s\n", a.in);
    memset(&limits, 0, sizeof limits);
    /* Textures give colours and the alpha test: without both, nothing to decode them for. */
    limits.skip_textures = a.no_colors && a.no_alpha_test;
    limits.max_texture_pixels = a.max_texture_pixels;
    limits.max_vox_voxels = a.max_vox_voxels;
    limits.vox_model = a.vox_model;
    guard.exists = !stat(a.out, &guard.out);
    guard.clash[0] = 0;
    limits.on_file = guard_read;
    limits.on_file_user = &guard;
    limits.run = run_jobs; /* textures decoded --threads at a time */
    limits.run_user = &a.threads;
    limits.threads = a.threads;
    if (!vdag_import_file(a.in, &limits, &sc, msg, sizeof msg)) {
        if (guard.clash[0])
            return vdag_fail("%s: is %s, a file the build reads; refusing to write over it", a.out, guard.clash);
        return vdag_fail("%s", msg);
    }
    choose_up(&a);
    turn_up(sc.points, sc.point_count, a.up, sc.points_are_voxels);
    turn_up(sc.positions, sc.vertex_count, a.up, 0);
    if (!sc.triangle_count && !sc.point_count && !a.allow_empty) {
        vdag_scene_free(&sc);
        return vdag_fail("%s: not a model: %s with no triangles and no points (lines are not voxelized; "
                         "--allow-empty builds an empty scene)", a.in, text ? "a text file" : "a file");
    }
    if (!sc.triangle_count && !sc.point_count)
        fprintf(stderr, "vdag: warning: %s holds no triangles and no points (lines are not voxelized): "
                        "the result has no voxels\n", a.in);
    a.input_items = sc.triangle_count ? sc.triangle_count : sc.point_count;
    if (sc.triangle_count) return build_mesh(&a, &sc, t0);
    if (a.solid) {
        vdag_scene_free(&sc);
        return vdag_fail("%s: --solid fills meshes, and this input has no triangles", a.in);
    }
    if (!a.levels && !sc.points_are_voxels && sc.point_count && choose_cloud_levels(&sc, &a)) {
        vdag_scene_free(&sc);
        return 1;
    }
    if (scene_to_grid(&sc, &a, &xyz, bounds)) {
        vdag_scene_free(&sc);
        return 1;
    }
    rc = build_opts(&a, !a.no_colors && sc.point_rgb != NULL, bounds, (double)sc.point_count, &o);
    if (rc) {
        free(xyz);
        vdag_scene_free(&sc);
        return 1;
    }
    rc = voxdag_builder_create(&o, &b, &err) != VOXDAG_OK;
    for (i = 0; !rc && i < sc.point_count; i += 1u << 20) {
        size_t n = sc.point_count - i < (1u << 20) ? sc.point_count - i : (1u << 20);
        rc = voxdag_builder_add(b, xyz + 3 * i, sc.point_rgb ? sc.point_rgb + 3 * i : NULL, n, &err) != VOXDAG_OK;
        if (rc) voxdag_builder_free(b);
    }
    free(xyz);
    vdag_scene_free(&sc);
    return finish_build(&a, b, rc, &err, t0);
}

/* The temporary file of the save in progress (voxdag_save_temp_path: the
   library creates it exclusively under this name), for save_stopped. */
static char save_temp[4200];

/* A signal that stops a save removes its temporary file, then ends the
   process as the signal would have (async-signal-safe: unlink, signal,
   raise). */
static void save_stopped(int sig) {
    unlink(save_temp);
    signal(sig, SIG_DFL);
    raise(sig);
}

/* voxdag_save_file, and on SIGINT, SIGTERM, SIGHUP or SIGXFSZ (a file-size
   limit) while it runs, no temporary file left behind. A signal the tool
   was started with ignored stays ignored (SIGXFSZ then fails the write with
   EFBIG, and the library removes the temporary). TMP receives the name. */
static voxdag_status save_file(const voxdag *dag, const char *path, char *tmp, size_t tmp_size, voxdag_error *err) {
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGXFSZ};
    struct sigaction sa, old[sizeof sigs / sizeof sigs[0]];
    voxdag_status st;
    size_t i;
    if (voxdag_save_temp_path(path, save_temp, sizeof save_temp) != VOXDAG_OK)
        return voxdag_save_file(dag, path, err); /* the path is too long: the library says so */
    snprintf(tmp, tmp_size, "%s", save_temp);
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = save_stopped;
    sigemptyset(&sa.sa_mask);
    for (i = 0; i < sizeof sigs / sizeof sigs[0]; i++) sigaddset(&sa.sa_mask, sigs[i]);
    for (i = 0; i < sizeof sigs / sizeof sigs[0]; i++)
        if (!sigaction(sigs[i], NULL, &old[i]) && old[i].sa_handler != SIG_IGN) sigaction(sigs[i], &sa, NULL);
    st = voxdag_save_file(dag, path, err);
    for (i = 0; i < sizeof sigs / sizeof sigs[0]; i++) sigaction(sigs[i], &old[i], NULL);
    return st;
}

/* Finishes a build whose input is all added (FAILED: adding failed, B is
   freed), compresses colours when asked, and saves. */
static int finish_build(build_args *a, voxdag_builder *b, int failed, voxdag_error *err, double t0) {
    char tmp[4200];
    voxdag *dag = NULL;
    voxdag_build_stats st;
    int rc = failed;
    double seconds;
    if (!rc) rc = voxdag_builder_finish(b, &dag, &st, err) != VOXDAG_OK;
    progress_end(a);
    seconds = now_seconds() - t0;
    if (!rc && a->spill->f) rc = attach_colors(&dag, a->spill, a);
    else if (rc && err->status == VOXDAG_ERR_LIMIT && a->max_memory && strstr(err->message, "max_memory"))
        vdag_fail("build: the builder needs more than --max-memory %u MiB (%s)", a->max_memory, err->message);
    else if (rc) vdag_fail("build: %s (%s)", voxdag_status_string(err->status), err->message);
    if (a->spill->f) fclose(a->spill->f);
    if (rc) {
        voxdag_free(dag);
        return 1;
    }
    if (!a->quiet) print_build_summary(dag, &st, seconds);
    if (!st.voxels && a->input_items)
        fprintf(stderr, "vdag: warning: %s gave no voxels (its triangles or points lie outside the grid, "
                        "or are degenerate)\n", a->in);
    errno = 0;
    phase_enter(&a->phases, "save");
    rc = save_file(dag, a->out, tmp, sizeof tmp, err) != VOXDAG_OK;
    voxdag_free(dag);
    phase_enter(&a->phases, NULL);
    if (a->timings) phase_print(&a->phases);
    if (rc && err->os_error == EEXIST)
        return vdag_fail("%s: %s is in the way (taken again while the save removed a stale one)", a->out, tmp);
    if (rc && err->os_error) return vdag_fail("%s: %s (%s)", a->out, err->message, strerror(err->os_error));
    if (rc) return vdag_fail("%s: %s", a->out, err->message);
    if (!a->quiet) fprintf(stderr, "vdag: wrote %s\n", a->out);
    return 0;
}

// -- vdag info / validate

/* V with a negative zero made positive, so that none is printed as "-0"
   (a world box of a file built from a turned axis: -z of 0). */
static double no_minus_zero(double v) { return v == 0 ? 0.0 : v; }

static const char *color_kind_name(voxdag_color_kind k) {
    return k == VOXDAG_COLORS_RGB8 ? "rgb8" : k == VOXDAG_COLORS_VOXCOLOR ? "voxcolor" : "none";
}

static int cmd_info(int argc, char **argv) {
    vdag_file f;
    voxdag_info in;
    int json = argc > 2 && !strcmp(argv[2], "--json");
    uint32_t l;
    double geo_bits;
    if (argc < 2 || argc > 3 || (argc == 3 && !json)) return vdag_fail("usage: vdag info FILE [--json]");
    if (!vdag_open(argv[1], &f)) return 1;
    voxdag_get_info(f.dag, &in);
    for (l = 0; l < 6; l++) in.bounds[l] = no_minus_zero(in.bounds[l]);
    geo_bits = in.voxels ? 8.0 * (double)(in.node_bytes + in.brick_bytes) / (double)in.voxels : 0.0;
    if (json) {
        printf("{\"levels\": %u, \"voxels\": %llu, \"symmetric\": %s, \"symmetry\": \"%s\", \"voxel_box\": [%u, %u, %u, %u, %u, %u], \"nodes_per_level\": [",
               in.levels, (unsigned long long)in.voxels, in.symmetry != VOXDAG_SYMMETRY_NONE ? "true" : "false",
               symmetry_name(in.symmetry), in.voxel_box[0], in.voxel_box[1],
               in.voxel_box[2], in.voxel_box[3], in.voxel_box[4], in.voxel_box[5]);
        for (l = 0; l + 1 < in.levels; l++) printf("%s%llu", l ? ", " : "", (unsigned long long)in.nodes[l]);
        printf("], \"bytes_per_level\": [");
        for (l = 0; l + 1 < in.levels; l++) printf("%s%llu", l ? ", " : "", (unsigned long long)in.level_bytes[l]);
        printf("], \"bytes\": {\"file\": %llu, \"nodes\": %llu, \"bricks\": %llu, \"lod_colors\": %llu, \"colors\": %llu}, ",
               (unsigned long long)in.file_bytes, (unsigned long long)in.node_bytes,
               (unsigned long long)in.brick_bytes, (unsigned long long)in.lod_color_bytes,
               (unsigned long long)in.color_bytes);
        printf("\"bits_per_voxel\": %.6f, \"color_format\": \"%s\", \"color_bits_per_voxel\": %.6f", geo_bits,
               color_kind_name(in.color_kind), in.voxels ? 8.0 * (double)in.color_bytes / (double)in.voxels : 0.0);
        if (in.has_bounds) /* the grid's world box */
            printf(", \"bounds\": [%.17g, %.17g, %.17g, %.17g, %.17g, %.17g]", in.bounds[0], in.bounds[1],
                   in.bounds[2], in.bounds[3], in.bounds[4], in.bounds[5]);
        printf("}\n");
    } else {
        printf("levels      %u (grid %u^3)\n", in.levels, 1u << in.levels);
        printf("voxels      %llu\n", (unsigned long long)in.voxels);
        printf("symmetry    %s\n", symmetry_name(in.symmetry));
        printf("level       nodes        bytes\n");
        for (l = 0; l + 1 < in.levels; l++)
            printf("%5u %11llu %12llu%s\n", l, (unsigned long long)in.nodes[l],
                   (unsigned long long)in.level_bytes[l], l + 2 == in.levels ? "  (4^3 bricks)" : "");
        printf("geometry    %llu bytes (%.4f bits/voxel)\n", (unsigned long long)(in.node_bytes + in.brick_bytes),
               geo_bits);
        printf("colours     %s, %llu bytes (%.3f bits/voxel)\n", color_kind_name(in.color_kind),
               (unsigned long long)in.color_bytes,
               in.voxels ? 8.0 * (double)in.color_bytes / (double)in.voxels : 0.0);
        if (in.lod_color_bytes) /* the means of level-of-detail cells of more than 64 voxels */
            printf("lod colours %llu bytes (%.1f %% of the colours)\n", (unsigned long long)in.lod_color_bytes,
                   100.0 * (double)in.lod_color_bytes / (double)in.color_bytes);
        printf("file        %llu bytes\n", (unsigned long long)in.file_bytes);
        if (in.voxels)
            printf("occupied    voxels (%u, %u, %u) - (%u, %u, %u), grid units, half-open\n", in.voxel_box[0],
                   in.voxel_box[1], in.voxel_box[2], in.voxel_box[3], in.voxel_box[4], in.voxel_box[5]);
        if (in.has_bounds) {
            double cell = (in.bounds[3] - in.bounds[0]) / (double)(1u << in.levels);
            printf("grid world box  (%g, %g, %g) - (%g, %g, %g), the source's units\n", in.bounds[0], in.bounds[1],
                   in.bounds[2], in.bounds[3], in.bounds[4], in.bounds[5]);
            if (in.voxels)
                printf("occupied world box  (%g, %g, %g) - (%g, %g, %g)\n",
                       no_minus_zero(in.bounds[0] + cell * in.voxel_box[0]),
                       no_minus_zero(in.bounds[1] + cell * in.voxel_box[1]),
                       no_minus_zero(in.bounds[2] + cell * in.voxel_box[2]),
                       no_minus_zero(in.bounds[0] + cell * in.voxel_box[3]),
                       no_minus_zero(in.bounds[1] + cell * in.voxel_box[4]),
                       no_minus_zero(in.bounds[2] + cell * in.voxel_box[5]));
        }
    }
    vdag_close(&f);
    return 0;
}

static int cmd_validate(int argc, char **argv) {
    vdag_file f;
    if (argc != 2) return vdag_fail("usage: vdag validate FILE");
    if (!vdag_open(argv[1], &f)) return 1;
    vdag_close(&f);
    fprintf(stderr, "vdag: %s: valid\n", argv[1]);
    return 0;
}

// -- vdag lookup / export-voxels

static int cmd_lookup(int argc, char **argv) {
    vdag_file f;
    voxdag_info in;
    uint32_t c[3];
    uint64_t index;
    int k;
    if (argc != 5) return vdag_fail("usage: vdag lookup FILE x y z");
    for (k = 0; k < 3; k++)
        if (!parse_u32(argv[2 + k], &c[k])) return vdag_fail("lookup: bad coordinate '%s'", argv[2 + k]);
    if (!vdag_open(argv[1], &f)) return 1;
    voxdag_get_info(f.dag, &in);
    if (c[0] >> in.levels || c[1] >> in.levels || c[2] >> in.levels) {
        vdag_close(&f);
        return vdag_fail("lookup: (%u, %u, %u) is outside the grid: %u^3 (levels %u), coordinates 0..%u", c[0], c[1],
                         c[2], 1u << in.levels, in.levels, (1u << in.levels) - 1);
    }
    if (voxdag_lookup(f.dag, c[0], c[1], c[2], &index)) {
        uint8_t rgb[3];
        vdag_voxel_color(&f, index, rgb);
        printf("1 %llu %u %u %u\n", (unsigned long long)index, rgb[0], rgb[1], rgb[2]);
    } else {
        printf("0\n");
    }
    vdag_close(&f);
    return 0;
}

static int export_voxel(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    const vdag_file *f = (const vdag_file *)user;
    uint8_t rgb[3];
    vdag_voxel_color(f, index, rgb);
    printf("%u %u %u %u %u %u\n", x, y, z, rgb[0], rgb[1], rgb[2]);
    return 0;
}

static int cmd_export(int argc, char **argv) {
    vdag_file f;
    if (argc != 2) return vdag_fail("usage: vdag export-voxels FILE");
    if (!vdag_open(argv[1], &f)) return 1;
    voxdag_for_each_voxel(f.dag, export_voxel, &f);
    vdag_close(&f);
    return fflush(stdout) ? vdag_fail("export-voxels: write error") : 0;
}

// -- vdag edit: operations from stdin, one a line

/* The operations of a script: name, the integers before an optional
   colour, and whether the colour is required (R G B close the line). */
typedef enum { ED_SET, ED_CLEAR, ED_FILL_BOX, ED_CARVE_BOX, ED_FILL_SPHERE, ED_CARVE_SPHERE, ED_PAINT_BOX,
               ED_PAINT_SPHERE, ED_COPY_BOX, ED_UNDO, ED_REDO } edit_kind;

static const struct {
    const char *name;
    edit_kind kind;
    int numbers;   /* integers before the colour */
    int color;     /* 0 none, 1 optional, 2 required */
} edit_ops[] = {
    {"set", ED_SET, 3, 1},           {"clear", ED_CLEAR, 3, 0},
    {"fill-box", ED_FILL_BOX, 6, 1}, {"carve-box", ED_CARVE_BOX, 6, 0},
    {"fill-sphere", ED_FILL_SPHERE, 4, 1}, {"carve-sphere", ED_CARVE_SPHERE, 4, 0},
    {"paint-box", ED_PAINT_BOX, 6, 2}, {"paint-sphere", ED_PAINT_SPHERE, 4, 2},
    {"copy-box", ED_COPY_BOX, 9, 0}, {"undo", ED_UNDO, 0, 0}, {"redo", ED_REDO, 0, 0},
};

#define EDIT_COORD_MAX ((long long)1 << 28)

/* One parsed line: its operation, numbers and colour. */
typedef struct edit_line {
    int op; /* index into edit_ops */
    long long v[9];
    int has_color;
    uint8_t rgb[3];
} edit_line;

/* Parses LINE (comments cut off); returns 1 (a blank line: op -1), or 0
   with WHY set. */
static int parse_edit_line(char *line, edit_line *e, const char **why) {
    char *tok[16], *p, *hash = strchr(line, '#');
    int n = 0, k, numbers;
    size_t i;
    if (hash) *hash = 0;
    for (p = strtok(line, " \t\r\n"); p; p = strtok(NULL, " \t\r\n")) {
        if (n == 16) return *why = "too many fields", 0;
        tok[n++] = p;
    }
    e->op = -1;
    if (!n) return 1;
    for (i = 0; i < sizeof edit_ops / sizeof edit_ops[0] && strcmp(tok[0], edit_ops[i].name); i++) {}
    if (i == sizeof edit_ops / sizeof edit_ops[0]) return *why = "unknown operation", 0;
    e->op = (int)i;
    numbers = edit_ops[i].numbers;
    e->has_color = n - 1 == numbers + 3;
    if (n - 1 != numbers && !(edit_ops[i].color && e->has_color)) return *why = "wrong number of fields", 0;
    if (edit_ops[i].color == 2 && !e->has_color) return *why = "wrong number of fields (R G B required)", 0;
    for (k = 0; k < n - 1; k++) {
        char *end;
        long long v;
        errno = 0;
        v = strtoll(tok[1 + k], &end, 10);
        if (end == tok[1 + k] || *end || errno) return *why = "not an integer", 0;
        if (k < numbers) {
            if (v < -EDIT_COORD_MAX || v > EDIT_COORD_MAX) return *why = "a number beyond +-2^28", 0;
            e->v[k] = v;
        } else {
            if (v < 0 || v > 255) return *why = "a colour outside 0..255", 0;
            e->rgb[k - numbers] = (uint8_t)v;
        }
    }
    if ((edit_ops[i].kind == ED_FILL_SPHERE || edit_ops[i].kind == ED_CARVE_SPHERE ||
         edit_ops[i].kind == ED_PAINT_SPHERE) && e->v[3] < 0)
        return *why = "a negative radius", 0;
    return 1;
}

/* Applies a parsed line to ED. */
static voxdag_status apply_edit_line(voxdag_editor *ed, uint32_t levels, const edit_line *e, voxdag_error *err) {
    voxdag_shape s;
    voxdag_brush b;
    const voxdag_brush *brush = e->has_color ? &b : NULL;
    int a;
    memset(&s, 0, sizeof s);
    memset(&b, 0, sizeof b);
    memcpy(b.rgb, e->rgb, 3);
    switch (edit_ops[e->op].kind) {
    case ED_SET:
    case ED_CLEAR: {
        uint32_t xyz[3];
        size_t n = 1;
        for (a = 0; a < 3; a++) {
            if (e->v[a] < 0 || e->v[a] >= (1ll << levels)) n = 0; /* outside the grid: clipped away */
            xyz[a] = (uint32_t)(e->v[a] & 0xFFFFFFFF);
        }
        return edit_ops[e->op].kind == ED_SET ? voxdag_editor_set(ed, xyz, brush ? b.rgb : NULL, n, err)
                                              : voxdag_editor_clear(ed, xyz, n, err);
    }
    case ED_FILL_BOX:
    case ED_CARVE_BOX:
    case ED_PAINT_BOX:
        s.kind = VOXDAG_SHAPE_BOX;
        for (a = 0; a < 3; a++) s.lo[a] = e->v[a], s.hi[a] = e->v[3 + a];
        break;
    case ED_FILL_SPHERE:
    case ED_CARVE_SPHERE:
    case ED_PAINT_SPHERE:
        s.kind = VOXDAG_SHAPE_SPHERE;
        for (a = 0; a < 3; a++) s.center[a] = e->v[a];
        s.radius = e->v[3];
        break;
    case ED_COPY_BOX: {
        int64_t lo[3], hi[3], d[3];
        for (a = 0; a < 3; a++) lo[a] = e->v[a], hi[a] = e->v[3 + a], d[a] = e->v[6 + a];
        return voxdag_editor_copy(ed, lo, hi, d, err);
    }
    case ED_UNDO:
        voxdag_editor_undo(ed);
        return VOXDAG_OK;
    case ED_REDO:
        voxdag_editor_redo(ed);
        return VOXDAG_OK;
    }
    switch (edit_ops[e->op].kind) {
    case ED_FILL_BOX:
    case ED_FILL_SPHERE: return voxdag_editor_fill(ed, &s, brush, err);
    case ED_CARVE_BOX:
    case ED_CARVE_SPHERE: return voxdag_editor_carve(ed, &s, err);
    default: return voxdag_editor_paint(ed, &s, &b, err);
    }
}

/* The committed DAG with its colours compressed by voxcolor within E. */
static int compress_colors(voxdag **dag, double e) {
    const void *rgb;
    size_t size, cap, len;
    uint8_t *stream;
    voxcolor_encode_opts o;
    voxcolor_error verr;
    voxdag *with = NULL;
    voxdag_error err;
    if (voxdag_colors(*dag, &rgb, &size) != VOXDAG_COLORS_RGB8) return 0;
    cap = voxcolor_encode_bound(size / 3);
    stream = (uint8_t *)malloc(cap ? cap : 1);
    if (!stream) return vdag_fail("edit: out of memory for the colours");
    memset(&o, 0, sizeof o);
    o.max_error = e;
    len = voxcolor_encode(stream, cap, (const uint8_t *)rgb, size / 3, &o, &verr);
    if (!len) {
        free(stream);
        return vdag_fail("edit: colour compression failed: %s", verr.message);
    }
    if (voxdag_with_colors(*dag, VOXDAG_COLORS_VOXCOLOR, stream, len, &with, &err) != VOXDAG_OK) {
        free(stream);
        return vdag_fail("edit: %s", err.message);
    }
    free(stream);
    voxdag_free(*dag);
    *dag = with;
    return 0;
}

/* Replaces F's voxcolor colours by their decoded RGB8 (this tool's
   voxdag.h decodes voxcolor only through F's view). */
static int decode_colors(vdag_file *f) {
    voxdag_info info;
    voxdag *raw = NULL;
    voxdag_error err;
    uint8_t *rgb;
    uint64_t i;
    voxdag_get_info(f->dag, &info);
    if (info.voxels > (uint64_t)(SIZE_MAX / 3)) return vdag_fail("edit: too many colours for memory");
    rgb = (uint8_t *)malloc(info.voxels ? (size_t)info.voxels * 3 : 1);
    if (!rgb) return vdag_fail("edit: out of memory for %llu colours", (unsigned long long)info.voxels);
    for (i = 0; i < info.voxels; i++) vdag_voxel_color(f, i, rgb + 3 * i);
    if (voxdag_with_colors(f->dag, VOXDAG_COLORS_RGB8, rgb, (size_t)info.voxels * 3, &raw, &err) != VOXDAG_OK) {
        free(rgb);
        return vdag_fail("edit: %s", err.message);
    }
    free(rgb);
    vdag_close(f);
    f->dag = raw;
    f->has_colors = 1;
    return 0;
}

static int cmd_edit(int argc, char **argv) {
    vdag_file f;
    voxdag_editor *ed = NULL;
    voxdag *out = NULL;
    voxdag_error err;
    voxdag_info info;
    voxdag_color_kind kind;
    const void *payload;
    size_t size, cap = 0;
    char *line = NULL, tmp[4200];
    double color_error = -1;
    unsigned long long number = 0, edits = 0;
    int rc = 0, warned = 0;
    if (argc == 5 && !strcmp(argv[3], "--color-error")) {
        char *end;
        color_error = strtod(argv[4], &end);
        if (end == argv[4] || *end || !(color_error >= 0) || color_error > 1e9)
            return vdag_fail("edit: --color-error takes a number >= 0");
    } else if (argc != 3) {
        return vdag_fail("usage: vdag edit IN.vdag OUT.vdag [--color-error E]   (operations on stdin)");
    }
    if (!vdag_check_output(argv[1], argv[2]) || !vdag_open(argv[1], &f)) return 1;
    kind = voxdag_colors(f.dag, &payload, &size);
    if (kind == VOXDAG_COLORS_VOXCOLOR && color_error < 0) {
        vdag_close(&f);
        return vdag_fail("edit: %s has voxcolor colours: give --color-error E, the bound for the output's "
                         "(the stream does not record its own)", argv[1]);
    }
    if (kind != VOXDAG_COLORS_VOXCOLOR && color_error >= 0) {
        vdag_close(&f);
        return vdag_fail("edit: --color-error is for input with voxcolor colours; %s has %s", argv[1],
                         kind == VOXDAG_COLORS_RGB8 ? "raw RGB8 colours, and so will the output" : "no colours");
    }
    voxdag_get_info(f.dag, &info);
    if (kind == VOXDAG_COLORS_VOXCOLOR && decode_colors(&f)) {
        vdag_close(&f);
        return 1;
    }
    if (voxdag_editor_create(f.dag, NULL, &ed, &err) != VOXDAG_OK) {
        vdag_close(&f);
        return vdag_fail("edit: %s (%s)", voxdag_status_string(err.status), err.message);
    }
    vdag_close(&f);
    while (!rc && getline(&line, &cap, stdin) >= 0) {
        edit_line e;
        const char *why = NULL;
        number++;
        if (!parse_edit_line(line, &e, &why)) {
            rc = vdag_fail("edit: line %llu: %s (nothing written)", number, why);
            break;
        }
        if (e.op < 0) continue;
        if (e.has_color && kind == VOXDAG_COLORS_NONE && !warned++)
            fprintf(stderr, "vdag: warning: %s has no colours; the colours in edits are ignored\n", argv[1]);
        if (apply_edit_line(ed, info.levels, &e, &err) != VOXDAG_OK)
            rc = vdag_fail("edit: line %llu: %s (%s; nothing written)", number, voxdag_status_string(err.status),
                           err.message);
        edits++;
    }
    free(line);
    if (!rc && ferror(stdin)) rc = vdag_fail("edit: cannot read the operations from stdin (nothing written)");
    if (!rc && voxdag_editor_commit(ed, &out, &err) != VOXDAG_OK)
        rc = vdag_fail("edit: %s (%s)", voxdag_status_string(err.status), err.message);
    if (!rc && kind == VOXDAG_COLORS_VOXCOLOR) rc = compress_colors(&out, color_error);
    if (!rc) {
        errno = 0;
        if (save_file(out, argv[2], tmp, sizeof tmp, &err) != VOXDAG_OK)
            rc = err.os_error ? vdag_fail("%s: %s (%s)", argv[2], err.message, strerror(err.os_error))
                              : vdag_fail("%s: %s", argv[2], err.message);
    }
    if (!rc)
        fprintf(stderr, "vdag: %llu edits, %llu voxels; wrote %s\n", edits,
                (unsigned long long)voxdag_editor_voxels(ed), argv[2]);
    voxdag_free(out);
    voxdag_editor_free(ed);
    return rc;
}

// -- vdag gen: the built-in demo scene

/* A coloured landscape: rolling terrain with grass and rock, a pond, and a
   striped sphere floating above, all from closed-form functions. */
static int cmd_gen(int argc, char **argv) {
    uint32_t levels = 7, n, x, y, z;
    FILE *out;
    if (argc == 5 && !strcmp(argv[3], "--levels")) {
        if (!parse_u32(argv[4], &levels) || levels < 4 || levels > 10) return vdag_fail("gen: --levels takes 4..10");
    } else if (argc != 3) {
        return vdag_fail("usage: vdag gen demo OUT.xyz [--levels L]");
    }
    if (strcmp(argv[1], "demo")) return vdag_fail("gen: unknown scene '%s' (known: demo)", argv[1]);
    if (!vdag_check_output(NULL, argv[2])) return 1;
    out = fopen(argv[2], "w");
    if (!out) return vdag_fail("%s: %s", argv[2], strerror(errno));
    n = 1u << levels;
    fprintf(out, "# voxdag demo scene, %u^3\n", n);
    for (z = 0; z < n; z++)
        for (y = 0; y < n; y++)
            for (x = 0; x < n; x++) {
                double u = (x + 0.5) / n, v = (y + 0.5) / n, w = (z + 0.5) / n;
                double ground = 0.22 + 0.08 * sin(6.3 * u) * cos(4.1 * v) + 0.05 * sin(17.0 * (u + v));
                double dx = u - 0.5, dy = v - 0.52, dz = w - 0.62, r = sqrt(dx * dx + dy * dy + dz * dz);
                int r8, g8, b8;
                if (w <= ground && w > ground - 3.0 / n) { /* terrain surface */
                    double shade = 0.75 + 0.25 * sin(40.0 * u * v);
                    if (ground < 0.17) { r8 = 40; g8 = 90; b8 = 200; }                  /* pond */
                    else if (ground > 0.31) { r8 = 130; g8 = 120; b8 = 110; }           /* rock */
                    else { r8 = 60; g8 = 150; b8 = 50; }                                 /* grass */
                    r8 = (int)(r8 * shade); g8 = (int)(g8 * shade); b8 = (int)(b8 * shade);
                } else if (r <= 0.18 && r > 0.18 - 2.5 / n) { /* shell of the sphere */
                    int band = (int)floor((dz / 0.18 + 1.0) * 4.0);
                    r8 = band & 1 ? 230 : 250; g8 = band & 1 ? 70 : 200; b8 = band & 1 ? 60 : 40;
                } else {
                    continue;
                }
                fprintf(out, "%u %u %u %d %d %d\n", x, y, z, r8, g8, b8);
            }
    if (fclose(out)) return vdag_fail("%s: write error", argv[2]);
    return 0;
}

// -- main

static int usage(FILE *f) {
    fputs("usage: vdag COMMAND ...   (vdag COMMAND --help: its options and defaults; vdag --version)\n"
          "  build IN OUT.vdag [--levels L] [--up x|y|z] [--symmetry none|reflect|full] [--no-symmetry]\n"
          "                    [--color-error E] [--raw-colors] [--color-bits W|auto]\n"
          "                    [--color-effort smallest|fast] [--verify-colors] [--no-colors]\n"
          "                    [--no-lod-colors] [--no-alpha-test] [--chunk-levels C]\n"
          "                    [--threads T] [--max-memory MIB] [--max-texture-pixels N]\n"
          "                    [--max-vox-voxels N] [--vox-model N] [--allow-empty] [--force] [--stats]\n"
          "                    [--timings] [--quiet]\n"
          "  info FILE [--json]\n"
          "  validate FILE\n"
          "  lookup FILE x y z         (grid units)\n"
          "  rays FILE                 (rays 'ox oy oz dx dy dz' on stdin, grid units)\n"
          "  render FILE OUT.png [--size WxH] [--eye x y z] [--target x y z] [--fov deg]\n"
          "                      [--shadows] [--light x y z] [--lod PIXELS] [--samples N]\n"
          "                      [--threads T] [--quiet]\n"
          "  export-voxels FILE\n"
          "  edit IN.vdag OUT.vdag [--color-error E]   (operations on stdin, one a line)\n"
          "  gen demo OUT.xyz [--levels L]\n",
          f);
    return f == stdout ? 0 : 1;
}

int main(int argc, char **argv) {
    static const struct {
        const char *name;
        int (*fn)(int, char **);
    } commands[] = {{"build", cmd_build},   {"info", cmd_info},         {"validate", cmd_validate},
                    {"lookup", cmd_lookup}, {"rays", vdag_cmd_rays},    {"render", vdag_cmd_render},
                    {"export-voxels", cmd_export}, {"edit", cmd_edit}, {"gen", cmd_gen}};
    size_t i;
    if (argc < 2) return usage(stderr);
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) return usage(stdout);
    if (!strcmp(argv[1], "--version")) {
        printf("vdag %d.%d.%d (voxdag.h %u, .vdag format %d)\n", VOXDAG_VERSION_MAJOR, VOXDAG_VERSION_MINOR,
               VOXDAG_VERSION_PATCH, (unsigned)voxdag_version(), VOXDAG_FORMAT_VERSION);
        return 0;
    }
    for (i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (!strcmp(argv[1], commands[i].name)) {
            if (vdag_help(commands[i].name, argc - 1, argv + 1)) return 0;
            return commands[i].fn(argc - 1, argv + 1);
        }
    vdag_fail("unknown command '%s' (see vdag --help)", argv[1]);
    return 1;
}
