/* Scene importers for the vdag tool: .xyz, .ply, .obj(+.mtl), .off, .vox.
   Every parser reads untrusted bytes: it returns 0 with a message on any
   malformed input, never crashes, and frees what it allocated. */
#ifndef VDAG_IMPORT_H
#define VDAG_IMPORT_H

#include <stddef.h>
#include <stdint.h>

#include "image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Most voxels a .vox scene may expand to (its scene graph can instance one
   model many times); a larger scene is an error, not an allocation. */
#ifndef VDAG_IMPORT_MAX_POINTS
#define VDAG_IMPORT_MAX_POINTS ((uint64_t)1 << 28)
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

    /* Triangles (polygons are fan-triangulated). */
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

/* Reads PATH, choosing the parser by extension (.xyz .ply .obj .off .vox).
   Returns 1 on success; 0 with a one-line reason in err otherwise. */
int vdag_import_file(const char *path, vdag_scene *out, char *err, size_t err_size);

/* Parses bytes already in memory; EXT names the format ("xyz", "ply", ...).
   BASE_DIR (may be NULL) resolves .mtl and texture files for .obj. */
int vdag_import_memory(const char *ext, const void *data, size_t size,
                       const char *base_dir, vdag_scene *out, char *err,
                       size_t err_size);

void vdag_scene_free(vdag_scene *scene);

#ifdef __cplusplus
}
#endif

#endif
