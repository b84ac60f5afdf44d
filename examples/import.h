/* Scene importers for the vdag tool: .xyz, .ply, .obj(+.mtl), .off, .stl,
   .vox, and game scenes .spm and .ac (rules in import_scene.c).
   Every parser reads untrusted bytes: it returns 0 with a message on any
   malformed input, never crashes, and frees what it allocated. Counts read
   from a file are checked against the bytes left before anything is sized
   by them; coordinates must be finite with a magnitude of at most 1e30.
   Text formats (all but .vox, .spm and binary .stl) may start with a UTF-8
   byte order mark; UTF-16 text is refused with a message that says so.
   What an importer tolerates or skips gets a warning on stderr (unless
   vdag_import_limits.quiet). Coordinates stay in the file's own axes,
   except where a format's rules below say otherwise.

   Polygons (.ply, .off, .obj, .ac) are triangulated in the plane of the
   axis their Newell normal leans on most: a convex polygon as a fan from
   its first corner, a concave one by ear clipping (n - 2 triangles either
   way, corners in the polygon's order). A polygon that is degenerate (no
   normal) or self-intersecting in that plane, or past a work limit of
   about 2^28 point tests per file, is fan-triangulated, and the file gets
   one warning with the number of such polygons.

   Formats, and the rules where they leave a choice:
   - .xyz: "x y z" or "x y z r g b" per line; '#' starts a comment. The
     first data line decides the number of values: every line must agree.
     When every coordinate is written as an integer the file is a voxel
     list (integers 0..2^32-1, colours integers 0..255); otherwise (a
     decimal point or an exponent anywhere) it is a point cloud, and the
     4th-6th values are colours when all of them are integers 0..255, else
     they are ignored (normals, as point-set tools write).
   - .ply: ASCII, binary little- and big-endian; any scalar types. Header
     lines with an unknown keyword are skipped with a warning. Vertex
     x y z, optional red green blue (integers 0..255, ushort 0..65535, or
     floats 0..1) and s t / u v texture coordinates; face vertex_indices
     (or vertex_index) lists, triangulated. Other elements and
     properties, lists included, are skipped. No faces: a point cloud.
   - .off: [ST][C][N]OFF headers; the counts may follow on the header line.
     COFF colours are 0..1 floats when written with a '.' or an exponent,
     else 0..255 integers (decided per vertex line). Text after a face's
     corners (a face colour) is ignored. No faces: a point cloud.
   - .obj: v (with "v x y z r g b" colours, 0..1), vt, f in every corner
     form with negative (relative) indices; polygons triangulated, lines
     and points ignored. One material per name given to usemtl, numbered by
     first use, white until a library (mtllib, read from BASE_DIR) gives its
     Kd and map_Kd; Kd values 0..1 map straight to 0..255. A map_Kd texture
     that cannot be decoded leaves image = -1 (the Kd colour) and a warning
     on stderr. Faces with texture coordinates give one vertex per distinct
     (v, vt) pair; corners without vt get uv (0, 0). No faces: a point cloud.
   - .stl: binary (80-byte header, u32 count, 50 bytes per triangle) or
     ASCII ("solid", facets of "vertex x y z" lines, "endsolid"; keywords in
     any case, several solids in a row, normals ignored). A file whose size
     is exactly that of its binary count is binary even when its header
     starts with "solid", as some exporters write; bytes after the last
     binary triangle are ignored with a warning. No colours are read.
   - .mtl on its own: every material, in file order.
   - .vox (MagicaVoxel 150 and 200): colour index i is RGBA entry i - 1
     (index 0 is empty); without an RGBA chunk, MagicaVoxel's default
     palette, which also fills the entries a short RGBA chunk lacks (some
     tools write 1020 bytes: entry 255 is never used). With a scene graph (nTRN, nGRP, nSHP from node 0, first
     animation frame), each model's centre sits at its transform's origin:
     voxel v fills the cell holding R (v + 1/2 - size/2) + t, rounded down
     where that lands on a cell corner. Without one, a file of one model
     gives that model in its own coordinates; a file of several (animation
     frames) gives one, vdag_import_limits.vox_model (the first by default),
     with a warning that names the count. Axes stay MagicaVoxel's (z up, as in the vdag tool), and
     the result is shifted so each axis starts at 0. A model
     shown by several shapes appears once per shape; hidden nodes and nodes
     on hidden layers are left out, as in MagicaVoxel's exports. */
#ifndef VDAG_IMPORT_H
#define VDAG_IMPORT_H

#include <stddef.h>
#include <stdint.h>

#include "image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Limits on an import, applied to totals (the whole input, all points, all
   vertices, all triangles; never per axis or per element): a larger input or
   scene is an error with a message, not an allocation. A NULL pointer or a
   zero field means the default below. While parsing, memory stays within a
   small multiple of the input bytes (every count read from a file is checked
   against the bytes that remain first), except for .vox scene graphs, which
   can instance one model many times: the voxels they place are counted
   before any is placed, and refused past max_vox_voxels (every voxel a
   shape's model lists, empty ones included, once per shape showing it) or
   past max_points (the voxels kept). Textures: their pixels in all (each
   file counted once, however it is named) are refused past
   max_texture_pixels, before decoding the image that would exceed it.
   Side files (material libraries, textures) are read only when they are
   regular files of at most VDAG_IMPORT_MAX_SIDE_FILE_BYTES (and at most
   max_input_bytes): a device, FIFO or directory is refused with a message
   naming it, without reading or waiting on it. */
typedef struct vdag_import_limits {
    uint64_t max_input_bytes; /* 0: VDAG_IMPORT_MAX_INPUT_BYTES */
    uint64_t max_points;      /* 0: VDAG_IMPORT_MAX_POINTS */
    uint64_t max_vertices;    /* 0: VDAG_IMPORT_MAX_VERTICES */
    uint64_t max_triangles;   /* 0: VDAG_IMPORT_MAX_TRIANGLES */
    uint64_t max_texture_pixels; /* 0: VDAG_IMPORT_MAX_TEXTURE_PIXELS (all textures) */
    uint64_t max_vox_voxels;  /* 0: VDAG_IMPORT_MAX_VOX_VOXELS (a .vox scene graph) */
    uint32_t vox_model;       /* a .vox with several models and no scene graph
                                 (animation frames): the model imported, from 0
                                 (0: the first, with a warning naming the count);
                                 past the last, or nonzero with a scene graph,
                                 an error */
    int skip_textures;        /* 1: do not decode texture images (materials keep
                                 their colours; for callers that need no colours) */
    int quiet;                /* 1: no warnings on stderr (what an import
                                 tolerates, skips or cannot decode) */
    int (*on_file)(void *user, const char *path); /* NULL, or called with the
                                 path of each file before it is read (the
                                 input, .mtl libraries, textures): returning 0
                                 stops the import with an error */
    void *on_file_user;
    /* Optional: textures decoded on the caller's threads. RUN calls
       JOB(JOB_USER, i) once for every i in [0, COUNT), on any threads, and
       returns when all have returned. With RUN and THREADS > 1, .spm, .obj
       and .mtl imports decode textures THREADS at a time (the files are
       still opened, and on_file called, as they are met; the scene,
       warnings and errors are the same, warnings coming when each batch is
       done); NULL, or THREADS 0 or 1: one by one as they are met. */
    void (*run)(void *user, void (*job)(void *job_user, uint32_t index), void *job_user, uint32_t count);
    void *run_user;
    uint32_t threads;
} vdag_import_limits;

#ifndef VDAG_IMPORT_MAX_INPUT_BYTES
#define VDAG_IMPORT_MAX_INPUT_BYTES ((uint64_t)1 << 32) /* 4 GiB */
#endif
#ifndef VDAG_IMPORT_MAX_POINTS
#define VDAG_IMPORT_MAX_POINTS ((uint64_t)1 << 28)
#endif
#ifndef VDAG_IMPORT_MAX_VERTICES
#define VDAG_IMPORT_MAX_VERTICES ((uint64_t)1 << 28)
#endif
#ifndef VDAG_IMPORT_MAX_TRIANGLES
#define VDAG_IMPORT_MAX_TRIANGLES ((uint64_t)1 << 28)
#endif
#ifndef VDAG_IMPORT_MAX_TEXTURE_PIXELS
#define VDAG_IMPORT_MAX_TEXTURE_PIXELS ((uint64_t)1 << 28)
#endif
#ifndef VDAG_IMPORT_MAX_VOX_VOXELS
#define VDAG_IMPORT_MAX_VOX_VOXELS ((uint64_t)1 << 31)
#endif
/* The largest side file (a material library or a texture) read, in bytes. */
#ifndef VDAG_IMPORT_MAX_SIDE_FILE_BYTES
#define VDAG_IMPORT_MAX_SIDE_FILE_BYTES ((uint64_t)256 << 20) /* 256 MiB */
#endif

typedef struct vdag_material {
    uint8_t rgb[3]; /* diffuse colour (Kd), 8-bit sRGB */
    int32_t image;  /* index into scene images (map_Kd), or -1 */
} vdag_material;

typedef struct vdag_scene {
    /* Points: voxels (integer grid coordinates, .xyz/.vox) or a point cloud. */
    size_t point_count;
    double *points;      /* 3 per point */
    uint8_t *point_rgb;  /* 3 per point, or NULL when the file has no colours */
    int points_are_voxels; /* 1: integer grid coordinates, used as they are */

    /* Triangles (polygons are triangulated: see the top of this file). */
    size_t vertex_count;
    double *positions;   /* 3 per vertex */
    uint8_t *vertex_rgb; /* 3 per vertex, or NULL */
    float *uv;           /* 2 per vertex, or NULL */
    size_t triangle_count;
    uint32_t *indices;   /* 3 per triangle, each < vertex_count */
    int32_t *triangle_material; /* per triangle, index into materials or -1; or NULL */
    size_t material_count;
    vdag_material *materials;
    size_t image_count;
    vdag_image *images;
} vdag_scene;

/* Reads PATH, choosing the parser by extension (.xyz .ply .obj .off .stl
   .vox .mtl .spm .ac); a directory is refused as such. LIMITS may be NULL (the defaults).
   Returns 1 on success; 0 with a one-line reason in err otherwise. */
int vdag_import_file(const char *path, const vdag_import_limits *limits, vdag_scene *out,
                     char *err, size_t err_size);

/* Parses bytes already in memory; EXT names the format ("xyz", "ply", ...).
   BASE_DIR (may be NULL) resolves .mtl and texture files for .obj. */
int vdag_import_memory(const char *ext, const void *data, size_t size,
                       const char *base_dir, const vdag_import_limits *limits,
                       vdag_scene *out, char *err, size_t err_size);

void vdag_scene_free(vdag_scene *scene);

#ifdef __cplusplus
}
#endif

#endif
