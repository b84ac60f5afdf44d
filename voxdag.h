/* voxdag.h - symmetry-aware sparse voxel DAGs in one header.      version 0.1.0

   Builds a voxel scene into a sparse voxel DAG whose subtrees are shared when
   they are equal up to one of the 48 symmetries of the cube (reflections and
   axis permutations: the SSVDAG's mirrors, extended), with a voxel count per
   node so that every voxel's index into a colour array is found on the way
   down. The result is a compact byte image (the .vdag file format, see
   FORMAT.md) that is queried in place, and ray cast.

   QUICK START
       #define VOXDAG_IMPLEMENTATION   // in exactly one C or C++ file
       #include "voxdag.h"

       voxdag_build_opts opts;
       memset(&opts, 0, sizeof opts);            // defaults (C and C++)
       opts.levels = 8;                          // a 256^3 grid
       voxdag_builder *b; voxdag *dag; uint64_t index; uint8_t out_rgb[3];
       voxdag_builder_create(&opts, &b, NULL);
       uint32_t xyz[] = { 1,2,3,  4,5,6 };
       uint8_t  rgb[] = { 255,0,0,  0,255,0 };
       voxdag_builder_add(b, xyz, rgb, 2, NULL);
       voxdag_builder_finish(b, &dag, NULL, NULL); // b is freed
       if (voxdag_lookup(dag, 4, 5, 6, &index)) { ... voxdag_color(dag, index, out_rgb) ... }
       voxdag_save_file(dag, "scene.vdag", NULL);
       voxdag_free(dag);

   CONVENTIONS
   - Grid of N = 2^L voxels per axis, coordinates 0..N-1; the root is level 0,
     4^3 bricks (64-bit masks) are level L-2.
   - Octant number of a child: bit 0 = upper x half, bit 1 = y, bit 2 = z.
   - Morton code: the octant numbers along the root-to-voxel path, root first.
   - Voxel index = rank of a full voxel's Morton code among all full voxels;
     colours are stored in this order.
   - Transform t in 0..47 (FORMAT.md, Transforms): perm * 8 + m, an axis
     permutation, then mirrors m (bit a set mirrors axis a about the node's
     centre); 0..7 are the reflections, 0 the identity.

   CONFIGURATION (define before including the implementation)
     VOXDAG_MALLOC(sz) / VOXDAG_FREE(p)  default allocator (define both or none)
     VOXDAG_ASSERT(x)     caller-contract checks (default: assert)
     VOXDAG_NO_STDIO      leave out the file helpers
     VOXDAG_NO_THREADS    single-threaded build (no threads, no thread pool)
     VOXDAG_NO_RAYTRACE   leave out ray casting
     VOXDAG_NO_BUILD      leave out the builder, the voxelizer and the encoder
                          (load-and-query programs: loading, queries, colours,
                          ray casting and voxdag_with_colors remain)
     VOXDAG_WITH_VOXCOLOR include "voxcolor.h" (beside voxdag.h) so that
                          voxdag_color decodes voxcolor colour sections; the
                          same happens when voxcolor.h is included before
                          the implementation. Without it, such a file loads
                          but voxdag_info.colors_decodable is 0 and each
                          voxdag_color call returns -1 (see there)
     VOXDAG_STATIC        give every function internal linkage
     VOXDAG_MAX_LEVELS    largest L accepted (default and maximum 21)

   THREADS: no global state. A voxdag is immutable: any number of threads may
   query one at a time. A builder belongs to one thread at a time; with
   opts.threads > 1 it spreads its work over a pool of its own (pthreads, or
   Win32 threads on Windows; workers started once and reused) or over the
   host's (opts.thread_pool: run a batch of jobs, wait), with the same bytes;
   so does voxdag_with_colors_opts, with a pool that lives for the call.

   ERRORS, reported in three shapes, by what a function does:
   - Work that can fail on its own (memory, files, limits, bad data: build,
     load, save, voxdag_with_colors) returns a voxdag_status, VOXDAG_OK or
     the reason, with a message and a byte offset in an optional
     voxdag_error.
   - Ray queries, where a wrong call must not look like "no hit", return an
     int: 1 yes, 0 no, -1 for a NULL argument or invalid options
     (voxdag_raycast, voxdag_occluded, voxdag_occluded_opts,
     voxdag_ray_from_hit): test `> 0`. voxdag_color: 1 when it wrote a
     colour, 0 when there is none (no colours, an index past the last
     voxel, a NULL argument), -1 when the colours cannot be decoded;
     voxdag_cell_color (a hit's level-of-detail cell) the same way.
   - Lookups and counts (voxdag_lookup, voxdag_lookup_many,
     voxdag_cell_count, voxdag_cell_count_many, voxdag_for_each_voxel) treat a NULL DAG as an empty scene: 0. They
     keep that shape because -1 would read as "full" in the
     `if (voxdag_lookup(...))` that existing code writes.

   EDITING: voxdag_editor (see there) changes a scene in place (voxel lists,
   boxes, spheres, paint, copies, undo and redo) and commits it as the same
   bytes a build of the final voxels gives.

   FILE FORMAT: FORMAT.md documents every byte; VOXDAG_FILE_* mirror it.
*/
#ifndef VOXDAG_H
#define VOXDAG_H

#include <stddef.h>
#include <stdint.h>

#define VOXDAG_VERSION_MAJOR 0
#define VOXDAG_VERSION_MINOR 1
#define VOXDAG_VERSION_PATCH 0
#define VOXDAG_VERSION \
    (VOXDAG_VERSION_MAJOR * 10000 + VOXDAG_VERSION_MINOR * 100 + VOXDAG_VERSION_PATCH)
#define VOXDAG_FORMAT_VERSION 3

#ifndef VOXDAG_MAX_LEVELS
#define VOXDAG_MAX_LEVELS 21
#endif
#if VOXDAG_MAX_LEVELS < 2 || VOXDAG_MAX_LEVELS > 21
#error "VOXDAG_MAX_LEVELS must be between 2 and 21"
#endif

#ifndef VOXDAG_API
#if defined(VOXDAG_STATIC) && (defined(__GNUC__) || defined(__clang__))
#define VOXDAG_API static __attribute__((unused)) /* a unit may use only some */
#elif defined(VOXDAG_STATIC)
#define VOXDAG_API static
#else
#define VOXDAG_API extern
#endif
#endif

#ifdef __cplusplus
extern "C" {
#endif

// -- Status and errors

typedef enum voxdag_status {
    VOXDAG_OK = 0,
    VOXDAG_ERR_INVALID_ARGUMENT, /* a caller argument is out of its range */
    VOXDAG_ERR_OUT_OF_MEMORY,    /* the allocator returned NULL */
    VOXDAG_ERR_LIMIT,            /* a configured or built-in limit was exceeded */
    VOXDAG_ERR_COORDINATE,       /* a voxel coordinate is outside the grid */
    VOXDAG_ERR_ORDER,            /* a voxel precedes voxels already flushed */
    VOXDAG_ERR_TRUNCATED,        /* the data ends before a field it declares */
    VOXDAG_ERR_BAD_MAGIC,        /* not a .vdag file */
    VOXDAG_ERR_VERSION,          /* a format version this reader does not know */
    VOXDAG_ERR_CHECKSUM,         /* a checksum does not match */
    VOXDAG_ERR_CORRUPT,          /* a field is inconsistent or out of range */
    VOXDAG_ERR_IO,               /* a file could not be read or written */
    VOXDAG_ERR_CANCELLED,        /* the build's progress_cancel callback stopped it */
    VOXDAG_ERR_NOT_CLOSED,       /* a solid mesh has open edges (voxdag_mesh.solid) */
    VOXDAG_STATUS_COUNT,
    VOXDAG_STATUS_FORCE_32BIT = 0x7fffffff
} voxdag_status;

/* What went wrong. NODE is the item at fault, UINT64_MAX when there is none;
   which item depends on the call and the status:
     voxdag_builder_add, VOXDAG_ERR_COORDINATE / VOXDAG_ERR_ORDER:
         the voxel's position in that call's arrays (0-based);
     voxdag_builder_add_bricks, VOXDAG_ERR_COORDINATE / VOXDAG_ERR_ORDER:
         the brick's position in that call's arrays;
     voxdag_builder_add_mesh, VOXDAG_ERR_INVALID_ARGUMENT:
         the triangle (an index >= vertex_count or a non-finite vertex);
     voxdag_builder_add_mesh, VOXDAG_ERR_NOT_CLOSED (mesh->solid): the lowest
         triangle with an open edge;
     loading, VOXDAG_ERR_CORRUPT: the level (0 = root) of a bad level-table
         entry, or the ordinal of a bad node record within its level (bricks:
         the brick's index); BYTE_OFFSET then points at the entry or record.
   Every other failure leaves it UINT64_MAX. */
typedef struct voxdag_error {
    voxdag_status status;
    const char *message;  /* static storage; never freed */
    uint64_t byte_offset; /* offset in the input, UINT64_MAX when not input-related */
    uint64_t node;        /* the item at fault (see above), UINT64_MAX when none */
    int os_error;         /* errno of the failed file operation (VOXDAG_ERR_IO), else 0 */
} voxdag_error;

/* Returns a static, human-readable name of a status. */
VOXDAG_API const char *voxdag_status_string(voxdag_status status);

/* Returns VOXDAG_VERSION of the implementation that was compiled. */
VOXDAG_API uint32_t voxdag_version(void);

// -- Allocation

/* Per-call allocator. alloc/free both NULL: VOXDAG_MALLOC/VOXDAG_FREE.
   free receives the size that was requested for the block. */
typedef struct voxdag_allocator {
    void *(*alloc)(void *user, size_t size);
    void (*free)(void *user, void *ptr, size_t size);
    void *user;
} voxdag_allocator;

// -- Building

/* The symmetries under which a build stores equal subtrees once (SSVDAG
   paper section 3, extended to the whole cube group). */
typedef enum voxdag_symmetry {
    VOXDAG_SYMMETRY_DEFAULT = 0, /* FULL */
    VOXDAG_SYMMETRY_NONE = 1,    /* identical subtrees only (SVDAG) */
    VOXDAG_SYMMETRY_REFLECT = 2, /* equal up to the 8 reflections (SSVDAG) */
    VOXDAG_SYMMETRY_FULL = 3,    /* equal up to the 48 symmetries of the cube:
                                    reflections and axis permutations */
    VOXDAG_SYMMETRY_COUNT,
    VOXDAG_SYMMETRY_FORCE_32BIT = 0x7fffffff
} voxdag_symmetry;

/* Capacity of the per-level arrays of public structs: fixed, so that units
   compiled with different VOXDAG_MAX_LEVELS agree on every layout. */
#define VOXDAG_LEVEL_CAPACITY 21

/* Progress of a build, from the building thread (voxdag_build_opts.progress
   and progress_cancel, both given progress_user). STAGE and FRACTION (0..1,
   never decreasing within a stage of one call):
     "voxelize"  voxdag_builder_add_mesh: the share of its (chunk, triangle)
                 pairs done, after each round of chunks;
     "reduce"    voxels added by voxdag_builder_add, reduced by the next
                 voxdag_builder_flush or by voxdag_builder_finish: the share of
                 those voxels reduced, every 2^16 (on one thread; the threaded
                 reduction reports when it is done); voxdag_builder_add_bricks:
                 the share of the call's bricks, every 2^14; and once at 1
                 when voxdag_builder_finish has reduced everything;
     "encode"    voxdag_builder_finish: 0 before the file image is encoded, 1
                 after. */
typedef void (*voxdag_progress_fn)(void *user, const char *stage, double fraction);
/* The same reports, for a host that may stop the build: return 0 to go on,
   nonzero to cancel. The call that reported then fails with
   VOXDAG_ERR_CANCELLED and the builder keeps that failure (later calls
   return it; voxdag_builder_finish frees the builder as on any failure, and
   any DAG it had made: *out stays NULL). Nothing leaks. */
typedef int (*voxdag_progress_cancel_fn)(void *user, const char *stage, double fraction);

/* A job of the builder's parallel work: run once for each INDEX of a batch. */
typedef void (*voxdag_job_fn)(void *job_user, uint32_t index);

/* The host's thread pool (optional; voxdag_build_opts.thread_pool). RUN
   starts a batch: JOB(JOB_USER, i) must be called once for every i in
   [0, COUNT), on any threads (the calling one too), in any order, before RUN
   returns or before WAIT returns. WAIT returns when every job of the batch
   has returned. The builder calls both from the thread that called it, one
   batch at a time, never from inside a job, and may do its own work between
   RUN and WAIT. Files are the same bytes whatever the pool does.
   voxcolor.h, which does not depend on this header, takes its own
   voxcolor_thread_pool: one RUN that returns when the batch is done. The
   same host pool serves both: give voxcolor a RUN that calls this RUN and
   then WAIT. */
typedef struct voxdag_thread_pool {
    void (*run)(void *user, voxdag_job_fn job, void *job_user, uint32_t count);
    void (*wait)(void *user);
    void *user;
} voxdag_thread_pool;

/* Build options. A NULL pointer or an all-zero struct means defaults. Every
   field is checked, in every build (NDEBUG too): out-of-range values make
   voxdag_builder_create fail with VOXDAG_ERR_INVALID_ARGUMENT (levels:
   VOXDAG_ERR_LIMIT). Initialise with memset or = {0}: a nonzero zero_begin
   or zero_end (a struct left uninitialised) is rejected. */
typedef struct voxdag_build_opts {
    uint32_t zero_begin;         /* must be 0 */
    uint32_t levels;             /* L, 2..VOXDAG_MAX_LEVELS; 0 means 10 */
    voxdag_symmetry symmetry;    /* 0: VOXDAG_SYMMETRY_FULL */
    int colors;                  /* 1: every voxel carries an RGB8 colour */
    int compare_structures;      /* 1: also count the nodes under the other two
                                    symmetry groups (3x work) */
    uint32_t threads;            /* T > 1: work split in T jobs per batch, run on the
                                    built-in pool (T - 1 workers, pthreads or Win32
                                    threads, started once per builder) or on
                                    thread_pool; 0 or 1: the calling thread only.
                                    At most 64 are used. The file is the same
                                    bytes whatever T. Voxel input (builder_add):
                                    the threads check and encode an add call of
                                    2^18 voxels or more, sort a flush of 2^16 or
                                    more voxels that are not in Morton order, and
                                    reduce a flush spanning enough subtrees;
                                    dropping repeats and colours run on the
                                    calling thread. The final encoding (its
                                    records, bricks, box and counts) and the
                                    level-of-detail colours of the file (and
                                    of voxdag_with_colors_opts) use the
                                    threads too. */
    uint64_t max_memory;         /* bytes the builder may hold (buffered voxels,
                                    nodes, the file image); 0: no limit; more
                                    is VOXDAG_ERR_LIMIT */
    uint64_t max_nodes;          /* unique nodes and bricks of the result, all
                                    levels together; 0: no limit */
    uint32_t chunk_levels;       /* meshes are voxelized in chunks of 2^chunk_levels
                                    voxels per axis; 0 means 8, else 2..8 */
    const double *bounds;        /* optional world-space min xyz, max xyz (6) */
    voxdag_allocator allocator;
    voxdag_progress_fn progress; /* optional; called from the building thread */
    void *progress_user;         /* given to progress and progress_cancel; it must
                                    stay valid until the builder is finished or freed */
    voxdag_progress_cancel_fn progress_cancel; /* optional, beside or instead of
                                    progress: the same reports, and it can cancel */
    /* Optional, with colors: receives the colours (RGB8) in voxel-index order,
       N at a time, as voxels are reduced (from the building thread); returns
       0 to go on, non-zero to fail the build with VOXDAG_ERR_IO. The DAG then
       has no colour section (voxdag_with_colors adds one), so the builder's
       memory does not grow with the colours. A sink without colors is
       rejected. */
    int (*color_sink)(void *user, const uint8_t *rgb, size_t n);
    void *color_sink_user;
    voxdag_thread_pool thread_pool; /* run and wait NULL: the built-in pool; both
                                    or neither. Ignored under VOXDAG_NO_THREADS,
                                    which builds on the calling thread only */
    int no_lod_colors;           /* 1: write no level-of-detail colour section
                                    (see voxdag_cell_color); 0: a file with
                                    colours gets one */
    uint32_t zero_end;           /* must be 0 */
} voxdag_build_opts;

typedef struct voxdag_builder voxdag_builder;
typedef struct voxdag voxdag;

#ifndef VOXDAG_NO_BUILD
/* Creates a builder. Returns VOXDAG_OK and *out, or an error (nothing allocated). */
VOXDAG_API voxdag_status voxdag_builder_create(const voxdag_build_opts *opts,
                                               voxdag_builder **out,
                                               voxdag_error *err);

/* Adds N voxels: XYZ holds 3 coordinates per voxel, RGB 3 bytes per voxel
   (required when opts.colors is set, ignored otherwise). Any order; a voxel
   added twice keeps the colour added last. Voxels are buffered until the next
   flush. Returns VOXDAG_ERR_COORDINATE for a coordinate >= 2^L, or
   VOXDAG_ERR_ORDER for a voxel before one already flushed; on error nothing of
   this call is added. */
VOXDAG_API voxdag_status voxdag_builder_add(voxdag_builder *b, const uint32_t *xyz,
                                            const uint8_t *rgb, size_t n,
                                            voxdag_error *err);

/* Reduces every buffered voxel into the DAG and empties the buffer. The caller
   promises that voxels added afterwards come later in Morton order (or repeat
   the last one): this streams scenes larger than memory in Morton-ordered
   chunks (e.g. aligned subtrees), keeping only unique nodes. */
VOXDAG_API voxdag_status voxdag_builder_flush(voxdag_builder *b, voxdag_error *err);

/* Adds N whole 4^3 bricks: the fast path of voxelizers (voxdag_builder_add_mesh
   feeds its chunks through it; a GPU voxelizer can do the same). BRICKS holds
   2 values per brick: its key, the Morton code of (x/4, y/4, z/4) for its
   lowest voxel (x, y, z), i.e. its voxels' Morton codes without their low 6
   bits; then its mask, where bit voxdag_morton_encode(x%4, y%4, z%4) is set for
   each full voxel. Keys must increase strictly, within the call and after
   every voxel and brick reduced before (bricks are reduced at once, in
   order, like a flush); masks of 0 are skipped. With opts.colors, RGB holds
   3 bytes per full voxel, brick by brick, each brick's voxels in mask bit
   order (else RGB is ignored). The voxel buffer must be empty (call
   voxdag_builder_flush first). The result is the same file as adding the
   same voxels with voxdag_builder_add. Returns VOXDAG_ERR_COORDINATE for a
   key outside the grid (>= 2^(3(L-2))), VOXDAG_ERR_ORDER for a key that does
   not increase (err->node: the brick's position); on those errors nothing of
   this call is added. */
VOXDAG_API voxdag_status voxdag_builder_add_bricks(voxdag_builder *b, const uint64_t *bricks,
                                                   const uint8_t *rgb, size_t n, voxdag_error *err);
#endif /* VOXDAG_NO_BUILD */

/* A triangle mesh to voxelize. Vertices are in grid units: the
   grid spans [0, 2^L)^3 and voxel (x, y, z) is the closed box
   [x, x+1] x [y, y+1] x [z, z+1]. */
typedef struct voxdag_mesh {
    const double *positions;   /* 3 per vertex */
    size_t vertex_count;
    const uint32_t *indices;   /* 3 per triangle */
    size_t triangle_count;
    /* Colour of the point with barycentric coordinates BARY on TRIANGLE
       (required when the builder has colours, else ignored). */
    void (*color)(void *user, size_t triangle, const double bary[3], uint8_t rgb[3]);
    void *user;
    /* Optional: returns 0 when the point with barycentric coordinates BARY on
       TRIANGLE is cut away (an alpha-tested texel, say); NULL keeps every
       point. Called once per voxel a triangle touches. */
    int (*keep)(void *user, size_t triangle, const double bary[3]);
    /* Nonzero: voxelize the inside too (a closed mesh; see
       voxdag_builder_add_mesh, SOLID). 0: the surface only. */
    int solid;
} voxdag_mesh;

/* Voxelizes MESH conservatively: a voxel is full when a triangle intersects
   its closed box (exact separating-axis test) and, with a keep callback,
   keeps the voxel's point (below) on that triangle. Parts outside the grid are
   clipped. Works chunk by chunk (aligned subtrees of 2^chunk_levels voxels
   per axis, chunk_levels clamped to 2..8, in Morton order; with threads,
   one chunk per thread at a time) and reduces each chunk at once, so memory
   holds the unique nodes plus a chunk bitmap per thread.
   A voxel's point on a triangle is the voxel centre's projection on the
   triangle's plane, given by its barycentric coordinates; when it falls
   outside the triangle, negative coordinates become 0 and the others are
   scaled to sum 1. A voxel's colour comes from the triangle with the highest
   index that touches (and keeps) it, at the voxel's point on it. The
   colour callback runs once per voxel, keep once per voxel and triangle
   touching it, both from several threads at once when opts.threads > 1.
   Call it on a builder that holds no voxels yet; more meshes need one
   combined call. Returns VOXDAG_ERR_INVALID_ARGUMENT for an
   index >= vertex_count or a non-finite vertex.

   SOLID (mesh->solid nonzero): a voxel is also full when its centre lies inside
   the mesh, by the nonzero winding rule: the winding number of the centre is
   the sum, over the triangles that the ray from the centre towards +z
   crosses, of +1 where the triangle turns counter-clockwise seen from +z and
   -1 where it turns clockwise (crossings at the centre itself not counted).
   So overlapping closed parts are filled once, a shell with an inward-facing
   inner surface stays hollow, and an inside-out mesh fills like its outward
   twin. The test is exact on the vertices' x and y rounded to multiples of
   2^-20 voxel (clamped to +-2^40): integer arithmetic decides which
   triangles a column crosses, and a column through an edge or a vertex
   passes beside it as if moved by (e, e^2), e infinitely small, so a column
   through an edge of two triangles crosses exactly one of them. The
   rounding moves the surface by less than 2^-20 voxel, which changes only
   centres that close to it, in voxels the surface touches (full anyway).
   The mesh must be closed: vertices at the same position are one vertex,
   and every edge must be used as often from a to b as from b to a (see
   voxdag_mesh_open_edges); otherwise the call fails with
   VOXDAG_ERR_NOT_CLOSED (err->node: the lowest triangle with an open edge),
   adds nothing and leaves the builder usable. Triangles above or below the
   grid count. keep applies to surface voxels only: a voxel whose centre is
   inside is full. An inside voxel that no triangle touches takes its
   colour from the nearest crossing above its centre (of equal heights, the
   highest triangle) at the crossing's point. Memory, besides the surface
   path's: the closedness check, 72 bytes per triangle and up to 20 per
   vertex, freed before voxelizing; the triangles binned by columns of
   chunks (12 bytes per triangle and column), and 12 bytes per chunk that
   the inside fills without a triangle touching it; per thread, a chunk's
   columns (12 bytes each, 24 with colours), its crossings (24 bytes each)
   and with colours a bit per voxel. Time grows with the inside's volume. */
#ifndef VOXDAG_NO_BUILD
VOXDAG_API voxdag_status voxdag_builder_add_mesh(voxdag_builder *b, const voxdag_mesh *mesh,
                                                 voxdag_error *err);

/* Counts the open edges of MESH, the test of a solid voxelization: vertices
   at the same position (x, y, z equal as doubles) are one vertex, and an
   edge {a, b} is open when the triangles use it a different number of times
   from a to b than from b to a (edges of a triangle with two equal vertices
   are skipped). Sets *OPEN_EDGES and *FIRST_TRIANGLE (the lowest triangle
   with an open edge, UINT64_MAX when none); either may be NULL. ALLOCATOR
   may be NULL (VOXDAG_MALLOC); memory is 72 bytes per triangle and at most
   20 per vertex, freed before the call returns. Returns VOXDAG_OK (also for an
   open mesh), VOXDAG_ERR_INVALID_ARGUMENT for a bad index or a non-finite
   vertex (err->node: the triangle), VOXDAG_ERR_LIMIT for more than 2^31-1
   vertices, or VOXDAG_ERR_OUT_OF_MEMORY. Thread-safe: reads MESH only. */
VOXDAG_API voxdag_status voxdag_mesh_open_edges(const voxdag_mesh *mesh, const voxdag_allocator *allocator,
                                                uint64_t *open_edges, uint64_t *first_triangle,
                                                voxdag_error *err);
#endif

/* Per-level node counts of a build, filled by voxdag_builder_finish. Arrays
   are indexed by level 0..levels-2; the last entry counts 4^3 bricks. With
   compare_structures, the same voxels are also reduced under every symmetry
   group; else those three arrays are 0 but the one of the build's group. */
typedef struct voxdag_build_stats {
    uint32_t levels;
    uint64_t voxels;
    uint64_t nodes[VOXDAG_LEVEL_CAPACITY];         /* stored unique nodes of the result */
    uint64_t svo_nodes[VOXDAG_LEVEL_CAPACITY];     /* nodes of the equivalent octree */
    uint64_t svdag_nodes[VOXDAG_LEVEL_CAPACITY];   /* identical subtrees shared */
    uint64_t reflect_nodes[VOXDAG_LEVEL_CAPACITY]; /* shared up to reflections */
    uint64_t full_nodes[VOXDAG_LEVEL_CAPACITY];    /* shared up to all 48 symmetries */
    uint64_t peak_memory;                          /* bytes held by the builder at most */
} voxdag_build_stats;

#ifndef VOXDAG_NO_BUILD
/* Finishes the build: encodes the DAG and frees the builder (also on error).
   STATS may be NULL. Returns the DAG in *out; free it with voxdag_free. */
VOXDAG_API voxdag_status voxdag_builder_finish(voxdag_builder *b, voxdag **out,
                                               voxdag_build_stats *stats,
                                               voxdag_error *err);

/* Frees a builder that will not be finished. NULL is allowed. */
VOXDAG_API void voxdag_builder_free(voxdag_builder *b);
#endif /* VOXDAG_NO_BUILD */

/* Morton code of (x, y, z) with 21 bits per axis. */
VOXDAG_API uint64_t voxdag_morton_encode(uint32_t x, uint32_t y, uint32_t z);
VOXDAG_API void voxdag_morton_decode(uint64_t code, uint32_t *x, uint32_t *y, uint32_t *z);

// -- Loading and saving

/* Load options. A NULL pointer or an all-zero struct means defaults; nonzero
   zero_begin / zero_end (an uninitialised struct) and an allocator with only
   one of alloc and free are rejected with VOXDAG_ERR_INVALID_ARGUMENT. */
typedef struct voxdag_load_opts {
    uint32_t zero_begin;      /* must be 0 */
    uint64_t max_input_bytes; /* 0: no limit */
    uint64_t max_nodes;       /* total nodes and bricks; 0: no limit */
    uint64_t max_memory;      /* bytes allocated by the load; 0: no limit;
                                 more is VOXDAG_ERR_LIMIT */
    uint32_t max_levels;      /* 0 or more than VOXDAG_MAX_LEVELS: VOXDAG_MAX_LEVELS */
    int copy;                 /* 1: copy the bytes (else they must outlive the DAG) */
    voxdag_allocator allocator;
    int skip_checksums;       /* 1: do not compute the sections' CRC-32C, for bytes
                                 known to be intact (e.g. written by this process).
                                 Every structural check still runs, so queries stay
                                 safe on any bytes; only corruption that keeps the
                                 structure valid (e.g. a flipped voxel) goes unseen.
                                 The header and section table are always checked. */
    uint32_t zero_end;        /* must be 0 */
} voxdag_load_opts;

/* Validates a .vdag image in memory completely (structure, every pointer,
   every count, checksums unless opts->skip_checksums) and returns a DAG that
   queries it in place. Unless opts->copy is set, DATA must stay valid and
   unchanged until voxdag_free. The DAG holds a few hundred bytes plus about
   half a KB per inner level (L - 2 of them) besides a copy; the symmetry
   tables are constants that every DAG shares. */
VOXDAG_API voxdag_status voxdag_load_memory(const void *data, size_t size,
                                            const voxdag_load_opts *opts,
                                            voxdag **out, voxdag_error *err);

/* The DAG's complete file image (owned by the DAG). */
VOXDAG_API const void *voxdag_image(const voxdag *dag, size_t *size);

/* Frees a DAG with the allocator that made it. NULL is allowed. */
VOXDAG_API void voxdag_free(voxdag *dag);

#ifndef VOXDAG_NO_STDIO
/* Reads and validates the file at PATH (as voxdag_load_memory with a copy).
   The header is read and checked first (magic, version, checksum, declared
   size against the file's): a file that is not a .vdag costs one 96-byte read. */
VOXDAG_API voxdag_status voxdag_load_file(const char *path, const voxdag_load_opts *opts,
                                          voxdag **out, voxdag_error *err);
/* Writes the DAG's image to PATH atomically: to a temporary file beside it,
   then renamed over PATH, so a failed save (full disk, quota, a file-size
   limit, no permission) leaves an existing file as it was and removes the
   temporary file. The temporary's name is PATH + ".vdag-tmp-" + the process
   id in decimal (voxdag_save_temp_path gives it); it is created exclusively
   (POSIX open with O_CREAT | O_EXCL, and O_NOFOLLOW where defined; Windows
   _open with _O_EXCL, that is CREATE_NEW), so a file or a link planted at
   that name is never written through. A name already taken is a stale
   temporary (left by a save that was killed, in a process of the same id):
   it is removed (a link itself, never its target) and the file created
   exclusively once more; if the name is taken again in between, the save
   fails (VOXDAG_ERR_IO, os_error EEXIST). The library
   installs no signal handlers: a program that wants its temporary removed
   when a signal stops a save unlinks voxdag_save_temp_path's name in its
   handler (examples/vdag.c does so for SIGINT, SIGTERM, SIGHUP, SIGXFSZ).
   A directory at PATH is refused (VOXDAG_ERR_IO, os_error EISDIR) and left
   as it is. The permission bits of an existing regular file at PATH are kept
   (POSIX; not its owner or group); a new file gets 0666 less the umask.
   Where rename does not replace a file (Windows), PATH is removed just
   before the rename, and only when it is a file open for writing.
   Where neither POSIX (__unix__, __APPLE__) nor Windows is detected, plain
   C99 stdio is all there is: the temporary (PATH + ".vdag-tmp") is probed
   with fopen "rb" and then opened "wb", which a link planted in between
   can redirect, and permissions are not kept.
   Thread-safe for different PATHs; two saves of one PATH at once in one
   process share the temporary name, and one of them may fail.
   On VOXDAG_ERR_IO, err->os_error holds errno. */
VOXDAG_API voxdag_status voxdag_save_file(const voxdag *dag, const char *path,
                                          voxdag_error *err);
/* Writes the name of the temporary file voxdag_save_file uses for PATH in
   this process (PATH + ".vdag-tmp-" + the process id) to BUF, zero-ended.
   Returns VOXDAG_OK, or VOXDAG_ERR_INVALID_ARGUMENT when PATH or BUF is NULL
   or SIZE is too small (PATH's length + 32 always suffices). Thread-safe. */
VOXDAG_API voxdag_status voxdag_save_temp_path(const char *path, char *buf, size_t size);
#endif

// -- Colours

/* Colour section kinds of a .vdag file. */
typedef enum voxdag_color_kind {
    VOXDAG_COLORS_NONE = 0,
    VOXDAG_COLORS_RGB8 = 1,     /* 3 bytes per voxel, in voxel-index order */
    VOXDAG_COLORS_VOXCOLOR = 2, /* a voxcolor.h stream (decoded by voxdag_color
                                   when voxcolor.h is compiled in, see there;
                                   voxdag_info.colors_decodable says) */
    VOXDAG_COLORS_FORCE_32BIT = 0x7fffffff
} voxdag_color_kind;

/* The colour section: its kind, payload and size (NULL/0 when none). */
VOXDAG_API voxdag_color_kind voxdag_colors(const voxdag *dag, const void **payload,
                                           size_t *size);

/* Makes a copy of SRC whose colour section is replaced by PAYLOAD of KIND
   (VOXDAG_COLORS_NONE removes it). An RGB8 payload must hold 3 bytes per voxel;
   a voxcolor payload is stored as given. The copy also gets a new
   level-of-detail colour section (FORMAT.md, LOD_COLORS; see
   voxdag_cell_color) computed from the new colours, except when there are
   none, at most 64 voxels, L = 2, or a voxcolor payload that this
   implementation cannot decode (compiled without voxcolor.h). */
VOXDAG_API voxdag_status voxdag_with_colors(const voxdag *src, voxdag_color_kind kind,
                                            const void *payload, size_t size,
                                            voxdag **out, voxdag_error *err);

/* voxdag_with_colors with options: OPTS (NULL: defaults) is read for
   zero_begin / zero_end (nonzero: VOXDAG_ERR_INVALID_ARGUMENT),
   no_lod_colors (1: no level-of-detail colour section), and threads and
   thread_pool, as the builder reads them (0 or 1: the calling thread only):
   the level-of-detail means, and their voxcolor encoding, run on T threads
   of a built-in pool that lives for the call, or on the host's pool, with
   the same bytes whatever T (a thread_pool with run but no wait, or wait
   but no run: VOXDAG_ERR_INVALID_ARGUMENT). Its other fields are ignored.
   Thread-safe on a shared SRC. */
VOXDAG_API voxdag_status voxdag_with_colors_opts(const voxdag *src, voxdag_color_kind kind,
                                                 const void *payload, size_t size,
                                                 const voxdag_build_opts *opts, voxdag **out,
                                                 voxdag_error *err);

// -- Queries (thread-safe on a shared voxdag; no allocation)

typedef struct voxdag_info {
    uint32_t levels;
    voxdag_symmetry symmetry;   /* the group it was built with (never DEFAULT) */
    uint64_t voxels;
    uint32_t voxel_box[6];      /* the occupied voxels: min x y z, max x y z (half-open,
                                   grid units); all 0 when there are none */
    uint64_t nodes[VOXDAG_LEVEL_CAPACITY]; /* stored nodes per level; last = bricks */
    uint64_t level_bytes[VOXDAG_LEVEL_CAPACITY];
    uint64_t file_bytes;
    uint64_t node_bytes;        /* all inner levels */
    uint64_t brick_bytes;
    uint64_t color_bytes;
    voxdag_color_kind color_kind;
    int colors_decodable;       /* 1: voxdag_color gives every voxel's colour (an
                                   RGB8 section, or a voxcolor one with voxcolor.h
                                   compiled in); 0: no colours, or a voxcolor
                                   section this implementation cannot decode */
    int has_bounds;
    double bounds[6];           /* world-space min xyz, max xyz */
    uint64_t lod_color_bytes;   /* the level-of-detail colour section (0: none) */
} voxdag_info;

/* Fills *INFO; all zero when DAG is NULL (nothing happens when INFO is NULL). */
VOXDAG_API void voxdag_get_info(const voxdag *dag, voxdag_info *info);

/* World space. A file built with opts.bounds stores the world box of its grid
   (voxdag_info.bounds: min x y z, max x y z): grid point g (voxel (x, y, z)
   spans [x, x+1) ... in grid units, the grid [0, 2^L)^3) is the world point
   min + g * (max - min) / 2^L, per axis. Without bounds, world space is grid
   space. These map points both ways with that affine map (exact up to
   rounding: a round trip is within a few ulps). IN and OUT may be the same
   array. Returns VOXDAG_OK, or VOXDAG_ERR_INVALID_ARGUMENT for a NULL
   argument. Thread-safe. */
VOXDAG_API voxdag_status voxdag_world_to_grid(const voxdag *dag, const double world[3], double grid[3]);
VOXDAG_API voxdag_status voxdag_grid_to_world(const voxdag *dag, const double grid[3], double world[3]);

/* Returns 1 when voxel (x, y, z) is full (and its index in *index, which may be
   NULL), 0 when it is empty, outside the grid, or DAG is NULL. */
VOXDAG_API int voxdag_lookup(const voxdag *dag, uint32_t x, uint32_t y, uint32_t z,
                             uint64_t *index);

/* Many voxdag_lookup calls at once: point i is XYZ[3 i .. 3 i + 2]; FULL[i]
   (when FULL is not NULL) is what voxdag_lookup returns for it and INDEX[i]
   (when INDEX is not NULL) its voxel index, written only for full points.
   Returns the number of full points. Consecutive points that share the
   upper part of their path from the root (nearby points, for example in
   Morton order) descend only from where the paths part. Thread-safe; no
   allocation. */
VOXDAG_API uint64_t voxdag_lookup_many(const voxdag *dag, const uint32_t *xyz, size_t count, uint8_t *full,
                                       uint64_t *index);

/* The voxels of the level-LEVEL cell (a cube 2^(L-LEVEL) voxels a side on
   that level's grid; LEVEL L is one voxel) that holds voxel (X, Y, Z):
   returns their count, and sets *FIRST (when FIRST is not NULL) to the
   index of the cell's first voxel in Morton order (its voxels are the
   indices [*FIRST, *FIRST + count)). Returns 0 (FIRST untouched) for an
   empty cell, a point outside the grid, LEVEL > L or a NULL DAG. A descent
   like voxdag_lookup's; thread-safe; no allocation. */
VOXDAG_API uint64_t voxdag_cell_count(const voxdag *dag, uint32_t level, uint32_t x, uint32_t y, uint32_t z,
                                      uint64_t *first);

/* Many voxdag_cell_count calls at one LEVEL, as voxdag_lookup_many does
   lookups: the cell of point i (XYZ[3 i .. 3 i + 2]) holds COUNT_OUT[i]
   voxels (when COUNT_OUT is not NULL; 0 when empty or outside the grid)
   and starts at voxel index FIRST[i] (when FIRST is not NULL; written only
   for non-empty cells). Returns the voxels of all the cells (a cell named
   twice counts twice); 0 for a NULL DAG or XYZ, or LEVEL > L. Nearby
   points share the upper part of their descent. Thread-safe; no
   allocation. */
VOXDAG_API uint64_t voxdag_cell_count_many(const voxdag *dag, uint32_t level, const uint32_t *xyz, size_t count,
                                           uint64_t *count_out, uint64_t *first);

/* Colour (RGB8) of voxel INDEX, whatever the colour section's kind: raw RGB8,
   or a voxcolor stream when the implementation was compiled with voxcolor.h
   (include voxcolor.h before the unit that defines VOXDAG_IMPLEMENTATION, or
   define VOXDAG_WITH_VOXCOLOR there: voxdag.h then includes "voxcolor.h"
   from its own directory; voxcolor.h itself does not depend on voxdag.h).
   Then loading also validates the stream (VOXDAG_ERR_CORRUPT for a bad one,
   err->byte_offset in the file) and each call decodes one colour in place,
   with no allocation. From a ray hit: voxdag_color(dag, hit.index, rgb) with
   ray opts.want_index set. Returns 1; 0 (RGB untouched) when the DAG has no
   colours, INDEX >= the voxel count, or DAG or RGB is NULL; -1 when the
   colours are a voxcolor stream and this implementation was compiled
   without voxcolor.h: every such call fails, and writes magenta (255, 0,
   255) to RGB so that a caller that tests only for nonzero shows it. Check
   voxdag_info.colors_decodable once after loading to catch that case (the
   DAG is never changed). Thread-safe. */
VOXDAG_API int voxdag_color(const voxdag *dag, uint64_t index, uint8_t rgb[3]);


/* Calls FN (may be NULL: counts) for every full voxel in voxel-index order;
   stops early when FN returns nonzero. Returns the number of voxels visited
   (0 when DAG is NULL). */
typedef int (*voxdag_voxel_fn)(void *user, uint32_t x, uint32_t y, uint32_t z,
                               uint64_t index);
VOXDAG_API uint64_t voxdag_for_each_voxel(const voxdag *dag, voxdag_voxel_fn fn,
                                          void *user);

// -- Ray casting
#ifndef VOXDAG_NO_RAYTRACE

/* A ray in grid units (the grid spans [0, 2^L)^3, voxel (x, y, z) occupies
   [x, x+1) x [y, y+1) x [z, z+1)). Points are origin + t * dir for t in
   [t_min, t_max]; dir need not be normalized (t is in units of |dir|), and
   t_max may be HUGE_VAL; t_max = 0 also means no limit, so a zeroed ray with
   only origin and dir set traces the whole ray. A ray that starts on a face between two voxels
   starts in the one it moves into; a zero direction component keeps that
   coordinate fixed (a ray lying in a face plane belongs to the voxels above
   it). Ties between axes (rays through edges and corners) are broken towards
   x, then y, then z, so every answer is exact and deterministic. */
typedef struct voxdag_ray {
    double origin[3];
    double dir[3];
    double t_min, t_max;
} voxdag_ray;

/* Ray options. A NULL pointer or an all-zero struct means defaults: no level
   of detail and no voxel index. Checked on every call, in every build:
   nonzero zero_begin / zero_end (an uninitialised struct), or a negative,
   NaN or infinite lod_factor or lod_pixels make voxdag_raycast return -1. */
typedef struct voxdag_ray_opts {
    uint32_t zero_begin; /* must be 0 */
    int want_index;    /* 1: fill hit.index (one extra descent at the hit) */
    double lod_factor; /* size of one pixel at distance t = 1, in grid units */
    double lod_pixels; /* stop at a full cell whose projected size, cell side /
                          (t * lod_factor), is below this; 0 = full detail. Cells
                          are nodes (4^3 bricks and coarser) and the 2^3 cells
                          of a brick (full when any of their 8 voxels is) */
    int t_max_exclusive; /* 1: the range is half-open, [t_min, t_max): a voxel
                            entered exactly at t_max is not hit, and t_max is
                            taken as given (0 is not "no limit"; t_max <= t_min
                            is empty). For line of sight from point A to B:
                            origin A, dir B - A, t in [0, 1) */
    uint32_t zero_end; /* must be 0 */
} voxdag_ray_opts;

typedef struct voxdag_hit {
    double t;         /* where the ray enters the voxel (t_min when it starts inside) */
    uint32_t xyz[3];  /* the voxel, or the lowest voxel of the level-of-detail cell */
    int normal[3];    /* entry face normal, one of -1/0/1 per axis; all 0 when the
                         ray starts inside the voxel */
    uint32_t level;   /* L for a voxel; a level-of-detail cell spans 2^(L-level) voxels */
    uint64_t index;   /* voxel index (a cell's first voxel, in Morton order), when
                         opts->want_index */
} voxdag_hit;

/* Colour (RGB8) of the cell that HIT (as voxdag_raycast filled it) stopped at:
   the voxel's own colour when hit->level is L, else the mean colour of the
   full voxels of the level-of-detail cell at hit->level that holds voxel
   hit->xyz (a node, a brick or a 2^3 cell of a brick). Those voxels are
   the colour range [a, a + n) (a: the cell's first voxel index, n: its
   voxel count), and the cell is found from hit->xyz and hit->level by a
   descent like voxdag_lookup's, so hit->index is not needed (ray
   opts.want_index may be 0). Cells of at most 64 voxels (every 2^3 cell
   and brick) are averaged from the colour section, exactly (the mean
   rounded to RGB8). Larger cells read one value of the level-of-detail
   colour section (FORMAT.md, LOD_COLORS): within 0.02 of the exact mean
   (Euclidean RGB distance / 255; the voxcolor colours' mean for a voxcolor
   file); files without that section (written before it, or built with
   no_lod_colors) give such cells the colour of their first voxel, a.
   Returns 1; 0 (RGB untouched) when the DAG has no colours, the cell is
   empty or outside the grid, hit->level > L, or an argument is NULL; -1 (and
   magenta) when the colours cannot be decoded, as voxdag_color.
   Thread-safe; no allocation. */
VOXDAG_API int voxdag_cell_color(const voxdag *dag, const voxdag_hit *hit, uint8_t rgb[3]);

/* Finds the first full voxel (or level-of-detail cell) along RAY and fills
   *HIT. Returns 1 on a hit, 0 on a miss (HIT untouched), -1 (HIT untouched)
   when DAG, RAY or HIT is NULL or OPTS is invalid (see voxdag_ray_opts), in
   every build: test `> 0` for a hit. OPTS may be NULL. Thread-safe on a
   shared DAG; no allocation; stack use bounded by VOXDAG_MAX_LEVELS. NaN
   inputs miss. */
VOXDAG_API int voxdag_raycast(const voxdag *dag, const voxdag_ray *ray,
                              const voxdag_ray_opts *opts, voxdag_hit *hit);

/* Shadow query: returns 1 when any full voxel lies along RAY within
   [t_min, t_max], else 0; -1 when DAG or RAY is NULL. Same answer as
   voxdag_raycast without level of detail, with less bookkeeping.
   Thread-safe; no allocation. */
VOXDAG_API int voxdag_occluded(const voxdag *dag, const voxdag_ray *ray);

/* voxdag_occluded with ray options: level of detail (a full cell coarser than
   opts->lod_pixels blocks the ray, for distant shadows) and t_max_exclusive;
   want_index is ignored. Returns 1 exactly when voxdag_raycast with the same
   OPTS hits, 0 when it misses, -1 when DAG or RAY is NULL or OPTS is invalid.
   OPTS may be NULL (then the same as voxdag_occluded). */
VOXDAG_API int voxdag_occluded_opts(const voxdag *dag, const voxdag_ray *ray, const voxdag_ray_opts *opts);

/* Many voxdag_raycast calls at once, with the same OPTS for every ray: for
   i < COUNT, RESULT[i] is what voxdag_raycast(DAG, &RAYS[i], OPTS, &HITS[i])
   returns (1 or 0) and HITS[i] what it fills (untouched on a miss), bit for
   bit. Returns the number of hits; -1 (nothing written) when DAG is NULL,
   OPTS is invalid, or COUNT > 0 and RAYS, HITS or RESULT is NULL. Coherent
   rays are faster: without level of detail, each run of up to 64
   consecutive rays with t_min >= 0 and directions within a narrow cone (an
   8 x 8 tile of primary rays, for example) is first checked as one beam
   against the DAG's nodes, and each ray then starts where that beam shows
   nothing full before it; other rays cost about what single calls do.
   Thread-safe on a shared DAG; no allocation; stack use bounded by
   VOXDAG_MAX_LEVELS. */
VOXDAG_API int64_t voxdag_raycast_many(const voxdag *dag, const voxdag_ray *rays, size_t count,
                                       const voxdag_ray_opts *opts, voxdag_hit *hits, uint8_t *result);

/* Many voxdag_occluded_opts calls at once: OCCLUDED[i] is what
   voxdag_occluded_opts(DAG, &RAYS[i], OPTS) returns (1 or 0). Returns the
   number of occluded rays; -1 (nothing written) when DAG is NULL, OPTS is
   invalid, or COUNT > 0 and RAYS or OCCLUDED is NULL. Coherent rays that
   start away from surfaces (lines of sight from one eye) gain as in
   voxdag_raycast_many; rays that leave a surface (shadow rays) cost about
   what single calls do. Thread-safe on a shared DAG; no allocation. */
VOXDAG_API int64_t voxdag_occluded_many(const voxdag *dag, const voxdag_ray *rays, size_t count,
                                        const voxdag_ray_opts *opts, uint8_t *occluded);

/* A ray leaving the surface that RAY hit (HIT as voxdag_raycast filled it),
   in direction DIR, for shadow and reflection rays: *OUT starts at the hit
   point on the hit cell's entry face, put exactly on the face's plane and
   inside its square (origin + t * dir rounded can lie inside the cell and
   hit it again: shadow acne), with t in [0, no limit). A ray that starts on
   a face starts in the cell it moves into, so when DIR points out of the
   face (DIR . normal > 0) OUT can never enter the hit cell again, at any
   level of detail; returns 1. Returns 0 when OUT starts in the hit cell
   (DIR points into the face or along it, or the hit has no entry face: RAY
   started inside the cell), so that a shadow ray towards a light behind
   the surface is blocked at once, as it should be; -1 (OUT untouched) when
   an argument is NULL. OUT may be RAY. */
VOXDAG_API int voxdag_ray_from_hit(const voxdag *dag, const voxdag_ray *ray, const voxdag_hit *hit,
                                   const double dir[3], voxdag_ray *out);

/* Maps a world-space ray (origin and direction in the units of the file's
   bounds, see voxdag_world_to_grid) to grid units: the origin as a point, the
   direction divided per axis by the voxel's world size (max - min) / 2^L. t_min and t_max are copied
   unchanged, because the map is affine: the point at t on the world ray is
   the point at t on the grid ray, so a hit's t is also its world-space
   parameter (world hit point = world origin + t * world dir; normals keep
   their signs). IN and OUT may be the same. Returns VOXDAG_OK, or
   VOXDAG_ERR_INVALID_ARGUMENT for a NULL argument. Thread-safe. */
VOXDAG_API voxdag_status voxdag_world_ray(const voxdag *dag, const voxdag_ray *world_ray,
                                          voxdag_ray *grid_ray);

#endif /* VOXDAG_NO_RAYTRACE */

// -- Editing (needs the builder: not under VOXDAG_NO_BUILD)
#ifndef VOXDAG_NO_BUILD

/* An editor holds a scene as a DAG in memory, hash-consed and canonical
   under the scene's symmetry group exactly as the builder's (the same node
   tables and canonical forms), with every node's voxel count. An edit
   rebuilds only the nodes along the edited region, bottom-up, and looks each
   one up, so a node that becomes equal to an existing one (up to the group)
   is shared again. Colours are kept per 4^3 brick, by position, not by voxel
   index: inserting a voxel shifts no colour, and an edit copies only the
   colour blocks of the bricks it changes (copy on write, which also makes
   undo cheap). voxdag_editor_commit encodes the result: the same bytes as
   voxdag_builder run on the final voxels with the same options.
   An editor belongs to one thread at a time. */
typedef struct voxdag_editor voxdag_editor;

/* Editor options. NULL or an all-zero struct means defaults; zero_begin and
   zero_end must be 0 (VOXDAG_ERR_INVALID_ARGUMENT otherwise). LEVELS,
   SYMMETRY and COLORS describe an empty scene; opening a DAG takes its own. */
typedef struct voxdag_editor_opts {
    uint32_t zero_begin;
    uint32_t levels;          /* empty scene: L, 2..VOXDAG_MAX_LEVELS; 0 means 10 */
    voxdag_symmetry symmetry; /* empty scene: 0 means VOXDAG_SYMMETRY_FULL */
    int colors;               /* empty scene: 1 gives every voxel an RGB8 colour */
    uint64_t max_memory;      /* bytes the editor may hold (nodes, colours, history,
                                 a commit's builder); 0: no limit; more is
                                 VOXDAG_ERR_LIMIT and the edit is not applied */
    voxdag_allocator allocator;
    uint32_t zero_end;
} voxdag_editor_opts;

/* Opens an editor on the voxels and colours of DAG (NULL: an empty scene as
   OPTS describes). A DAG with voxcolor colours needs voxcolor.h compiled in
   (VOXDAG_ERR_INVALID_ARGUMENT otherwise); the editor then holds the decoded
   colours. The DAG is not kept. Returns VOXDAG_OK and *OUT, or an error with
   nothing allocated. */
VOXDAG_API voxdag_status voxdag_editor_create(const voxdag *dag, const voxdag_editor_opts *opts,
                                              voxdag_editor **out, voxdag_error *err);

/* Frees an editor (NULL is allowed). DAGs it committed stay valid. */
VOXDAG_API void voxdag_editor_free(voxdag_editor *ed);

/* The colour an edit gives voxels: RGB when FN is NULL, else FN's answer for
   each voxel's position. A NULL brush gives new voxels white (255, 255, 255)
   and leaves the colours of voxels already there. */
typedef void (*voxdag_color_at_fn)(void *user, uint32_t x, uint32_t y, uint32_t z, uint8_t rgb[3]);
typedef struct voxdag_brush {
    uint8_t rgb[3];
    voxdag_color_at_fn fn;
    void *user;
} voxdag_brush;

/* A region of the grid, in signed voxel coordinates (each within +-2^28,
   VOXDAG_ERR_COORDINATE otherwise); the part outside the grid is ignored.
   BOX: voxels with lo[a] <= v[a] < hi[a], empty when hi[a] <= lo[a].
   SPHERE: voxels with (2x+1-2c[0])^2 + (2y+1-2c[1])^2 + (2z+1-2c[2])^2
   <= 4 radius^2 (radius 0..2^28). */
typedef enum voxdag_shape_kind {
    VOXDAG_SHAPE_BOX = 0,
    VOXDAG_SHAPE_SPHERE = 1,
    VOXDAG_SHAPE_COUNT,
    VOXDAG_SHAPE_FORCE_32BIT = 0x7fffffff
} voxdag_shape_kind;

typedef struct voxdag_shape {
    voxdag_shape_kind kind;
    int64_t lo[3], hi[3]; /* BOX */
    int64_t center[3];    /* SPHERE */
    int64_t radius;       /* SPHERE */
} voxdag_shape;

/* Edits. Each call is one edit in the history (also one that changes
   nothing); after an undo, a new edit discards what could be redone. A
   failed edit changes nothing. Returns VOXDAG_OK, VOXDAG_ERR_COORDINATE for
   a coordinate outside the grid (set, clear: err->node is the voxel's
   position in XYZ) or beyond +-2^28 (shapes, copy),
   VOXDAG_ERR_INVALID_ARGUMENT for a NULL pointer, a bad shape kind or a
   negative radius, VOXDAG_ERR_OUT_OF_MEMORY or VOXDAG_ERR_LIMIT.
   set:   makes the N voxels XYZ (3 coordinates each) full; RGB, 3 bytes per
          voxel, gives their colours (NULL: new voxels white, the others
          keep theirs). A voxel given twice takes the last colour.
   clear: makes the N voxels XYZ empty.
   fill:  makes SHAPE full; BRUSH (may be NULL) colours it, also the
          voxels already there.
   carve: makes SHAPE empty.
   paint: recolours the full voxels in SHAPE with BRUSH (geometry untouched).
   copy:  copies the voxels of box LO..HI (full and empty, with colours) to
          the same box moved by OFFSET; the whole source is read before
          anything is written, and destinations outside the grid are dropped. */
VOXDAG_API voxdag_status voxdag_editor_set(voxdag_editor *ed, const uint32_t *xyz, const uint8_t *rgb,
                                           size_t n, voxdag_error *err);
VOXDAG_API voxdag_status voxdag_editor_clear(voxdag_editor *ed, const uint32_t *xyz, size_t n,
                                             voxdag_error *err);
VOXDAG_API voxdag_status voxdag_editor_fill(voxdag_editor *ed, const voxdag_shape *shape,
                                            const voxdag_brush *brush, voxdag_error *err);
VOXDAG_API voxdag_status voxdag_editor_carve(voxdag_editor *ed, const voxdag_shape *shape,
                                             voxdag_error *err);
VOXDAG_API voxdag_status voxdag_editor_paint(voxdag_editor *ed, const voxdag_shape *shape,
                                             const voxdag_brush *brush, voxdag_error *err);
VOXDAG_API voxdag_status voxdag_editor_copy(voxdag_editor *ed, const int64_t lo[3], const int64_t hi[3],
                                            const int64_t offset[3], voxdag_error *err);

/* Undoes the last applied edit, or redoes the last undone one. Returns 1,
   or 0 when there is none (or ED is NULL). No allocation; cannot fail. */
VOXDAG_API int voxdag_editor_undo(voxdag_editor *ed);
VOXDAG_API int voxdag_editor_redo(voxdag_editor *ed);

/* Forgets the history (nothing to undo or redo afterwards) and frees the
   colour blocks only the history held: an edit keeps every block it
   replaced (256 bytes per brick whose colours it changed) until then, or
   until a new edit discards it from the edits that could be redone (their
   blocks are reused).
   Nodes are kept (they are shared and small). Returns VOXDAG_OK, or
   VOXDAG_ERR_OUT_OF_MEMORY / VOXDAG_ERR_LIMIT with nothing changed. */
VOXDAG_API voxdag_status voxdag_editor_forget_history(voxdag_editor *ed, voxdag_error *err);

/* Queries on the edited scene, with the meaning of voxdag_lookup,
   voxdag_color and voxdag_for_each_voxel (voxel indices are ranks in Morton
   order of the scene as it is now). voxdag_editor_voxels gives the voxel
   count. Thread-safe between edits (they only read). */
VOXDAG_API int voxdag_editor_lookup(const voxdag_editor *ed, uint32_t x, uint32_t y, uint32_t z,
                                    uint64_t *index);
VOXDAG_API int voxdag_editor_color(const voxdag_editor *ed, uint64_t index, uint8_t rgb[3]);
VOXDAG_API uint64_t voxdag_editor_for_each_voxel(const voxdag_editor *ed, voxdag_voxel_fn fn, void *user);
VOXDAG_API uint64_t voxdag_editor_voxels(const voxdag_editor *ed);

/* Bytes the editor holds now (nodes of every state the history can reach,
   colour blocks, history), the figure max_memory limits. */
VOXDAG_API uint64_t voxdag_editor_memory(const voxdag_editor *ed);

/* The unique nodes the scene reaches now, per level as voxdag_info.nodes
   (levels 0..L-2, the last entry 4^3 bricks; the rest of NODES set to 0):
   the canonical counts of the scene's voxels, as a build gives them. Returns
   VOXDAG_OK, VOXDAG_ERR_INVALID_ARGUMENT for a NULL argument, or
   VOXDAG_ERR_OUT_OF_MEMORY / VOXDAG_ERR_LIMIT (a byte per stored node is
   needed for a moment). */
VOXDAG_API voxdag_status voxdag_editor_nodes(voxdag_editor *ed, uint64_t nodes[VOXDAG_LEVEL_CAPACITY],
                                             voxdag_error *err);

/* Encodes the scene as it is now into a new DAG (*OUT, freed with
   voxdag_free): the bytes voxdag_builder gives for the same voxels and
   colours with the same levels, symmetry and world bounds, colours raw RGB8
   (voxdag_with_colors can replace them). The editor stays usable. Time and
   memory are those of a build of the scene's voxels. */
VOXDAG_API voxdag_status voxdag_editor_commit(voxdag_editor *ed, voxdag **out, voxdag_error *err);

#ifndef VOXDAG_NO_RAYTRACE
/* voxdag_raycast and voxdag_occluded_opts on the edited scene. They trace a
   commit that the editor keeps until the next edit, undo or redo (so the
   first ray after a change costs a commit). Return -1 also when that commit
   fails (memory, limits). */
VOXDAG_API int voxdag_editor_raycast(voxdag_editor *ed, const voxdag_ray *ray,
                                     const voxdag_ray_opts *opts, voxdag_hit *hit);
VOXDAG_API int voxdag_editor_occluded(voxdag_editor *ed, const voxdag_ray *ray,
                                      const voxdag_ray_opts *opts);
#endif
#endif /* VOXDAG_NO_BUILD */

// -- File layout (FORMAT.md): byte offsets and codes, checked by the tests

#define VOXDAG_FILE_HEADER_SIZE 96
#define VOXDAG_FILE_OFF_MAGIC 0
#define VOXDAG_FILE_OFF_VERSION 8
#define VOXDAG_FILE_OFF_ENDIAN 12
#define VOXDAG_FILE_OFF_HEADER_SIZE 16
#define VOXDAG_FILE_OFF_FLAGS 20
#define VOXDAG_FILE_OFF_FILE_SIZE 24
#define VOXDAG_FILE_OFF_VOXELS 32
#define VOXDAG_FILE_OFF_LEVELS 40
#define VOXDAG_FILE_OFF_ROOT_TRANSFORM 41
#define VOXDAG_FILE_OFF_SYMMETRY 42
#define VOXDAG_FILE_OFF_SECTION_COUNT 44
#define VOXDAG_FILE_OFF_TABLE_CRC 48
#define VOXDAG_FILE_OFF_HEADER_CRC 52
#define VOXDAG_FILE_OFF_VOXEL_BOX 56
#define VOXDAG_FILE_OFF_RESERVED 80
#define VOXDAG_FILE_SECTION_ENTRY_SIZE 32
#define VOXDAG_FILE_LEVEL_ENTRY_SIZE 80
#define VOXDAG_FILE_ENDIAN_TAG 0x0A0B0C0Du
#define VOXDAG_FILE_SECTION_OPTIONAL 1u
#define VOXDAG_FILE_MAX_SECTIONS 16
#define VOXDAG_FILE_NODE_PADDING 16

enum {
    VOXDAG_SECTION_LEVELS = 1,
    VOXDAG_SECTION_NODES = 2,
    VOXDAG_SECTION_BRICKS = 3,
    VOXDAG_SECTION_COLORS_RGB8 = 4,
    VOXDAG_SECTION_COLORS_VOXCOLOR = 5,
    VOXDAG_SECTION_BOUNDS = 6,
    VOXDAG_SECTION_LOD_COLORS = 7
};

/* The level-of-detail colour section (FORMAT.md, LOD_COLORS). */
#define VOXDAG_FILE_LOD_HEADER_SIZE 16
#define VOXDAG_FILE_LOD_OFF_KIND 0
#define VOXDAG_FILE_LOD_OFF_SLOT_SHIFT 1
#define VOXDAG_FILE_LOD_OFF_FIRST_LEVEL 2
#define VOXDAG_FILE_LOD_OFF_LEVEL_COUNT 3
#define VOXDAG_FILE_LOD_OFF_RESERVED 4
#define VOXDAG_FILE_LOD_OFF_SLOTS 8
#define VOXDAG_FILE_LOD_SLOT_SHIFT 6 /* a slot every 64 voxels */

#ifdef __cplusplus
}
#endif

#endif /* VOXDAG_H */

/* ======================================================================== */
/*                              IMPLEMENTATION                              */
/* ======================================================================== */

#ifdef VOXDAG_IMPLEMENTATION
#ifndef VOXDAG_IMPLEMENTED
#define VOXDAG_IMPLEMENTED

#include <string.h>

#if defined(VOXDAG_MALLOC) != defined(VOXDAG_FREE)
#error "define both VOXDAG_MALLOC and VOXDAG_FREE, or neither"
#endif
#ifndef VOXDAG_MALLOC
#include <stdlib.h>
#define VOXDAG_MALLOC(sz) malloc(sz)
#define VOXDAG_FREE(p) free(p)
#endif
#ifndef VOXDAG_ASSERT
#include <assert.h>
#define VOXDAG_ASSERT(x) assert(x)
#endif
#ifndef VOXDAG_NO_STDIO
#include <errno.h>
#include <stdio.h>
#if defined(_WIN32)
#include <fcntl.h> /* the CRT's _open, _write: saving (no <windows.h> needed) */
#include <io.h>
#include <process.h>
#include <sys/stat.h>
#elif defined(__unix__) || defined(__APPLE__)
#include <fcntl.h> /* open, write, fchmod: saving */
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>
#if !defined(__cplusplus)
int fchmod(int fd, mode_t mode); /* POSIX; strict C99 headers (-std=c99) leave it out */
#endif
#endif
#endif
#ifndef VOXDAG_NO_THREADS
#if defined(_WIN32)
/* Only what threads need, and no min/max macros in the includer's unit;
   an includer's own choice of these two macros is kept. */
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#define VOXDAGI_LEAN_AND_MEAN
#endif
#ifndef NOMINMAX
#define NOMINMAX
#define VOXDAGI_NOMINMAX
#endif
#include <windows.h> /* Win32 threads (Vista and later): SRW locks, condition variables */
#ifdef VOXDAGI_LEAN_AND_MEAN
#undef WIN32_LEAN_AND_MEAN
#undef VOXDAGI_LEAN_AND_MEAN
#endif
#ifdef VOXDAGI_NOMINMAX
#undef NOMINMAX
#undef VOXDAGI_NOMINMAX
#endif
typedef SRWLOCK voxdagi_lock_t;
typedef CONDITION_VARIABLE voxdagi_cond_t;
typedef HANDLE voxdagi_thread_t;
#define voxdagi_lock_init(m) InitializeSRWLock(m)
#define voxdagi_lock_destroy(m) ((void)(m))
#define voxdagi_lock(m) AcquireSRWLockExclusive(m)
#define voxdagi_unlock(m) ReleaseSRWLockExclusive(m)
#define voxdagi_cond_init(c) InitializeConditionVariable(c)
#define voxdagi_cond_destroy(c) ((void)(c))
#define voxdagi_cond_wait(c, m) SleepConditionVariableSRW(c, m, INFINITE, 0)
#define voxdagi_cond_wake_all(c) WakeAllConditionVariable(c)
#else
#include <pthread.h>
typedef pthread_mutex_t voxdagi_lock_t;
typedef pthread_cond_t voxdagi_cond_t;
typedef pthread_t voxdagi_thread_t;
#define voxdagi_lock_init(m) pthread_mutex_init(m, NULL)
#define voxdagi_lock_destroy(m) pthread_mutex_destroy(m)
#define voxdagi_lock(m) pthread_mutex_lock(m)
#define voxdagi_unlock(m) pthread_mutex_unlock(m)
#define voxdagi_cond_init(c) pthread_cond_init(c, NULL)
#define voxdagi_cond_destroy(c) pthread_cond_destroy(c)
#define voxdagi_cond_wait(c, m) pthread_cond_wait(c, m)
#define voxdagi_cond_wake_all(c) pthread_cond_broadcast(c)
#endif
#endif
/* voxdag_color decodes voxcolor streams when voxcolor.h's declarations are
   here (included before this implementation, or by VOXDAG_WITH_VOXCOLOR). */
#if defined(VOXDAG_WITH_VOXCOLOR) && !defined(VOXCOLOR_H)
#include "voxcolor.h"
#endif
#ifdef VOXCOLOR_H
#define VOXDAGI_VOXCOLOR 1
#endif

static const uint8_t voxdagi_magic[8] = {0x89, 'V', 'D', 'A', 'G', '\r', '\n', 0x1A};

// -- Errors

static voxdag_status voxdagi_fail(voxdag_error *err, voxdag_status status,
                                  const char *message, uint64_t offset, uint64_t node) {
    if (err) {
        err->status = status;
        err->message = message;
        err->byte_offset = offset;
        err->node = node;
        err->os_error = 0;
    }
    return status;
}

#ifndef VOXDAG_NO_STDIO
/* A failed file operation: the message, and errno for the caller. */
static voxdag_status voxdagi_fail_io(voxdag_error *err, const char *message) {
    int e = errno;
    voxdagi_fail(err, VOXDAG_ERR_IO, message, UINT64_MAX, UINT64_MAX);
    if (err) err->os_error = e;
    return VOXDAG_ERR_IO;
}
#endif

static voxdag_status voxdagi_ok(voxdag_error *err) {
    if (err) {
        err->status = VOXDAG_OK;
        err->message = "ok";
        err->byte_offset = UINT64_MAX;
        err->node = UINT64_MAX;
        err->os_error = 0;
    }
    return VOXDAG_OK;
}

/* For the few helpers on the ray path that compilers would otherwise call. */
#if defined(__GNUC__) || defined(__clang__)
#define VOXDAGI_INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define VOXDAGI_INLINE static __forceinline
#else
#define VOXDAGI_INLINE static
#endif

#define VOXDAGI_FAIL(err, status, msg) voxdagi_fail(err, status, msg, UINT64_MAX, UINT64_MAX)

VOXDAG_API const char *voxdag_status_string(voxdag_status status) {
    switch (status) {
    case VOXDAG_OK: return "ok";
    case VOXDAG_ERR_INVALID_ARGUMENT: return "invalid argument";
    case VOXDAG_ERR_OUT_OF_MEMORY: return "out of memory";
    case VOXDAG_ERR_LIMIT: return "limit exceeded";
    case VOXDAG_ERR_COORDINATE: return "coordinate outside the grid";
    case VOXDAG_ERR_ORDER: return "voxel out of streaming order";
    case VOXDAG_ERR_TRUNCATED: return "truncated data";
    case VOXDAG_ERR_BAD_MAGIC: return "not a .vdag file";
    case VOXDAG_ERR_VERSION: return "unsupported format version";
    case VOXDAG_ERR_CHECKSUM: return "checksum mismatch";
    case VOXDAG_ERR_CORRUPT: return "corrupt data";
    case VOXDAG_ERR_IO: return "i/o error";
    case VOXDAG_ERR_CANCELLED: return "cancelled";
    case VOXDAG_ERR_NOT_CLOSED: return "mesh not closed";
    default: return "unknown status";
    }
}

VOXDAG_API uint32_t voxdag_version(void) { return VOXDAG_VERSION; }

// -- Memory: per-call allocator with a byte count, a peak and a limit

typedef struct voxdagi_mem {
    voxdag_allocator a;
    uint64_t used, peak, limit; /* limit 0: none */
    int over_limit;             /* an allocation was refused by the limit */
#ifndef VOXDAG_NO_THREADS
    voxdagi_lock_t lock; /* workers allocate concurrently */
#endif
} voxdagi_mem;

static void voxdagi_mem_init(voxdagi_mem *m, const voxdag_allocator *a, uint64_t limit) {
    memset(m, 0, sizeof *m);
    if (a) m->a = *a;
    m->limit = limit;
#ifndef VOXDAG_NO_THREADS
    voxdagi_lock_init(&m->lock);
#endif
}

static void voxdagi_mem_destroy(voxdagi_mem *m) {
#ifndef VOXDAG_NO_THREADS
    voxdagi_lock_destroy(&m->lock);
#else
    (void)m;
#endif
}

static void *voxdagi_alloc(voxdagi_mem *m, size_t size) {
    void *p = NULL;
    int ok;
    if (size == 0) size = 1;
#ifndef VOXDAG_NO_THREADS
    voxdagi_lock(&m->lock);
#endif
    ok = !m->limit || (m->used <= m->limit && size <= m->limit - m->used);
    if (!ok) m->over_limit = 1;
    if (ok) {
        p = m->a.alloc ? m->a.alloc(m->a.user, size) : VOXDAG_MALLOC(size);
        if (p) {
            m->used += size;
            if (m->used > m->peak) m->peak = m->used;
        }
    }
#ifndef VOXDAG_NO_THREADS
    voxdagi_unlock(&m->lock);
#endif
    return p;
}

static void voxdagi_free(voxdagi_mem *m, void *p, size_t size) {
    if (!p) return;
    if (size == 0) size = 1;
#ifndef VOXDAG_NO_THREADS
    voxdagi_lock(&m->lock);
#endif
    if (m->a.free) m->a.free(m->a.user, p, size);
    else if (!m->a.alloc) VOXDAG_FREE(p);
    m->used -= size;
#ifndef VOXDAG_NO_THREADS
    voxdagi_unlock(&m->lock);
#endif
}

/* Reports a failure of status ST with MESSAGE, except that a failure after
   the limit (max_memory) refused an allocation is VOXDAG_ERR_LIMIT with a
   message that says so. Returns the status reported. */
static voxdag_status voxdagi_mem_fail(const voxdagi_mem *m, voxdag_error *err, voxdag_status st, const char *message) {
    if ((st == VOXDAG_ERR_OUT_OF_MEMORY || st == VOXDAG_ERR_LIMIT) && m->over_limit)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, "more memory needed than max_memory allows");
    return VOXDAGI_FAIL(err, st, message);
}

#ifndef VOXDAG_NO_BUILD
/* Grows *p (holding *cap elements of ELEM bytes) to at least NEED elements,
   doubling. Returns 0 when out of memory (the old block is kept). */
static int voxdagi_grow(voxdagi_mem *m, void **p, size_t *cap, size_t need, size_t elem) {
    size_t n = *cap ? *cap : 16;
    void *q;
    if (need <= *cap) return 1;
    while (n < need) {
        if (n > ((size_t)-1 / 2) / elem) return 0;
        n *= 2;
    }
    q = voxdagi_alloc(m, n * elem);
    if (!q) return 0;
    if (*cap) memcpy(q, *p, *cap * elem);
    voxdagi_free(m, *p, *cap * elem);
    *p = q;
    *cap = n;
    return 1;
}
#endif

// -- Threads: the built-in pool, teams and batches of jobs

#define VOXDAGI_MAX_THREADS 64

/* A batch of jobs: FN on each of the COUNT SIZE-byte elements of JOBS (the
   JOB_USER of voxdag_job_fn). */
typedef struct voxdagi_batch {
    void *(*fn)(void *);
    char *jobs;
    size_t size;
    uint32_t count;
    int pooled; /* running on a pool (else the wait runs it) */
} voxdagi_batch;

static void voxdagi_batch_job(void *user, uint32_t index) {
    voxdagi_batch *bt = (voxdagi_batch *)user;
    bt->fn(bt->jobs + (size_t)index * bt->size);
}

#ifndef VOXDAG_NO_THREADS
/* The built-in pool: THREADS - 1 workers started on the first batch and kept
   until the builder is freed. RUN hands a batch to the workers; WAIT takes the
   jobs no worker has taken yet, then waits for the rest. */
typedef struct voxdagi_pool {
    voxdagi_lock_t lock;
    voxdagi_cond_t wake, done;
    voxdag_job_fn job;
    void *job_user;
    uint32_t count, next, finished, batch, workers;
    int quit;
    voxdagi_thread_t tid[VOXDAGI_MAX_THREADS - 1];
} voxdagi_pool;

/* Runs jobs of the current batch until none is left; called and returns with
   the lock held. */
static void voxdagi_pool_take(voxdagi_pool *p) {
    while (p->next < p->count) {
        uint32_t i = p->next++;
        voxdagi_unlock(&p->lock);
        p->job(p->job_user, i);
        voxdagi_lock(&p->lock);
        if (++p->finished == p->count) voxdagi_cond_wake_all(&p->done);
    }
}

static void voxdagi_pool_worker(voxdagi_pool *p) {
    uint32_t seen = 0;
    voxdagi_lock(&p->lock);
    while (!p->quit) {
        if (p->batch == seen) {
            voxdagi_cond_wait(&p->wake, &p->lock);
            continue;
        }
        seen = p->batch;
        voxdagi_pool_take(p);
    }
    voxdagi_unlock(&p->lock);
}

#if defined(_WIN32)
static DWORD WINAPI voxdagi_pool_main(LPVOID p) {
    voxdagi_pool_worker((voxdagi_pool *)p);
    return 0;
}
#else
static void *voxdagi_pool_main(void *p) {
    voxdagi_pool_worker((voxdagi_pool *)p);
    return NULL;
}
#endif

/* Starts up to WORKERS threads (those the system refuses are left to WAIT). */
static void voxdagi_pool_start(voxdagi_pool *p, uint32_t workers) {
    memset(p, 0, sizeof *p);
    voxdagi_lock_init(&p->lock);
    voxdagi_cond_init(&p->wake);
    voxdagi_cond_init(&p->done);
    for (; p->workers < workers; p->workers++) {
#if defined(_WIN32)
        p->tid[p->workers] = CreateThread(NULL, 0, voxdagi_pool_main, p, 0, NULL);
        if (!p->tid[p->workers]) break;
#else
        if (pthread_create(&p->tid[p->workers], NULL, voxdagi_pool_main, p) != 0) break;
#endif
    }
}

static void voxdagi_pool_run(void *user, voxdag_job_fn job, void *job_user, uint32_t count) {
    voxdagi_pool *p = (voxdagi_pool *)user;
    voxdagi_lock(&p->lock);
    p->job = job;
    p->job_user = job_user;
    p->count = count;
    p->next = p->finished = 0;
    p->batch++;
    voxdagi_cond_wake_all(&p->wake);
    voxdagi_unlock(&p->lock);
}

static void voxdagi_pool_wait(void *user) {
    voxdagi_pool *p = (voxdagi_pool *)user;
    voxdagi_lock(&p->lock);
    voxdagi_pool_take(p);
    while (p->finished < p->count) voxdagi_cond_wait(&p->done, &p->lock);
    voxdagi_unlock(&p->lock);
}

static void voxdagi_pool_stop(voxdagi_pool *p) {
    uint32_t t;
    voxdagi_lock(&p->lock);
    p->quit = 1;
    voxdagi_cond_wake_all(&p->wake);
    voxdagi_unlock(&p->lock);
    for (t = 0; t < p->workers; t++) {
#if defined(_WIN32)
        WaitForSingleObject(p->tid[t], INFINITE);
        CloseHandle(p->tid[t]);
#else
        pthread_join(p->tid[t], NULL);
#endif
    }
    voxdagi_cond_destroy(&p->wake);
    voxdagi_cond_destroy(&p->done);
    voxdagi_lock_destroy(&p->lock);
}
#endif

/* A team of threads for one call: THREADS (1: the calling thread only) on
   the host's POOL or on the built-in pool, started on the first batch and
   kept until voxdagi_team_stop. */
typedef struct voxdagi_team {
    uint32_t threads;
    voxdag_thread_pool pool;     /* the host's (run NULL: the built-in one) */
    voxdagi_batch batch;         /* between voxdagi_batch_start and _wait */
    voxdagi_mem *mem;            /* where the built-in pool is allocated */
#ifndef VOXDAG_NO_THREADS
    voxdagi_pool *builtin;       /* started on the first batch */
#endif
} voxdagi_team;

/* A team of THREADS (clamped to 1..VOXDAGI_MAX_THREADS; 1 under
   VOXDAG_NO_THREADS) on POOL (NULL or run NULL: the built-in one). */
static void voxdagi_team_init(voxdagi_team *t, voxdagi_mem *mem, uint32_t threads, const voxdag_thread_pool *pool) {
    memset(t, 0, sizeof *t);
    t->mem = mem;
    t->threads = threads < 1 ? 1 : threads > VOXDAGI_MAX_THREADS ? VOXDAGI_MAX_THREADS : threads;
#ifdef VOXDAG_NO_THREADS
    t->threads = 1;
    (void)pool;
#else
    if (pool) t->pool = *pool;
#endif
}

static void voxdagi_team_stop(voxdagi_team *t) {
#ifndef VOXDAG_NO_THREADS
    if (t->builtin) {
        voxdagi_pool_stop(t->builtin);
        voxdagi_free(t->mem, t->builtin, sizeof *t->builtin);
        t->builtin = NULL;
    }
#else
    (void)t;
#endif
}

#ifndef VOXDAG_NO_THREADS
/* Whether team T has a pool: the host's, or the built-in one, started here
   on first use (0 when that cannot be allocated). */
static int voxdagi_team_ready(voxdagi_team *t) {
    if (t->pool.run || t->builtin) return 1;
    t->builtin = (voxdagi_pool *)voxdagi_alloc(t->mem, sizeof *t->builtin);
    if (t->builtin) voxdagi_pool_start(t->builtin, t->threads - 1);
    return t->builtin != NULL;
}
#endif

/* Starts FN on each of the COUNT SIZE-byte elements of JOBS on the thread
   pool of team T, the host's or the built-in one (started on the first batch),
   while the calling thread does other work; voxdagi_batch_wait ends the batch.
   With one thread (or no pool) the wait runs the jobs itself. */
static void voxdagi_batch_start(voxdagi_team *t, void *(*fn)(void *), void *jobs, size_t size,
                                unsigned count) {
    t->batch.fn = fn;
    t->batch.jobs = (char *)jobs;
    t->batch.size = size;
    t->batch.count = count;
    t->batch.pooled = 0;
#ifndef VOXDAG_NO_THREADS
    if (t->threads < 2 || !count || !voxdagi_team_ready(t)) return; /* the wait does it all */
    if (t->pool.run) t->pool.run(t->pool.user, voxdagi_batch_job, &t->batch, count);
    else voxdagi_pool_run(t->builtin, voxdagi_batch_job, &t->batch, count);
    t->batch.pooled = 1;
#endif
}

static void voxdagi_batch_wait(voxdagi_team *t) {
    uint32_t i;
#ifndef VOXDAG_NO_THREADS
    if (t->batch.pooled) {
        if (t->pool.wait) t->pool.wait(t->pool.user);
        else voxdagi_pool_wait(t->builtin);
        t->batch.pooled = 0;
        return;
    }
#endif
    for (i = 0; i < t->batch.count; i++) voxdagi_batch_job(&t->batch, i);
}

/* Runs FN on the COUNT jobs, in parallel when the team has threads. */
static void voxdagi_run_parallel(voxdagi_team *t, void *(*fn)(void *), void *jobs, size_t size, unsigned count) {
    voxdagi_batch_start(t, fn, jobs, size, count);
    voxdagi_batch_wait(t);
}

#ifdef VOXDAGI_VOXCOLOR
/* voxcolor_thread_pool.run on team T (USER): COUNT jobs on its pool, then
   their wait, or on the calling thread when it has one thread. */
static void voxdagi_team_voxcolor_run(void *user, voxcolor_job_fn job, void *job_user, uint32_t count) {
    voxdagi_team *t = (voxdagi_team *)user;
    uint32_t i;
#ifndef VOXDAG_NO_THREADS
    if (t->threads > 1 && count && voxdagi_team_ready(t)) {
        if (t->pool.run) {
            t->pool.run(t->pool.user, job, job_user, count);
            t->pool.wait(t->pool.user);
        } else {
            voxdagi_pool_run(t->builtin, job, job_user, count);
            voxdagi_pool_wait(t->builtin);
        }
        return;
    }
#endif
    for (i = 0; i < count; i++) job(job_user, i);
}
#endif

// -- Bits: popcount, Morton codes, little-endian access, hashing

static int voxdagi_popcount64(uint64_t x) {
#if (defined(__GNUC__) || defined(__clang__)) && defined(__POPCNT__)
    return __builtin_popcountll(x);
#else /* branch-free; faster than the library call compilers emit without -mpopcnt */
    x = x - ((x >> 1) & 0x5555555555555555ull);
    x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
    x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    return (int)((x * 0x0101010101010101ull) >> 56);
#endif
}

/* The number of bits of V (0 for 0). */
VOXDAGI_INLINE unsigned voxdagi_bit_length(uint64_t v) {
#if defined(__GNUC__) || defined(__clang__)
    return 64u - (unsigned)__builtin_clzll(v | 1) - (v == 0); /* no branch: zeros are common */
#else
    unsigned n = 0;
    if (v >> 32) n += 32, v >>= 32;
    if (v >> 16) n += 16, v >>= 16;
    if (v >> 8) n += 8, v >>= 8;
    if (v >> 4) n += 4, v >>= 4;
    if (v >> 2) n += 2, v >>= 2;
    if (v >> 1) n += 1, v >>= 1;
    return n + (unsigned)v;
#endif
}

/* The position of the lowest set bit of X (X != 0). */
VOXDAGI_INLINE unsigned voxdagi_lowest_bit(uint64_t x) {
#if defined(__GNUC__) || defined(__clang__)
    return (unsigned)__builtin_ctzll(x);
#else
    return (unsigned)voxdagi_popcount64((x & (0 - x)) - 1);
#endif
}

/* Bit i of a byte moved to bit 3i, for all 256 bytes, built by the
   preprocessor. */
#define VOXDAGI_S8(v)                                                                        \
    (((v) & 1) | ((v) & 2) << 2 | ((v) & 4) << 4 | ((v) & 8) << 6 | ((v) & 16) << 8 |            \
     ((v) & 32) << 10 | ((v) & 64) << 12 | ((v) & 128) << 14)
#define VOXDAGI_S4(v) VOXDAGI_S8(v), VOXDAGI_S8((v) + 1), VOXDAGI_S8((v) + 2), VOXDAGI_S8((v) + 3)
#define VOXDAGI_S16(v) VOXDAGI_S4(v), VOXDAGI_S4((v) + 4), VOXDAGI_S4((v) + 8), VOXDAGI_S4((v) + 12)
#define VOXDAGI_S64(v) VOXDAGI_S16(v), VOXDAGI_S16((v) + 16), VOXDAGI_S16((v) + 32), VOXDAGI_S16((v) + 48)
static const uint32_t voxdagi_spread8[256] = {VOXDAGI_S64(0u), VOXDAGI_S64(64u), VOXDAGI_S64(128u),
                                              VOXDAGI_S64(192u)};

static uint64_t voxdagi_spread3(uint32_t v) { /* bit i of v -> bit 3i, 21 bits */
    return (uint64_t)voxdagi_spread8[v & 0xFF] | (uint64_t)voxdagi_spread8[(v >> 8) & 0xFF] << 24 |
           (uint64_t)voxdagi_spread8[(v >> 16) & 0x1F] << 48;
}

static uint32_t voxdagi_compact3(uint64_t x) { /* inverse of voxdagi_spread3 */
    x &= 0x1249249249249249ull;
    x = (x | x >> 2) & 0x10C30C30C30C30C3ull;
    x = (x | x >> 4) & 0x100F00F00F00F00Full;
    x = (x | x >> 8) & 0x1F0000FF0000FFull;
    x = (x | x >> 16) & 0x1F00000000FFFFull;
    x = (x | x >> 32) & 0x1FFFFFull;
    return (uint32_t)x;
}

VOXDAG_API uint64_t voxdag_morton_encode(uint32_t x, uint32_t y, uint32_t z) {
    return voxdagi_spread3(x) | voxdagi_spread3(y) << 1 | voxdagi_spread3(z) << 2;
}

VOXDAG_API void voxdag_morton_decode(uint64_t code, uint32_t *x, uint32_t *y, uint32_t *z) {
    if (x) *x = voxdagi_compact3(code);
    if (y) *y = voxdagi_compact3(code >> 1);
    if (z) *z = voxdagi_compact3(code >> 2);
}

static uint64_t voxdagi_le(const uint8_t *p, unsigned n) { /* n <= 8 bytes */
    uint64_t v = 0;
    while (n--) v = v << 8 | p[n];
    return v;
}

/* Little-endian hosts that read unaligned words cheaply. */
#if (defined(__x86_64__) || defined(__i386__) || defined(_M_X64) || defined(__aarch64__)) && \
    (!defined(__BYTE_ORDER__) || __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__)
#define VOXDAGI_LE_WORDS 1
#else
#define VOXDAGI_LE_WORDS 0
#endif

/* Reads N bytes at P where at least 8 bytes are readable (padded data). */
static uint64_t voxdagi_le_fast(const uint8_t *p, unsigned n) {
#if VOXDAGI_LE_WORDS
    uint64_t v;
    memcpy(&v, p, 8);
    return n >= 8 ? v : v & ((1ull << (8 * n)) - 1);
#else
    return voxdagi_le(p, n);
#endif
}

static unsigned voxdagi_le16(const uint8_t *p) {
#if VOXDAGI_LE_WORDS
    uint16_t v;
    memcpy(&v, p, 2);
    return v;
#else
    return (unsigned)p[0] | (unsigned)p[1] << 8;
#endif
}

static void voxdagi_put_le(uint8_t *p, uint64_t v, unsigned n) {
    unsigned i;
    for (i = 0; i < n; i++) p[i] = (uint8_t)(v >> (8 * i));
}

#ifndef VOXDAG_NO_BUILD
static uint64_t voxdagi_mix64(uint64_t z) { /* a strong 64-bit finalizer */
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
#endif

/* CRC-32C (Castagnoli, reflected polynomial 0x82F63B78), slicing by 16:
   sixteen bytes per step through sixteen 256-entry tables, T[k][b] being the
   CRC register after byte b followed by k zero bytes. T[0] is a constant
   (the tests compute it bit by bit); the other fifteen (15 KiB) are built
   from it per call in about 4,000 steps, only for inputs of 4 KiB or more
   (sections), so that small inputs (the header, the section table, the
   sections of a small file) go byte by byte through T[0] with nothing to
   build. The data is read byte by byte, so the result does not depend on
   alignment or byte order. */
static const uint32_t voxdagi_crc_t0[256] = {
    0x00000000u, 0xF26B8303u, 0xE13B70F7u, 0x1350F3F4u, 0xC79A971Fu, 0x35F1141Cu, 0x26A1E7E8u, 0xD4CA64EBu,
    0x8AD958CFu, 0x78B2DBCCu, 0x6BE22838u, 0x9989AB3Bu, 0x4D43CFD0u, 0xBF284CD3u, 0xAC78BF27u, 0x5E133C24u,
    0x105EC76Fu, 0xE235446Cu, 0xF165B798u, 0x030E349Bu, 0xD7C45070u, 0x25AFD373u, 0x36FF2087u, 0xC494A384u,
    0x9A879FA0u, 0x68EC1CA3u, 0x7BBCEF57u, 0x89D76C54u, 0x5D1D08BFu, 0xAF768BBCu, 0xBC267848u, 0x4E4DFB4Bu,
    0x20BD8EDEu, 0xD2D60DDDu, 0xC186FE29u, 0x33ED7D2Au, 0xE72719C1u, 0x154C9AC2u, 0x061C6936u, 0xF477EA35u,
    0xAA64D611u, 0x580F5512u, 0x4B5FA6E6u, 0xB93425E5u, 0x6DFE410Eu, 0x9F95C20Du, 0x8CC531F9u, 0x7EAEB2FAu,
    0x30E349B1u, 0xC288CAB2u, 0xD1D83946u, 0x23B3BA45u, 0xF779DEAEu, 0x05125DADu, 0x1642AE59u, 0xE4292D5Au,
    0xBA3A117Eu, 0x4851927Du, 0x5B016189u, 0xA96AE28Au, 0x7DA08661u, 0x8FCB0562u, 0x9C9BF696u, 0x6EF07595u,
    0x417B1DBCu, 0xB3109EBFu, 0xA0406D4Bu, 0x522BEE48u, 0x86E18AA3u, 0x748A09A0u, 0x67DAFA54u, 0x95B17957u,
    0xCBA24573u, 0x39C9C670u, 0x2A993584u, 0xD8F2B687u, 0x0C38D26Cu, 0xFE53516Fu, 0xED03A29Bu, 0x1F682198u,
    0x5125DAD3u, 0xA34E59D0u, 0xB01EAA24u, 0x42752927u, 0x96BF4DCCu, 0x64D4CECFu, 0x77843D3Bu, 0x85EFBE38u,
    0xDBFC821Cu, 0x2997011Fu, 0x3AC7F2EBu, 0xC8AC71E8u, 0x1C661503u, 0xEE0D9600u, 0xFD5D65F4u, 0x0F36E6F7u,
    0x61C69362u, 0x93AD1061u, 0x80FDE395u, 0x72966096u, 0xA65C047Du, 0x5437877Eu, 0x4767748Au, 0xB50CF789u,
    0xEB1FCBADu, 0x197448AEu, 0x0A24BB5Au, 0xF84F3859u, 0x2C855CB2u, 0xDEEEDFB1u, 0xCDBE2C45u, 0x3FD5AF46u,
    0x7198540Du, 0x83F3D70Eu, 0x90A324FAu, 0x62C8A7F9u, 0xB602C312u, 0x44694011u, 0x5739B3E5u, 0xA55230E6u,
    0xFB410CC2u, 0x092A8FC1u, 0x1A7A7C35u, 0xE811FF36u, 0x3CDB9BDDu, 0xCEB018DEu, 0xDDE0EB2Au, 0x2F8B6829u,
    0x82F63B78u, 0x709DB87Bu, 0x63CD4B8Fu, 0x91A6C88Cu, 0x456CAC67u, 0xB7072F64u, 0xA457DC90u, 0x563C5F93u,
    0x082F63B7u, 0xFA44E0B4u, 0xE9141340u, 0x1B7F9043u, 0xCFB5F4A8u, 0x3DDE77ABu, 0x2E8E845Fu, 0xDCE5075Cu,
    0x92A8FC17u, 0x60C37F14u, 0x73938CE0u, 0x81F80FE3u, 0x55326B08u, 0xA759E80Bu, 0xB4091BFFu, 0x466298FCu,
    0x1871A4D8u, 0xEA1A27DBu, 0xF94AD42Fu, 0x0B21572Cu, 0xDFEB33C7u, 0x2D80B0C4u, 0x3ED04330u, 0xCCBBC033u,
    0xA24BB5A6u, 0x502036A5u, 0x4370C551u, 0xB11B4652u, 0x65D122B9u, 0x97BAA1BAu, 0x84EA524Eu, 0x7681D14Du,
    0x2892ED69u, 0xDAF96E6Au, 0xC9A99D9Eu, 0x3BC21E9Du, 0xEF087A76u, 0x1D63F975u, 0x0E330A81u, 0xFC588982u,
    0xB21572C9u, 0x407EF1CAu, 0x532E023Eu, 0xA145813Du, 0x758FE5D6u, 0x87E466D5u, 0x94B49521u, 0x66DF1622u,
    0x38CC2A06u, 0xCAA7A905u, 0xD9F75AF1u, 0x2B9CD9F2u, 0xFF56BD19u, 0x0D3D3E1Au, 0x1E6DCDEEu, 0xEC064EEDu,
    0xC38D26C4u, 0x31E6A5C7u, 0x22B65633u, 0xD0DDD530u, 0x0417B1DBu, 0xF67C32D8u, 0xE52CC12Cu, 0x1747422Fu,
    0x49547E0Bu, 0xBB3FFD08u, 0xA86F0EFCu, 0x5A048DFFu, 0x8ECEE914u, 0x7CA56A17u, 0x6FF599E3u, 0x9D9E1AE0u,
    0xD3D3E1ABu, 0x21B862A8u, 0x32E8915Cu, 0xC083125Fu, 0x144976B4u, 0xE622F5B7u, 0xF5720643u, 0x07198540u,
    0x590AB964u, 0xAB613A67u, 0xB831C993u, 0x4A5A4A90u, 0x9E902E7Bu, 0x6CFBAD78u, 0x7FAB5E8Cu, 0x8DC0DD8Fu,
    0xE330A81Au, 0x115B2B19u, 0x020BD8EDu, 0xF0605BEEu, 0x24AA3F05u, 0xD6C1BC06u, 0xC5914FF2u, 0x37FACCF1u,
    0x69E9F0D5u, 0x9B8273D6u, 0x88D28022u, 0x7AB90321u, 0xAE7367CAu, 0x5C18E4C9u, 0x4F48173Du, 0xBD23943Eu,
    0xF36E6F75u, 0x0105EC76u, 0x12551F82u, 0xE03E9C81u, 0x34F4F86Au, 0xC69F7B69u, 0xD5CF889Du, 0x27A40B9Eu,
    0x79B737BAu, 0x8BDCB4B9u, 0x988C474Du, 0x6AE7C44Eu, 0xBE2DA0A5u, 0x4C4623A6u, 0x5F16D052u, 0xAD7D5351u};

typedef struct voxdagi_crc_tables {
    uint32_t t[16][256];
} voxdagi_crc_tables;

static void voxdagi_crc_tables_init(voxdagi_crc_tables *c) {
    uint32_t i, k;
    memcpy(c->t[0], voxdagi_crc_t0, sizeof voxdagi_crc_t0);
    for (k = 1; k < 16; k++)
        for (i = 0; i < 256; i++) c->t[k][i] = (c->t[k - 1][i] >> 8) ^ c->t[0][c->t[k - 1][i] & 0xFF];
}

static uint32_t voxdagi_le32_bytes(const uint8_t *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The CRC register after the 16 bytes at P, from register CRC; the four
   lookups of each 4 bytes are XORed apart, so that a step's loads overlap. */
VOXDAGI_INLINE uint32_t voxdagi_crc_step(const voxdagi_crc_tables *c, uint32_t crc, const uint8_t *p) {
    const uint32_t(*t)[256] = c->t;
    uint32_t a = crc ^ voxdagi_le32_bytes(p), b = voxdagi_le32_bytes(p + 4), d = voxdagi_le32_bytes(p + 8),
             e = voxdagi_le32_bytes(p + 12);
    uint32_t x0 = t[15][a & 0xFF] ^ t[14][a >> 8 & 0xFF] ^ t[13][a >> 16 & 0xFF] ^ t[12][a >> 24];
    uint32_t x1 = t[11][b & 0xFF] ^ t[10][b >> 8 & 0xFF] ^ t[9][b >> 16 & 0xFF] ^ t[8][b >> 24];
    uint32_t x2 = t[7][d & 0xFF] ^ t[6][d >> 8 & 0xFF] ^ t[5][d >> 16 & 0xFF] ^ t[4][d >> 24];
    uint32_t x3 = t[3][e & 0xFF] ^ t[2][e >> 8 & 0xFF] ^ t[1][e >> 16 & 0xFF] ^ t[0][e >> 24];
    return (x0 ^ x1) ^ (x2 ^ x3);
}

/* A * B modulo the CRC polynomial, both reflected (bit 31 is x^0). */
static uint32_t voxdagi_crc_mulmod(uint32_t a, uint32_t b) {
    uint32_t m, p = 0;
    for (m = 1u << 31; m; m >>= 1) { /* B times x^k for bit k of A */
        if (a & m) p ^= b;
        b = b & 1 ? (b >> 1) ^ 0x82F63B78u : b >> 1;
    }
    return p;
}

/* The CRC-32C of A followed by B from CRC1 (A's), CRC2 (B's) and B's length:
   A's register moved past N zero bytes is A's times x^(8N) (zlib's
   crc32_combine). */
static uint32_t voxdagi_crc_combine(uint32_t crc1, uint32_t crc2, uint64_t n) {
    uint32_t x = 1u << 31, sq = 1u << 23; /* x^0 and x^8 */
    for (; n; n >>= 1, sq = voxdagi_crc_mulmod(sq, sq))
        if (n & 1) x = voxdagi_crc_mulmod(sq, x);
    return voxdagi_crc_mulmod(x, crc1) ^ crc2;
}

/* From 64 KiB on, three thirds at once, combined after: each step waits for
   the previous one's lookups, and three independent chains fill that wait. */
static uint32_t voxdagi_crc32c(const uint8_t *p, uint64_t n) {
    voxdagi_crc_tables c;
    uint32_t crc = 0xFFFFFFFFu;
    int sliced = n >= 4096;
    if (sliced) voxdagi_crc_tables_init(&c);
    if (n >= 65536) {
        uint64_t part = n / 48 * 16, i; /* a third, in whole steps */
        uint32_t c1 = 0xFFFFFFFFu, c2 = 0xFFFFFFFFu;
        for (i = 0; i < part; i += 16) {
            crc = voxdagi_crc_step(&c, crc, p + i);
            c1 = voxdagi_crc_step(&c, c1, p + part + i);
            c2 = voxdagi_crc_step(&c, c2, p + 2 * part + i);
        }
        crc = ~voxdagi_crc_combine(voxdagi_crc_combine(~crc, ~c1, part), ~c2, part);
        p += 3 * part, n -= 3 * part;
    }
    for (; sliced && n >= 16; n -= 16, p += 16) crc = voxdagi_crc_step(&c, crc, p);
    while (n--) crc = voxdagi_crc_t0[(crc ^ *p++) & 0xFF] ^ (crc >> 8);
    return ~crc;
}

#ifndef VOXDAG_NO_BUILD
static unsigned voxdagi_bytes_for(uint64_t v) { /* bytes to hold v, >= 1 */
    unsigned n = 1;
    while (n < 8 && (v >> (8 * n))) n++;
    return n;
}
#endif

// -- The cube group: the 48 symmetries of a cube (SSVDAG 3, extended)
//
// A transform T = (perm, m) first moves axis a to axis perm[a], then mirrors
// every axis a whose bit is set in m about the cube's centre. T is numbered
// perm * 8 + m, the permutations in lexicographic order, so 0 is the identity
// and 0..7 are the eight reflections (a group of their own). T acts the same
// way on a child octant (bit a: the upper half along axis a) and on each of
// the two coordinate-bit triples of a Morton position inside a 4^3 brick.
// The tables below depend on nothing else, so every DAG and every build
// shares these constant copies; they were printed from this definition, and
// the tests derive each entry again from it (test_format.c, "cube tables").

#define VOXDAGI_TRANSFORMS 48

typedef struct voxdagi_cube {
    uint8_t act[VOXDAGI_TRANSFORMS][8];  /* T(i) for octant i */
    uint8_t comp[VOXDAGI_TRANSFORMS][VOXDAGI_TRANSFORMS]; /* comp[A][B]: B, then A */
    uint8_t inv[VOXDAGI_TRANSFORMS];
} voxdagi_cube;

static const voxdagi_cube voxdagi_cube_tables = {
    {/* act */
     {0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 3, 2, 5, 4, 7, 6}, {2, 3, 0, 1, 6, 7, 4, 5}, {3, 2, 1, 0, 7, 6, 5, 4},
     {4, 5, 6, 7, 0, 1, 2, 3}, {5, 4, 7, 6, 1, 0, 3, 2}, {6, 7, 4, 5, 2, 3, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0},
     {0, 1, 4, 5, 2, 3, 6, 7}, {1, 0, 5, 4, 3, 2, 7, 6}, {2, 3, 6, 7, 0, 1, 4, 5}, {3, 2, 7, 6, 1, 0, 5, 4},
     {4, 5, 0, 1, 6, 7, 2, 3}, {5, 4, 1, 0, 7, 6, 3, 2}, {6, 7, 2, 3, 4, 5, 0, 1}, {7, 6, 3, 2, 5, 4, 1, 0},
     {0, 2, 1, 3, 4, 6, 5, 7}, {1, 3, 0, 2, 5, 7, 4, 6}, {2, 0, 3, 1, 6, 4, 7, 5}, {3, 1, 2, 0, 7, 5, 6, 4},
     {4, 6, 5, 7, 0, 2, 1, 3}, {5, 7, 4, 6, 1, 3, 0, 2}, {6, 4, 7, 5, 2, 0, 3, 1}, {7, 5, 6, 4, 3, 1, 2, 0},
     {0, 2, 4, 6, 1, 3, 5, 7}, {1, 3, 5, 7, 0, 2, 4, 6}, {2, 0, 6, 4, 3, 1, 7, 5}, {3, 1, 7, 5, 2, 0, 6, 4},
     {4, 6, 0, 2, 5, 7, 1, 3}, {5, 7, 1, 3, 4, 6, 0, 2}, {6, 4, 2, 0, 7, 5, 3, 1}, {7, 5, 3, 1, 6, 4, 2, 0},
     {0, 4, 1, 5, 2, 6, 3, 7}, {1, 5, 0, 4, 3, 7, 2, 6}, {2, 6, 3, 7, 0, 4, 1, 5}, {3, 7, 2, 6, 1, 5, 0, 4},
     {4, 0, 5, 1, 6, 2, 7, 3}, {5, 1, 4, 0, 7, 3, 6, 2}, {6, 2, 7, 3, 4, 0, 5, 1}, {7, 3, 6, 2, 5, 1, 4, 0},
     {0, 4, 2, 6, 1, 5, 3, 7}, {1, 5, 3, 7, 0, 4, 2, 6}, {2, 6, 0, 4, 3, 7, 1, 5}, {3, 7, 1, 5, 2, 6, 0, 4},
     {4, 0, 6, 2, 5, 1, 7, 3}, {5, 1, 7, 3, 4, 0, 6, 2}, {6, 2, 4, 0, 7, 3, 5, 1}, {7, 3, 5, 1, 6, 2, 4, 0}},
    {/* comp */
     {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23,
      24, 25, 26, 27, 28, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 45, 46, 47},
     {1, 0, 3, 2, 5, 4, 7, 6, 9, 8, 11, 10, 13, 12, 15, 14, 17, 16, 19, 18, 21, 20, 23, 22,
      25, 24, 27, 26, 29, 28, 31, 30, 33, 32, 35, 34, 37, 36, 39, 38, 41, 40, 43, 42, 45, 44, 47, 46},
     {2, 3, 0, 1, 6, 7, 4, 5, 10, 11, 8, 9, 14, 15, 12, 13, 18, 19, 16, 17, 22, 23, 20, 21,
      26, 27, 24, 25, 30, 31, 28, 29, 34, 35, 32, 33, 38, 39, 36, 37, 42, 43, 40, 41, 46, 47, 44, 45},
     {3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 19, 18, 17, 16, 23, 22, 21, 20,
      27, 26, 25, 24, 31, 30, 29, 28, 35, 34, 33, 32, 39, 38, 37, 36, 43, 42, 41, 40, 47, 46, 45, 44},
     {4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11, 20, 21, 22, 23, 16, 17, 18, 19,
      28, 29, 30, 31, 24, 25, 26, 27, 36, 37, 38, 39, 32, 33, 34, 35, 44, 45, 46, 47, 40, 41, 42, 43},
     {5, 4, 7, 6, 1, 0, 3, 2, 13, 12, 15, 14, 9, 8, 11, 10, 21, 20, 23, 22, 17, 16, 19, 18,
      29, 28, 31, 30, 25, 24, 27, 26, 37, 36, 39, 38, 33, 32, 35, 34, 45, 44, 47, 46, 41, 40, 43, 42},
     {6, 7, 4, 5, 2, 3, 0, 1, 14, 15, 12, 13, 10, 11, 8, 9, 22, 23, 20, 21, 18, 19, 16, 17,
      30, 31, 28, 29, 26, 27, 24, 25, 38, 39, 36, 37, 34, 35, 32, 33, 46, 47, 44, 45, 42, 43, 40, 41},
     {7, 6, 5, 4, 3, 2, 1, 0, 15, 14, 13, 12, 11, 10, 9, 8, 23, 22, 21, 20, 19, 18, 17, 16,
      31, 30, 29, 28, 27, 26, 25, 24, 39, 38, 37, 36, 35, 34, 33, 32, 47, 46, 45, 44, 43, 42, 41, 40},
     {8, 9, 12, 13, 10, 11, 14, 15, 0, 1, 4, 5, 2, 3, 6, 7, 32, 33, 36, 37, 34, 35, 38, 39,
      40, 41, 44, 45, 42, 43, 46, 47, 16, 17, 20, 21, 18, 19, 22, 23, 24, 25, 28, 29, 26, 27, 30, 31},
     {9, 8, 13, 12, 11, 10, 15, 14, 1, 0, 5, 4, 3, 2, 7, 6, 33, 32, 37, 36, 35, 34, 39, 38,
      41, 40, 45, 44, 43, 42, 47, 46, 17, 16, 21, 20, 19, 18, 23, 22, 25, 24, 29, 28, 27, 26, 31, 30},
     {10, 11, 14, 15, 8, 9, 12, 13, 2, 3, 6, 7, 0, 1, 4, 5, 34, 35, 38, 39, 32, 33, 36, 37,
      42, 43, 46, 47, 40, 41, 44, 45, 18, 19, 22, 23, 16, 17, 20, 21, 26, 27, 30, 31, 24, 25, 28, 29},
     {11, 10, 15, 14, 9, 8, 13, 12, 3, 2, 7, 6, 1, 0, 5, 4, 35, 34, 39, 38, 33, 32, 37, 36,
      43, 42, 47, 46, 41, 40, 45, 44, 19, 18, 23, 22, 17, 16, 21, 20, 27, 26, 31, 30, 25, 24, 29, 28},
     {12, 13, 8, 9, 14, 15, 10, 11, 4, 5, 0, 1, 6, 7, 2, 3, 36, 37, 32, 33, 38, 39, 34, 35,
      44, 45, 40, 41, 46, 47, 42, 43, 20, 21, 16, 17, 22, 23, 18, 19, 28, 29, 24, 25, 30, 31, 26, 27},
     {13, 12, 9, 8, 15, 14, 11, 10, 5, 4, 1, 0, 7, 6, 3, 2, 37, 36, 33, 32, 39, 38, 35, 34,
      45, 44, 41, 40, 47, 46, 43, 42, 21, 20, 17, 16, 23, 22, 19, 18, 29, 28, 25, 24, 31, 30, 27, 26},
     {14, 15, 10, 11, 12, 13, 8, 9, 6, 7, 2, 3, 4, 5, 0, 1, 38, 39, 34, 35, 36, 37, 32, 33,
      46, 47, 42, 43, 44, 45, 40, 41, 22, 23, 18, 19, 20, 21, 16, 17, 30, 31, 26, 27, 28, 29, 24, 25},
     {15, 14, 11, 10, 13, 12, 9, 8, 7, 6, 3, 2, 5, 4, 1, 0, 39, 38, 35, 34, 37, 36, 33, 32,
      47, 46, 43, 42, 45, 44, 41, 40, 23, 22, 19, 18, 21, 20, 17, 16, 31, 30, 27, 26, 29, 28, 25, 24},
     {16, 18, 17, 19, 20, 22, 21, 23, 24, 26, 25, 27, 28, 30, 29, 31, 0, 2, 1, 3, 4, 6, 5, 7,
      8, 10, 9, 11, 12, 14, 13, 15, 40, 42, 41, 43, 44, 46, 45, 47, 32, 34, 33, 35, 36, 38, 37, 39},
     {17, 19, 16, 18, 21, 23, 20, 22, 25, 27, 24, 26, 29, 31, 28, 30, 1, 3, 0, 2, 5, 7, 4, 6,
      9, 11, 8, 10, 13, 15, 12, 14, 41, 43, 40, 42, 45, 47, 44, 46, 33, 35, 32, 34, 37, 39, 36, 38},
     {18, 16, 19, 17, 22, 20, 23, 21, 26, 24, 27, 25, 30, 28, 31, 29, 2, 0, 3, 1, 6, 4, 7, 5,
      10, 8, 11, 9, 14, 12, 15, 13, 42, 40, 43, 41, 46, 44, 47, 45, 34, 32, 35, 33, 38, 36, 39, 37},
     {19, 17, 18, 16, 23, 21, 22, 20, 27, 25, 26, 24, 31, 29, 30, 28, 3, 1, 2, 0, 7, 5, 6, 4,
      11, 9, 10, 8, 15, 13, 14, 12, 43, 41, 42, 40, 47, 45, 46, 44, 35, 33, 34, 32, 39, 37, 38, 36},
     {20, 22, 21, 23, 16, 18, 17, 19, 28, 30, 29, 31, 24, 26, 25, 27, 4, 6, 5, 7, 0, 2, 1, 3,
      12, 14, 13, 15, 8, 10, 9, 11, 44, 46, 45, 47, 40, 42, 41, 43, 36, 38, 37, 39, 32, 34, 33, 35},
     {21, 23, 20, 22, 17, 19, 16, 18, 29, 31, 28, 30, 25, 27, 24, 26, 5, 7, 4, 6, 1, 3, 0, 2,
      13, 15, 12, 14, 9, 11, 8, 10, 45, 47, 44, 46, 41, 43, 40, 42, 37, 39, 36, 38, 33, 35, 32, 34},
     {22, 20, 23, 21, 18, 16, 19, 17, 30, 28, 31, 29, 26, 24, 27, 25, 6, 4, 7, 5, 2, 0, 3, 1,
      14, 12, 15, 13, 10, 8, 11, 9, 46, 44, 47, 45, 42, 40, 43, 41, 38, 36, 39, 37, 34, 32, 35, 33},
     {23, 21, 22, 20, 19, 17, 18, 16, 31, 29, 30, 28, 27, 25, 26, 24, 7, 5, 6, 4, 3, 1, 2, 0,
      15, 13, 14, 12, 11, 9, 10, 8, 47, 45, 46, 44, 43, 41, 42, 40, 39, 37, 38, 36, 35, 33, 34, 32},
     {24, 26, 28, 30, 25, 27, 29, 31, 16, 18, 20, 22, 17, 19, 21, 23, 40, 42, 44, 46, 41, 43, 45, 47,
      32, 34, 36, 38, 33, 35, 37, 39, 0, 2, 4, 6, 1, 3, 5, 7, 8, 10, 12, 14, 9, 11, 13, 15},
     {25, 27, 29, 31, 24, 26, 28, 30, 17, 19, 21, 23, 16, 18, 20, 22, 41, 43, 45, 47, 40, 42, 44, 46,
      33, 35, 37, 39, 32, 34, 36, 38, 1, 3, 5, 7, 0, 2, 4, 6, 9, 11, 13, 15, 8, 10, 12, 14},
     {26, 24, 30, 28, 27, 25, 31, 29, 18, 16, 22, 20, 19, 17, 23, 21, 42, 40, 46, 44, 43, 41, 47, 45,
      34, 32, 38, 36, 35, 33, 39, 37, 2, 0, 6, 4, 3, 1, 7, 5, 10, 8, 14, 12, 11, 9, 15, 13},
     {27, 25, 31, 29, 26, 24, 30, 28, 19, 17, 23, 21, 18, 16, 22, 20, 43, 41, 47, 45, 42, 40, 46, 44,
      35, 33, 39, 37, 34, 32, 38, 36, 3, 1, 7, 5, 2, 0, 6, 4, 11, 9, 15, 13, 10, 8, 14, 12},
     {28, 30, 24, 26, 29, 31, 25, 27, 20, 22, 16, 18, 21, 23, 17, 19, 44, 46, 40, 42, 45, 47, 41, 43,
      36, 38, 32, 34, 37, 39, 33, 35, 4, 6, 0, 2, 5, 7, 1, 3, 12, 14, 8, 10, 13, 15, 9, 11},
     {29, 31, 25, 27, 28, 30, 24, 26, 21, 23, 17, 19, 20, 22, 16, 18, 45, 47, 41, 43, 44, 46, 40, 42,
      37, 39, 33, 35, 36, 38, 32, 34, 5, 7, 1, 3, 4, 6, 0, 2, 13, 15, 9, 11, 12, 14, 8, 10},
     {30, 28, 26, 24, 31, 29, 27, 25, 22, 20, 18, 16, 23, 21, 19, 17, 46, 44, 42, 40, 47, 45, 43, 41,
      38, 36, 34, 32, 39, 37, 35, 33, 6, 4, 2, 0, 7, 5, 3, 1, 14, 12, 10, 8, 15, 13, 11, 9},
     {31, 29, 27, 25, 30, 28, 26, 24, 23, 21, 19, 17, 22, 20, 18, 16, 47, 45, 43, 41, 46, 44, 42, 40,
      39, 37, 35, 33, 38, 36, 34, 32, 7, 5, 3, 1, 6, 4, 2, 0, 15, 13, 11, 9, 14, 12, 10, 8},
     {32, 36, 33, 37, 34, 38, 35, 39, 40, 44, 41, 45, 42, 46, 43, 47, 8, 12, 9, 13, 10, 14, 11, 15,
      0, 4, 1, 5, 2, 6, 3, 7, 24, 28, 25, 29, 26, 30, 27, 31, 16, 20, 17, 21, 18, 22, 19, 23},
     {33, 37, 32, 36, 35, 39, 34, 38, 41, 45, 40, 44, 43, 47, 42, 46, 9, 13, 8, 12, 11, 15, 10, 14,
      1, 5, 0, 4, 3, 7, 2, 6, 25, 29, 24, 28, 27, 31, 26, 30, 17, 21, 16, 20, 19, 23, 18, 22},
     {34, 38, 35, 39, 32, 36, 33, 37, 42, 46, 43, 47, 40, 44, 41, 45, 10, 14, 11, 15, 8, 12, 9, 13,
      2, 6, 3, 7, 0, 4, 1, 5, 26, 30, 27, 31, 24, 28, 25, 29, 18, 22, 19, 23, 16, 20, 17, 21},
     {35, 39, 34, 38, 33, 37, 32, 36, 43, 47, 42, 46, 41, 45, 40, 44, 11, 15, 10, 14, 9, 13, 8, 12,
      3, 7, 2, 6, 1, 5, 0, 4, 27, 31, 26, 30, 25, 29, 24, 28, 19, 23, 18, 22, 17, 21, 16, 20},
     {36, 32, 37, 33, 38, 34, 39, 35, 44, 40, 45, 41, 46, 42, 47, 43, 12, 8, 13, 9, 14, 10, 15, 11,
      4, 0, 5, 1, 6, 2, 7, 3, 28, 24, 29, 25, 30, 26, 31, 27, 20, 16, 21, 17, 22, 18, 23, 19},
     {37, 33, 36, 32, 39, 35, 38, 34, 45, 41, 44, 40, 47, 43, 46, 42, 13, 9, 12, 8, 15, 11, 14, 10,
      5, 1, 4, 0, 7, 3, 6, 2, 29, 25, 28, 24, 31, 27, 30, 26, 21, 17, 20, 16, 23, 19, 22, 18},
     {38, 34, 39, 35, 36, 32, 37, 33, 46, 42, 47, 43, 44, 40, 45, 41, 14, 10, 15, 11, 12, 8, 13, 9,
      6, 2, 7, 3, 4, 0, 5, 1, 30, 26, 31, 27, 28, 24, 29, 25, 22, 18, 23, 19, 20, 16, 21, 17},
     {39, 35, 38, 34, 37, 33, 36, 32, 47, 43, 46, 42, 45, 41, 44, 40, 15, 11, 14, 10, 13, 9, 12, 8,
      7, 3, 6, 2, 5, 1, 4, 0, 31, 27, 30, 26, 29, 25, 28, 24, 23, 19, 22, 18, 21, 17, 20, 16},
     {40, 44, 42, 46, 41, 45, 43, 47, 32, 36, 34, 38, 33, 37, 35, 39, 24, 28, 26, 30, 25, 29, 27, 31,
      16, 20, 18, 22, 17, 21, 19, 23, 8, 12, 10, 14, 9, 13, 11, 15, 0, 4, 2, 6, 1, 5, 3, 7},
     {41, 45, 43, 47, 40, 44, 42, 46, 33, 37, 35, 39, 32, 36, 34, 38, 25, 29, 27, 31, 24, 28, 26, 30,
      17, 21, 19, 23, 16, 20, 18, 22, 9, 13, 11, 15, 8, 12, 10, 14, 1, 5, 3, 7, 0, 4, 2, 6},
     {42, 46, 40, 44, 43, 47, 41, 45, 34, 38, 32, 36, 35, 39, 33, 37, 26, 30, 24, 28, 27, 31, 25, 29,
      18, 22, 16, 20, 19, 23, 17, 21, 10, 14, 8, 12, 11, 15, 9, 13, 2, 6, 0, 4, 3, 7, 1, 5},
     {43, 47, 41, 45, 42, 46, 40, 44, 35, 39, 33, 37, 34, 38, 32, 36, 27, 31, 25, 29, 26, 30, 24, 28,
      19, 23, 17, 21, 18, 22, 16, 20, 11, 15, 9, 13, 10, 14, 8, 12, 3, 7, 1, 5, 2, 6, 0, 4},
     {44, 40, 46, 42, 45, 41, 47, 43, 36, 32, 38, 34, 37, 33, 39, 35, 28, 24, 30, 26, 29, 25, 31, 27,
      20, 16, 22, 18, 21, 17, 23, 19, 12, 8, 14, 10, 13, 9, 15, 11, 4, 0, 6, 2, 5, 1, 7, 3},
     {45, 41, 47, 43, 44, 40, 46, 42, 37, 33, 39, 35, 36, 32, 38, 34, 29, 25, 31, 27, 28, 24, 30, 26,
      21, 17, 23, 19, 20, 16, 22, 18, 13, 9, 15, 11, 12, 8, 14, 10, 5, 1, 7, 3, 4, 0, 6, 2},
     {46, 42, 44, 40, 47, 43, 45, 41, 38, 34, 36, 32, 39, 35, 37, 33, 30, 26, 28, 24, 31, 27, 29, 25,
      22, 18, 20, 16, 23, 19, 21, 17, 14, 10, 12, 8, 15, 11, 13, 9, 6, 2, 4, 0, 7, 3, 5, 1},
     {47, 43, 45, 41, 46, 42, 44, 40, 39, 35, 37, 33, 38, 34, 36, 32, 31, 27, 29, 25, 30, 26, 28, 24,
      23, 19, 21, 17, 22, 18, 20, 16, 15, 11, 13, 9, 14, 10, 12, 8, 7, 3, 5, 1, 6, 2, 4, 0}},
    {/* inv */
     0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 12, 13, 10, 11, 14, 15, 16, 18, 17, 19, 20, 22, 21, 23,
     32, 36, 33, 37, 34, 38, 35, 39, 24, 26, 28, 30, 25, 27, 29, 31, 40, 44, 42, 46, 41, 45, 43, 47}};

/* voxdagi_occupancy[MI][p]: the world octants w holding a child, for stored
   presence P seen through world-to-stored transform MI (w is full when MI(w)
   is: bit w of the entry is bit MI(w) of P). Each row is given by its
   entries for P below 16 and for P = 16 h, and an entry is the OR of the
   entries of P's two nibbles (a bit permutation is linear). */
#define VOXDAGI_OCCUPANCY_ROWS(X) \
    X(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15,  0, 16, 32, 48, 64, 80, 96, 112, 128, 144, 160, 176, 192, 208, 224, 240) \
    X(0, 2, 1, 3, 8, 10, 9, 11, 4, 6, 5, 7, 12, 14, 13, 15,  0, 32, 16, 48, 128, 160, 144, 176, 64, 96, 80, 112, 192, 224, 208, 240) \
    X(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15,  0, 64, 128, 192, 16, 80, 144, 208, 32, 96, 160, 224, 48, 112, 176, 240) \
    X(0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15,  0, 128, 64, 192, 32, 160, 96, 224, 16, 144, 80, 208, 48, 176, 112, 240) \
    X(0, 16, 32, 48, 64, 80, 96, 112, 128, 144, 160, 176, 192, 208, 224, 240,  0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15) \
    X(0, 32, 16, 48, 128, 160, 144, 176, 64, 96, 80, 112, 192, 224, 208, 240,  0, 2, 1, 3, 8, 10, 9, 11, 4, 6, 5, 7, 12, 14, 13, 15) \
    X(0, 64, 128, 192, 16, 80, 144, 208, 32, 96, 160, 224, 48, 112, 176, 240,  0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15) \
    X(0, 128, 64, 192, 32, 160, 96, 224, 16, 144, 80, 208, 48, 176, 112, 240,  0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15) \
    X(0, 1, 2, 3, 16, 17, 18, 19, 32, 33, 34, 35, 48, 49, 50, 51,  0, 4, 8, 12, 64, 68, 72, 76, 128, 132, 136, 140, 192, 196, 200, 204) \
    X(0, 2, 1, 3, 32, 34, 33, 35, 16, 18, 17, 19, 48, 50, 49, 51,  0, 8, 4, 12, 128, 136, 132, 140, 64, 72, 68, 76, 192, 200, 196, 204) \
    X(0, 16, 32, 48, 1, 17, 33, 49, 2, 18, 34, 50, 3, 19, 35, 51,  0, 64, 128, 192, 4, 68, 132, 196, 8, 72, 136, 200, 12, 76, 140, 204) \
    X(0, 32, 16, 48, 2, 34, 18, 50, 1, 33, 17, 49, 3, 35, 19, 51,  0, 128, 64, 192, 8, 136, 72, 200, 4, 132, 68, 196, 12, 140, 76, 204) \
    X(0, 4, 8, 12, 64, 68, 72, 76, 128, 132, 136, 140, 192, 196, 200, 204,  0, 1, 2, 3, 16, 17, 18, 19, 32, 33, 34, 35, 48, 49, 50, 51) \
    X(0, 8, 4, 12, 128, 136, 132, 140, 64, 72, 68, 76, 192, 200, 196, 204,  0, 2, 1, 3, 32, 34, 33, 35, 16, 18, 17, 19, 48, 50, 49, 51) \
    X(0, 64, 128, 192, 4, 68, 132, 196, 8, 72, 136, 200, 12, 76, 140, 204,  0, 16, 32, 48, 1, 17, 33, 49, 2, 18, 34, 50, 3, 19, 35, 51) \
    X(0, 128, 64, 192, 8, 136, 72, 200, 4, 132, 68, 196, 12, 140, 76, 204,  0, 32, 16, 48, 2, 34, 18, 50, 1, 33, 17, 49, 3, 35, 19, 51) \
    X(0, 1, 4, 5, 2, 3, 6, 7, 8, 9, 12, 13, 10, 11, 14, 15,  0, 16, 64, 80, 32, 48, 96, 112, 128, 144, 192, 208, 160, 176, 224, 240) \
    X(0, 4, 1, 5, 8, 12, 9, 13, 2, 6, 3, 7, 10, 14, 11, 15,  0, 64, 16, 80, 128, 192, 144, 208, 32, 96, 48, 112, 160, 224, 176, 240) \
    X(0, 2, 8, 10, 1, 3, 9, 11, 4, 6, 12, 14, 5, 7, 13, 15,  0, 32, 128, 160, 16, 48, 144, 176, 64, 96, 192, 224, 80, 112, 208, 240) \
    X(0, 8, 2, 10, 4, 12, 6, 14, 1, 9, 3, 11, 5, 13, 7, 15,  0, 128, 32, 160, 64, 192, 96, 224, 16, 144, 48, 176, 80, 208, 112, 240) \
    X(0, 16, 64, 80, 32, 48, 96, 112, 128, 144, 192, 208, 160, 176, 224, 240,  0, 1, 4, 5, 2, 3, 6, 7, 8, 9, 12, 13, 10, 11, 14, 15) \
    X(0, 64, 16, 80, 128, 192, 144, 208, 32, 96, 48, 112, 160, 224, 176, 240,  0, 4, 1, 5, 8, 12, 9, 13, 2, 6, 3, 7, 10, 14, 11, 15) \
    X(0, 32, 128, 160, 16, 48, 144, 176, 64, 96, 192, 224, 80, 112, 208, 240,  0, 2, 8, 10, 1, 3, 9, 11, 4, 6, 12, 14, 5, 7, 13, 15) \
    X(0, 128, 32, 160, 64, 192, 96, 224, 16, 144, 48, 176, 80, 208, 112, 240,  0, 8, 2, 10, 4, 12, 6, 14, 1, 9, 3, 11, 5, 13, 7, 15) \
    X(0, 1, 16, 17, 2, 3, 18, 19, 32, 33, 48, 49, 34, 35, 50, 51,  0, 4, 64, 68, 8, 12, 72, 76, 128, 132, 192, 196, 136, 140, 200, 204) \
    X(0, 16, 1, 17, 32, 48, 33, 49, 2, 18, 3, 19, 34, 50, 35, 51,  0, 64, 4, 68, 128, 192, 132, 196, 8, 72, 12, 76, 136, 200, 140, 204) \
    X(0, 2, 32, 34, 1, 3, 33, 35, 16, 18, 48, 50, 17, 19, 49, 51,  0, 8, 128, 136, 4, 12, 132, 140, 64, 72, 192, 200, 68, 76, 196, 204) \
    X(0, 32, 2, 34, 16, 48, 18, 50, 1, 33, 3, 35, 17, 49, 19, 51,  0, 128, 8, 136, 64, 192, 72, 200, 4, 132, 12, 140, 68, 196, 76, 204) \
    X(0, 4, 64, 68, 8, 12, 72, 76, 128, 132, 192, 196, 136, 140, 200, 204,  0, 1, 16, 17, 2, 3, 18, 19, 32, 33, 48, 49, 34, 35, 50, 51) \
    X(0, 64, 4, 68, 128, 192, 132, 196, 8, 72, 12, 76, 136, 200, 140, 204,  0, 16, 1, 17, 32, 48, 33, 49, 2, 18, 3, 19, 34, 50, 35, 51) \
    X(0, 8, 128, 136, 4, 12, 132, 140, 64, 72, 192, 200, 68, 76, 196, 204,  0, 2, 32, 34, 1, 3, 33, 35, 16, 18, 48, 50, 17, 19, 49, 51) \
    X(0, 128, 8, 136, 64, 192, 72, 200, 4, 132, 12, 140, 68, 196, 76, 204,  0, 32, 2, 34, 16, 48, 18, 50, 1, 33, 3, 35, 17, 49, 19, 51) \
    X(0, 1, 4, 5, 16, 17, 20, 21, 64, 65, 68, 69, 80, 81, 84, 85,  0, 2, 8, 10, 32, 34, 40, 42, 128, 130, 136, 138, 160, 162, 168, 170) \
    X(0, 4, 1, 5, 64, 68, 65, 69, 16, 20, 17, 21, 80, 84, 81, 85,  0, 8, 2, 10, 128, 136, 130, 138, 32, 40, 34, 42, 160, 168, 162, 170) \
    X(0, 16, 64, 80, 1, 17, 65, 81, 4, 20, 68, 84, 5, 21, 69, 85,  0, 32, 128, 160, 2, 34, 130, 162, 8, 40, 136, 168, 10, 42, 138, 170) \
    X(0, 64, 16, 80, 4, 68, 20, 84, 1, 65, 17, 81, 5, 69, 21, 85,  0, 128, 32, 160, 8, 136, 40, 168, 2, 130, 34, 162, 10, 138, 42, 170) \
    X(0, 2, 8, 10, 32, 34, 40, 42, 128, 130, 136, 138, 160, 162, 168, 170,  0, 1, 4, 5, 16, 17, 20, 21, 64, 65, 68, 69, 80, 81, 84, 85) \
    X(0, 8, 2, 10, 128, 136, 130, 138, 32, 40, 34, 42, 160, 168, 162, 170,  0, 4, 1, 5, 64, 68, 65, 69, 16, 20, 17, 21, 80, 84, 81, 85) \
    X(0, 32, 128, 160, 2, 34, 130, 162, 8, 40, 136, 168, 10, 42, 138, 170,  0, 16, 64, 80, 1, 17, 65, 81, 4, 20, 68, 84, 5, 21, 69, 85) \
    X(0, 128, 32, 160, 8, 136, 40, 168, 2, 130, 34, 162, 10, 138, 42, 170,  0, 64, 16, 80, 4, 68, 20, 84, 1, 65, 17, 81, 5, 69, 21, 85) \
    X(0, 1, 16, 17, 4, 5, 20, 21, 64, 65, 80, 81, 68, 69, 84, 85,  0, 2, 32, 34, 8, 10, 40, 42, 128, 130, 160, 162, 136, 138, 168, 170) \
    X(0, 16, 1, 17, 64, 80, 65, 81, 4, 20, 5, 21, 68, 84, 69, 85,  0, 32, 2, 34, 128, 160, 130, 162, 8, 40, 10, 42, 136, 168, 138, 170) \
    X(0, 4, 64, 68, 1, 5, 65, 69, 16, 20, 80, 84, 17, 21, 81, 85,  0, 8, 128, 136, 2, 10, 130, 138, 32, 40, 160, 168, 34, 42, 162, 170) \
    X(0, 64, 4, 68, 16, 80, 20, 84, 1, 65, 5, 69, 17, 81, 21, 85,  0, 128, 8, 136, 32, 160, 40, 168, 2, 130, 10, 138, 34, 162, 42, 170) \
    X(0, 2, 32, 34, 8, 10, 40, 42, 128, 130, 160, 162, 136, 138, 168, 170,  0, 1, 16, 17, 4, 5, 20, 21, 64, 65, 80, 81, 68, 69, 84, 85) \
    X(0, 32, 2, 34, 128, 160, 130, 162, 8, 40, 10, 42, 136, 168, 138, 170,  0, 16, 1, 17, 64, 80, 65, 81, 4, 20, 5, 21, 68, 84, 69, 85) \
    X(0, 8, 128, 136, 2, 10, 130, 138, 32, 40, 160, 168, 34, 42, 162, 170,  0, 4, 64, 68, 1, 5, 65, 69, 16, 20, 80, 84, 17, 21, 81, 85) \
    X(0, 128, 8, 136, 32, 160, 40, 168, 2, 130, 10, 138, 34, 162, 42, 170,  0, 64, 4, 68, 16, 80, 20, 84, 1, 65, 5, 69, 17, 81, 21, 85)
#define VOXDAGI_OCC16(h, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15) \
    h | l0, h | l1, h | l2, h | l3, h | l4, h | l5, h | l6, h | l7, h | l8, h | l9, h | l10, h | l11, h | l12, \
        h | l13, h | l14, h | l15
#define VOXDAGI_OCC_ROW(l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15, h0, h1, h2, h3, h4, \
                        h5, h6, h7, h8, h9, h10, h11, h12, h13, h14, h15) \
    {VOXDAGI_OCC16(h0, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h1, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h2, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h3, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h4, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h5, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h6, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h7, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h8, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h9, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h10, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h11, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h12, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h13, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h14, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15), \
     VOXDAGI_OCC16(h15, l0, l1, l2, l3, l4, l5, l6, l7, l8, l9, l10, l11, l12, l13, l14, l15)},
static const uint8_t voxdagi_occupancy[VOXDAGI_TRANSFORMS][256] = {VOXDAGI_OCCUPANCY_ROWS(VOXDAGI_OCC_ROW)};
#undef VOXDAGI_OCC_ROW
#undef VOXDAGI_OCC16
#undef VOXDAGI_OCCUPANCY_ROWS

#ifndef VOXDAG_NO_BUILD /* the builder, the voxelizer (up to the file image assembly) */

// -- Unique node stores (one per level) with hash-consing

#define VOXDAGI_NONE 0xFFFFFFFFu    /* an absent child reference */
#define VOXDAGI_MAX_IDS (1u << 26)  /* references pack (id << 6 | transform) */

/* The unique nodes of one level. Inner nodes keep 8 child references (each
   (id << 6 | tag) into the next level, tag normalized by the child's
   stabilizer) and a fingerprint; bricks keep their 64-bit mask in KEY. What
   a parent reads of a child sits together (one cache miss). */
typedef struct voxdagi_node {
    uint64_t key;   /* fingerprint (inner) or mask (brick) */
    uint64_t stab;  /* stabilizer: bit s set when transform s maps the node to itself */
    uint64_t count; /* voxels below */
} voxdagi_node;

typedef struct voxdagi_store {
    uint32_t *child;   /* 8 per node; NULL on the brick level */
    voxdagi_node *node;
    size_t n, cap;
    uint32_t *slot;    /* open-addressing table of id + 1 and a hash tag above it; 0 = free */
    size_t slot_count; /* power of two */
    uint64_t svo;      /* tree nodes reduced into this level */
} voxdagi_store;

static void voxdagi_store_free_arrays(voxdagi_mem *m, voxdagi_store *s) {
    voxdagi_free(m, s->child, s->cap * 8 * sizeof *s->child);
    voxdagi_free(m, s->node, s->cap * sizeof *s->node);
}

static void voxdagi_store_free(voxdagi_mem *m, voxdagi_store *s) {
    voxdagi_store_free_arrays(m, s);
    voxdagi_free(m, s->slot, s->slot_count * sizeof *s->slot);
    memset(s, 0, sizeof *s);
}

/* Whether node ID is (KEY, CHILD). An inner node's key is a function of
   its children, so they alone decide. */
static int voxdagi_store_same(const voxdagi_store *s, uint32_t id, uint64_t key,
                              const uint32_t *child) {
    return child ? !memcmp(s->child + 8 * (size_t)id, child, 8 * sizeof *child) : s->node[id].key == key;
}

/* A slot holds id + 1 (below 2^26) and the hash's top 6 bits above it, so
   that most probes of other nodes end without reading the node arrays. */
#define VOXDAGI_SLOT_ID(v) (((v) & (VOXDAGI_MAX_IDS - 1)) - 1)
#define VOXDAGI_SLOT_TAG(h) ((uint32_t)((h) >> 58) << 26)

/* Doubles the capacity of every array of S, all or nothing. */
static int voxdagi_store_reserve(voxdagi_mem *m, voxdagi_store *s, int inner) {
    size_t cap = s->cap ? s->cap * 2 : 256;
    voxdagi_node *node = (voxdagi_node *)voxdagi_alloc(m, cap * sizeof *node);
    uint32_t *child = inner ? (uint32_t *)voxdagi_alloc(m, cap * 8 * sizeof *child) : NULL;
    if (!node || (inner && !child)) {
        voxdagi_free(m, node, cap * sizeof *node);
        voxdagi_free(m, child, cap * 8 * sizeof *child);
        return 0;
    }
    if (s->n) {
        memcpy(node, s->node, s->n * sizeof *node);
        if (inner) memcpy(child, s->child, s->n * 8 * sizeof *child);
    }
    voxdagi_store_free_arrays(m, s);
    s->node = node;
    s->child = child;
    s->cap = cap;
    return 1;
}

/* Finds the node (KEY, CHILD) or appends it (with COUNT voxels; a brick's
   are its mask's). Returns its id, or VOXDAGI_NONE when out of memory or
   ids. */
static uint32_t voxdagi_store_intern(voxdagi_mem *m, voxdagi_store *s, int inner,
                                     uint64_t key, const uint32_t *child,
                                     uint64_t count, uint64_t stab) {
    uint64_t h = inner ? key : voxdagi_mix64(key);
    uint32_t tag = VOXDAGI_SLOT_TAG(h), id;
    size_t i, mask;
    if (s->slot_count) {
        mask = s->slot_count - 1;
        for (i = (size_t)h & mask; s->slot[i]; i = (i + 1) & mask) {
            id = VOXDAGI_SLOT_ID(s->slot[i]);
            if ((s->slot[i] ^ tag) < VOXDAGI_MAX_IDS && voxdagi_store_same(s, id, key, child)) return id;
        }
    }
    if (s->n + 1 >= VOXDAGI_MAX_IDS) return VOXDAGI_NONE;
    if ((s->n + 1) * 2 > s->slot_count) { /* rehash at half load */
        size_t count2 = s->slot_count ? s->slot_count * 2 : 64, j;
        uint32_t *slot = (uint32_t *)voxdagi_alloc(m, count2 * sizeof *slot);
        if (!slot) return VOXDAGI_NONE;
        memset(slot, 0, count2 * sizeof *slot);
        for (j = 0; j < s->n; j++) {
            uint64_t hj = inner ? s->node[j].key : voxdagi_mix64(s->node[j].key);
            for (i = (size_t)hj & (count2 - 1); slot[i]; i = (i + 1) & (count2 - 1)) {}
            slot[i] = ((uint32_t)j + 1) | VOXDAGI_SLOT_TAG(hj);
        }
        voxdagi_free(m, s->slot, s->slot_count * sizeof *s->slot);
        s->slot = slot;
        s->slot_count = count2;
    }
    if (s->n == s->cap && !voxdagi_store_reserve(m, s, inner)) return VOXDAGI_NONE;
    id = (uint32_t)s->n++;
    s->node[id].key = key;
    s->node[id].stab = stab;
    s->node[id].count = inner ? count : (uint64_t)voxdagi_popcount64(key);
    if (inner) memcpy(s->child + 8 * (size_t)id, child, 8 * sizeof *child);
    mask = s->slot_count - 1;
    for (i = (size_t)h & mask; s->slot[i]; i = (i + 1) & mask) {}
    s->slot[i] = (id + 1) | tag;
    return id;
}

// -- Canonical forms under a group of cube symmetries (SSVDAG 3.3, exact)
//
// A reference (n, t) is "stored node n transformed by t". It names the same
// subtree as (n, t o s) for every s in the stabilizer S(n) (the transforms
// mapping n to itself), so keys use the smallest tag of that coset. A node's
// key is its 8 (child, tag) slots; transforming the node by T puts the child
// of octant i, with tag T o t, in slot T(i). The canonical form is the
// transform with the smallest key; all transforms reaching it are T* o S.

/* The transforms a build shares nodes under (0..count-1: 1 for none, the 8
   reflections, or all 48), and the tables canonicalization uses. */
typedef struct voxdagi_group {
    uint8_t src[VOXDAGI_TRANSFORMS][8];      /* octant whose child lands in slot i: T^-1(i) */
    uint8_t mask8[VOXDAGI_TRANSFORMS][256];  /* a child-presence mask seen through T */
    uint8_t least[256];                      /* per presence mask: its smallest image in the group */
    uint64_t least_by[256];                  /* the transforms of the group giving it */
    unsigned count;
} voxdagi_group;

static void voxdagi_group_init(voxdagi_group *g, voxdag_symmetry symmetry) {
    unsigned tf, x, i;
    for (tf = 0; tf < VOXDAGI_TRANSFORMS; tf++) {
        for (i = 0; i < 8; i++) g->src[tf][i] = voxdagi_cube_tables.act[voxdagi_cube_tables.inv[tf]][i];
        for (x = 0; x < 256; x++) {
            unsigned y = 0;
            for (i = 0; i < 8; i++) y |= (x >> i & 1) << voxdagi_cube_tables.act[tf][i];
            g->mask8[tf][x] = (uint8_t)y;
        }
    }
    g->count = symmetry == VOXDAG_SYMMETRY_NONE ? 1 : symmetry == VOXDAG_SYMMETRY_REFLECT ? 8 : 48;
    for (x = 0; x < 256; x++) {
        g->least[x] = 255;
        g->least_by[x] = 0;
        for (tf = 0; tf < g->count; tf++) {
            if (g->mask8[tf][x] < g->least[x]) g->least[x] = g->mask8[tf][x], g->least_by[x] = 0;
            if (g->mask8[tf][x] == g->least[x]) g->least_by[x] |= 1ull << tf;
        }
    }
}

/* Brick MASK transformed by T (the voxel at Morton position p moves to
   T(p)): byte k of the result is cell T^-1(k), its bits moved like octants. */
static uint64_t voxdagi_transform_brick(const voxdagi_group *g, uint64_t mask, unsigned tf) {
    uint64_t r = 0;
    unsigned k;
    for (k = 0; k < 8; k++) r |= (uint64_t)g->mask8[tf][mask >> 8 * g->src[tf][k] & 0xFF] << 8 * k;
    return r;
}

/* The smallest tag of the coset T o S. */
static unsigned voxdagi_normalize(const voxdagi_cube *c, unsigned t, uint64_t stabs) {
    unsigned best = t;
    stabs &= ~1ull; /* the identity gives t itself */
    while (stabs) {
        unsigned s = voxdagi_lowest_bit(stabs), u = c->comp[t][s];
        if (u < best) best = u;
        stabs &= stabs - 1;
    }
    return best;
}

/* The reference "T applied to reference REF": the same node, tag T o t. */
static uint32_t voxdagi_ref_compose(unsigned tf, uint32_t ref) {
    return (ref & ~63u) | voxdagi_cube_tables.comp[tf][ref & 63];
}

/* A reference to the canonical form: its key, the tag that maps the canonical
   node back to the input, and the canonical node's stabilizer. */
typedef struct voxdagi_canon {
    uint64_t key, stab;
    unsigned tag;
} voxdagi_canon;

/* Bricks: the canonical form is the transform with the smallest occupancy
   of its eight 2^3 cells (a table lookup), then the smallest mask, compared
   a byte (a cell) at a time from the top: T puts cell T^-1(k), its bits
   moved like octants, at byte k. Those left after the last byte give the
   same mask. */
static voxdagi_canon voxdagi_canon_brick(const voxdagi_group *g, uint64_t mask) {
    voxdagi_canon c;
    uint64_t cand;
    unsigned cell[8], occ = 0, k, best;
    for (k = 0; k < 8; k++) {
        cell[k] = (unsigned)(mask >> 8 * k & 0xFF);
        occ |= (unsigned)(cell[k] != 0) << k;
    }
    cand = g->least_by[occ];
    for (k = 8; k-- > 0 && (cand & (cand - 1));) {
        uint64_t rest, keep = 0;
        unsigned low = 256;
        for (rest = cand; rest; rest &= rest - 1) {
            unsigned tf = voxdagi_lowest_bit(rest), v = g->mask8[tf][cell[g->src[tf][k]]];
            if (v < low) low = v, keep = 0;
            if (v == low) keep |= 1ull << tf;
        }
        cand = keep;
    }
    best = voxdagi_lowest_bit(cand);
    c.key = voxdagi_transform_brick(g, mask, best);
    c.tag = voxdagi_cube_tables.inv[best];
    c.stab = 0;
    for (; cand; cand &= cand - 1) c.stab |= 1ull << voxdagi_cube_tables.comp[voxdagi_lowest_bit(cand)][c.tag];
    return c;
}

/* The children of an inner node as the reducer sees them. */
typedef struct voxdagi_children {
    unsigned present;  /* bit j: octant j has a child */
    uint32_t id[8];
    unsigned tag[8];
    uint64_t stab[8];
    uint64_t fp[8];    /* the child's fingerprint */
} voxdagi_children;

/* Total order on transforms of one node with presence mask PRESENT under
   both: per slot the child's fingerprint, normalized tag and id. Fingerprints
   come first so that the choice does not depend on id numbering (which
   varies with thread count); ids only break fingerprint collisions, keeping
   the order total. */
static int voxdagi_compare_transforms(const voxdagi_group *g, const voxdagi_children *c,
                                      unsigned present, unsigned a, unsigned b) {
    unsigned i;
    for (i = 0; i < 8; i++) {
        unsigned ja = g->src[a][i], jb = g->src[b][i], ta, tb;
        if (!(present >> i & 1)) continue;
        if (c->fp[ja] != c->fp[jb]) return c->fp[ja] < c->fp[jb] ? -1 : 1;
        ta = voxdagi_normalize(&voxdagi_cube_tables, voxdagi_cube_tables.comp[a][c->tag[ja]], c->stab[ja]);
        tb = voxdagi_normalize(&voxdagi_cube_tables, voxdagi_cube_tables.comp[b][c->tag[jb]], c->stab[jb]);
        if (ta != tb) return ta < tb ? -1 : 1;
        if (c->id[ja] != c->id[jb]) return c->id[ja] < c->id[jb] ? -1 : 1;
    }
    return 0;
}

/* Inner nodes: the canonical slots (presence mask first, then the order
   above) and their fingerprint. */
static voxdagi_canon voxdagi_canon_node(const voxdagi_group *g, const voxdagi_children *c,
                                        uint32_t slots[8]) {
    voxdagi_canon r;
    unsigned i, best_present = g->least[c->present];
    uint64_t cand = g->least_by[c->present], tie = cand & (0 - cand); /* TIE: the candidates equal to BEST */
    unsigned best = voxdagi_lowest_bit(cand);
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (cand &= cand - 1; cand; cand &= cand - 1) {
        unsigned tf = voxdagi_lowest_bit(cand);
        int order = voxdagi_compare_transforms(g, c, best_present, tf, best);
        if (order < 0) best = tf, tie = 0;
        if (order <= 0) tie |= 1ull << tf;
    }
    r.tag = voxdagi_cube_tables.inv[best];
    r.stab = 0;
    for (; tie; tie &= tie - 1) r.stab |= 1ull << voxdagi_cube_tables.comp[voxdagi_lowest_bit(tie)][r.tag];
    for (i = 0; i < 8; i++) {
        unsigned j = g->src[best][i], t;
        uint64_t v = 0;
        if (best_present >> i & 1) {
            t = voxdagi_normalize(&voxdagi_cube_tables, voxdagi_cube_tables.comp[best][c->tag[j]], c->stab[j]);
            slots[i] = c->id[j] << 6 | t;
            v = c->fp[j] + (uint64_t)(t + 1) * 0xD6E8FEB86659FD93ull;
        } else {
            slots[i] = VOXDAGI_NONE;
        }
        h = voxdagi_mix64(h ^ v) + i;
    }
    r.key = h;
    return r;
}

// -- Streaming bottom-up reduction (hash-consed, one open node per level)

/* Consumes voxels (or finished subtrees) in Morton order, keeping one open
   brick and one partially filled node per level; a node is reduced as soon as
   the Morton prefix of its level changes. TOP is the level of the root this
   reducer produces (0 for a whole scene, deeper for a worker's subtree). */
typedef struct voxdagi_reducer {
    voxdagi_mem *mem;
    const voxdagi_group *group;
    uint32_t levels, top;
    voxdagi_store store[VOXDAG_MAX_LEVELS]; /* levels top..L-2 */
    uint64_t brick_key, brick_mask;
    int brick_open;
    uint64_t part_key[VOXDAG_MAX_LEVELS];
    int part_open[VOXDAG_MAX_LEVELS];
    uint32_t part_child[VOXDAG_MAX_LEVELS][8];
    uint32_t root; /* reference to the root, or VOXDAGI_NONE */
    int failed;    /* out of memory or node ids */
    struct voxdagi_memo *memo; /* recent inputs -> references; NULL: none */
} voxdagi_reducer;

/* A direct-mapped memo of recent reductions: the same brick mask or the same
   8 child references recur constantly in real scenes (flat floors, repeated
   walls), and their reference never changes once interned, so a hit skips
   the canonicalization and the hash-table probe. */
#define VOXDAGI_MEMO_SIZE 8192
typedef struct voxdagi_memo {
    uint32_t word[VOXDAGI_MEMO_SIZE][8]; /* child references, or the brick mask */
    uint32_t level[VOXDAGI_MEMO_SIZE];
    uint32_t ref[VOXDAGI_MEMO_SIZE];     /* VOXDAGI_NONE: empty */
} voxdagi_memo;

static uint32_t *voxdagi_memo_slot(voxdagi_reducer *r, uint32_t level, const uint32_t word[8]) {
    uint64_t h = level;
    unsigned i;
    if (!r->memo) {
        r->memo = (voxdagi_memo *)voxdagi_alloc(r->mem, sizeof *r->memo);
        if (!r->memo) return NULL;
        memset(r->memo->ref, 0xFF, sizeof r->memo->ref);
    }
    for (i = 0; i < 8; i++) h = (h ^ word[i]) * 0x9E3779B97F4A7C15ull;
    i = (unsigned)(h >> 51) & (VOXDAGI_MEMO_SIZE - 1);
    if (r->memo->ref[i] == VOXDAGI_NONE || r->memo->level[i] != level ||
        memcmp(r->memo->word[i], word, sizeof r->memo->word[i])) {
        memcpy(r->memo->word[i], word, sizeof r->memo->word[i]);
        r->memo->level[i] = level;
        r->memo->ref[i] = VOXDAGI_NONE;
    }
    return &r->memo->ref[i];
}

static void voxdagi_reducer_init(voxdagi_reducer *r, voxdagi_mem *mem,
                                 const voxdagi_group *g, uint32_t levels, uint32_t top) {
    memset(r, 0, sizeof *r);
    r->mem = mem;
    r->group = g;
    r->levels = levels;
    r->top = top;
    r->root = VOXDAGI_NONE;
}

static void voxdagi_reducer_free(voxdagi_reducer *r) {
    uint32_t l;
    for (l = 0; l < VOXDAG_MAX_LEVELS; l++) voxdagi_store_free(r->mem, &r->store[l]);
    voxdagi_free(r->mem, r->memo, sizeof *r->memo);
    r->memo = NULL;
}

/* Interns a brick mask; returns the reference (id << 6 | transform). */
static uint32_t voxdagi_reduce_brick(voxdagi_reducer *r, uint64_t mask) {
    uint32_t word[8] = {0}, *memo, id;
    voxdagi_canon c;
    word[0] = (uint32_t)mask;
    word[1] = (uint32_t)(mask >> 32);
    memo = voxdagi_memo_slot(r, r->levels - 2, word);
    if (memo && *memo != VOXDAGI_NONE) return *memo;
    c = voxdagi_canon_brick(r->group, mask);
    id = voxdagi_store_intern(r->mem, &r->store[r->levels - 2], 0, c.key, NULL, 0, c.stab);
    if (id == VOXDAGI_NONE) {
        r->failed = 1;
        return VOXDAGI_NONE;
    }
    if (memo) *memo = id << 6 | c.tag;
    return id << 6 | c.tag;
}

/* Interns the inner node of level L with child references REF[8] (into level
   L+1); returns its reference. */
static uint32_t voxdagi_reduce_node(voxdagi_reducer *r, uint32_t level, const uint32_t ref[8]) {
    const voxdagi_store *cs = &r->store[level + 1];
    voxdagi_children c;
    voxdagi_canon k;
    uint32_t slots[8], id, *memo = voxdagi_memo_slot(r, level, ref);
    uint64_t count = 0;
    unsigned j;
    if (memo && *memo != VOXDAGI_NONE) return *memo;
    c.present = 0;
    for (j = 0; j < 8; j++) {
        if (ref[j] == VOXDAGI_NONE) {
            c.id[j] = 0;
            c.tag[j] = 0;
            c.stab[j] = 0;
            c.fp[j] = 0;
            continue;
        }
        c.present |= 1u << j;
        c.id[j] = ref[j] >> 6;
        c.tag[j] = ref[j] & 63;
        c.stab[j] = cs->node[c.id[j]].stab;
        c.fp[j] = cs->node[c.id[j]].key;
        count += cs->node[c.id[j]].count;
    }
    k = voxdagi_canon_node(r->group, &c, slots);
    id = voxdagi_store_intern(r->mem, &r->store[level], 1, k.key, slots, count, k.stab);
    if (id == VOXDAGI_NONE) {
        r->failed = 1;
        return VOXDAGI_NONE;
    }
    if (memo) *memo = id << 6 | k.tag;
    return id << 6 | k.tag;
}

static void voxdagi_reducer_push(voxdagi_reducer *r, uint32_t level, uint64_t key, uint32_t ref);

/* Reduces the open node of LEVEL and hands it to its parent. */
static void voxdagi_reducer_close(voxdagi_reducer *r, uint32_t level) {
    uint32_t ref = voxdagi_reduce_node(r, level, r->part_child[level]);
    r->part_open[level] = 0;
    r->store[level].svo++;
    if (ref != VOXDAGI_NONE) voxdagi_reducer_push(r, level, r->part_key[level], ref);
}

/* Hands the finished subtree REF of LEVEL with Morton prefix KEY to its parent. */
static void voxdagi_reducer_push(voxdagi_reducer *r, uint32_t level, uint64_t key, uint32_t ref) {
    uint32_t p;
    unsigned j;
    if (level == r->top) {
        r->root = ref;
        return;
    }
    p = level - 1;
    if (r->part_open[p] && r->part_key[p] != key >> 3) voxdagi_reducer_close(r, p);
    if (!r->part_open[p]) {
        r->part_open[p] = 1;
        r->part_key[p] = key >> 3;
        for (j = 0; j < 8; j++) r->part_child[p][j] = VOXDAGI_NONE;
    }
    r->part_child[p][key & 7] = ref;
}

static void voxdagi_reducer_close_brick(voxdagi_reducer *r) {
    uint32_t ref;
    if (!r->brick_open) return;
    r->brick_open = 0;
    r->store[r->levels - 2].svo++;
    ref = voxdagi_reduce_brick(r, r->brick_mask);
    if (ref != VOXDAGI_NONE) voxdagi_reducer_push(r, r->levels - 2, r->brick_key, ref);
}

/* Adds the voxels MASK of the brick with Morton code KEY (the voxel codes
   without their low 6 bits); KEY must not precede the previous one. */
static void voxdagi_reducer_brick(voxdagi_reducer *r, uint64_t key, uint64_t mask) {
    if (r->brick_open && r->brick_key != key) voxdagi_reducer_close_brick(r);
    if (!r->brick_open) {
        r->brick_open = 1;
        r->brick_key = key;
        r->brick_mask = 0;
    }
    r->brick_mask |= mask;
}

/* Adds one voxel; CODE must not precede the previous one. */
static void voxdagi_reducer_voxel(voxdagi_reducer *r, uint64_t code) {
    voxdagi_reducer_brick(r, code >> 6, 1ull << (code & 63));
}

/* Closes everything still open; the root reference is then in r->root. */
static void voxdagi_reducer_finish(voxdagi_reducer *r) {
    uint32_t l;
    voxdagi_reducer_close_brick(r);
    for (l = r->levels - 2; l-- > r->top;)
        if (r->part_open[l]) voxdagi_reducer_close(r, l);
}

// -- Sorting: LSD radix sort of Morton codes with their colours

/* Sorts CODE (and RGB, packed 0xRRGGBB, when non-NULL) by the low BITS bits
   of the codes, stably. TMP_CODE/TMP_RGB hold N elements each. */
#define VOXDAGI_RADIX_BITS 11
#define VOXDAGI_RADIX_BUCKETS (1u << VOXDAGI_RADIX_BITS)

static void voxdagi_radix_sort(uint64_t *code, uint32_t *rgb, uint64_t *tmp_code,
                               uint32_t *tmp_rgb, size_t n, unsigned bits) {
    enum { radix_bits = VOXDAGI_RADIX_BITS, radix_buckets = VOXDAGI_RADIX_BUCKETS };
    size_t count[radix_buckets];
    unsigned shift;
    for (shift = 0; shift < bits; shift += radix_bits) {
        size_t i, sum = 0;
        uint64_t *c;
        uint32_t *t;
        memset(count, 0, sizeof count);
        for (i = 0; i < n; i++) count[(code[i] >> shift) & (radix_buckets - 1)]++;
        for (i = 0; i < radix_buckets; i++) {
            size_t k = count[i];
            count[i] = sum;
            sum += k;
        }
        for (i = 0; i < n; i++) {
            size_t d = count[(code[i] >> shift) & (radix_buckets - 1)]++;
            tmp_code[d] = code[i];
            if (rgb) tmp_rgb[d] = rgb[i];
        }
        c = code; code = tmp_code; tmp_code = c;
        t = rgb; rgb = tmp_rgb; tmp_rgb = t;
    }
    if (((bits + radix_bits - 1) / radix_bits) & 1) { /* odd pass count: result is in tmp */
        memcpy(tmp_code, code, n * sizeof *code);
        if (rgb) memcpy(tmp_rgb, rgb, n * sizeof *rgb);
    }
}

// -- Builder

struct voxdag_builder {
    voxdagi_mem mem;
    voxdag_build_opts opts;
    uint32_t levels;
    uint32_t threads;
    int has_bounds;
    double bounds[6];
    voxdag_symmetry symmetry;    /* resolved: NONE, REFLECT or FULL */
    voxdagi_group group[3];      /* [0]: as requested, [1], [2]: the others (comparison) */
    voxdagi_reducer red[3];      /* the result, and the other structures when compared */
    unsigned red_count;
    uint64_t *pend_code;         /* buffered voxels */
    uint32_t *pend_rgb;
    size_t pend_n, pend_cap;
    uint64_t last_code;          /* largest code reduced so far */
    int any_reduced;
    uint8_t *colors;             /* RGB8 in voxel-index order, from voxel COLORS_BASE */
    size_t colors_cap;           /* in voxels */
    uint64_t colors_base;        /* with a colour sink: the first colour not yet sent */
    uint64_t voxels;
    voxdag_status failed;        /* sticky error */
    voxdagi_team team;           /* its threads */
};

VOXDAG_API voxdag_status voxdag_builder_create(const voxdag_build_opts *opts,
                                               voxdag_builder **out, voxdag_error *err) {
    voxdag_build_opts o;
    voxdagi_mem mem;
    voxdag_builder *b;
    unsigned k, n;
    if (!out) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "out is NULL");
    *out = NULL;
    memset(&o, 0, sizeof o);
    if (opts) o = *opts;
    if (o.zero_begin || o.zero_end)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT,
                            "build options not zero-initialized");
    if (!o.levels) o.levels = 10;
    if ((unsigned)o.symmetry >= VOXDAG_SYMMETRY_COUNT)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "symmetry is not a voxdag_symmetry");
    if (o.levels < 2 || o.levels > VOXDAG_MAX_LEVELS)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, "levels outside 2..VOXDAG_MAX_LEVELS");
    if ((o.allocator.alloc == NULL) != (o.allocator.free == NULL))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT,
                            "allocator needs both alloc and free");
    if (o.chunk_levels == 1 || o.chunk_levels > 8)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "chunk_levels is not 0 or 2..8");
    if (o.color_sink && !o.colors)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "color_sink without colors");
    if ((o.thread_pool.run == NULL) != (o.thread_pool.wait == NULL))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT,
                            "thread_pool needs both run and wait");
    if (o.bounds) {
        for (k = 0; k < 3; k++)
            if (!(o.bounds[k] < o.bounds[k + 3]) || o.bounds[k] != o.bounds[k] ||
                o.bounds[k + 3] - o.bounds[k] > 1e300)
                return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT,
                                    "bounds must be finite with min < max");
    }
    voxdagi_mem_init(&mem, &o.allocator, o.max_memory);
    b = (voxdag_builder *)voxdagi_alloc(&mem, sizeof *b);
    if (!b) {
        voxdagi_mem_destroy(&mem);
        return voxdagi_mem_fail(&mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot allocate the builder");
    }
    memset(b, 0, sizeof *b);
    b->mem = mem; /* the mutex is moved before any other use */
    b->opts = o;
    b->levels = o.levels;
    voxdagi_team_init(&b->team, &b->mem, o.threads, &o.thread_pool);
    b->threads = b->team.threads;
    if (o.bounds) {
        b->has_bounds = 1;
        memcpy(b->bounds, o.bounds, sizeof b->bounds);
    }
    b->opts.bounds = NULL;
    b->symmetry = o.symmetry ? o.symmetry : VOXDAG_SYMMETRY_FULL;
    voxdagi_group_init(&b->group[0], b->symmetry);
    for (k = VOXDAG_SYMMETRY_NONE, n = 1; k <= VOXDAG_SYMMETRY_FULL; k++)
        if (k != (unsigned)b->symmetry) voxdagi_group_init(&b->group[n++], (voxdag_symmetry)k);
    b->red_count = o.compare_structures ? 3 : 1;
    for (k = 0; k < b->red_count; k++)
        voxdagi_reducer_init(&b->red[k], &b->mem, &b->group[k], b->levels, 0);
    *out = b;
    return voxdagi_ok(err);
}

VOXDAG_API void voxdag_builder_free(voxdag_builder *b) {
    voxdagi_mem mem;
    unsigned k;
    if (!b) return;
    for (k = 0; k < b->red_count; k++) voxdagi_reducer_free(&b->red[k]);
    voxdagi_free(&b->mem, b->pend_code, b->pend_cap * sizeof *b->pend_code);
    voxdagi_free(&b->mem, b->pend_rgb, b->opts.colors ? b->pend_cap * sizeof *b->pend_rgb : 0);
    voxdagi_free(&b->mem, b->colors, b->colors_cap * 3);
    voxdagi_team_stop(&b->team);
    mem = b->mem;
    voxdagi_free(&mem, b, sizeof *b);
    voxdagi_mem_destroy(&mem);
}

/* One job of a parallel radix sort pass: counts the digits of elements
   [begin, end) (COUNT: radix_buckets entries), or, once COUNT holds each
   digit's first destination for this slice, moves them there. */
typedef struct voxdagi_sort_job {
    const uint64_t *code;
    const uint32_t *rgb;
    uint64_t *to_code;
    uint32_t *to_rgb;
    size_t begin, end, *count;
    unsigned shift;
    int scatter;
} voxdagi_sort_job;

static void *voxdagi_sort_run(void *arg) {
    voxdagi_sort_job *j = (voxdagi_sort_job *)arg;
    const uint64_t mask = VOXDAGI_RADIX_BUCKETS - 1;
    size_t i;
    if (!j->scatter) {
        memset(j->count, 0, VOXDAGI_RADIX_BUCKETS * sizeof *j->count);
        for (i = j->begin; i < j->end; i++) j->count[(j->code[i] >> j->shift) & mask]++;
        return NULL;
    }
    for (i = j->begin; i < j->end; i++) {
        size_t d = j->count[(j->code[i] >> j->shift) & mask]++;
        j->to_code[d] = j->code[i];
        if (j->rgb) j->to_rgb[d] = j->rgb[i];
    }
    return NULL;
}

/* voxdagi_radix_sort on the builder's threads: each pass counts, then moves,
   one slice of the elements per job, every slice's elements of a digit
   placed after those of the slices before it, so the order is the serial
   sort's (a stable sort has one result) whatever the thread count. Serial
   with one thread, for small inputs, or when the counts cannot be
   allocated. */
static void voxdagi_sort(voxdag_builder *b, uint64_t *code, uint32_t *rgb, uint64_t *tmp_code, uint32_t *tmp_rgb,
                         size_t n, unsigned bits) {
    voxdagi_sort_job job[VOXDAGI_MAX_THREADS];
    unsigned jobs = b->threads, t, shift;
    size_t *count = NULL, d, sum;
    if (jobs > 1 && n >= (1u << 16)) /* below, the batches would cost more than they save */
        count = (size_t *)voxdagi_alloc(&b->mem, jobs * VOXDAGI_RADIX_BUCKETS * sizeof *count);
    if (!count) {
        voxdagi_radix_sort(code, rgb, tmp_code, tmp_rgb, n, bits);
        return;
    }
    for (shift = 0; shift < bits; shift += VOXDAGI_RADIX_BITS) {
        uint64_t *c;
        uint32_t *r;
        for (t = 0; t < jobs; t++) {
            job[t].code = code, job[t].rgb = rgb, job[t].to_code = tmp_code, job[t].to_rgb = tmp_rgb;
            job[t].begin = n / jobs * t;
            job[t].end = t + 1 == jobs ? n : n / jobs * (t + 1);
            job[t].count = count + (size_t)t * VOXDAGI_RADIX_BUCKETS;
            job[t].shift = shift;
            job[t].scatter = 0;
        }
        voxdagi_run_parallel(&b->team, voxdagi_sort_run, job, sizeof job[0], jobs);
        for (d = 0, sum = 0; d < VOXDAGI_RADIX_BUCKETS; d++) /* digit by digit, slices in order */
            for (t = 0; t < jobs; t++) {
                size_t k = job[t].count[d];
                job[t].count[d] = sum;
                sum += k;
            }
        for (t = 0; t < jobs; t++) job[t].scatter = 1;
        voxdagi_run_parallel(&b->team, voxdagi_sort_run, job, sizeof job[0], jobs);
        c = code; code = tmp_code; tmp_code = c;
        r = rgb; rgb = tmp_rgb; tmp_rgb = r;
    }
    if (((bits + VOXDAGI_RADIX_BITS - 1) / VOXDAGI_RADIX_BITS) & 1) { /* odd pass count: the result is in tmp */
        memcpy(tmp_code, code, n * sizeof *code);
        if (rgb) memcpy(tmp_rgb, rgb, n * sizeof *rgb);
    }
    voxdagi_free(&b->mem, count, jobs * VOXDAGI_RADIX_BUCKETS * sizeof *count);
}

/* Morton encoding and checks of voxels [begin, end) of an add call. */
typedef struct voxdagi_encode_job {
    const voxdag_builder *b;
    const uint32_t *xyz;
    uint64_t *code;
    size_t begin, end, bad;
    voxdag_status status;
} voxdagi_encode_job;

static void *voxdagi_encode_run(void *arg) {
    voxdagi_encode_job *j = (voxdagi_encode_job *)arg;
    const voxdag_builder *b = j->b;
    size_t i;
    j->status = VOXDAG_OK;
    for (i = j->begin; i < j->end; i++) {
        const uint32_t *p = j->xyz + 3 * i;
        if ((p[0] | p[1] | p[2]) >> b->levels) {
            j->status = VOXDAG_ERR_COORDINATE;
            break;
        }
        j->code[i] = voxdag_morton_encode(p[0], p[1], p[2]);
        if (j->code[i] < b->last_code && b->any_reduced) {
            j->status = VOXDAG_ERR_ORDER;
            break;
        }
    }
    j->bad = i;
    return NULL;
}

/* Grows the voxel buffer (codes and colours together) to hold NEED voxels. */
static int voxdagi_builder_reserve(voxdag_builder *b, size_t need) {
    size_t cap = b->pend_cap ? b->pend_cap : 1024;
    size_t rgb_size = b->opts.colors ? sizeof *b->pend_rgb : 0;
    uint64_t *code;
    uint32_t *rgb = NULL;
    while (cap < need) cap *= 2;
    code = (uint64_t *)voxdagi_alloc(&b->mem, cap * sizeof *code);
    if (rgb_size) rgb = (uint32_t *)voxdagi_alloc(&b->mem, cap * rgb_size);
    if (!code || (rgb_size && !rgb)) {
        voxdagi_free(&b->mem, code, cap * sizeof *code);
        voxdagi_free(&b->mem, rgb, cap * rgb_size);
        return 0;
    }
    if (b->pend_n) {
        memcpy(code, b->pend_code, b->pend_n * sizeof *code);
        if (rgb) memcpy(rgb, b->pend_rgb, b->pend_n * rgb_size);
    }
    voxdagi_free(&b->mem, b->pend_code, b->pend_cap * sizeof *code);
    voxdagi_free(&b->mem, b->pend_rgb, b->pend_cap * rgb_size);
    b->pend_code = code;
    b->pend_rgb = rgb;
    b->pend_cap = cap;
    return 1;
}

VOXDAG_API voxdag_status voxdag_builder_add(voxdag_builder *b, const uint32_t *xyz,
                                            const uint8_t *rgb, size_t n, voxdag_error *err) {
    size_t i;
    uint64_t *code;
    if (!b || (n && !xyz) || (n && b->opts.colors && !rgb))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT,
                            "builder, coordinates or colours missing");
    if (b->failed) return VOXDAGI_FAIL(err, b->failed, "the builder failed earlier");
    if (!n) return voxdagi_ok(err); /* the buffer may not exist yet */
    if (n > ((size_t)-1) / 16 - b->pend_n)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "too many voxels");
    if (b->pend_n + n > b->pend_cap && !voxdagi_builder_reserve(b, b->pend_n + n))
        return voxdagi_mem_fail(&b->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot grow the voxel buffer");
    /* Encode into the free tail of the buffer; it only counts once all pass. */
    code = b->pend_code + b->pend_n;
    {
        voxdagi_encode_job job[VOXDAGI_MAX_THREADS];
        unsigned t, jobs = n >= (1u << 18) ? b->threads : 1;
        voxdag_status st = VOXDAG_OK;
        size_t bad = n;
        for (t = 0; t < jobs; t++) {
            job[t].b = b;
            job[t].xyz = xyz;
            job[t].code = code;
            job[t].begin = n / jobs * t;
            job[t].end = t + 1 == jobs ? n : n / jobs * (t + 1);
        }
        voxdagi_run_parallel(&b->team, voxdagi_encode_run, job, sizeof job[0], jobs);
        for (t = 0; t < jobs && st == VOXDAG_OK; t++)
            if (job[t].status != VOXDAG_OK) {
                st = job[t].status;
                bad = job[t].bad;
            }
        if (st == VOXDAG_ERR_COORDINATE)
            return voxdagi_fail(err, st, "voxel coordinate >= 2^levels", UINT64_MAX, (uint64_t)bad);
        if (st == VOXDAG_ERR_ORDER)
            return voxdagi_fail(err, st, "voxel precedes voxels already flushed", UINT64_MAX, (uint64_t)bad);
    }
    if (b->opts.colors)
        for (i = 0; i < n; i++)
            b->pend_rgb[b->pend_n + i] = (uint32_t)rgb[3 * i] << 16 |
                                         (uint32_t)rgb[3 * i + 1] << 8 | rgb[3 * i + 2];
    b->pend_n += n;
    return voxdagi_ok(err);
}

/* Sends the HELD buffered colours to the sink but for the last KEEP (0 or 1). */
static voxdag_status voxdagi_builder_send_colors(voxdag_builder *b, size_t held, size_t keep) {
    if (!b->opts.colors || !b->opts.color_sink || held <= keep) return VOXDAG_OK;
    if (b->opts.color_sink(b->opts.color_sink_user, b->colors, held - keep)) return VOXDAG_ERR_IO;
    memmove(b->colors, b->colors + 3 * (held - keep), 3 * keep);
    b->colors_base += held - keep;
    return VOXDAG_OK;
}

/* Appends the colours of N sorted, distinct voxels that follow the reduced
   ones, as bytes (RGB8) or, when RGB8 is NULL, packed 0xRRGGBB (RGB). With a
   sink, the colours go out at once, but for the last one: a repeat of that
   voxel at the start of the next flush may still replace it. */
static voxdag_status voxdagi_builder_colors(voxdag_builder *b, const uint32_t *rgb, const uint8_t *rgb8, size_t n) {
    size_t i, held = (size_t)(b->voxels - b->colors_base);
    uint8_t *c;
    if (!b->opts.colors) return VOXDAG_OK;
    if (!voxdagi_grow(&b->mem, (void **)&b->colors, &b->colors_cap, held + n, 3)) return VOXDAG_ERR_OUT_OF_MEMORY;
    c = b->colors + 3 * held;
    if (rgb8) {
        memcpy(c, rgb8, 3 * n);
    } else {
        for (i = 0; i < n; i++) {
            c[3 * i] = (uint8_t)(rgb[i] >> 16);
            c[3 * i + 1] = (uint8_t)(rgb[i] >> 8);
            c[3 * i + 2] = (uint8_t)rgb[i];
        }
    }
    return voxdagi_builder_send_colors(b, held + n, 1);
}

#ifndef VOXDAG_NO_THREADS
/* Closes the open brick and the open nodes of levels >= LEVEL (they belong to
   subtrees that precede the one about to be pushed at LEVEL). */
static void voxdagi_reducer_close_below(voxdagi_reducer *r, uint32_t level) {
    uint32_t l;
    voxdagi_reducer_close_brick(r);
    for (l = r->levels - 2; l-- > level;)
        if (r->part_open[l]) voxdagi_reducer_close(r, l);
}

/* Parallel reduction: complete subtrees of level SPLIT are
   reduced by workers into stores of their own, then merged into the builder's
   stores in Morton order with the same interning (so the result does not
   depend on how the work was split). */
typedef struct voxdagi_piece {
    size_t begin, end;  /* range of buffered voxels */
    uint32_t root[3];   /* the worker's root reference, per reducer */
} voxdagi_piece;

typedef struct voxdagi_worker {
    voxdag_builder *b;
    voxdagi_reducer red[3];
    voxdagi_piece *piece;
    size_t piece_count;
    const uint64_t *code;
} voxdagi_worker;

static void *voxdagi_worker_run(void *arg) {
    voxdagi_worker *w = (voxdagi_worker *)arg;
    size_t p, i;
    unsigned k;
    for (p = 0; p < w->piece_count; p++) {
        voxdagi_piece *pc = &w->piece[p];
        for (k = 0; k < w->b->red_count; k++) {
            voxdagi_reducer *r = &w->red[k];
            for (i = pc->begin; i < pc->end; i++) voxdagi_reducer_voxel(r, w->code[i]);
            voxdagi_reducer_finish(r);
            pc->root[k] = r->root;
            r->root = VOXDAGI_NONE;
        }
    }
    return NULL;
}

/* Re-interns every node of a worker's reducer W into R, bottom-up. MAP[l]
   receives, per worker id, the reference in R. Returns 0 when out of memory. */
static int voxdagi_merge(voxdagi_reducer *r, voxdagi_reducer *w, uint32_t **map, size_t *map_size) {
    uint32_t l = r->levels - 1;
    while (l-- > w->top) {
        voxdagi_store *s = &w->store[l];
        size_t i;
        unsigned j;
        if (!s->n) continue;
        map_size[l] = s->n * sizeof(uint32_t);
        map[l] = (uint32_t *)voxdagi_alloc(r->mem, map_size[l]);
        if (!map[l]) return 0;
        for (i = 0; i < s->n; i++) {
            uint32_t ref, c[8], same = 0, id;
            if (s->child) /* children as references into R; SAME: any not in W's orientation */
                for (j = 0; j < 8; j++) {
                    uint32_t x = s->child[8 * i + j];
                    if (x == VOXDAGI_NONE) {
                        c[j] = x;
                        continue;
                    }
                    c[j] = voxdagi_ref_compose(x & 63, map[l + 1][x >> 6]);
                    same |= map[l + 1][x >> 6] & 63;
                }
            if (!same) {
                /* Canonical forms do not depend on ids (fingerprints decide),
                   so W's node is already canonical in R: intern it as is. */
                id = voxdagi_store_intern(r->mem, &r->store[l], s->child != NULL, s->node[i].key, s->child ? c : NULL,
                                          s->node[i].count, s->node[i].stab);
                ref = id == VOXDAGI_NONE ? id : id << 6;
            } else { /* a fingerprint collision made the orientations differ */
                ref = voxdagi_reduce_node(r, l, c);
            }
            if (ref == VOXDAGI_NONE) {
                r->failed = 1;
                return 0;
            }
            map[l][i] = ref;
        }
        r->store[l].svo += s->svo;
    }
    return 1;
}

/* Reduces sorted distinct voxels CODE[0..n) with workers. Returns 0 when
   the split does not pay (the caller then reduces serially). */
static voxdag_status voxdagi_reduce_parallel(voxdag_builder *b, const uint64_t *code, size_t n,
                                             int final, int *done) {
    uint32_t split = 1, nlevels = b->levels;
    size_t npieces = 0, cap = 0, i, start, per;
    voxdagi_piece *piece = NULL;
    voxdagi_worker *worker;
    unsigned t, k;
    voxdag_status st = VOXDAG_OK;
    uint64_t shift, first_open = UINT64_MAX, last_open = UINT64_MAX;
    *done = 0;
    while ((1ull << (3 * split)) < 16ull * b->threads) split++;
    if (b->threads < 2 || split + 3 > nlevels || n < 4096) return VOXDAG_OK;
    shift = 3ull * (nlevels - split);
    /* A subtree may continue from an earlier flush, or into a later one: those
       two are reduced by the builder itself, not as pieces. */
    if (b->any_reduced) first_open = b->last_code >> shift;
    if (!final) last_open = code[n - 1] >> shift;
    for (start = 0; start < n;) {
        uint64_t prefix = code[start] >> shift;
        size_t end = start + 1;
        while (end < n && code[end] >> shift == prefix) end++;
        if (prefix != first_open && prefix != last_open) {
            if (!voxdagi_grow(&b->mem, (void **)&piece, &cap, npieces + 1, sizeof *piece)) {
                voxdagi_free(&b->mem, piece, cap * sizeof *piece);
                return VOXDAG_ERR_OUT_OF_MEMORY;
            }
            piece[npieces].begin = start;
            piece[npieces].end = end;
            npieces++;
        }
        start = end;
    }
    if (npieces < 2 * b->threads) {
        voxdagi_free(&b->mem, piece, cap * sizeof *piece);
        return VOXDAG_OK;
    }
    worker = (voxdagi_worker *)voxdagi_alloc(&b->mem, b->threads * sizeof *worker);
    if (!worker) {
        voxdagi_free(&b->mem, piece, cap * sizeof *piece);
        return VOXDAG_ERR_OUT_OF_MEMORY;
    }
    /* Contiguous runs of pieces with about n / threads voxels each. */
    per = n / b->threads + 1;
    for (t = 0, i = 0; t < b->threads; t++) {
        size_t first = i, load = 0;
        while (i < npieces && (load < per || t + 1 == b->threads)) {
            load += piece[i].end - piece[i].begin;
            i++;
        }
        worker[t].b = b;
        worker[t].piece = piece + first;
        worker[t].piece_count = i - first;
        worker[t].code = code;
        for (k = 0; k < b->red_count; k++)
            voxdagi_reducer_init(&worker[t].red[k], &b->mem, &b->group[k], nlevels, split);
    }
    voxdagi_run_parallel(&b->team, voxdagi_worker_run, worker, sizeof *worker, b->threads);

    /* Merge in worker order, then feed voxels and subtrees in Morton order. */
    for (t = 0; t < b->threads && st == VOXDAG_OK; t++)
        for (k = 0; k < b->red_count; k++) {
            uint32_t *map[VOXDAG_MAX_LEVELS];
            size_t map_size[VOXDAG_MAX_LEVELS], p;
            memset(map, 0, sizeof map);
            memset(map_size, 0, sizeof map_size);
            if (worker[t].red[k].failed || !voxdagi_merge(&b->red[k], &worker[t].red[k], map, map_size))
                st = VOXDAG_ERR_OUT_OF_MEMORY;
            for (p = 0; p < worker[t].piece_count && st == VOXDAG_OK; p++) {
                uint32_t x = worker[t].piece[p].root[k];
                worker[t].piece[p].root[k] = voxdagi_ref_compose(x & 63, map[split][x >> 6]);
            }
            for (i = 0; i < VOXDAG_MAX_LEVELS; i++) voxdagi_free(&b->mem, map[i], map_size[i]);
        }
    for (t = 0; t < b->threads; t++)
        for (k = 0; k < b->red_count; k++) voxdagi_reducer_free(&worker[t].red[k]);
    if (st == VOXDAG_OK) {
        size_t p = 0;
        for (start = 0; start < n; start++) {
            if (p < npieces && piece[p].begin == start) {
                for (k = 0; k < b->red_count; k++) {
                    voxdagi_reducer_close_below(&b->red[k], split);
                    voxdagi_reducer_push(&b->red[k], split, code[start] >> shift, piece[p].root[k]);
                }
                start = piece[p].end - 1;
                p++;
                continue;
            }
            for (k = 0; k < b->red_count; k++) voxdagi_reducer_voxel(&b->red[k], code[start]);
        }
        *done = 1;
    }
    voxdagi_free(&b->mem, worker, b->threads * sizeof *worker);
    voxdagi_free(&b->mem, piece, cap * sizeof *piece);
    return st;
}
#endif

/* Unique nodes and bricks reduced so far, all levels together (what
   opts.max_nodes caps). */
static uint64_t voxdagi_builder_nodes(const voxdag_builder *b) {
    uint64_t n = 0;
    uint32_t l;
    for (l = 0; l + 1 < b->levels; l++) n += b->red[0].store[l].n;
    return n;
}

static const char *voxdagi_reduce_message(voxdag_status st) {
    return st == VOXDAG_ERR_LIMIT       ? "more nodes than max_nodes"
           : st == VOXDAG_ERR_IO        ? "the colour sink failed"
           : st == VOXDAG_ERR_CANCELLED ? "the build was cancelled (progress_cancel)"
                                        : "out of memory while reducing voxels";
}

/* Reports progress (voxdag_progress_fn). Returns VOXDAG_ERR_CANCELLED when
   progress_cancel asks to stop, else VOXDAG_OK. */
static voxdag_status voxdagi_progress(const voxdag_builder *b, const char *stage, double fraction) {
    if (b->opts.progress) b->opts.progress(b->opts.progress_user, stage, fraction);
    if (b->opts.progress_cancel && b->opts.progress_cancel(b->opts.progress_user, stage, fraction))
        return VOXDAG_ERR_CANCELLED;
    return VOXDAG_OK;
}

/* Voxels (and bricks) between two progress reports while reducing. */
#define VOXDAGI_PROGRESS_VOXELS ((size_t)1 << 16)
#define VOXDAGI_PROGRESS_BRICKS ((size_t)1 << 14)

/* Sorts, deduplicates and reduces the buffered voxels. FINAL: no voxel follows. */
static voxdag_status voxdagi_builder_reduce(voxdag_builder *b, int final) {
    size_t n = b->pend_n, i, w;
    uint64_t *code = b->pend_code;
    uint32_t *rgb = b->pend_rgb;
    int sorted = 1, distinct = 1, done = 0;
    unsigned k;
    voxdag_status st;
    if (!n) return VOXDAG_OK;
    for (i = 1; i < n && sorted; i++) {
        sorted = code[i - 1] <= code[i];
        distinct &= code[i - 1] != code[i];
    }
    distinct &= sorted;
    if (!sorted) {
        size_t rgb_size = rgb ? n * sizeof *rgb : 0;
        uint64_t *tc = (uint64_t *)voxdagi_alloc(&b->mem, n * sizeof *tc);
        uint32_t *tr = rgb ? (uint32_t *)voxdagi_alloc(&b->mem, rgb_size) : NULL;
        if (!tc || (rgb && !tr)) {
            voxdagi_free(&b->mem, tc, n * sizeof *tc);
            voxdagi_free(&b->mem, tr, rgb_size);
            return VOXDAG_ERR_OUT_OF_MEMORY;
        }
        voxdagi_sort(b, code, rgb, tc, tr, n, 3 * b->levels);
        voxdagi_free(&b->mem, tc, n * sizeof *tc);
        voxdagi_free(&b->mem, tr, rgb_size);
    }
    /* Keep the last of equal codes; a repeat of the last reduced voxel only
       replaces its colour. */
    w = distinct ? n : 0;
    for (i = w; i < n; i++) {
        if (w && code[w - 1] == code[i]) {
            if (rgb) rgb[w - 1] = rgb[i];
            continue;
        }
        code[w] = code[i];
        if (rgb) rgb[w] = rgb[i];
        w++;
    }
    i = 0;
    if (b->any_reduced && code[0] < b->last_code) return VOXDAG_ERR_ORDER;
    if (b->any_reduced && code[0] == b->last_code) {
        if (rgb) {
            uint8_t *c = b->colors + 3 * (size_t)(b->voxels - 1 - b->colors_base);
            c[0] = (uint8_t)(rgb[0] >> 16);
            c[1] = (uint8_t)(rgb[0] >> 8);
            c[2] = (uint8_t)rgb[0];
        }
        i = 1;
    }
    n = w - i;
    code += i;
    if (rgb) rgb += i;
    b->pend_n = 0;
    if (!n) return VOXDAG_OK;
    if ((st = voxdagi_builder_colors(b, rgb, NULL, n)) != VOXDAG_OK) return st;
#ifndef VOXDAG_NO_THREADS
    if ((st = voxdagi_reduce_parallel(b, code, n, final, &done)) != VOXDAG_OK) return st;
#else
    (void)final;
#endif
    if (!done) {
        double total = (double)n * b->red_count;
        for (k = 0; k < b->red_count; k++)
            for (i = 0; i < n;) {
                size_t end = n - i > VOXDAGI_PROGRESS_VOXELS ? i + VOXDAGI_PROGRESS_VOXELS : n;
                for (; i < end; i++) voxdagi_reducer_voxel(&b->red[k], code[i]);
                if ((st = voxdagi_progress(b, "reduce", ((double)k * (double)n + (double)i) / total)) != VOXDAG_OK)
                    return st;
            }
    } else if ((st = voxdagi_progress(b, "reduce", 1.0)) != VOXDAG_OK) {
        return st;
    }
    for (k = 0; k < b->red_count; k++)
        if (b->red[k].failed) return VOXDAG_ERR_OUT_OF_MEMORY;
    b->voxels += n;
    b->last_code = code[n - 1];
    b->any_reduced = 1;
    if (b->opts.max_nodes && voxdagi_builder_nodes(b) > b->opts.max_nodes) return VOXDAG_ERR_LIMIT;
    return VOXDAG_OK;
}

VOXDAG_API voxdag_status voxdag_builder_flush(voxdag_builder *b, voxdag_error *err) {
    voxdag_status st;
    if (!b) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "builder is NULL");
    if (b->failed) return VOXDAGI_FAIL(err, b->failed, "the builder failed earlier");
    st = voxdagi_builder_reduce(b, 0);
    if (st != VOXDAG_OK) {
        b->failed = voxdagi_mem_fail(&b->mem, err, st, voxdagi_reduce_message(st));
        return b->failed;
    }
    return voxdagi_ok(err);
}

/* Checks N bricks (key, mask pairs) for voxdag_builder_add_bricks: keys in
   the grid and increasing after the last reduced voxel. Returns the status
   and in *BAD the first brick at fault; *VOXELS: their voxel count. */
static voxdag_status voxdagi_check_bricks(const voxdag_builder *b, const uint64_t *bricks, size_t n, size_t *bad,
                                          uint64_t *voxels) {
    uint64_t limit = 1ull << (3 * (b->levels - 2)), last = b->last_code >> 6;
    int any = b->any_reduced;
    size_t i;
    *voxels = 0;
    for (i = 0; i < n; i++) {
        uint64_t key = bricks[2 * i], mask = bricks[2 * i + 1];
        *bad = i;
        if (!mask) continue;
        if (key >= limit) return VOXDAG_ERR_COORDINATE;
        if (any && key <= last) return VOXDAG_ERR_ORDER;
        any = 1;
        last = key;
        *voxels += (uint64_t)voxdagi_popcount64(mask);
    }
    return VOXDAG_OK;
}

/* Reduces N checked bricks and takes their colours (RGB8, one per voxel, or
   packed 0xRRGGBB in RGB32 when not NULL): the voxelizer's path and
   voxdag_builder_add_bricks'. */
static voxdag_status voxdagi_builder_bricks(voxdag_builder *b, const uint64_t *bricks, const uint8_t *rgb8,
                                            const uint32_t *rgb32, size_t n, uint64_t voxels, int report) {
    voxdag_status st;
    uint64_t m = 0, key = 0;
    size_t i, end;
    unsigned k;
    if (!voxels) return report ? voxdagi_progress(b, "reduce", 1.0) : VOXDAG_OK;
    if ((st = voxdagi_builder_colors(b, rgb32, rgb8, (size_t)voxels)) != VOXDAG_OK) return st;
    for (k = 0; k < b->red_count; k++) {
        for (i = 0; i < n;) {
            end = report && n - i > VOXDAGI_PROGRESS_BRICKS ? i + VOXDAGI_PROGRESS_BRICKS : n;
            for (; i < end; i++)
                if (bricks[2 * i + 1]) voxdagi_reducer_brick(&b->red[k], bricks[2 * i], bricks[2 * i + 1]);
            if (report && (st = voxdagi_progress(b, "reduce", ((double)k * (double)n + (double)i) /
                                                                    ((double)n * b->red_count))) != VOXDAG_OK)
                return st;
        }
        if (b->red[k].failed) return VOXDAG_ERR_OUT_OF_MEMORY;
    }
    for (i = n; i-- > 0;)
        if (bricks[2 * i + 1]) {
            key = bricks[2 * i];
            m = bricks[2 * i + 1];
            break;
        }
    b->voxels += voxels;
    for (k = 1; k < 64; k *= 2) m |= m >> k; /* the last voxel: the mask's highest bit */
    b->last_code = key << 6 | (uint64_t)(voxdagi_popcount64(m) - 1);
    b->any_reduced = 1;
    if (b->opts.max_nodes && voxdagi_builder_nodes(b) > b->opts.max_nodes) return VOXDAG_ERR_LIMIT;
    return VOXDAG_OK;
}

VOXDAG_API voxdag_status voxdag_builder_add_bricks(voxdag_builder *b, const uint64_t *bricks, const uint8_t *rgb,
                                                   size_t n, voxdag_error *err) {
    voxdag_status st;
    uint64_t voxels;
    size_t bad = 0;
    if (!b || (n && !bricks) || (n && b->opts.colors && !rgb))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "builder, bricks or colours missing");
    if (b->failed) return VOXDAGI_FAIL(err, b->failed, "the builder failed earlier");
    if (b->pend_n)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "voxels are buffered: flush before adding bricks");
    st = voxdagi_check_bricks(b, bricks, n, &bad, &voxels);
    if (st == VOXDAG_ERR_COORDINATE)
        return voxdagi_fail(err, st, "brick key outside the grid", UINT64_MAX, (uint64_t)bad);
    if (st == VOXDAG_ERR_ORDER)
        return voxdagi_fail(err, st, "brick key does not follow the bricks and voxels before it", UINT64_MAX,
                            (uint64_t)bad);
    st = voxdagi_builder_bricks(b, bricks, rgb, NULL, n, voxels, 1);
    if (st != VOXDAG_OK) {
        b->failed = st;
        return VOXDAGI_FAIL(err, st, voxdagi_reduce_message(st));
    }
    return voxdagi_ok(err);
}

// -- Triangle voxelization (conservative, exact separating-axis test)

/* Small replacements for libm so that the header needs libc only. */
static double voxdagi_abs(double x) { return x < 0 ? -x : x; }
static double voxdagi_floor(double x) { /* |x| < 2^62 */
    double i = (double)(int64_t)x;
    return i > x ? i - 1 : i;
}

typedef struct voxdagi_tri {
    double v[3][3];      /* vertices, grid units */
    double n[3];         /* normal (unnormalized; zero when degenerate) */
    double lo[3], hi[3]; /* bounding box */
} voxdagi_tri;

/* The 13 axes of the separating-axis theorem for a triangle and boxes of one
   size: the box normals (0..2), the triangle normal (3), and the cross
   products edge i x box normal k (4 + 3k + i, which have no k component).
   The box [p, p + size]^3 and the triangle intersect, touching included, iff
   lo <= a.p <= hi on every axis a ([lo, hi] is the triangle's interval on a,
   less the box's extent). Degenerate triangles give zero axes (lo <= 0 <= hi),
   which never separate, so segments and points are handled by the others. */
typedef struct voxdagi_axes {
    double a[13][3], lo[13], hi[13];
} voxdagi_axes;

static void voxdagi_axes_init(voxdagi_axes *x, const voxdagi_tri *t, double size) {
    unsigned i, k, j, c;
    memset(x->a, 0, sizeof x->a);
    for (k = 0; k < 3; k++) {
        x->a[k][k] = 1;
        x->a[3][k] = t->n[k];
        for (i = 0; i < 3; i++) {
            double *a = x->a[4 + 3 * k + i];
            a[(k + 1) % 3] = t->v[(i + 1) % 3][(k + 2) % 3] - t->v[i][(k + 2) % 3];
            a[(k + 2) % 3] = t->v[i][(k + 1) % 3] - t->v[(i + 1) % 3][(k + 1) % 3];
        }
    }
    for (j = 0; j < 13; j++) {
        const double *a = x->a[j];
        double mn = 1e308, mx = -1e308, ext_lo = 0, ext_hi = 0;
        for (c = 0; c < 3; c++) {
            double p = a[0] * t->v[c][0] + a[1] * t->v[c][1] + a[2] * t->v[c][2];
            if (p < mn) mn = p;
            if (p > mx) mx = p;
        }
        for (k = 0; k < 3; k++) {
            if (a[k] > 0) ext_hi += size * a[k];
            else ext_lo += size * a[k];
        }
        x->lo[j] = mn - ext_hi;
        x->hi[j] = mx - ext_lo;
    }
}

static int voxdagi_axes_test(const voxdagi_axes *x, const double p[3], unsigned j) {
    double s = x->a[j][0] * p[0] + x->a[j][1] * p[1] + x->a[j][2] * p[2];
    return s >= x->lo[j] && s <= x->hi[j];
}

/* Range of voxels whose closed boxes [x, x+1] may touch [lo, hi], clamped to
   [0, limit). Returns 0 when empty. */
static int voxdagi_voxel_range(double lo, double hi, int64_t limit, int64_t *first, int64_t *last) {
    double f, l;
    if (lo < -2) lo = -2; /* keeps the values small enough for voxdagi_floor */
    if (hi > (double)limit + 1) hi = (double)limit + 1;
    if (lo > hi) return 0;
    f = -voxdagi_floor(1 - lo); /* ceil(lo - 1) */
    l = voxdagi_floor(hi);
    if (f < 0) f = 0;
    if (l > (double)(limit - 1)) l = (double)(limit - 1);
    if (f > l) return 0;
    *first = (int64_t)f;
    *last = (int64_t)l;
    return 1;
}

/* Barycentric coordinates of P's projection on T's plane, clamped into the
   triangle (negative ones 0, the rest scaled to sum 1). */
static void voxdagi_tri_bary(const voxdagi_tri *t, const double p[3], double bary[3]) {
    double nn = t->n[0] * t->n[0] + t->n[1] * t->n[1] + t->n[2] * t->n[2], sum = 0;
    unsigned i, k;
    if (!(nn > 0)) {
        bary[0] = bary[1] = bary[2] = 1.0 / 3;
        return;
    }
    for (i = 0; i < 3; i++) { /* signed area of (p, v[i+1], v[i+2]) along n */
        const double *a = t->v[(i + 1) % 3], *c = t->v[(i + 2) % 3];
        double x[3], y[3], w = 0;
        for (k = 0; k < 3; k++) {
            x[k] = a[k] - p[k];
            y[k] = c[k] - p[k];
        }
        for (k = 0; k < 3; k++) w += t->n[k] * (x[(k + 1) % 3] * y[(k + 2) % 3] - x[(k + 2) % 3] * y[(k + 1) % 3]);
        bary[i] = w > 0 ? w / nn : 0;
        sum += bary[i];
    }
    for (i = 0; i < 3; i++) bary[i] = sum > 0 ? bary[i] / sum : 1.0 / 3;
}

static int voxdagi_load_tri(const voxdag_mesh *mesh, size_t i, voxdagi_tri *t) {
    double e1[3], e2[3];
    unsigned c, k;
    for (c = 0; c < 3; c++) {
        uint32_t vi = mesh->indices[3 * i + c];
        if (vi >= mesh->vertex_count) return 0;
        for (k = 0; k < 3; k++) {
            double x = mesh->positions[3 * (size_t)vi + k];
            if (!(x > -1e300 && x < 1e300)) return 0;
            t->v[c][k] = x;
        }
    }
    for (k = 0; k < 3; k++) {
        e1[k] = t->v[1][k] - t->v[0][k];
        e2[k] = t->v[2][k] - t->v[0][k];
        t->lo[k] = t->hi[k] = t->v[0][k];
        for (c = 1; c < 3; c++) {
            if (t->v[c][k] < t->lo[k]) t->lo[k] = t->v[c][k];
            if (t->v[c][k] > t->hi[k]) t->hi[k] = t->v[c][k];
        }
    }
    for (k = 0; k < 3; k++) t->n[k] = e1[(k + 1) % 3] * e2[(k + 2) % 3] - e1[(k + 2) % 3] * e2[(k + 1) % 3];
    return 1;
}

// -- Solid voxelization: exact column tests, the closedness check

/* Vertex x and y for the exact column tests: fixed point in units of 2^-20
   voxel, clamped to +-2^40 voxels, so differences fit 62 bits. Columns run
   through voxel centres, at odd multiples of 2^19. */
static int64_t voxdagi_fix(double x) {
    if (x > 1099511627776.0) x = 1099511627776.0;
    if (x < -1099511627776.0) x = -1099511627776.0;
    return (int64_t)voxdagi_floor(x * 1048576.0 + 0.5);
}

static int64_t voxdagi_fix_centre(int64_t voxel) { return voxel * 1048576 + 524288; }

/* The edge function (B - A) x (Q - A) of fixed-point points, exactly (with
   128-bit products made of 32-bit halves where the values need them), at Q
   moved by (e, e^2) for an infinitely small e: returns its sign, never 0
   unless A = B, and sets *W to its value at Q itself (0 on the edge's line). */
static int voxdagi_edge_sign(const int64_t a[2], const int64_t b[2], const int64_t q[2], double *w) {
    int64_t dx = b[0] - a[0], dy = b[1] - a[1], qx = q[0] - a[0], qy = q[1] - a[1];
    const int64_t small = (int64_t)1 << 31;
    uint64_t hi = 0, lo = 0;
    int neg;
    if (dx > -small && dx < small && dy > -small && dy < small && qx > -small && qx < small && qy > -small &&
        qy < small) {
        int64_t v = dx * qy - dy * qx; /* |v| < 2^63 */
        *w = (double)v;
        if (v) return v > 0 ? 1 : -1;
    } else {
        int64_t f[4];
        uint64_t h[2], l[2];
        unsigned k;
        f[0] = dx, f[1] = qy, f[2] = dy, f[3] = qx;
        for (k = 0; k < 2; k++) { /* h:l = f[2k] * f[2k+1], two's complement */
            uint64_t ua = f[2 * k] < 0 ? 0 - (uint64_t)f[2 * k] : (uint64_t)f[2 * k];
            uint64_t ub = f[2 * k + 1] < 0 ? 0 - (uint64_t)f[2 * k + 1] : (uint64_t)f[2 * k + 1];
            uint64_t a0 = ua & 0xffffffffu, a1 = ua >> 32, b0 = ub & 0xffffffffu, b1 = ub >> 32;
            uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0;
            uint64_t mid = (p00 >> 32) + (p01 & 0xffffffffu) + (p10 & 0xffffffffu);
            l[k] = mid << 32 | (p00 & 0xffffffffu);
            h[k] = a1 * b1 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
            if ((f[2 * k] < 0) != (f[2 * k + 1] < 0)) {
                l[k] = ~l[k] + 1;
                h[k] = ~h[k] + (uint64_t)(l[k] == 0);
            }
        }
        lo = l[0] - l[1];
        hi = h[0] - h[1] - (uint64_t)(l[0] < l[1]);
        neg = (int)(hi >> 63);
        if (neg) {
            lo = ~lo + 1;
            hi = ~hi + (uint64_t)(lo == 0);
        }
        if (hi | lo) {
            *w = ((double)hi * 18446744073709551616.0 + (double)lo) * (neg ? -1.0 : 1.0);
            return neg ? -1 : 1;
        }
        *w = 0;
    }
    /* on the line: the value at Q + (e, e^2) is -dy e + dx e^2 */
    return dy ? (dy < 0 ? 1 : -1) : dx > 0 ? 1 : dx < 0 ? -1 : 0;
}

/* A triangle for the column tests: x and y in fixed point, z as given. */
typedef struct voxdagi_ftri {
    int64_t p[3][2];
    double z[3];
} voxdagi_ftri;

static void voxdagi_ftri_init(voxdagi_ftri *f, const voxdagi_tri *t) {
    unsigned c;
    for (c = 0; c < 3; c++) {
        f->p[c][0] = voxdagi_fix(t->v[c][0]);
        f->p[c][1] = voxdagi_fix(t->v[c][1]);
        f->z[c] = t->v[c][2];
    }
}

/* Whether the column through Q (fixed point, moved by (e, e^2)) crosses T:
   returns +1 where T turns counter-clockwise seen from +z, -1 where it turns
   clockwise, and sets *H to the crossing's height and BARY to its
   barycentric coordinates (from the exact edge values, so H lies within the
   vertices' heights); 0 where the column passes beside T. */
static int voxdagi_column_cross(const voxdagi_ftri *t, const int64_t q[2], double *h, double bary[3]) {
    double w[3], sum;
    int s = voxdagi_edge_sign(t->p[1], t->p[2], q, &w[0]);
    if (!s || voxdagi_edge_sign(t->p[2], t->p[0], q, &w[1]) != s || voxdagi_edge_sign(t->p[0], t->p[1], q, &w[2]) != s)
        return 0;
    sum = w[0] + w[1] + w[2]; /* twice the area, nonzero when the signs agree */
    if (sum == 0) {
        bary[0] = bary[1] = bary[2] = 1.0 / 3;
    } else {
        bary[0] = w[0] / sum;
        bary[1] = w[1] / sum;
        bary[2] = 1 - bary[0] - bary[1];
        if (bary[2] < 0) bary[2] = 0;
    }
    *h = bary[0] * t->z[0] + bary[1] * t->z[1] + bary[2] * t->z[2];
    return s;
}

static uint64_t voxdagi_position_hash(const double *p) {
    uint64_t h = 0x9E3779B97F4A7C15ull, x;
    unsigned k;
    for (k = 0; k < 3; k++) {
        double v = p[k] + 0.0; /* -0 as +0 */
        memcpy(&x, &v, 8);
        h = (h ^ x) * 0xBF58476D1CE4E5B9ull;
        h ^= h >> 29;
    }
    return h;
}

/* voxdag_mesh_open_edges with memory M. Returns VOXDAG_ERR_INVALID_ARGUMENT
   with *BAD, the triangle, for a bad index or vertex. */
static voxdag_status voxdagi_open_edges(voxdagi_mem *m, const voxdag_mesh *mesh, uint64_t *open, uint64_t *first,
                                        uint64_t *bad) {
    size_t v = mesh->vertex_count, t = mesh->triangle_count, hs = 16, n = 0, i, j, e = t ? 3 * t : 1;
    uint32_t *canon = NULL, *table = NULL, *tri = NULL, *tmp_tri = NULL;
    uint64_t *key = NULL, *tmp_key = NULL;
    voxdag_status st = VOXDAG_OK;
    *open = 0;
    *first = UINT64_MAX;
    if (v > 0x7fffffffu) return VOXDAG_ERR_LIMIT;
    if (t > UINT32_MAX) return VOXDAG_ERR_LIMIT;
    if (t > (size_t)-1 / 24 || v > (size_t)-1 / 16) return VOXDAG_ERR_OUT_OF_MEMORY; /* 32-bit sizes */
    while (hs < 2 * v) hs *= 2;
    canon = (uint32_t *)voxdagi_alloc(m, (v ? v : 1) * 4);
    table = (uint32_t *)voxdagi_alloc(m, hs * 4);
    key = (uint64_t *)voxdagi_alloc(m, e * 8);
    tmp_key = (uint64_t *)voxdagi_alloc(m, e * 8);
    tri = (uint32_t *)voxdagi_alloc(m, e * 4);
    tmp_tri = (uint32_t *)voxdagi_alloc(m, e * 4);
    if (!canon || !table || !key || !tmp_key || !tri || !tmp_tri) st = VOXDAG_ERR_OUT_OF_MEMORY;
    if (st == VOXDAG_OK) {
        memset(canon, 0xff, (v ? v : 1) * 4);
        memset(table, 0xff, hs * 4);
    }
    for (i = 0; i < t && st == VOXDAG_OK; i++) { /* vertices welded by position, then directed edges */
        voxdagi_tri tr;
        uint32_t c[3];
        unsigned k;
        if (!voxdagi_load_tri(mesh, i, &tr)) {
            *bad = i;
            st = VOXDAG_ERR_INVALID_ARGUMENT;
            break;
        }
        for (k = 0; k < 3; k++) {
            uint32_t vi = mesh->indices[3 * i + k];
            if (canon[vi] == UINT32_MAX) {
                const double *p = mesh->positions + 3 * (size_t)vi;
                size_t s = (size_t)voxdagi_position_hash(p) & (hs - 1);
                while (table[s] != UINT32_MAX) {
                    const double *o = mesh->positions + 3 * (size_t)table[s];
                    if (o[0] == p[0] && o[1] == p[1] && o[2] == p[2]) break;
                    s = (s + 1) & (hs - 1);
                }
                if (table[s] == UINT32_MAX) table[s] = vi;
                canon[vi] = table[s];
            }
            c[k] = canon[vi];
        }
        for (k = 0; k < 3; k++) {
            uint32_t a = c[k], b = c[(k + 1) % 3];
            if (a == b) continue;
            key[n] = (uint64_t)(a < b ? a : b) << 32 | (uint64_t)(a < b ? b : a) << 1 | (uint64_t)(a > b);
            tri[n++] = (uint32_t)i;
        }
    }
    if (st == VOXDAG_OK) {
        voxdagi_radix_sort(key, tri, tmp_key, tmp_tri, n, 63);
        for (i = 0; i < n; i = j) { /* a run of one undirected edge: as often each way? */
            int64_t sum = 0;
            uint32_t low = UINT32_MAX;
            for (j = i; j < n && key[j] >> 1 == key[i] >> 1; j++) {
                sum += (key[j] & 1) ? -1 : 1;
                if (tri[j] < low) low = tri[j];
            }
            if (sum) {
                ++*open;
                if (low < *first) *first = low;
            }
        }
    }
    voxdagi_free(m, canon, (v ? v : 1) * 4);
    voxdagi_free(m, table, hs * 4);
    voxdagi_free(m, key, e * 8);
    voxdagi_free(m, tmp_key, e * 8);
    voxdagi_free(m, tri, e * 4);
    voxdagi_free(m, tmp_tri, e * 4);
    return st;
}

VOXDAG_API voxdag_status voxdag_mesh_open_edges(const voxdag_mesh *mesh, const voxdag_allocator *allocator,
                                                uint64_t *open_edges, uint64_t *first_triangle,
                                                voxdag_error *err) {
    voxdagi_mem m;
    uint64_t open = 0, first = UINT64_MAX, bad = 0;
    voxdag_status st;
    if (!mesh || (mesh->triangle_count && (!mesh->indices || !mesh->positions)) ||
        (allocator && (allocator->alloc == NULL) != (allocator->free == NULL)))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "mesh arrays missing, or half an allocator");
    voxdagi_mem_init(&m, allocator, 0);
    st = voxdagi_open_edges(&m, mesh, &open, &first, &bad);
    voxdagi_mem_destroy(&m);
    if (open_edges) *open_edges = open;
    if (first_triangle) *first_triangle = first;
    if (st == VOXDAG_ERR_INVALID_ARGUMENT)
        return voxdagi_fail(err, st, "triangle index out of range or non-finite vertex", UINT64_MAX, bad);
    if (st == VOXDAG_ERR_LIMIT) return VOXDAGI_FAIL(err, st, "more than 2^31-1 vertices or 2^32-1 triangles");
    if (st != VOXDAG_OK) return VOXDAGI_FAIL(err, st, "out of memory");
    return voxdagi_ok(err);
}

/* The triangles of a solid mesh by columns of chunks: every triangle whose
   x and y ranges meet a chunk column's, whatever its z. */
typedef struct voxdagi_solid {
    const uint64_t *key; /* sorted: cy << 32 | cx */
    const uint32_t *tri; /* ascending within a column */
    size_t n;
} voxdagi_solid;

/* A column's crossing inside a chunk's range of voxel centres. */
typedef struct voxdagi_event {
    double h;
    uint32_t tri, col;
    int32_t sign;
} voxdagi_event;

/* One chunk being voxelized: a bitmap of its voxels in local Morton order
   (so each 64-bit word is a 4^3 brick), then its bricks and colours in Morton
   order, ready for the builder. Each thread owns one. */
typedef struct voxdagi_chunk {
    voxdag_builder *b;
    const voxdag_mesh *mesh;
    unsigned shift;            /* edge 2^shift voxels, 2..8 */
    uint64_t *bits;            /* 2^(3 shift - 6) words */
    uint64_t *used;            /* one bit per nonzero word of BITS */
    uint32_t *owner;           /* per voxel: the last triangle touching it (colours only) */
    uint64_t *brick;           /* the chunk's bricks: (brick Morton code, voxel mask) pairs */
    uint32_t *rgb;             /* the chunk's colours, 0xRRGGBB, in Morton order */
    size_t bricks, brick_cap, rgb_cap, voxels;
    uint64_t code;             /* this round: chunk Morton code */
    const uint32_t *tri;       /* this round: its triangles, ascending */
    size_t tri_count;
    int failed;                /* out of memory */
    /* Solid meshes (voxdagi_chunk_solid), else NULL: */
    const voxdagi_solid *solid;
    int32_t *top;              /* per column: the winding number above the chunk */
    size_t *col_start;         /* per column, and one more: its first event */
    uint32_t *above;           /* per column: the nearest crossing above the chunk (colours only) */
    double *above_h;           /* its height (colours only) */
    uint64_t *inner;           /* like BITS: voxels set by the winding rule (colours only) */
    voxdagi_event *ev, *ev_sorted;
    size_t ev_n, ev_cap, ev_sorted_cap;
} voxdagi_chunk;

static size_t voxdagi_chunk_words(const voxdagi_chunk *c) { return (size_t)1 << (3 * c->shift - 6); }
static size_t voxdagi_chunk_used_words(const voxdagi_chunk *c) { return (voxdagi_chunk_words(c) + 63) / 64; }

static size_t voxdagi_chunk_columns(const voxdagi_chunk *c) { return (size_t)1 << (2 * c->shift); }

static int voxdagi_chunk_init(voxdagi_chunk *c, voxdag_builder *b, const voxdag_mesh *mesh, unsigned shift,
                              const voxdagi_solid *solid) {
    size_t cols;
    memset(c, 0, sizeof *c);
    c->b = b;
    c->mesh = mesh;
    c->shift = shift;
    c->bits = (uint64_t *)voxdagi_alloc(&b->mem, voxdagi_chunk_words(c) * 8);
    c->used = (uint64_t *)voxdagi_alloc(&b->mem, voxdagi_chunk_used_words(c) * 8);
    if (b->opts.colors) c->owner = (uint32_t *)voxdagi_alloc(&b->mem, voxdagi_chunk_words(c) * 64 * 4);
    if (!c->bits || !c->used || (b->opts.colors && !c->owner)) return 0;
    memset(c->bits, 0, voxdagi_chunk_words(c) * 8);
    memset(c->used, 0, voxdagi_chunk_used_words(c) * 8);
    if (!solid) return 1;
    cols = voxdagi_chunk_columns(c);
    c->solid = solid;
    c->top = (int32_t *)voxdagi_alloc(&b->mem, cols * sizeof *c->top);
    c->col_start = (size_t *)voxdagi_alloc(&b->mem, (cols + 1) * sizeof *c->col_start);
    if (!c->top || !c->col_start) return 0;
    if (!b->opts.colors) return 1;
    c->above = (uint32_t *)voxdagi_alloc(&b->mem, cols * sizeof *c->above);
    c->above_h = (double *)voxdagi_alloc(&b->mem, cols * sizeof *c->above_h);
    c->inner = (uint64_t *)voxdagi_alloc(&b->mem, voxdagi_chunk_words(c) * 8);
    if (!c->above || !c->above_h || !c->inner) return 0;
    memset(c->inner, 0, voxdagi_chunk_words(c) * 8);
    return 1;
}

static void voxdagi_chunk_free(voxdagi_chunk *c) {
    voxdagi_mem *m = &c->b->mem;
    size_t cols = voxdagi_chunk_columns(c);
    voxdagi_free(m, c->bits, c->bits ? voxdagi_chunk_words(c) * 8 : 0);
    voxdagi_free(m, c->used, c->used ? voxdagi_chunk_used_words(c) * 8 : 0);
    voxdagi_free(m, c->owner, c->owner ? voxdagi_chunk_words(c) * 64 * 4 : 0);
    voxdagi_free(m, c->top, cols * sizeof *c->top);
    voxdagi_free(m, c->col_start, (cols + 1) * sizeof *c->col_start);
    voxdagi_free(m, c->above, cols * sizeof *c->above);
    voxdagi_free(m, c->above_h, cols * sizeof *c->above_h);
    voxdagi_free(m, c->inner, c->inner ? voxdagi_chunk_words(c) * 8 : 0);
    voxdagi_free(m, c->ev, c->ev_cap * sizeof *c->ev);
    voxdagi_free(m, c->ev_sorted, c->ev_sorted_cap * sizeof *c->ev_sorted);
    voxdagi_free(m, c->brick, c->brick_cap * 16);
    voxdagi_free(m, c->rgb, c->rgb_cap * sizeof *c->rgb);
}

/* Sets the voxels of column P (P[w] varies over [QLO, QHI]) that the
   triangle's box test passes and KEEP, when not NULL, keeps; UV: the
   column's Morton bits. */
VOXDAGI_INLINE void voxdagi_chunk_column(voxdagi_chunk *c, const voxdagi_tri *t, const voxdagi_axes *x, uint32_t tri,
                                         double p[3], unsigned w, double qlo, double qhi, int64_t clo_w, uint64_t uv,
                                         const unsigned per_voxel[7],
                                         int (*keep)(void *user, size_t triangle, const double bary[3])) {
    int64_t q;
    unsigned j, k;
    for (q = (int64_t)-voxdagi_floor(-qlo); q <= (int64_t)voxdagi_floor(qhi); q++) {
        uint64_t code;
        p[w] = (double)q;
        for (j = 0; j < 7 && voxdagi_axes_test(x, p, per_voxel[j]); j++) continue;
        if (j < 7) continue;
        if (keep) { /* the voxel centre's point on the triangle */
            double centre[3], bary[3];
            for (k = 0; k < 3; k++) centre[k] = p[k] + 0.5;
            voxdagi_tri_bary(t, centre, bary);
            if (!keep(c->mesh->user, tri, bary)) continue;
        }
        code = uv | voxdagi_spread3((uint32_t)(q - clo_w)) << w;
        c->bits[code >> 6] |= 1ull << (code & 63);
        c->used[code >> 12] |= 1ull << ((code >> 6) & 63);
        if (c->owner) c->owner[code] = tri;
    }
}

/* Marks every voxel of triangle TRI (T, with unit-box axes X) inside the
   chunk whose lowest voxel is CLO. Columns run along the normal's dominant
   axis w: the three axes without a w component are tested once per column,
   the plane bounds the column to the few voxels it crosses, and the other
   seven axes decide each of those (the box normals hold by the ranges). */
static void voxdagi_chunk_tri(voxdagi_chunk *c, const voxdagi_tri *t, const voxdagi_axes *x, uint32_t tri,
                              const int64_t clo[3]) {
    int (*keep)(void *, size_t, const double *) = c->mesh->keep;
    unsigned w = 2, u, v, k, j, per_voxel[7], col[3];
    int64_t first[3], last[3], i, jj;
    for (k = 0; k < 3; k++) {
        int64_t lim = clo[k] + ((int64_t)1 << c->shift);
        if (!voxdagi_voxel_range(t->lo[k], t->hi[k], lim, &first[k], &last[k]) || last[k] < clo[k]) return;
        if (first[k] < clo[k]) first[k] = clo[k]; /* the chunk's own voxels only */
    }
    if (voxdagi_abs(t->n[0]) > voxdagi_abs(t->n[w])) w = 0;
    if (voxdagi_abs(t->n[1]) > voxdagi_abs(t->n[w])) w = 1;
    u = (w + 1) % 3;
    v = (w + 2) % 3;
    per_voxel[0] = 3;
    for (j = 0; j < 3; j++) {
        col[j] = 4 + 3 * w + j;
        per_voxel[1 + j] = 4 + 3 * u + j;
        per_voxel[4 + j] = 4 + 3 * v + j;
    }
    for (i = first[u]; i <= last[u]; i++)
        for (jj = first[v]; jj <= last[v]; jj++) {
            double p[3], qlo = (double)first[w], qhi = (double)last[w];
            uint32_t local[3];
            uint64_t uv;
            p[u] = (double)i;
            p[v] = (double)jj;
            p[w] = 0;
            for (j = 0; j < 3 && voxdagi_axes_test(x, p, col[j]); j++) continue;
            if (j < 3) continue;
            if (t->n[w] != 0) { /* the plane's slab on this column, widened by rounding */
                double base = t->n[u] * p[u] + t->n[v] * p[v];
                double qa = (x->lo[3] - base) / t->n[w], qb = (x->hi[3] - base) / t->n[w];
                double lo = qa < qb ? qa : qb, hi = qa < qb ? qb : qa;
                lo -= 1e-6 * (1 + voxdagi_abs(lo));
                hi += 1e-6 * (1 + voxdagi_abs(hi));
                if (lo > qlo) qlo = lo;
                if (hi < qhi) qhi = hi;
                if (qlo > qhi) continue;
            }
            local[u] = (uint32_t)(i - clo[u]);
            local[v] = (uint32_t)(jj - clo[v]);
            local[w] = 0;
            uv = voxdagi_spread3(local[0]) | voxdagi_spread3(local[1]) << 1 | voxdagi_spread3(local[2]) << 2;
            /* the call of a keep callback would cost the loop its registers */
            if (keep) voxdagi_chunk_column(c, t, x, tri, p, w, qlo, qhi, clo[w], uv, per_voxel, keep);
            else voxdagi_chunk_column(c, t, x, tri, p, w, qlo, qhi, clo[w], uv, per_voxel, NULL);
        }
}

/* Winding numbers of the chunk's voxel centres (the solid rule of
   voxdag_builder_add_mesh) from the triangles of its chunk column: the
   crossings above the chunk summed per column, those within it sorted per
   column from the top down; voxels with a nonzero winding number that no
   triangle set are set, owned by the nearest crossing above (with
   colours). */
static void voxdagi_chunk_solid(voxdagi_chunk *c, const int64_t clo[3]) {
    const voxdagi_solid *s = c->solid;
    size_t side = (size_t)1 << c->shift, cols = side * side, lo = 0, hi = s->n, i, e;
    uint64_t key = (uint64_t)(clo[1] >> c->shift) << 32 | (uint64_t)(clo[0] >> c->shift);
    double zlo = (double)clo[2] + 0.5, ztop = (double)clo[2] + (double)side - 0.5;
    uint32_t col;
    while (lo < hi) { /* the column's first triangle */
        size_t mid = lo + (hi - lo) / 2;
        if (s->key[mid] < key) lo = mid + 1;
        else hi = mid;
    }
    memset(c->top, 0, cols * sizeof *c->top);
    if (c->above) {
        memset(c->above, 0xff, cols * sizeof *c->above);
        for (i = 0; i < cols; i++) c->above_h[i] = 1e308;
    }
    c->ev_n = 0;
    for (i = lo; i < s->n && s->key[i] == key; i++) {
        uint32_t tri = s->tri[i];
        voxdagi_tri t;
        voxdagi_ftri f;
        int64_t fx, lx, fy, ly, x, y;
        voxdagi_load_tri(c->mesh, tri, &t);
        if (!(t.hi[2] > zlo)) continue; /* crossings at or below every centre */
        if (!voxdagi_voxel_range(t.lo[0], t.hi[0], clo[0] + (int64_t)side, &fx, &lx) || lx < clo[0] ||
            !voxdagi_voxel_range(t.lo[1], t.hi[1], clo[1] + (int64_t)side, &fy, &ly) || ly < clo[1])
            continue;
        if (fx < clo[0]) fx = clo[0];
        if (fy < clo[1]) fy = clo[1];
        voxdagi_ftri_init(&f, &t);
        for (y = fy; y <= ly; y++)
            for (x = fx; x <= lx; x++) {
                int64_t q[2];
                double h, bary[3];
                int sign;
                q[0] = voxdagi_fix_centre(x);
                q[1] = voxdagi_fix_centre(y);
                sign = voxdagi_column_cross(&f, q, &h, bary);
                if (!sign || !(h > zlo)) continue;
                col = (uint32_t)((size_t)(y - clo[1]) * side + (size_t)(x - clo[0]));
                if (h > ztop) {
                    c->top[col] += sign;
                    if (c->above && (h < c->above_h[col] || (h == c->above_h[col] && tri > c->above[col]))) {
                        c->above_h[col] = h;
                        c->above[col] = tri;
                    }
                    continue;
                }
                if (!voxdagi_grow(&c->b->mem, (void **)&c->ev, &c->ev_cap, c->ev_n + 1, sizeof *c->ev)) {
                    c->failed = 1;
                    return;
                }
                c->ev[c->ev_n].h = h;
                c->ev[c->ev_n].tri = tri;
                c->ev[c->ev_n].col = col;
                c->ev[c->ev_n].sign = sign;
                c->ev_n++;
            }
    }
    /* The events by column (counting sort), each column's from the top down
       (of equal heights, the highest triangle last: the nearest above). */
    if (!voxdagi_grow(&c->b->mem, (void **)&c->ev_sorted, &c->ev_sorted_cap, c->ev_n, sizeof *c->ev)) {
        c->failed = 1;
        return;
    }
    memset(c->col_start, 0, (cols + 1) * sizeof *c->col_start);
    for (e = 0; e < c->ev_n; e++) c->col_start[c->ev[e].col + 1]++;
    for (i = 0; i < cols; i++) c->col_start[i + 1] += c->col_start[i];
    for (e = 0; e < c->ev_n; e++) c->ev_sorted[c->col_start[c->ev[e].col]++] = c->ev[e];
    for (i = cols; i > 0; i--) c->col_start[i] = c->col_start[i - 1];
    c->col_start[0] = 0;
    for (col = 0; col < cols; col++) {
        size_t first = c->col_start[col], end = c->col_start[col + 1];
        int32_t w = c->top[col];
        uint32_t owner = c->above ? c->above[col] : 0, lx = col & (uint32_t)(side - 1), ly = col >> c->shift;
        uint64_t xy = voxdagi_spread3(lx) | voxdagi_spread3(ly) << 1;
        int64_t zb;
        for (e = first + 1; e < end; e++) { /* insertion sort: few per column */
            voxdagi_event v = c->ev_sorted[e];
            size_t k = e;
            while (k > first && (c->ev_sorted[k - 1].h < v.h ||
                                 (c->ev_sorted[k - 1].h == v.h && c->ev_sorted[k - 1].tri > v.tri))) {
                c->ev_sorted[k] = c->ev_sorted[k - 1];
                k--;
            }
            c->ev_sorted[k] = v;
        }
        e = first;
        if (!w && e == end) continue;
        for (zb = (int64_t)side / 4 - 1; zb >= 0; zb--) { /* 4 voxels of a brick at a time */
            uint64_t code = xy | voxdagi_spread3((uint32_t)(4 * zb)) << 2, pattern = 0;
            uint32_t own[4];
            size_t word = (size_t)(code >> 6);
            int j;
            for (j = 3; j >= 0; j--) {
                double centre = (double)(clo[2] + 4 * zb + j) + 0.5;
                for (; e < end && c->ev_sorted[e].h > centre; e++) {
                    w += c->ev_sorted[e].sign;
                    owner = c->ev_sorted[e].tri;
                }
                own[j] = owner;
                if (w) pattern |= 1ull << (voxdagi_spread3((uint32_t)j) << 2); /* bit 0, 4, 32, 36 */
            }
            if (!pattern) continue;
            pattern <<= code & 63;
            if (c->owner) { /* surface voxels keep their owners */
                uint64_t m = pattern & ~c->bits[word];
                c->inner[word] |= m;
                for (; m; m &= m - 1) {
                    unsigned bit = voxdagi_lowest_bit(m);
                    uint32_t zj = voxdagi_compact3((uint64_t)bit >> 2) & 3;
                    c->owner[64 * word + bit] = own[zj];
                }
            }
            c->bits[word] |= pattern;
            c->used[word >> 6] |= 1ull << (word & 63);
        }
    }
}

/* Colours of the voxels of brick WORD of the chunk at CLO, appended to RGB:
   each from its owner triangle at the point nearest to the voxel centre, or
   for an inside voxel (INNER) at the crossing of its column. */
static void voxdagi_chunk_colors(voxdagi_chunk *c, const int64_t clo[3], size_t word, uint64_t m, uint64_t inner) {
    voxdagi_tri t;
    voxdagi_ftri f;
    uint32_t cached = 0;
    int have = 0;
    while (m) {
        uint64_t bit = m & (0 - m), code = 64 * (uint64_t)word + (uint64_t)voxdagi_popcount64(bit - 1);
        uint32_t tri = c->owner[code], xyz[3];
        double centre[3], bary[3], h;
        uint8_t rgb[3];
        unsigned k;
        m ^= bit;
        if (!have || tri != cached) {
            voxdagi_load_tri(c->mesh, tri, &t);
            if (c->inner) voxdagi_ftri_init(&f, &t);
        }
        cached = tri;
        have = 1;
        voxdag_morton_decode(code, &xyz[0], &xyz[1], &xyz[2]);
        for (k = 0; k < 3; k++) centre[k] = (double)(clo[k] + xyz[k]) + 0.5;
        if (inner & bit) {
            int64_t q[2];
            q[0] = voxdagi_fix_centre(clo[0] + xyz[0]);
            q[1] = voxdagi_fix_centre(clo[1] + xyz[1]);
            if (!voxdagi_column_cross(&f, q, &h, bary)) voxdagi_tri_bary(&t, centre, bary); /* never */
        } else {
            voxdagi_tri_bary(&t, centre, bary);
        }
        c->mesh->color(c->mesh->user, tri, bary, rgb);
        c->rgb[c->voxels++] = (uint32_t)rgb[0] << 16 | (uint32_t)rgb[1] << 8 | rgb[2];
    }
}

/* Voxelizes the chunk's triangles (ascending, so a voxel's last owner is its
   highest triangle), then collects its bricks and colours in Morton order,
   clearing the bitmap. */
static void *voxdagi_chunk_run(void *arg) {
    voxdagi_chunk *c = (voxdagi_chunk *)arg;
    int64_t clo[3];
    uint32_t xyz[3];
    size_t i, wu;
    unsigned k;
    voxdag_morton_decode(c->code, &xyz[0], &xyz[1], &xyz[2]);
    for (k = 0; k < 3; k++) clo[k] = (int64_t)xyz[k] << c->shift;
    for (i = 0; i < c->tri_count; i++) {
        voxdagi_tri t;
        voxdagi_axes x;
        if (c->tri[i] == UINT32_MAX) continue; /* a chunk that only the inside fills */
        voxdagi_load_tri(c->mesh, c->tri[i], &t);
        voxdagi_axes_init(&x, &t, 1.0);
        voxdagi_chunk_tri(c, &t, &x, c->tri[i], clo);
    }
    if (c->solid && !c->failed && !c->owner && c->tri_count == 1 && c->tri[0] == UINT32_MAX) {
        size_t words = voxdagi_chunk_words(c); /* inside, untouched: every voxel */
        memset(c->bits, 0xff, words * 8);
        for (wu = 0; wu < voxdagi_chunk_used_words(c); wu++)
            c->used[wu] = words - 64 * wu >= 64 ? ~0ull : (1ull << (words - 64 * wu)) - 1;
    } else if (c->solid && !c->failed) {
        voxdagi_chunk_solid(c, clo);
    }
    c->bricks = c->voxels = 0;
    for (wu = 0; wu < voxdagi_chunk_used_words(c); wu++)
        while (c->used[wu]) {
            uint64_t low = c->used[wu] & (0 - c->used[wu]);
            size_t word = 64 * wu + (size_t)voxdagi_popcount64(low - 1);
            uint64_t m = c->bits[word], inner = 0;
            c->used[wu] ^= low;
            c->bits[word] = 0;
            if (c->inner) {
                inner = c->inner[word];
                c->inner[word] = 0;
            }
            if (c->failed || !voxdagi_grow(&c->b->mem, (void **)&c->brick, &c->brick_cap, c->bricks + 1, 16) ||
                (c->owner && !voxdagi_grow(&c->b->mem, (void **)&c->rgb, &c->rgb_cap,
                                           c->voxels + (size_t)voxdagi_popcount64(m), sizeof *c->rgb))) {
                c->failed = 1;
                continue;
            }
            c->brick[2 * c->bricks] = c->code << (3 * c->shift - 6) | word;
            c->brick[2 * c->bricks + 1] = m;
            c->bricks++;
            if (c->owner) voxdagi_chunk_colors(c, clo, word, m, inner);
            else c->voxels += (size_t)voxdagi_popcount64(m);
        }
    return NULL;
}

/* Gives the next chunks of the sorted (chunk, triangle) pairs from *P on to
   up to COUNT workspaces; returns how many got one. */
static unsigned voxdagi_chunk_assign(voxdagi_chunk *c, unsigned count, const uint64_t *pair_chunk,
                                     const uint32_t *pair_tri, size_t pairs, size_t *p) {
    unsigned t;
    for (t = 0; t < count && *p < pairs; t++) {
        c[t].code = pair_chunk[*p];
        c[t].tri = pair_tri + *p;
        for (c[t].tri_count = 0; *p < pairs && pair_chunk[*p] == c[t].code; ++*p) c[t].tri_count++;
    }
    return t;
}

/* Reduces a voxelized chunk's bricks and takes its colours, through the
   brick feed of voxdag_builder_add_bricks. */
static voxdag_status voxdagi_builder_take(voxdag_builder *b, const voxdagi_chunk *c) {
    uint64_t voxels;
    size_t bad;
    if (c->failed) return VOXDAG_ERR_OUT_OF_MEMORY;
    if (voxdagi_check_bricks(b, c->brick, c->bricks, &bad, &voxels) != VOXDAG_OK) return VOXDAG_ERR_ORDER;
    return voxdagi_builder_bricks(b, c->brick, NULL, c->rgb, c->bricks, voxels, 0);
}

/* Sorts N (key, triangle) pairs by the low BITS bits of the keys, stably.
   Returns 0 when out of memory. */
static int voxdagi_sort_pairs(voxdagi_mem *m, uint64_t *key, uint32_t *tri, size_t n, unsigned bits) {
    uint64_t *tmp_key = (uint64_t *)voxdagi_alloc(m, (n ? n : 1) * sizeof *tmp_key);
    uint32_t *tmp_tri = (uint32_t *)voxdagi_alloc(m, (n ? n : 1) * sizeof *tmp_tri);
    int ok = tmp_key && tmp_tri;
    if (ok) voxdagi_radix_sort(key, tri, tmp_key, tmp_tri, n, bits);
    voxdagi_free(m, tmp_key, (n ? n : 1) * sizeof *tmp_key);
    voxdagi_free(m, tmp_tri, (n ? n : 1) * sizeof *tmp_tri);
    return ok;
}

/* Appends (KEY, TRI) to the pair arrays. Returns 0 when out of memory. */
static int voxdagi_push_pair(voxdagi_mem *m, uint64_t **key, uint32_t **tri, size_t *n, size_t *cap, size_t *cap2,
                             uint64_t k, uint32_t t) {
    if (*n == *cap) {
        size_t c1 = *cap;
        int ok = voxdagi_grow(m, (void **)key, &c1, *n + 1, sizeof **key) &&
                 voxdagi_grow(m, (void **)tri, cap2, c1, sizeof **tri);
        *cap = c1;
        if (!ok) return 0;
    }
    (*key)[*n] = k;
    (*tri)[*n] = t;
    ++*n;
    return 1;
}

/* The chunks of a solid mesh that no triangle touches but the inside fills:
   each chunk column's crossings at its first voxel column give the winding
   number of each of its chunks' lowest voxel centre, which holds for the
   whole chunk (no surface passes through it). Appends (chunk, UINT32_MAX)
   for each to the pairs, whose first SURFACE are sorted. */
static int voxdagi_solid_chunks(voxdagi_mem *m, const voxdag_mesh *mesh, const voxdagi_solid *s, unsigned shift,
                                int64_t chunks, uint64_t **pair_chunk, uint32_t **pair_tri, size_t *pairs,
                                size_t *cap, size_t *cap2) {
    size_t i, j, k, ev_cap = 0, surface = *pairs;
    voxdagi_event *ev = NULL;
    int ok = 1;
    for (i = 0; i < s->n && ok; i = j) {
        uint64_t key = s->key[i];
        uint32_t cx = (uint32_t)(key & 0xffffffffu), cy = (uint32_t)(key >> 32);
        int64_t q[2], cz;
        size_t ne = 0;
        q[0] = voxdagi_fix_centre((int64_t)cx << shift);
        q[1] = voxdagi_fix_centre((int64_t)cy << shift);
        for (j = i; j < s->n && s->key[j] == key; j++) {
            voxdagi_tri t;
            voxdagi_ftri f;
            double h, bary[3];
            int sign;
            voxdagi_load_tri(mesh, s->tri[j], &t);
            voxdagi_ftri_init(&f, &t);
            if (!(sign = voxdagi_column_cross(&f, q, &h, bary))) continue;
            if (!voxdagi_grow(m, (void **)&ev, &ev_cap, ne + 1, sizeof *ev)) {
                ok = 0;
                break;
            }
            ev[ne].h = h;
            ev[ne++].sign = sign;
        }
        for (cz = 0; cz < chunks && ok; cz++) {
            uint64_t code = voxdag_morton_encode(cx, cy, (uint32_t)cz);
            double centre = (double)(cz << shift) + 0.5;
            size_t lo = 0, hi = surface;
            int32_t w = 0;
            for (k = 0; k < ne; k++)
                if (ev[k].h > centre) w += ev[k].sign;
            if (!w) continue;
            while (lo < hi) { /* touched by a triangle? */
                size_t mid = lo + (hi - lo) / 2;
                if ((*pair_chunk)[mid] < code) lo = mid + 1;
                else hi = mid;
            }
            if (lo < surface && (*pair_chunk)[lo] == code) continue;
            ok = voxdagi_push_pair(m, pair_chunk, pair_tri, pairs, cap, cap2, code, UINT32_MAX);
        }
    }
    voxdagi_free(m, ev, ev_cap * sizeof *ev);
    return ok;
}

VOXDAG_API voxdag_status voxdag_builder_add_mesh(voxdag_builder *b, const voxdag_mesh *mesh, voxdag_error *err) {
    unsigned shift = b && b->opts.chunk_levels ? b->opts.chunk_levels : 8, t, k, jobs = 0, sets, cur = 0, bits = 0;
    int64_t n, chunks;
    uint64_t *pair_chunk = NULL;
    uint32_t *pair_tri = NULL;
    size_t pairs = 0, cap = 0, cap2 = 0, i = 0, p;
    voxdagi_chunk chunk[2 * VOXDAGI_MAX_THREADS];
    voxdagi_solid solid;
    uint64_t *col_key = NULL;
    uint32_t *col_tri = NULL;
    size_t cols = 0, col_cap = 0, col_cap2 = 0;
    voxdag_status st = VOXDAG_OK;
    if (!b || !mesh || (mesh->triangle_count && (!mesh->indices || !mesh->positions)) ||
        (b->opts.colors && !mesh->color))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "builder, mesh arrays or colour callback missing");
    if (b->failed) return VOXDAGI_FAIL(err, b->failed, "the builder failed earlier");
    if (b->pend_n || b->any_reduced)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "meshes go into a builder without voxels");
    if (mesh->triangle_count > UINT32_MAX)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, "more than 2^32-1 triangles");
    if (mesh->solid) { /* closed, or nothing */
        uint64_t open = 0, first = UINT64_MAX, bad = 0;
        st = voxdagi_open_edges(&b->mem, mesh, &open, &first, &bad);
        if (st == VOXDAG_ERR_INVALID_ARGUMENT)
            return voxdagi_fail(err, st, "triangle index out of range or non-finite vertex", UINT64_MAX, bad);
        if (st == VOXDAG_ERR_LIMIT && !b->mem.over_limit)
            return VOXDAGI_FAIL(err, st, "a solid mesh has more than 2^31-1 vertices");
        if (st != VOXDAG_OK) {
            b->failed = voxdagi_mem_fail(&b->mem, err, st, voxdagi_reduce_message(st));
            return b->failed;
        }
        if (open)
            return voxdagi_fail(err, VOXDAG_ERR_NOT_CLOSED,
                                "a solid mesh must be closed: some edge is not used as often each way "
                                "(voxdag_mesh_open_edges counts them)",
                                UINT64_MAX, first);
    }
    memset(&solid, 0, sizeof solid);
    if (shift > 8) shift = 8;
    if (shift > b->levels) shift = b->levels;
    if (shift < 2) shift = 2;
    n = (int64_t)1 << b->levels;
    chunks = n >> shift;
    /* Bin: (chunk Morton code, triangle) for every chunk a triangle touches. */
    for (i = 0; i < mesh->triangle_count && st == VOXDAG_OK; i++) {
        voxdagi_tri tr;
        voxdagi_axes x;
        int64_t first[3], last[3], cx, cy, cz;
        int inside = 1;
        if (!voxdagi_load_tri(mesh, i, &tr)) {
            st = VOXDAG_ERR_INVALID_ARGUMENT;
            break;
        }
        for (k = 0; k < 3 && inside; k++) {
            inside = voxdagi_voxel_range(tr.lo[k], tr.hi[k], n, &first[k], &last[k]);
            first[k] >>= shift;
            last[k] >>= shift;
        }
        if (!inside) continue;
        voxdagi_axes_init(&x, &tr, (double)((int64_t)1 << shift));
        for (cz = first[2]; cz <= last[2]; cz++)
            for (cy = first[1]; cy <= last[1]; cy++)
                for (cx = first[0]; cx <= last[0]; cx++) {
                    double corner[3];
                    corner[0] = (double)(cx << shift);
                    corner[1] = (double)(cy << shift);
                    corner[2] = (double)(cz << shift);
                    for (k = 3; k < 13 && voxdagi_axes_test(&x, corner, k); k++) continue;
                    if (k < 13) continue;
                    if (pairs == cap) {
                        size_t c1 = cap;
                        if (!voxdagi_grow(&b->mem, (void **)&pair_chunk, &c1, pairs + 1, sizeof *pair_chunk) ||
                            !voxdagi_grow(&b->mem, (void **)&pair_tri, &cap2, c1, sizeof *pair_tri)) {
                            cap = c1;
                            st = VOXDAG_ERR_OUT_OF_MEMORY;
                            cz = last[2] + 1;
                            break;
                        }
                        cap = c1;
                    }
                    pair_chunk[pairs] = voxdag_morton_encode((uint32_t)cx, (uint32_t)cy, (uint32_t)cz);
                    pair_tri[pairs] = (uint32_t)i;
                    pairs++;
                }
    }
    while (((int64_t)1 << bits) < chunks) bits++;
    /* stable: each chunk keeps its triangles ascending */
    if (st == VOXDAG_OK && pairs && !voxdagi_sort_pairs(&b->mem, pair_chunk, pair_tri, pairs, 3 * bits))
        st = VOXDAG_ERR_OUT_OF_MEMORY;
    if (st == VOXDAG_OK && mesh->solid) { /* the triangles by chunk columns, and the chunks inside */
        for (i = 0; i < mesh->triangle_count && st == VOXDAG_OK; i++) {
            voxdagi_tri tr;
            int64_t fx, lx, fy, ly, cx, cy;
            voxdagi_load_tri(mesh, i, &tr);
            if (!voxdagi_voxel_range(tr.lo[0], tr.hi[0], n, &fx, &lx) ||
                !voxdagi_voxel_range(tr.lo[1], tr.hi[1], n, &fy, &ly))
                continue;
            for (cy = fy >> shift; cy <= ly >> shift && st == VOXDAG_OK; cy++)
                for (cx = fx >> shift; cx <= lx >> shift && st == VOXDAG_OK; cx++)
                    if (!voxdagi_push_pair(&b->mem, &col_key, &col_tri, &cols, &col_cap, &col_cap2,
                                           (uint64_t)cy << 32 | (uint64_t)cx, (uint32_t)i))
                        st = VOXDAG_ERR_OUT_OF_MEMORY;
        }
        if (st == VOXDAG_OK && !voxdagi_sort_pairs(&b->mem, col_key, col_tri, cols, 32 + bits))
            st = VOXDAG_ERR_OUT_OF_MEMORY;
        solid.key = col_key;
        solid.tri = col_tri;
        solid.n = cols;
        if (st == VOXDAG_OK && !voxdagi_solid_chunks(&b->mem, mesh, &solid, shift, chunks, &pair_chunk, &pair_tri,
                                                     &pairs, &cap, &cap2))
            st = VOXDAG_ERR_OUT_OF_MEMORY;
        if (st == VOXDAG_OK && pairs && !voxdagi_sort_pairs(&b->mem, pair_chunk, pair_tri, pairs, 3 * bits))
            st = VOXDAG_ERR_OUT_OF_MEMORY;
    }
    /* Voxelize in rounds of one chunk per thread and reduce each round's
       chunks in Morton order; with threads, while the next round runs. */
    sets = b->threads > 1 ? 2 : 1;
    for (; jobs < sets * b->threads && st == VOXDAG_OK && pairs; jobs++)
        if (!voxdagi_chunk_init(&chunk[jobs], b, mesh, shift, mesh->solid ? &solid : NULL)) st = VOXDAG_ERR_OUT_OF_MEMORY;
    p = 0;
    t = st == VOXDAG_OK ? voxdagi_chunk_assign(chunk, b->threads, pair_chunk, pair_tri, pairs, &p) : 0;
    voxdagi_run_parallel(&b->team, voxdagi_chunk_run, chunk, sizeof *chunk, t);
    while (t) { /* chunk[cur..cur + t) are voxelized */
        voxdagi_chunk *next = sets == 2 ? chunk + (b->threads - cur) : chunk;
        unsigned m = 0;
        if (sets == 2) {
            m = voxdagi_chunk_assign(next, b->threads, pair_chunk, pair_tri, pairs, &p);
            voxdagi_batch_start(&b->team, voxdagi_chunk_run, next, sizeof *chunk, st == VOXDAG_OK ? m : 0);
        }
        for (k = 0; k < t && st == VOXDAG_OK; k++) st = voxdagi_builder_take(b, &chunk[cur + k]);
        if (sets == 2) {
            voxdagi_batch_wait(&b->team);
        } else if (st == VOXDAG_OK) {
            m = voxdagi_chunk_assign(next, b->threads, pair_chunk, pair_tri, pairs, &p);
            voxdagi_run_parallel(&b->team, voxdagi_chunk_run, next, sizeof *chunk, m);
        }
        if (st == VOXDAG_OK) st = voxdagi_progress(b, "voxelize", (double)p / (double)pairs);
        cur = (unsigned)(next - chunk);
        t = st == VOXDAG_OK ? m : 0;
    }
    for (t = 0; t < jobs; t++) voxdagi_chunk_free(&chunk[t]);
    voxdagi_free(&b->mem, pair_chunk, cap * sizeof *pair_chunk);
    voxdagi_free(&b->mem, pair_tri, cap2 * sizeof *pair_tri);
    voxdagi_free(&b->mem, col_key, col_cap * sizeof *col_key);
    voxdagi_free(&b->mem, col_tri, col_cap2 * sizeof *col_tri);
    if (st == VOXDAG_ERR_INVALID_ARGUMENT)
        return voxdagi_fail(err, st, "triangle index out of range or non-finite vertex", UINT64_MAX, (uint64_t)i);
    if (st != VOXDAG_OK) {
        b->failed = voxdagi_mem_fail(&b->mem, err, st, voxdagi_reduce_message(st));
        return b->failed;
    }
    return voxdagi_ok(err);
}

#endif /* VOXDAG_NO_BUILD */

// -- File image assembly (FORMAT.md: header, section table, sections)

typedef struct voxdagi_layout {
    uint32_t count;
    uint32_t type[VOXDAG_FILE_MAX_SECTIONS];
    uint32_t flags[VOXDAG_FILE_MAX_SECTIONS];
    uint64_t offset[VOXDAG_FILE_MAX_SECTIONS];
    uint64_t size[VOXDAG_FILE_MAX_SECTIONS];
    uint64_t total;
} voxdagi_layout;

static void voxdagi_layout_add(voxdagi_layout *lay, uint32_t type, uint32_t flags, uint64_t size) {
    lay->type[lay->count] = type;
    lay->flags[lay->count] = flags;
    lay->size[lay->count] = size;
    lay->count++;
}

/* Places the sections one after the other at 8-byte alignment. Returns 0 when
   the total does not fit in size_t. */
static int voxdagi_layout_place(voxdagi_layout *lay) {
    uint64_t at = VOXDAG_FILE_HEADER_SIZE + (uint64_t)lay->count * VOXDAG_FILE_SECTION_ENTRY_SIZE;
    uint32_t i;
    for (i = 0; i < lay->count; i++) {
        at = (at + 7) & ~(uint64_t)7;
        lay->offset[i] = at;
        if (lay->size[i] > ((uint64_t)(size_t)-1) - at) return 0;
        at += lay->size[i];
    }
    lay->total = at;
    return (uint64_t)(size_t)at == at;
}

static uint8_t *voxdagi_layout_section(uint8_t *image, const voxdagi_layout *lay, uint32_t type) {
    uint32_t i;
    for (i = 0; i < lay->count; i++)
        if (lay->type[i] == type) return image + lay->offset[i];
    return NULL;
}

/* What the header says about the scene. */
typedef struct voxdagi_scene {
    uint32_t levels, root_transform;
    voxdag_symmetry symmetry;
    uint64_t voxels;
    uint32_t voxel_box[6];
} voxdagi_scene;

/* Writes the header and section table (with checksums) of a filled image. */
static void voxdagi_layout_seal(uint8_t *img, const voxdagi_layout *lay, const voxdagi_scene *sc) {
    uint8_t *table = img + VOXDAG_FILE_HEADER_SIZE;
    uint32_t i;
    memcpy(img + VOXDAG_FILE_OFF_MAGIC, voxdagi_magic, 8);
    voxdagi_put_le(img + VOXDAG_FILE_OFF_VERSION, VOXDAG_FORMAT_VERSION, 4);
    voxdagi_put_le(img + VOXDAG_FILE_OFF_ENDIAN, VOXDAG_FILE_ENDIAN_TAG, 4);
    voxdagi_put_le(img + VOXDAG_FILE_OFF_HEADER_SIZE, VOXDAG_FILE_HEADER_SIZE, 4);
    voxdagi_put_le(img + VOXDAG_FILE_OFF_FILE_SIZE, lay->total, 8);
    voxdagi_put_le(img + VOXDAG_FILE_OFF_VOXELS, sc->voxels, 8);
    img[VOXDAG_FILE_OFF_LEVELS] = (uint8_t)sc->levels;
    img[VOXDAG_FILE_OFF_ROOT_TRANSFORM] = (uint8_t)sc->root_transform;
    img[VOXDAG_FILE_OFF_SYMMETRY] = (uint8_t)sc->symmetry;
    for (i = 0; i < 6; i++) voxdagi_put_le(img + VOXDAG_FILE_OFF_VOXEL_BOX + 4 * i, sc->voxel_box[i], 4);
    voxdagi_put_le(img + VOXDAG_FILE_OFF_SECTION_COUNT, lay->count, 4);
    for (i = 0; i < lay->count; i++) {
        uint8_t *e = table + i * VOXDAG_FILE_SECTION_ENTRY_SIZE;
        voxdagi_put_le(e, lay->type[i], 4);
        voxdagi_put_le(e + 4, lay->flags[i], 4);
        voxdagi_put_le(e + 8, lay->offset[i], 8);
        voxdagi_put_le(e + 16, lay->size[i], 8);
        voxdagi_put_le(e + 24, voxdagi_crc32c(img + lay->offset[i], lay->size[i]), 4);
    }
    voxdagi_put_le(img + VOXDAG_FILE_OFF_TABLE_CRC,
                   voxdagi_crc32c(table, (uint64_t)lay->count * VOXDAG_FILE_SECTION_ENTRY_SIZE), 4);
    voxdagi_put_le(img + VOXDAG_FILE_OFF_HEADER_CRC, 0, 4);
    voxdagi_put_le(img + VOXDAG_FILE_OFF_HEADER_CRC, voxdagi_crc32c(img, VOXDAG_FILE_HEADER_SIZE), 4);
}

// -- Compact encoding (FORMAT.md; SSVDAG 4.3, extended)
//
// Per level, nodes are ordered by reference count (most referenced first) so
// that most pointers are short, and every node is stored in the orientation
// most of its references see it in, so that most pointers carry no
// transform. A record is byte-aligned: a 16-bit header with a 2-bit tag per
// child octant (0 absent, else one of the level's three pointer classes), the
// node's voxel count in the level's count width C in bits (none at level L-3,
// whose counts are the popcounts of its bricks), then the present children's
// pointers in octant order, bit-packed. A pointer of class t has W_t = O_t +
// K_t bits: the target (byte offset in the next level, or brick index) above
// a K_t-bit code into the level's transform table (sorted by frequency, so
// code 0 is the most common transform).
// Private children (Lefebvre & Hoppe 4: implicit addressing): a node
// referenced once is stored, in its referrer's frame, right after the other
// private children of the same parent, at the end of its level. A level that
// uses them gives tag 3 to private children: such a pointer has no bits, and
// the record holds one base field of P bits (after the count) with the offset
// of its first private child; the next ones follow it record by record. Each
// level picks this or a third class, and its classes, for the fewest bytes.

#ifndef VOXDAG_NO_BUILD
/* ORs the low N bits of V into P at bit POS (P zeroed beforehand). */
static void voxdagi_put_bits(uint8_t *p, uint64_t pos, uint64_t v, unsigned n) {
    while (n) {
        unsigned sh = (unsigned)(pos & 7), take = 8 - sh < n ? 8 - sh : n;
        p[pos >> 3] = (uint8_t)(p[pos >> 3] | (v & ((1u << take) - 1)) << sh);
        v >>= take, pos += take, n -= take;
    }
}
#endif

/* N <= 57 bits at bit POS of P; 8 bytes from byte POS / 8 must be readable. */
VOXDAGI_INLINE uint64_t voxdagi_get_bits(const uint8_t *p, uint64_t pos, unsigned n) {
    return voxdagi_le_fast(p + (pos >> 3), 8) >> (pos & 7) & ((1ull << n) - 1);
}

/* N <= 64 bits at bit POS of P; 9 bytes from byte POS / 8 must be readable. */
static uint64_t voxdagi_get_bits_wide(const uint8_t *p, uint64_t pos, unsigned n) {
    unsigned sh = (unsigned)(pos & 7);
    uint64_t v = voxdagi_le_fast(p + (pos >> 3), 8) >> sh;
    if (sh + n > 64) v |= (uint64_t)p[(pos >> 3) + 8] << (64 - sh);
    return n < 64 ? v & ((1ull << n) - 1) : v;
}

#ifndef VOXDAG_NO_BUILD /* the encoder */

/* Storage order of a level: most referenced first, ties by fingerprint (or
   mask), then by id; two stable radix sorts. Fills ORDER with ids. Returns 0
   when out of memory. */
static int voxdagi_storage_order(voxdagi_mem *m, const voxdagi_store *s, const uint32_t *refs,
                                 uint32_t *order) {
    size_t n = s->n, i;
    uint64_t *key = (uint64_t *)voxdagi_alloc(m, n * sizeof *key);
    uint64_t *tmp_key = (uint64_t *)voxdagi_alloc(m, n * sizeof *tmp_key);
    uint32_t *tmp_id = (uint32_t *)voxdagi_alloc(m, n * sizeof *tmp_id);
    uint32_t max_refs = 0;
    int ok = key && tmp_key && tmp_id;
    if (ok) {
        for (i = 0; i < n; i++) {
            key[i] = s->node[i].key;
            order[i] = (uint32_t)i;
            if (refs[i] > max_refs) max_refs = refs[i];
        }
        voxdagi_radix_sort(key, order, tmp_key, tmp_id, n, 64);
        for (i = 0; i < n; i++) key[i] = max_refs - refs[order[i]];
        voxdagi_radix_sort(key, order, tmp_key, tmp_id, n, 8 * voxdagi_bytes_for(max_refs));
    }
    voxdagi_free(m, key, n * sizeof *key);
    voxdagi_free(m, tmp_key, n * sizeof *tmp_key);
    voxdagi_free(m, tmp_id, n * sizeof *tmp_id);
    return ok;
}

/* A level's pointer classes: tag t (1..N) holds O[t] target bits above K[t]
   code bits; N = 2 when tag 3 marks private children (then O[3] = K[3] = 0
   and P is the width of the base field). */
typedef struct voxdagi_classes {
    unsigned char target_bits[4], code_bits[4], classes, base_bits;
} voxdagi_classes;

/* The cheapest class (1..N) that holds a target of OB bits and a code of KB
   bits, or 0 when none does. */
static unsigned voxdagi_class_for(const voxdagi_classes *c, unsigned ob, unsigned kb) {
    unsigned t, best = 0;
    for (t = 1; t <= c->classes; t++)
        if (c->target_bits[t] >= ob && c->code_bits[t] >= kb && (!best || c->target_bits[t] + c->code_bits[t] < c->target_bits[best] + c->code_bits[best])) best = t;
    return best;
}

/* The pointer bits of a level under classes X[0..2] ({target bits, code
   bits} each; repeats allowed), every pointer in the narrowest class that
   holds it, or UINT64_MAX when one fits none. MASS[ob][kb] counts the
   pointers of at most ob target and kb code bits, so a class holds the
   pointers of a rectangle anchored at (0, 0); the narrowest class takes its
   rectangle, the next its own less the overlap, and so on (inclusion and
   exclusion; overlaps of such rectangles are such rectangles). */
static uint64_t voxdagi_classes_cost(uint64_t mass[58][7], const unsigned *x[3]) {
    const unsigned *w[3], *t;
    uint64_t m[3];
    unsigned i, j, ob[4], kb[4]; /* [i]: class w[i]'s rectangle; [3]: the overlap of all three */
    for (i = 0; i < 3; i++) /* by width */
        for (w[i] = x[i], j = i; j > 0 && w[j][0] + w[j][1] < w[j - 1][0] + w[j - 1][1]; j--)
            t = w[j], w[j] = w[j - 1], w[j - 1] = t;
    for (i = 0; i < 3; i++) ob[i] = w[i][0], kb[i] = w[i][1];
    ob[3] = ob[0] < ob[1] ? ob[0] : ob[1], kb[3] = kb[0] < kb[1] ? kb[0] : kb[1];
    ob[3] = ob[3] < ob[2] ? ob[3] : ob[2], kb[3] = kb[3] < kb[2] ? kb[3] : kb[2];
#define VOXDAGI_OVERLAP(a, b) mass[ob[a] < ob[b] ? ob[a] : ob[b]][kb[a] < kb[b] ? kb[a] : kb[b]]
    m[0] = mass[ob[0]][kb[0]];
    m[1] = mass[ob[1]][kb[1]] - VOXDAGI_OVERLAP(0, 1);
    m[2] = mass[ob[2]][kb[2]] - VOXDAGI_OVERLAP(2, 0) - VOXDAGI_OVERLAP(2, 1) + mass[ob[3]][kb[3]];
#undef VOXDAGI_OVERLAP
    if (m[0] + m[1] + m[2] != mass[57][6]) return UINT64_MAX;
    return m[0] * (ob[0] + kb[0]) + m[1] * (ob[1] + kb[1]) + m[2] * (ob[2] + kb[2]);
}

/* Chooses N (2 or 3) classes for the fewest pointer bits, given how many
   pointers need OB target bits and KB code bits (HIST[ob][kb]). Candidate
   classes take a target width that occurs and any code width up to the
   largest; the first cheapest set in candidate order wins. Returns its
   pointer bits. */
static uint64_t voxdagi_choose_classes(uint64_t hist[58][7], unsigned n, voxdagi_classes *best) {
    unsigned cand[7 * 58][2], nc = 0, ob, kb, kmax = 0, a, b, c, widest;
    uint64_t best_cost = UINT64_MAX, mass[58][7];
    for (ob = 0; ob < 58; ob++)
        for (kb = 0; kb < 7; kb++) {
            mass[ob][kb] = hist[ob][kb] + (ob ? mass[ob - 1][kb] : 0) + (kb ? mass[ob][kb - 1] : 0) -
                           (ob && kb ? mass[ob - 1][kb - 1] : 0);
            if (hist[ob][kb] && kb > kmax) kmax = kb;
        }
    for (ob = 0; ob < 58; ob++) {
        int any = 0;
        for (kb = 0; kb < 7; kb++) any |= hist[ob][kb] != 0;
        if (!any) continue;
        for (kb = 0; kb <= kmax; kb++) cand[nc][0] = ob, cand[nc][1] = kb, nc++;
    }
    memset(best, 0, sizeof *best); /* no pointers: zero widths */
    best->classes = (unsigned char)n;
    /* Some class must hold the widest targets: the last class of a set
       (candidates run by target width) comes from the last KMAX + 1. */
    widest = nc ? nc - kmax - 1 : 0;
    for (a = 0; a < nc; a++)
        for (b = n == 2 && a < widest ? widest : a; b < nc; b++)
            for (c = n == 3 && b < widest ? widest : b; c < (n == 3 ? nc : b + 1); c++) {
                const unsigned *x[3];
                uint64_t cost;
                x[0] = cand[a], x[1] = cand[b], x[2] = cand[c];
                cost = voxdagi_classes_cost(mass, x);
                if (cost < best_cost) {
                    best_cost = cost;
                    best->target_bits[1] = (unsigned char)cand[a][0], best->code_bits[1] = (unsigned char)cand[a][1];
                    best->target_bits[2] = (unsigned char)cand[b][0], best->code_bits[2] = (unsigned char)cand[b][1];
                    best->target_bits[3] = (unsigned char)cand[c][0], best->code_bits[3] = (unsigned char)cand[c][1];
                }
            }
    if (n == 2) best->target_bits[3] = best->code_bits[3] = 0;
    return nc ? best_cost : 0;
}

/* A job of voxdagi_choose_level over the nodes [BEGIN, END) of level L:
   stage 0 counts the stored transforms of the pointers (FREQ), stage 1 the
   pointers by target and code bits (HIST; TOO_WIDE: one needs more than 57)
   and, with private children, the bases (BASES, the largest MAX_BASE). */
typedef struct voxdagi_level_job {
    const struct voxdagi_encoder *e;
    uint32_t l;
    int stage, private_children, too_wide;
    size_t begin, end;
    uint64_t freq[VOXDAGI_TRANSFORMS], hist[58][7], bases, max_base;
} voxdagi_level_job;

typedef struct voxdagi_encoder {
    voxdagi_mem *mem;
    voxdagi_team *team;                  /* the builder's threads */
    voxdagi_level_job *level_job;        /* voxdagi_choose_level's, LEVEL_JOBS of them */
    unsigned level_jobs;
    const voxdagi_reducer *r;
    const voxdagi_group *group;
    uint32_t levels;
    uint32_t *order[VOXDAG_MAX_LEVELS];  /* ids in storage order */
    uint64_t *pos[VOXDAG_MAX_LEVELS];    /* per id: byte offset, or brick index */
    uint8_t *orient[VOXDAG_MAX_LEVELS];  /* per id: R, the node is stored as R(canonical) */
    uint8_t *tag[VOXDAG_MAX_LEVELS];     /* per child slot of an inner level: its stored transform */
    uint8_t *single[VOXDAG_MAX_LEVELS];  /* per id: referenced once, through the identity */
    uint64_t size[VOXDAG_MAX_LEVELS];    /* bytes of each inner level */
    unsigned count_bits[VOXDAG_MAX_LEVELS];
    voxdagi_classes cls[VOXDAG_MAX_LEVELS];
    uint8_t class_of[VOXDAG_MAX_LEVELS][58][7]; /* [target bits][code bits]: voxdagi_class_for */
    uint8_t code[VOXDAG_MAX_LEVELS][VOXDAGI_TRANSFORMS];  /* transform -> code */
    uint8_t table[VOXDAG_MAX_LEVELS][VOXDAGI_TRANSFORMS]; /* code -> transform */
    unsigned table_len[VOXDAG_MAX_LEVELS];
    unsigned root_transform;
} voxdagi_encoder;

static void voxdagi_encoder_free(voxdagi_encoder *e) {
    uint32_t l;
    for (l = 0; l < VOXDAG_MAX_LEVELS; l++) {
        size_t n = e->r->store[l].n;
        voxdagi_free(e->mem, e->order[l], n * sizeof(uint32_t));
        voxdagi_free(e->mem, e->pos[l], n * sizeof(uint64_t));
        voxdagi_free(e->mem, e->orient[l], n);
        if (e->tag[l]) voxdagi_free(e->mem, e->tag[l], 8 * n);
        voxdagi_free(e->mem, e->single[l], n);
    }
    voxdagi_free(e->mem, e->level_job, e->level_jobs * sizeof *e->level_job);
}

/* The stored transform of the reference from a node stored as RP(canonical)
   to child reference X (id << 6 | t) of level L + 1: RP o t o s o RC^-1 for
   s in the child's stabilizer, the smallest of them. */
static unsigned voxdagi_stored_tag(const voxdagi_encoder *e, uint32_t l, unsigned rp, uint32_t x) {
    const voxdagi_cube *c = &voxdagi_cube_tables;
    unsigned u = c->comp[rp][x & 63], rc_inv = c->inv[e->orient[l + 1][x >> 6]];
    unsigned best = c->comp[u][rc_inv];
    uint64_t stabs = e->r->store[l + 1].node[x >> 6].stab & ~1ull;
    while (stabs) {
        unsigned s = voxdagi_lowest_bit(stabs), v = c->comp[c->comp[u][s]][rc_inv];
        if (v < best) best = v;
        stabs &= stabs - 1;
    }
    return best;
}

/* Most jobs a level is split in by the encoder. */
#define VOXDAGI_ENCODE_JOBS (4 * VOXDAGI_MAX_THREADS)

/* A job of voxdagi_orient: the orientations of nodes [BEGIN, END) of level
   L from the transforms SEEN by the references into them (node i's from
   FIRST[i] to FIRST[i + 1]). */
typedef struct voxdagi_orient_job {
    voxdagi_encoder *e;
    const uint64_t *first;
    const uint8_t *seen;
    size_t begin, end;
    uint32_t l;
} voxdagi_orient_job;

static void *voxdagi_orient_run(void *arg) {
    const voxdagi_orient_job *j = (const voxdagi_orient_job *)arg;
    const voxdagi_cube *c = &voxdagi_cube_tables;
    const voxdagi_store *s = &j->e->r->store[j->l];
    uint64_t votes[VOXDAGI_TRANSFORMS];
    size_t i;
    memset(votes, 0, sizeof votes);
    for (i = j->begin; i < j->end; i++) { /* BEST: the smallest transform with the most votes so far */
        unsigned best = 0;
        uint64_t k, stabs;
        for (k = j->first[i]; k < j->first[i + 1]; k++)
            for (stabs = s->node[i].stab; stabs; stabs &= stabs - 1) {
                unsigned tf = c->comp[j->seen[k]][voxdagi_lowest_bit(stabs)];
                votes[tf]++;
                if (votes[tf] > votes[best] || (votes[tf] == votes[best] && tf < best)) best = tf;
            }
        j->e->orient[j->l][i] = (uint8_t)best;
        for (k = j->first[i]; k < j->first[i + 1]; k++) /* back to no votes */
            for (stabs = s->node[i].stab; stabs; stabs &= stabs - 1)
                votes[c->comp[j->seen[k]][voxdagi_lowest_bit(stabs)]] = 0;
    }
    return NULL;
}

/* Orientations, top-down: a node is stored as R(canonical) for the R that
   makes the most references to it carry the identity (ties: the smallest R).
   A reference (n, t) from a parent stored as RP does so for every R in
   RP o t o S(n). The references into a level are gathered per node first. */
static int voxdagi_orient(voxdagi_encoder *e) {
    const voxdagi_reducer *r = e->r;
    const voxdagi_cube *c = &voxdagi_cube_tables;
    voxdagi_orient_job job[VOXDAGI_ENCODE_JOBS];
    uint32_t brick_level = e->levels - 2, l;
    unsigned jobs, k;
    for (l = 0; l <= brick_level; l++) {
        const voxdagi_store *s = &r->store[l], *ps = l ? &r->store[l - 1] : NULL;
        size_t n = s->n, i, p, total = l ? 0 : 1;
        uint64_t *first = (uint64_t *)voxdagi_alloc(e->mem, (n + 1) * sizeof *first);
        uint8_t *seen;
        if (!first) return 0;
        memset(first, 0, (n + 1) * sizeof *first);
        if (l) {
            for (p = 0; p < 8 * ps->n; p++)
                if (ps->child[p] != VOXDAGI_NONE) first[(ps->child[p] >> 6) + 1]++, total++;
        } else {
            first[(r->root >> 6) + 1]++;
        }
        for (i = 0; i < n; i++) first[i + 1] += first[i];
        seen = (uint8_t *)voxdagi_alloc(e->mem, total);
        if (!seen) {
            voxdagi_free(e->mem, first, (n + 1) * sizeof *first);
            return 0;
        }
        if (l) { /* RP o t per reference; FIRST[id] advances to the next free slot */
            for (p = 0; p < 8 * ps->n; p++)
                if (ps->child[p] != VOXDAGI_NONE)
                    seen[first[ps->child[p] >> 6]++] = c->comp[e->orient[l - 1][p >> 3]][ps->child[p] & 63];
        } else {
            seen[first[r->root >> 6]++] = (uint8_t)(r->root & 63);
        }
        for (i = n; i > 0; i--) first[i] = first[i - 1]; /* back to the starts */
        first[0] = 0;
        jobs = e->team->threads < 2 || n < 4096 ? 1 : 4 * e->team->threads;
        if (jobs > VOXDAGI_ENCODE_JOBS) jobs = VOXDAGI_ENCODE_JOBS;
        for (k = 0; k < jobs; k++) {
            job[k].e = e, job[k].first = first, job[k].seen = seen, job[k].l = l;
            job[k].begin = n * k / jobs, job[k].end = n * (k + 1) / jobs;
        }
        voxdagi_run_parallel(e->team, voxdagi_orient_run, job, sizeof job[0], jobs);
        voxdagi_free(e->mem, seen, total);
        voxdagi_free(e->mem, first, (n + 1) * sizeof *first);
    }
    return 1;
}

/* Count widths C (bits) of each inner level: enough for its largest count,
   and 0 (counts derived from the children's) at level L-3, whose children are
   bricks. A derived count costs the voxel index one sum over at most 8 stored
   counts per sibling, so on large DAGs, where that sum misses the cache, the
   counts stay; the writer derives at most one more level, the one among
   0..L-5 where counts take the most bits (the deepest on ties), and only
   when they are at least 1/32 of an estimate of the geometry's bits (16-bit
   headers, counts, 16-bit pointers, bricks): small DAGs, which are mostly
   counts and stay in the cache. */
static void voxdagi_count_widths(voxdagi_encoder *e) {
    uint32_t brick_level = e->levels - 2, l, drop = brick_level;
    uint64_t most = 0, estimate = 64 * (uint64_t)e->r->store[brick_level].n;
    for (l = 0; l < brick_level; l++) {
        const voxdagi_store *s = &e->r->store[l];
        uint64_t max_count = 0, bits;
        size_t i;
        for (i = 0; i < s->n; i++)
            if (s->node[i].count > max_count) max_count = s->node[i].count;
        for (i = 0; i < 8 * s->n; i++) estimate += s->child[i] != VOXDAGI_NONE ? 16u : 0u;
        e->count_bits[l] = l + 1 < brick_level ? voxdagi_bit_length(max_count) : 0;
        bits = (uint64_t)s->n * e->count_bits[l];
        estimate += 16 * (uint64_t)s->n + bits;
        if (l + 2 < brick_level && bits >= most) {
            most = bits;
            drop = l;
        }
    }
    if (drop < brick_level && most >= estimate / 32) e->count_bits[drop] = 0;
}

/* Whether child reference X of a node of inner level L is a private child:
   the level uses them and the child is referenced once, through the
   identity. */
static int voxdagi_is_private(const voxdagi_encoder *e, uint32_t l, uint32_t x) {
    return e->cls[l].classes == 2 && e->single[l + 1][x >> 6];
}

/* The children of node ID of inner level L in stored octant order (stored
   octant R(j) holds canonical child j), with their stored transforms. */
static void voxdagi_stored_children(const voxdagi_encoder *e, uint32_t l, uint32_t id, uint32_t child[8],
                                    unsigned tag[8]) {
    const uint32_t *ch = e->r->store[l].child + 8 * (size_t)id;
    const uint8_t *act = voxdagi_cube_tables.act[e->orient[l][id]];
    unsigned j;
    for (j = 0; j < 8; j++) child[j] = VOXDAGI_NONE, tag[j] = 0;
    for (j = 0; j < 8; j++)
        if (ch[j] != VOXDAGI_NONE) child[act[j]] = ch[j], tag[act[j]] = e->tag[l][8 * (size_t)id + j];
}

/* The base of the record of node ID of inner level L: the offset of its
   first private child (in stored octant order, which is also storage order,
   so the lowest), or UINT64_MAX when it has none. */
static uint64_t voxdagi_private_base(const voxdagi_encoder *e, uint32_t l, uint32_t id) {
    const uint32_t *ch = e->r->store[l].child + 8 * (size_t)id;
    uint64_t base = UINT64_MAX;
    unsigned j;
    for (j = 0; j < 8; j++)
        if (ch[j] != VOXDAGI_NONE && voxdagi_is_private(e, l, ch[j]) && e->pos[l + 1][ch[j] >> 6] < base)
            base = e->pos[l + 1][ch[j] >> 6];
    return base;
}

/* The record of node ID of inner level L under the level's plan: its bits,
   and the record itself written at P (zeroed) unless P is NULL. */
static uint64_t voxdagi_record(const voxdagi_encoder *e, uint32_t l, uint32_t id, uint8_t *p) {
    const voxdagi_classes *cls = &e->cls[l];
    const uint32_t *ch = e->r->store[l].child + 8 * (size_t)id;
    const uint8_t *act = voxdagi_cube_tables.act[e->orient[l][id]], *tags = e->tag[l] + 8 * (size_t)id;
    uint64_t target[8], bits = 16 + e->count_bits[l], base = voxdagi_private_base(e, l, id);
    unsigned code[8], present = 0, private_children = 0, header = 0, j, s;
    for (j = 0; j < 8; j++) { /* canonical child j sits in stored octant R(j) */
        if (ch[j] == VOXDAGI_NONE) continue;
        s = act[j];
        present |= 1u << s;
        target[s] = e->pos[l + 1][ch[j] >> 6];
        code[s] = e->code[l][tags[j]];
        if (voxdagi_is_private(e, l, ch[j])) private_children |= 1u << s;
    }
    if (p) voxdagi_put_bits(p, 16, e->r->store[l].node[id].count, e->count_bits[l]);
    if (private_children) {
        if (p) voxdagi_put_bits(p, bits, base, cls->base_bits);
        bits += cls->base_bits;
    }
    for (s = 0; s < 8; s++) {
        unsigned t, width;
        if (!(present >> s & 1)) continue;
        if (private_children >> s & 1) {
            header |= 3u << (2 * s);
            continue;
        }
        t = e->class_of[l][voxdagi_bit_length(target[s])][voxdagi_bit_length(code[s])];
        width = cls->target_bits[t] + cls->code_bits[t];
        header |= t << (2 * s);
        if (p) voxdagi_put_bits(p, bits, target[s] << cls->code_bits[t] | code[s], width);
        bits += width;
    }
    if (p) voxdagi_put_le(p, header, 2);
    return bits;
}

/* Chooses inner level L's transform table, N pointer classes (2: private
   children, with the base width) for the fewest bits; *BITS: the bits of
   its records without padding (the level's bytes are at least an eighth of
   them). Returns 0 when a pointer or a base needs more than 57 bits. */
static void *voxdagi_level_run(void *arg) {
    voxdagi_level_job *j = (voxdagi_level_job *)arg;
    const voxdagi_encoder *e = j->e;
    const voxdagi_store *s = &e->r->store[j->l];
    uint32_t l = j->l;
    size_t i;
    if (j->stage == 0) {
        memset(j->freq, 0, sizeof j->freq);
        for (i = 8 * j->begin; i < 8 * j->end; i++)
            if (s->child[i] != VOXDAGI_NONE && !voxdagi_is_private(e, l, s->child[i])) j->freq[e->tag[l][i]]++;
        return NULL;
    }
    memset(j->hist, 0, sizeof j->hist);
    j->too_wide = 0, j->bases = j->max_base = 0;
    for (i = 8 * j->begin; i < 8 * j->end; i++) {
        uint32_t x = s->child[i];
        unsigned ob, kb;
        if (x == VOXDAGI_NONE || voxdagi_is_private(e, l, x)) continue;
        ob = voxdagi_bit_length(e->pos[l + 1][x >> 6]);
        kb = voxdagi_bit_length(e->code[l][e->tag[l][i]]);
        if (ob + kb > 57) {
            j->too_wide = 1;
            return NULL;
        }
        j->hist[ob][kb]++;
    }
    for (i = j->begin; j->private_children && i < j->end; i++) {
        uint64_t base = voxdagi_private_base(e, l, (uint32_t)i);
        if (base != UINT64_MAX) j->bases++;
        if (base != UINT64_MAX && base > j->max_base) j->max_base = base;
    }
    return NULL;
}

static int voxdagi_choose_level(voxdagi_encoder *e, uint32_t l, unsigned n, uint64_t *bits) {
    const voxdagi_store *s = &e->r->store[l];
    voxdagi_classes *cls = &e->cls[l];
    voxdagi_level_job *job = e->level_job;
    uint64_t freq[VOXDAGI_TRANSFORMS], hist[58][7], max_base = 0, bases = 0;
    unsigned tf, k, len = 0, jobs = s->n < 4096 ? 1 : e->level_jobs, ob, kb;
    int too_wide = 0;
    cls->classes = (unsigned char)n;
    for (k = 0; k < jobs; k++) {
        job[k].e = e, job[k].l = l, job[k].stage = 0, job[k].private_children = n == 2;
        job[k].begin = s->n * k / jobs, job[k].end = s->n * (k + 1) / jobs;
    }
    voxdagi_run_parallel(e->team, voxdagi_level_run, job, sizeof job[0], jobs);
    memset(freq, 0, sizeof freq);
    for (k = 0; k < jobs; k++)
        for (tf = 0; tf < VOXDAGI_TRANSFORMS; tf++) freq[tf] += job[k].freq[tf];
    for (tf = 0; tf < VOXDAGI_TRANSFORMS; tf++) { /* the table: stored transforms by decreasing frequency, ties by value */
        if (!freq[tf]) continue;
        for (k = len; k > 0 && freq[e->table[l][k - 1]] < freq[tf]; k--) e->table[l][k] = e->table[l][k - 1];
        e->table[l][k] = (uint8_t)tf;
        len++;
    }
    if (!len) e->table[l][len++] = 0; /* only private children: a table is never empty */
    for (k = 0; k < len; k++) e->code[l][e->table[l][k]] = (uint8_t)k;
    e->table_len[l] = len;
    for (k = 0; k < jobs; k++) job[k].stage = 1;
    voxdagi_run_parallel(e->team, voxdagi_level_run, job, sizeof job[0], jobs);
    memset(hist, 0, sizeof hist);
    for (k = 0; k < jobs; k++) {
        too_wide |= job[k].too_wide;
        for (ob = 0; ob < 58; ob++)
            for (kb = 0; kb < 7; kb++) hist[ob][kb] += job[k].hist[ob][kb];
        bases += job[k].bases;
        if (job[k].max_base > max_base) max_base = job[k].max_base;
    }
    if (too_wide) return 0;
    *bits = (16 + e->count_bits[l]) * (uint64_t)s->n + voxdagi_choose_classes(hist, n, cls);
    cls->classes = (unsigned char)n;
    for (k = 0; k < 58 * 7; k++) e->class_of[l][k / 7][k % 7] = (uint8_t)voxdagi_class_for(cls, k / 7, k % 7);
    cls->base_bits = (unsigned char)voxdagi_bit_length(max_base);
    *bits += bases * cls->base_bits;
    return cls->base_bits <= 57;
}

/* A job of the encoder: the records (or bricks) of level L at storage
   positions [BEGIN, END). OUT NULL: each record's bytes to its e->pos
   entry; else the records written at OUT (zeroed) + their e->pos. */
typedef struct voxdagi_record_job {
    const voxdagi_encoder *e;
    uint64_t *pos;
    uint8_t *out;
    size_t begin, end;
    uint32_t l;
} voxdagi_record_job;

static void *voxdagi_record_run(void *arg) {
    voxdagi_record_job *j = (voxdagi_record_job *)arg;
    const voxdagi_encoder *e = j->e;
    const voxdagi_store *s = &e->r->store[j->l];
    size_t i;
    for (i = j->begin; i < j->end; i++) {
        uint32_t id = e->order[j->l][i];
        if (j->l == e->levels - 2) /* bricks */
            voxdagi_put_le(j->out + 8 * i, voxdagi_transform_brick(e->group, s->node[id].key, e->orient[j->l][id]), 8);
        else if (!j->out)
            j->pos[id] = (voxdagi_record(e, j->l, id, NULL) + 7) / 8;
        else
            voxdagi_record(e, j->l, id, j->out + j->pos[id]);
    }
    return NULL;
}

/* Runs voxdagi_record_run over the N nodes of level L on the builder's
   threads (one job for small levels). */
static void voxdagi_records(const voxdagi_encoder *e, uint32_t l, uint8_t *out) {
    voxdagi_record_job job[VOXDAGI_ENCODE_JOBS];
    size_t n = e->r->store[l].n, k;
    unsigned jobs = e->team->threads < 2 || n < 4096 ? 1 : 4 * e->team->threads;
    if (jobs > VOXDAGI_ENCODE_JOBS) jobs = VOXDAGI_ENCODE_JOBS;
    for (k = 0; k < jobs; k++) {
        job[k].e = e, job[k].pos = e->pos[l], job[k].out = out, job[k].l = l;
        job[k].begin = n * k / jobs, job[k].end = n * (k + 1) / jobs;
    }
    voxdagi_run_parallel(e->team, voxdagi_record_run, job, sizeof job[0], jobs);
}

/* Record offsets of inner level L in storage order; returns its bytes. */
static uint64_t voxdagi_level_offsets(voxdagi_encoder *e, uint32_t l) {
    uint64_t at = 0;
    size_t i;
    voxdagi_records(e, l, NULL); /* each record's bytes, then their offsets */
    for (i = 0; i < e->r->store[l].n; i++) {
        uint64_t *pos = &e->pos[l][e->order[l][i]], bytes = *pos;
        *pos = at;
        at += bytes;
    }
    return at;
}

/* What a level's plan decides: kept while the other plan is tried. */
typedef struct voxdagi_level_plan {
    voxdagi_classes cls;
    uint8_t code[VOXDAGI_TRANSFORMS], table[VOXDAGI_TRANSFORMS], class_of[58][7];
    unsigned table_len;
} voxdagi_level_plan;

static void voxdagi_plan_swap(voxdagi_encoder *e, uint32_t l, voxdagi_level_plan *p) {
    voxdagi_level_plan cur;
    cur.cls = e->cls[l], cur.table_len = e->table_len[l];
    memcpy(cur.code, e->code[l], sizeof cur.code);
    memcpy(cur.table, e->table[l], sizeof cur.table);
    memcpy(cur.class_of, e->class_of[l], sizeof cur.class_of);
    e->cls[l] = p->cls, e->table_len[l] = p->table_len;
    memcpy(e->code[l], p->code, sizeof p->code);
    memcpy(e->table[l], p->table, sizeof p->table);
    memcpy(e->class_of[l], p->class_of, sizeof p->class_of);
    *p = cur;
}

/* Plans inner level L bottom-up (pointer widths depend on where the next
   level put its nodes): with private children when the next level has
   candidates and they make the level smaller, else with three classes.
   The plan with fewer record bits is laid out first; the other only when
   its bits (its bytes are at least an eighth of them) do not already show
   it larger. Returns 0 when out of memory or when no plan holds the
   pointers. */
static int voxdagi_plan_level(voxdagi_encoder *e, uint32_t l, int candidates) {
    size_t n = e->r->store[l].n;
    voxdagi_level_plan other;
    uint64_t bits[4], size[4], *first_pos;
    int ok[4], first, second;
    ok[3] = voxdagi_choose_level(e, l, 3, &bits[3]);
    if (!candidates) {
        if (ok[3]) e->size[l] = voxdagi_level_offsets(e, l);
        return ok[3];
    }
    memset(&other, 0, sizeof other);
    voxdagi_plan_swap(e, l, &other); /* OTHER holds the three-class plan */
    ok[2] = voxdagi_choose_level(e, l, 2, &bits[2]);
    if (!ok[2] && !ok[3]) return 0;
    first = ok[2] && (!ok[3] || bits[2] <= bits[3]) ? 2 : 3;
    second = 5 - first;
    if (first == 3) voxdagi_plan_swap(e, l, &other);
    e->size[l] = size[first] = voxdagi_level_offsets(e, l);
    if (!ok[second] || 8 * size[first] < bits[second]) return 1;
    first_pos = (uint64_t *)voxdagi_alloc(e->mem, n * sizeof *first_pos);
    if (!first_pos) return 0;
    memcpy(first_pos, e->pos[l], n * sizeof *first_pos);
    voxdagi_plan_swap(e, l, &other);
    e->size[l] = size[second] = voxdagi_level_offsets(e, l);
    if (size[first] < size[second] || (size[first] == size[second] && first == 3)) { /* ties: three classes */
        voxdagi_plan_swap(e, l, &other);
        memcpy(e->pos[l], first_pos, n * sizeof *first_pos);
        e->size[l] = size[first];
    }
    voxdagi_free(e->mem, first_pos, n * sizeof *first_pos);
    return 1;
}

/* A job of voxdagi_private_order (FIRST and SEEN unused): the stored
   transforms of the child references of nodes [BEGIN, END) of level L. */
static void *voxdagi_tag_run(void *arg) {
    const voxdagi_orient_job *j = (const voxdagi_orient_job *)arg;
    const voxdagi_store *s = &j->e->r->store[j->l];
    size_t i;
    for (i = 8 * j->begin; i < 8 * j->end; i++)
        if (s->child[i] != VOXDAGI_NONE)
            j->e->tag[j->l][i] = (uint8_t)voxdagi_stored_tag(j->e, j->l, j->e->orient[j->l][i >> 3], s->child[i]);
    return NULL;
}

/* Stored transforms of every pointer, the private-child candidates (nodes
   referenced once through the identity: their orientation is their one
   referrer's), and each level's order of them: after the shared nodes, by
   parent in storage order, then by stored octant, so that the private
   children of a record follow each other. Top-down. */
static void voxdagi_private_order(voxdagi_encoder *e, uint32_t *const *refs, int *candidates) {
    voxdagi_orient_job job[VOXDAGI_ENCODE_JOBS];
    const voxdagi_reducer *r = e->r;
    uint32_t brick_level = e->levels - 2, l;
    for (l = 0; l < brick_level; l++) {
        const voxdagi_store *s = &r->store[l];
        uint32_t *o = e->order[l + 1];
        size_t i, k = 0, n1 = r->store[l + 1].n;
        unsigned jobs = e->team->threads < 2 || s->n < 4096 ? 1 : 4 * e->team->threads, t;
        if (jobs > VOXDAGI_ENCODE_JOBS) jobs = VOXDAGI_ENCODE_JOBS;
        for (t = 0; t < jobs; t++) {
            job[t].e = e, job[t].l = l;
            job[t].begin = s->n * t / jobs, job[t].end = s->n * (t + 1) / jobs;
        }
        voxdagi_run_parallel(e->team, voxdagi_tag_run, job, sizeof job[0], jobs);
        memset(e->single[l + 1], 0, n1);
        candidates[l] = 0;
        for (i = 0; i < 8 * s->n; i++) {
            uint32_t x = s->child[i];
            if (x != VOXDAGI_NONE && refs[l + 1][x >> 6] == 1 && e->tag[l][i] == 0)
                e->single[l + 1][x >> 6] = 1, candidates[l] = 1;
        }
        for (i = 0; i < n1; i++)
            if (!e->single[l + 1][o[i]]) o[k++] = o[i];
        for (i = 0; i < s->n; i++) {
            uint32_t child[8];
            unsigned tag[8], j;
            voxdagi_stored_children(e, l, e->order[l][i], child, tag);
            for (j = 0; j < 8; j++)
                if (child[j] != VOXDAGI_NONE && e->single[l + 1][child[j] >> 6]) o[k++] = child[j] >> 6;
        }
    }
}

/* Orders every level and plans record offsets. Returns 0 when out of memory
   or when a level needs pointers wider than 57 bits. */
static int voxdagi_encoder_plan(voxdagi_encoder *e) {
    const voxdagi_reducer *r = e->r;
    uint32_t brick_level = e->levels - 2, l;
    uint32_t *refs[VOXDAG_MAX_LEVELS];
    int ok = 1, candidates[VOXDAG_MAX_LEVELS];
    memset(refs, 0, sizeof refs);
    e->level_jobs = e->team->threads < 2 ? 1 : 2 * e->team->threads;
    e->level_job = (voxdagi_level_job *)voxdagi_alloc(e->mem, e->level_jobs * sizeof *e->level_job);
    if (!e->level_job) ok = 0;
    for (l = 0; l <= brick_level; l++) {
        size_t n = r->store[l].n;
        refs[l] = (uint32_t *)voxdagi_alloc(e->mem, n * sizeof(uint32_t));
        e->order[l] = (uint32_t *)voxdagi_alloc(e->mem, n * sizeof(uint32_t));
        e->pos[l] = (uint64_t *)voxdagi_alloc(e->mem, n * sizeof(uint64_t));
        e->orient[l] = (uint8_t *)voxdagi_alloc(e->mem, n);
        e->tag[l] = l < brick_level ? (uint8_t *)voxdagi_alloc(e->mem, 8 * n) : NULL;
        e->single[l] = (uint8_t *)voxdagi_alloc(e->mem, n);
        if (!refs[l] || !e->order[l] || !e->pos[l] || !e->orient[l] || (l < brick_level && !e->tag[l]) || !e->single[l]) ok = 0;
        else memset(refs[l], 0, n * sizeof(uint32_t));
    }
    if (ok) {
        refs[0][r->root >> 6] = 1;
        for (l = 0; l < brick_level; l++) { /* reference counts, saturating */
            const voxdagi_store *s = &r->store[l];
            size_t i;
            for (i = 0; i < 8 * s->n; i++)
                if (s->child[i] != VOXDAGI_NONE && refs[l + 1][s->child[i] >> 6] != UINT32_MAX)
                    refs[l + 1][s->child[i] >> 6]++;
        }
        voxdagi_count_widths(e);
        ok = voxdagi_orient(e);
    }
    if (ok) { /* the root's transform: world = root tag o R^-1 (stored root) */
        const voxdagi_cube *c = &voxdagi_cube_tables;
        uint32_t x = r->root;
        unsigned best = c->comp[x & 63][c->inv[e->orient[0][x >> 6]]];
        uint64_t stabs = r->store[0].node[x >> 6].stab;
        while (stabs) {
            unsigned s = voxdagi_lowest_bit(stabs);
            unsigned v = c->comp[c->comp[x & 63][s]][c->inv[e->orient[0][x >> 6]]];
            if (v < best) best = v;
            stabs &= stabs - 1;
        }
        e->root_transform = best;
    }
    for (l = 0; ok && l <= brick_level; l++) ok = voxdagi_storage_order(e->mem, &r->store[l], refs[l], e->order[l]);
    if (ok) voxdagi_private_order(e, refs, candidates);
    for (l = brick_level + 1; ok && l-- > 0;) {
        size_t i;
        if (l < brick_level) ok = voxdagi_plan_level(e, l, candidates[l]);
        else
            for (i = 0; i < r->store[l].n; i++) e->pos[l][e->order[l][i]] = i;
    }
    for (l = 0; l <= brick_level; l++) voxdagi_free(e->mem, refs[l], r->store[l].n * sizeof(uint32_t));
    return ok;
}

/* Writes the level table, the inner levels into NODES (zeroed) and the
   bricks into BRICKS. */
static void voxdagi_encoder_write(const voxdagi_encoder *e, uint8_t *levels_table, uint8_t *nodes,
                                  uint8_t *bricks) {
    const voxdagi_reducer *r = e->r;
    uint32_t brick_level = e->levels - 2, l;
    uint64_t level_at = 0;
    for (l = 0; l < brick_level; l++) {
        const voxdagi_classes *cls = &e->cls[l];
        uint8_t *p = nodes + level_at, *te = levels_table + l * VOXDAG_FILE_LEVEL_ENTRY_SIZE;
        unsigned t;
        voxdagi_put_le(te, level_at, 8);
        voxdagi_put_le(te + 8, e->size[l], 8);
        voxdagi_put_le(te + 16, r->store[l].n, 4);
        te[20] = (uint8_t)e->count_bits[l];
        te[21] = (uint8_t)e->table_len[l];
        for (t = 1; t <= 3; t++) {
            te[21 + t] = cls->target_bits[t];
            te[24 + t] = cls->code_bits[t];
        }
        te[28] = cls->classes == 2;
        te[29] = cls->base_bits;
        memcpy(te + 32, e->table[l], e->table_len[l]);
        voxdagi_records(e, l, p); /* each at its offset */
        level_at += e->size[l];
    }
    voxdagi_records(e, brick_level, bricks);
}

#endif /* VOXDAG_NO_BUILD */

// -- The DAG: a parsed view of a file image

typedef struct voxdagi_level {
    const uint8_t *data;
    uint64_t size, nodes;
    unsigned count_bits;
    unsigned char width[4];    /* pointer bits of tags 1..3 ([0] = 0; [3] = 0 with private children) */
    unsigned private_children; /* tag 3 marks a private child */
    unsigned base_bits;        /* P: the base field of a record with private children */
    unsigned char code_bits[4];
    uint64_t code_mask[4];
    uint8_t table_inv[64];     /* code -> inverse of its transform */
    uint8_t table[64];         /* code -> transform */
    unsigned table_len;
    uint8_t ptr_bits[256];     /* header byte (4 octants' tags) -> the bits of their pointers */
} voxdagi_level;

struct voxdag {
    voxdag_allocator alloc;
    uint8_t *owned;               /* the image when the DAG owns it */
    size_t owned_size;
    const uint8_t *image;
    size_t image_size;
    uint32_t levels, root_transform;
    voxdag_symmetry symmetry;
    uint64_t voxels;
    uint32_t voxel_box[6];
    voxdagi_level *level;         /* inner levels 0..L-3: L - 2 of them, sized by the file */
    uint32_t level_count;         /* entries allocated in LEVEL */
    uint64_t node_bytes;
    const uint8_t *bricks;
    uint64_t brick_count;
    voxdag_color_kind color_kind;
    const uint8_t *color;
    uint64_t color_size;
    int has_bounds;
    double bounds[6];
    const uint8_t *lod;           /* the level-of-detail colour section, or NULL */
    uint64_t lod_size;
    const uint8_t *lod_slots;     /* its slots: RGB8 (3 bytes each) or a voxcolor stream */
    uint32_t lod_first, lod_levels; /* levels lod_first .. lod_first + lod_levels - 1 */
    uint64_t lod_per_level;       /* slots per level: ceil(voxels / 64) */
#ifdef VOXDAGI_VOXCOLOR
    voxcolor_view color_view; /* the voxcolor colour section, validated */
    voxcolor_view lod_view;   /* the level-of-detail slots when they are voxcolor */
#endif
};

static void voxdagi_release(const voxdag_allocator *a, void *p, size_t size) {
    if (!p) return;
    if (a->free) a->free(a->user, p, size ? size : 1);
    else if (!a->alloc) VOXDAG_FREE(p);
}

VOXDAG_API void voxdag_free(voxdag *dag) {
    voxdag_allocator a;
    if (!dag) return;
    a = dag->alloc;
    voxdagi_release(&a, dag->owned, dag->owned_size);
    voxdagi_release(&a, dag->level, dag->level_count * sizeof *dag->level);
    voxdagi_release(&a, dag, sizeof *dag);
}

VOXDAG_API const void *voxdag_image(const voxdag *dag, size_t *size) {
    if (size) *size = dag ? dag->image_size : 0;
    return dag ? dag->image : NULL;
}

// -- Node access on the encoded form

/* The octants with a child, from a record header (bit i: tag i non-zero). */
static unsigned voxdagi_presence(unsigned header) {
    unsigned x = (header | header >> 1) & 0x5555;
    x = (x | x >> 1) & 0x3333;
    x = (x | x >> 2) & 0x0F0F;
    return (x | x >> 4) & 0xFF;
}

/* A stored brick mask seen through world-to-stored transform MI, in world
   order: byte w of the result (the 2^3 cell w) is stored byte MI(w) with its
   bits mapped the same way; branch-free, one table lookup a byte. */
VOXDAGI_INLINE uint64_t voxdagi_brick_to_world(uint64_t mask, unsigned mi) {
    const uint8_t *to_stored = voxdagi_cube_tables.act[mi], *occ = voxdagi_occupancy[mi];
    uint64_t w = 0;
    unsigned k;
    for (k = 0; k < 8; k++) w |= (uint64_t)occ[(mask >> 8 * to_stored[k]) & 0xFF] << 8 * k;
    return w;
}

/* Whether a record with HEADER has private children (then its base field
   follows the count); never on a level without them, whose P is 0. */
VOXDAGI_INLINE unsigned voxdagi_has_private(unsigned header) { return (header & header >> 1 & 0x5555) != 0; }

/* Fills LV->ptr_bits from its pointer widths: for each header byte, the sum
   of the widths of its four tags. */
static void voxdagi_ptr_bits_init(voxdagi_level *lv) {
    uint8_t two[16]; /* two tags */
    unsigned h, l;
    for (l = 0; l < 16; l++) two[l] = (uint8_t)(lv->width[l & 3] + lv->width[l >> 2]);
    for (h = 0; h < 16; h++)
        for (l = 0; l < 16; l++) lv->ptr_bits[16 * h + l] = (uint8_t)(two[h] + two[l]); /* 4 x 57 < 256 */
}

/* Bit offset of child octant S's pointer inside a record with HEADER: the
   base field, then the widths of the lower octants' pointers (two lookups). */
VOXDAGI_INLINE unsigned voxdagi_child_bit(const voxdagi_level *lv, unsigned header, unsigned s) {
    unsigned h = header & ((1u << (2 * s)) - 1);
    return 16 + lv->count_bits + (lv->base_bits & (0u - voxdagi_has_private(header))) + lv->ptr_bits[h & 0xFF] +
           lv->ptr_bits[h >> 8];
}

static uint64_t voxdagi_record_bits(const voxdagi_level *lv, unsigned header) {
    return voxdagi_child_bit(lv, header, 8);
}

/* Bytes of the record at byte OFFSET of inner level LV. */
VOXDAGI_INLINE uint64_t voxdagi_record_bytes(const voxdagi_level *lv, uint64_t offset) {
    return (voxdagi_record_bits(lv, voxdagi_le16(lv->data + offset)) + 7) >> 3;
}

/* The offset of the private child of stored octant S of record REC of
   inner level L: the base, then one node further per lower private child
   (bricks: one each). */
VOXDAGI_INLINE uint64_t voxdagi_private_child(const voxdag *d, uint32_t l, const uint8_t *rec, unsigned header, unsigned s) {
    const voxdagi_level *lv = &d->level[l];
    unsigned h = header & ((1u << (2 * s)) - 1), k;
    uint64_t at = voxdagi_get_bits(rec, 16 + lv->count_bits, lv->base_bits);
    h &= h >> 1 & 0x5555; /* the lower private children, bits 0, 2, ..., 14 */
    h = (h & 0x3333) + (h >> 2 & 0x3333);
    h = (h + (h >> 4)) & 0x0F0F;
    k = (h + (h >> 8)) & 0x1F;
    if (l + 3 == d->levels) return at + k;
    lv++; /* the children's level: skip K records */
    while (k--) at += voxdagi_record_bytes(lv, at);
    return at;
}

/* A pointer V of class T of level LV as target << 6 | TABLE[its code]. */
VOXDAGI_INLINE uint64_t voxdagi_pointer_ref(const voxdagi_level *lv, uint64_t v, unsigned t, const uint8_t *table) {
    return (v >> lv->code_bits[t]) << 6 | table[v & lv->code_mask[t]];
}

/* The child of stored octant S (which must be present) of record REC of
   inner level L: its offset << 6 | the pointer's transform, inverted when
   INVERSE (what traversals compose). */
VOXDAGI_INLINE uint64_t voxdagi_child_ref(const voxdag *d, uint32_t l, const uint8_t *rec, unsigned header,
                                          unsigned s, int inverse) {
    const voxdagi_level *lv = &d->level[l];
    unsigned t = header >> (2 * s) & 3;
    uint64_t v;
    if (t == 3 && lv->private_children) return voxdagi_private_child(d, l, rec, header, s) << 6;
    v = voxdagi_get_bits(rec, voxdagi_child_bit(lv, header, s), lv->width[t]);
    return voxdagi_pointer_ref(lv, v, t, inverse ? lv->table_inv : lv->table);
}

/* REF[s] for each stored octant s in SET (all present) of record REC of
   inner level L: what voxdagi_child_ref with INVERSE gives, in one pass over
   the record (private children one after another). */
static void voxdagi_child_refs(const voxdag *d, uint32_t l, const uint8_t *rec, unsigned header, unsigned set,
                               uint64_t ref[8]) {
    const voxdagi_level *lv = &d->level[l], *next = lv + 1;
    unsigned bit = 16 + lv->count_bits, s, skip = 0, bricks = l + 3 == d->levels;
    uint64_t priv = 0;
    if (voxdagi_has_private(header)) priv = voxdagi_get_bits(rec, bit, lv->base_bits), bit += lv->base_bits;
    for (s = 0; set >> s; s++) {
        unsigned t = header >> (2 * s) & 3;
        if (!t) continue;
        if (t == 3 && lv->private_children) {
            if (skip) priv += bricks ? 1 : voxdagi_record_bytes(next, priv);
            skip = 1;
            ref[s] = priv << 6;
        } else {
            uint64_t v = voxdagi_get_bits(rec, bit, lv->width[t]);
            bit += lv->width[t];
            ref[s] = voxdagi_pointer_ref(lv, v, t, lv->table_inv);
        }
    }
}

static uint64_t voxdagi_brick(const voxdag *d, uint64_t index) {
    return voxdagi_le_fast(d->bricks + 8 * index, 8);
}

/* Voxels below the node at byte OFFSET of inner level L whose level stores
   counts (or below brick OFFSET when L is the brick level). */
static uint64_t voxdagi_stored_count(const voxdag *d, uint32_t l, uint64_t offset) {
    if (l == d->levels - 2) return (uint64_t)voxdagi_popcount64(voxdagi_brick(d, offset));
    return voxdagi_get_bits_wide(d->level[l].data + offset, 16, d->level[l].count_bits);
}

/* Voxels below the node at byte OFFSET of inner level L (or brick OFFSET when
   L is the brick level): stored, or, at a level without counts (C = 0), the
   sum of its children's, whose level stores them (validated on load). */
static uint64_t voxdagi_node_count(const voxdag *d, uint32_t l, uint64_t offset) {
    const uint8_t *rec;
    unsigned header, set, s;
    uint64_t sum = 0, ref[8];
    if (l == d->levels - 2 || d->level[l].count_bits) return voxdagi_stored_count(d, l, offset);
    rec = d->level[l].data + offset;
    header = voxdagi_le16(rec);
    set = voxdagi_presence(header);
    voxdagi_child_refs(d, l, rec, header, set, ref);
    for (s = 0; s < 8; s++)
        if (set >> s & 1) sum += voxdagi_stored_count(d, l + 1, ref[s] >> 6);
    return sum;
}

// -- Colours through voxcolor.h (when compiled in)

/* Validates a voxcolor colour section and keeps its view for voxdag_color. */
static voxdag_status voxdagi_open_colors(voxdag *d, voxdag_error *err) {
#ifdef VOXDAGI_VOXCOLOR
    voxcolor_error ve;
    uint64_t at = d->color ? (uint64_t)(d->color - d->image) : 0;
    if (d->color_kind != VOXDAG_COLORS_VOXCOLOR) return VOXDAG_OK;
    if (voxcolor_view_init(&d->color_view, d->color, (size_t)d->color_size, &ve) != VOXCOLOR_OK)
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "voxcolor colour section does not validate",
                            ve.byte_offset == UINT64_MAX ? at : at + ve.byte_offset, UINT64_MAX);
    if (d->color_view.count != d->voxels)
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "voxcolor colour count differs from the voxel count",
                            at + VOXCOLOR_OFF_COUNT, UINT64_MAX);
#else
    (void)d, (void)err;
#endif
    return VOXDAG_OK;
}

/* Validates the level-of-detail colour section (FORMAT.md, LOD_COLORS)
   against the header and the colour section, and keeps its slots. */
static voxdag_status voxdagi_open_lod(voxdag *d, voxdag_error *err) {
    const uint8_t *p = d->lod;
    uint64_t at, total, need;
    unsigned kind;
    if (!p) return VOXDAG_OK;
    at = (uint64_t)(p - d->image);
    if (d->lod_size < VOXDAG_FILE_LOD_HEADER_SIZE)
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "level-of-detail colour section shorter than its header", at,
                            UINT64_MAX);
    kind = p[VOXDAG_FILE_LOD_OFF_KIND];
    d->lod_first = p[VOXDAG_FILE_LOD_OFF_FIRST_LEVEL];
    d->lod_levels = p[VOXDAG_FILE_LOD_OFF_LEVEL_COUNT];
    d->lod_per_level = voxdagi_le(p + VOXDAG_FILE_LOD_OFF_SLOTS, 8);
    if (d->color_kind == VOXDAG_COLORS_NONE || kind != (unsigned)d->color_kind)
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "level-of-detail colour kind differs from the colour section's",
                            at + VOXDAG_FILE_LOD_OFF_KIND, UINT64_MAX);
    if (p[VOXDAG_FILE_LOD_OFF_SLOT_SHIFT] != VOXDAG_FILE_LOD_SLOT_SHIFT || voxdagi_le(p + VOXDAG_FILE_LOD_OFF_RESERVED, 4))
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "level-of-detail colour slot shift or reserved field",
                            at + VOXDAG_FILE_LOD_OFF_SLOT_SHIFT, UINT64_MAX);
    if (!d->lod_levels || d->lod_first + d->lod_levels + 2 > d->levels)
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "level-of-detail colour levels outside 0..L-3",
                            at + VOXDAG_FILE_LOD_OFF_FIRST_LEVEL, UINT64_MAX);
    if (d->lod_per_level != (d->voxels >> VOXDAG_FILE_LOD_SLOT_SHIFT) + ((d->voxels & 63) != 0))
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "level-of-detail slots per level differ from ceil(voxels / 64)",
                            at + VOXDAG_FILE_LOD_OFF_SLOTS, UINT64_MAX);
    total = d->lod_per_level * d->lod_levels; /* < 2^57 * 19: no overflow */
    d->lod_slots = p + VOXDAG_FILE_LOD_HEADER_SIZE;
    need = d->lod_size - VOXDAG_FILE_LOD_HEADER_SIZE;
    if (kind == VOXDAG_COLORS_RGB8) {
        if (need != 3 * total)
            return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "level-of-detail colour section size", at, UINT64_MAX);
        return VOXDAG_OK;
    }
#ifdef VOXDAGI_VOXCOLOR
    {
        voxcolor_error ve;
        uint64_t s = at + VOXDAG_FILE_LOD_HEADER_SIZE;
        if (voxcolor_view_init(&d->lod_view, d->lod_slots, (size_t)need, &ve) != VOXCOLOR_OK)
            return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "voxcolor level-of-detail colours do not validate",
                                ve.byte_offset == UINT64_MAX ? s : s + ve.byte_offset, UINT64_MAX);
        if (d->lod_view.count != total)
            return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "voxcolor level-of-detail colour count differs from the slots",
                                s + VOXCOLOR_OFF_COUNT, UINT64_MAX);
    }
#endif
    return VOXDAG_OK;
}

// -- Loading: header, sections and full structural validation (FORMAT.md)

/* What validation keeps of a checked level to check the level above it.
   START: per 32 byte offsets, the number of records that start before them
   (bits 32-63) and one bit per offset where a record starts (bits 0-31), so
   that a pointer's check and its record's rank (its index in the level) take
   one load and one popcount. Per record, by rank: its voxel count, so that a
   parent adds its children's counts without decoding them, and whether it is
   referenced, and as a private child. Every count kept is a checked sum, at
   most the volume of its cell: below 2^27 when the cells are at most 2^9 on
   a side, and there each record is one 32-bit word, REC32 (the count, bit
   30 referenced, bit 31 private), else COUNT64 and 2 bits in REFS (bit 2r
   referenced, bit 2r+1 private). On the brick level a brick's index is its
   rank, the count its popcount, and there is no START. One allocation. */
typedef struct voxdagi_vlevel {
    void *block;
    size_t block_size;
    uint64_t *start, *count64, *refs;
    uint32_t *rec32;
    uint64_t records;
} voxdagi_vlevel;

#define VOXDAGI_REC_REF (1u << 30)
#define VOXDAGI_REC_PRIVATE (1u << 31)

/* Allocates V for a level of UNITS bytes (none for the bricks, BRICKS 1) and
   RECORDS records, 32-bit unless WIDE; START and REFS zeroed. Returns 0 when
   out of memory. */
static int voxdagi_vlevel_alloc(voxdagi_mem *m, voxdagi_vlevel *v, uint64_t units, uint64_t records, int bricks,
                                int wide) {
    uint64_t sw = bricks ? 0 : (units + 31) / 32, rw = wide ? (records + 31) / 32 : 0;
    uint64_t bytes = 8 * (sw + rw) + (wide ? 8 : 4) * records; /* units <= the image size */
    memset(v, 0, sizeof *v);
    if ((uint64_t)(size_t)bytes != bytes) return 0;
    v->block = voxdagi_alloc(m, (size_t)bytes);
    if (!v->block) return 0;
    v->block_size = (size_t)bytes;
    v->records = records;
    v->start = (uint64_t *)v->block;
    memset(v->block, 0, (size_t)(8 * (sw + rw)));
    if (wide) v->refs = v->start + sw, v->count64 = v->refs + rw;
    else v->rec32 = (uint32_t *)(v->start + sw);
    return 1;
}

static void voxdagi_vlevel_free(voxdagi_mem *m, voxdagi_vlevel *v) {
    voxdagi_free(m, v->block, v->block_size);
    memset(v, 0, sizeof *v);
}

/* The set bits of X; branch-free with 32-bit constants (cheaper than
   voxdagi_popcount64 where the popcount instruction is not enabled). */
static unsigned voxdagi_popcount32(uint32_t x) {
#if (defined(__GNUC__) || defined(__clang__)) && defined(__POPCNT__)
    return (unsigned)__builtin_popcount(x);
#else
    x = x - ((x >> 1) & 0x55555555u);
    x = (x & 0x33333333u) + ((x >> 2) & 0x33333333u);
    return ((x + (x >> 4)) & 0x0F0F0F0Fu) * 0x01010101u >> 24;
#endif
}

/* Returns WHY from voxdagi_validate_records, for the record at AT. */
#define VOXDAGI_BAD(why) \
    do { \
        *at_out = at, *record_out = records; \
        return why; \
    } while (0)

/* Checks the records of inner level L against CHILD, what validation kept
   of level L + 1, and fills CUR for level L (START without ranks). BRICKS:
   level L + 1 is the bricks; WIDE: CHILD keeps 64-bit counts (both constant
   at each call, so that each case compiles to its own loop). Returns NULL, or
   what is wrong with the record at byte *AT, the *RECORD-th of the level;
   then CHILD's reference bits are partly set. After the last record, *AT is
   the level's size and *RECORD the number of records. */
VOXDAGI_INLINE const char *voxdagi_validate_records(const voxdag *d, uint32_t l, voxdagi_vlevel *child,
                                                    const voxdagi_vlevel *cur, const uint16_t *tag_seq,
                                                    uint64_t *at_out, uint64_t *record_out, const int bricks,
                                                    const int wide) {
    const voxdagi_level level = d->level[l], *lv = &level; /* a copy, which the stores below cannot change */
    const uint64_t wmask[4] = {0, (1ull << level.width[1]) - 1, (1ull << level.width[2]) - 1,
                               (1ull << level.width[3]) - 1}; /* each class's pointer bits */
    const uint8_t *data = lv->data;
    const unsigned table_len = lv->table_len, count_bits = lv->count_bits;
    const unsigned private_tag = lv->private_children ? 3 : 4; /* the tag of a private child (4: none) */
    const uint64_t size = lv->size, child_units = bricks ? d->brick_count : d->level[l + 1].size;
    const uint64_t *const start = child->start;
    uint64_t *const cur_start = cur->start, *const refs = child->refs;
    uint32_t *const rec32 = child->rec32;
    uint64_t at = 0, records = 0;
    while (at < size) {
        const uint8_t *rec = data + at;
        unsigned header, h, bit;
        uint64_t sum = 0, bits, bytes, next_private;
        if (size - at < 2) VOXDAGI_BAD("record runs past its level");
        header = voxdagi_le16(rec);
        if (!header) VOXDAGI_BAD("node without children");
        bit = voxdagi_child_bit(lv, header, 0); /* the first pointer; then each one's width, in octant order */
        bits = bit + lv->ptr_bits[header & 0xFF] + lv->ptr_bits[header >> 8]; /* voxdagi_record_bits */
        bytes = (bits + 7) / 8;
        if (size - at < bytes) VOXDAGI_BAD("record runs past its level");
        if (voxdagi_get_bits(rec, bits, (unsigned)(8 * bytes - bits))) VOXDAGI_BAD("record padding bits not zero");
        next_private = voxdagi_get_bits(rec, 16 + count_bits, bit - 16 - count_bits); /* the base, when there is one */
        h = tag_seq[header & 0xFF];
        h = (h & 0xFF) | (tag_seq[header >> 8] & 0xFFu) << (h >> 8);
        for (; h; h >>= 2) { /* the present octants' tags, lowest first */
            unsigned t = h & 3, private_child, used;
            uint64_t v, target, c, r;
            private_child = t == private_tag;
            if (private_child) {
                target = next_private;
            } else {
                v = voxdagi_le_fast(rec + (bit >> 3), 8) >> (bit & 7) & wmask[t]; /* voxdagi_get_bits */
                bit += lv->width[t];
                if ((v & lv->code_mask[t]) >= table_len) VOXDAGI_BAD("transform code outside the level's table");
                target = v >> lv->code_bits[t];
            }
            if (target >= child_units) VOXDAGI_BAD("child pointer does not land on a node");
            if (bricks) {
                r = target;
            } else {
                uint64_t w = start[target >> 5];
                if (!(w >> (target & 31) & 1)) VOXDAGI_BAD("child pointer does not land on a node");
                r = (w >> 32) + voxdagi_popcount32((uint32_t)w & ((1u << (target & 31)) - 1));
            }
            if (!wide) {
                uint32_t e = rec32[r];
                used = e >> 30;
                if (private_child ? used : used & 2) /* a private child's own bits are both set */
                    VOXDAGI_BAD("private child referenced twice");
                rec32[r] = e | VOXDAGI_REC_REF | (private_child ? VOXDAGI_REC_PRIVATE : 0);
                sum += e & (VOXDAGI_REC_REF - 1); /* 8 counts below 2^27: no overflow */
            } else {
                used = (unsigned)(refs[r >> 5] >> (2 * (r & 31))) & 3;
                if (private_child ? used : used & 2) VOXDAGI_BAD("private child referenced twice");
                refs[r >> 5] |= (uint64_t)(private_child ? 3 : 1) << (2 * (r & 31));
                c = child->count64[r];
                if (sum + c < sum) VOXDAGI_BAD("voxel count overflows");
                sum += c;
            }
            if (private_child) next_private = target + (bricks ? 1 : voxdagi_record_bytes(&d->level[l + 1], target));
        }
        if (count_bits && voxdagi_get_bits_wide(rec, 16, count_bits) != sum)
            VOXDAGI_BAD("node count differs from its children's sum");
        cur_start[at >> 5] |= 1ull << (at & 31);
        if (records < cur->records) { /* more records than the level table says: refused by the caller */
            if (cur->rec32) cur->rec32[records] = (uint32_t)sum;
            else cur->count64[records] = sum;
        }
        at += bytes;
        records++;
    }
    *at_out = at, *record_out = records;
    return NULL;
}
#undef VOXDAGI_BAD

/* voxdagi_validate_records for level L, one loop per case. */
static const char *voxdagi_validate_level(const voxdag *d, uint32_t l, voxdagi_vlevel *child,
                                          const voxdagi_vlevel *cur, const uint16_t *tag_seq, uint64_t *at,
                                          uint64_t *record) {
    if (l + 3 == d->levels) return voxdagi_validate_records(d, l, child, cur, tag_seq, at, record, 1, 0);
    if (child->rec32) return voxdagi_validate_records(d, l, child, cur, tag_seq, at, record, 0, 0);
    return voxdagi_validate_records(d, l, child, cur, tag_seq, at, record, 0, 1);
}

/* TAG_SEQ[b] for each header byte b (4 octants' tags): its non-zero tags
   packed from bit 0, lowest octant first, and their bits (2 each) from bit
   8; the pointer loop then takes one tag after the other, with no search for
   the next present octant on its critical path. */
static void voxdagi_tag_seq_init(uint16_t tag_seq[256]) {
    unsigned b;
    for (b = 0; b < 16; b++) /* two tags: the upper one moves down when the lower is 0 */
        tag_seq[b] = (uint16_t)((b & 3 ? b : b >> 2) | ((unsigned)((b & 3) != 0) + (unsigned)(b > 3)) << 9);
    for (b = 16; b < 256; b++) { /* the upper two tags after the lower two */
        unsigned lo = tag_seq[b & 15], hi = tag_seq[b >> 4];
        tag_seq[b] = (uint16_t)(((lo & 0xFF) | (hi & 0xFF) << (lo >> 8)) | ((lo >> 9) + (hi >> 9)) << 9);
    }
}

/* Every record of every inner level, bottom-up: sizes, zero padding, pointer
   codes (inside the level's transform table), targets (a record start of
   the next level, or a brick; private children: from the base, one node
   after the other, inside the level, each referenced by nothing else),
   counts (the sum of the children's), every node and brick referenced, one
   root holding every voxel. */
static voxdag_status voxdagi_validate_nodes(const voxdag *d, voxdagi_mem *m, voxdag_error *err) {
    uint32_t brick_level = d->levels - 2, l;
    uint64_t base = brick_level ? (uint64_t)(d->level[0].data - d->image) : 0, i; /* no node data when L = 2 */
    voxdagi_vlevel child, cur;
    uint16_t tag_seq[256];
    voxdag_status st = VOXDAG_OK;
    const char *msg = NULL;
    uint64_t where = UINT64_MAX, node = UINT64_MAX;
    memset(&child, 0, sizeof child);
    memset(&cur, 0, sizeof cur);
    for (i = 0; i < d->brick_count; i++)
        if (!voxdagi_brick(d, i))
            return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "empty brick",
                                (uint64_t)(d->bricks - d->image) + 8 * i, i);
    if (d->voxels == 0) {
        if (d->brick_count || d->node_bytes)
            return VOXDAGI_FAIL(err, VOXDAG_ERR_CORRUPT, "nodes in an empty scene");
        return VOXDAG_OK;
    }
    if (brick_level == 0) {
        if (d->brick_count != 1 || (uint64_t)voxdagi_popcount64(voxdagi_brick(d, 0)) != d->voxels)
            return VOXDAGI_FAIL(err, VOXDAG_ERR_CORRUPT, "root brick does not match the voxel count");
        return VOXDAG_OK;
    }
    if (!voxdagi_vlevel_alloc(m, &child, d->brick_count, d->brick_count, 1, 0))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot allocate validation bitmaps");
    for (i = 0; i < d->brick_count; i++) child.rec32[i] = (uint32_t)voxdagi_popcount64(voxdagi_brick(d, i));
    voxdagi_tag_seq_init(tag_seq);
    for (l = brick_level; st == VOXDAG_OK && l-- > 0;) {
        const voxdagi_level *lv = &d->level[l];
        uint64_t at, records;
        if (!voxdagi_vlevel_alloc(m, &cur, lv->size, lv->nodes, 0, d->levels - l > 9)) {
            st = VOXDAG_ERR_OUT_OF_MEMORY;
            msg = "cannot allocate validation bitmaps";
            break;
        }
        msg = voxdagi_validate_level(d, l, &child, &cur, tag_seq, &at, &records);
        if (msg) {
            st = VOXDAG_ERR_CORRUPT, where = base + (uint64_t)(lv->data - d->level[0].data) + at, node = records;
        } else if (records != lv->nodes) {
            st = VOXDAG_ERR_CORRUPT; msg = "level node count differs from its records";
        }
        if (st == VOXDAG_OK) { /* every child referenced: the AND of their reference bits */
            uint64_t all = ~0ull, want;
            if (child.rec32) {
                for (i = 0; i < child.records; i++) all &= child.rec32[i];
                want = VOXDAGI_REC_REF;
            } else {
                for (i = 0; i < child.records; i += 32) /* the bits past the last record count as set */
                    all &= child.refs[i >> 5] | (child.records - i >= 32 ? 0 : ~0ull << 2 * (child.records - i));
                want = 0x5555555555555555ull;
            }
            if ((all & want) != want) { st = VOXDAG_ERR_CORRUPT; msg = "unreferenced node"; }
        }
        voxdagi_vlevel_free(m, &child);
        child = cur;
        memset(&cur, 0, sizeof cur);
        if (st == VOXDAG_OK) {
            uint64_t w, n = 0;
            for (w = 0; w < (lv->size + 31) / 32; w++) {
                uint64_t starts = child.start[w];
                child.start[w] = n << 32 | starts; /* n <= the level's record count, a u32 */
                n += (uint64_t)voxdagi_popcount64(starts);
            }
        }
    }
    if (st == VOXDAG_OK &&
        (d->level[0].nodes != 1 || (child.rec32 ? child.rec32[0] : child.count64[0]) != d->voxels)) {
        st = VOXDAG_ERR_CORRUPT; msg = "root does not hold the header's voxel count"; where = base; node = 0;
    }
    voxdagi_vlevel_free(m, &child);
    voxdagi_vlevel_free(m, &cur);
    return st == VOXDAG_OK ? VOXDAG_OK : voxdagi_fail(err, st, msg, where, node);
}

/* The Morton positions p of a 4^3 brick with bit k of p clear. */
static const uint64_t voxdagi_brick_bit_clear[6] = {0x5555555555555555ull, 0x3333333333333333ull,
                                                    0x0F0F0F0F0F0F0F0Full, 0x00FF00FF00FF00FFull,
                                                    0x0000FFFF0000FFFFull, 0x00000000FFFFFFFFull};

/* The box (lo x, y, z, hi x, y, z; half-open) of the voxels of a non-empty
   brick MASK: coordinate a of position p is bit a of p plus twice bit a+3. */
static void voxdagi_brick_box(uint64_t mask, uint32_t box[6]) {
    unsigned a, v;
    for (a = 0; a < 3; a++) {
        box[a] = 4, box[a + 3] = 0;
        for (v = 0; v < 4; v++) {
            uint64_t lo = voxdagi_brick_bit_clear[a], hi = voxdagi_brick_bit_clear[a + 3];
            if (!(mask & (v & 1 ? ~lo : lo) & (v & 2 ? ~hi : hi))) continue;
            if (v < box[a]) box[a] = v;
            box[a + 3] = v + 1;
        }
    }
}

/* A set of (node, transform) pairs, keys offset << 6 | MI, as an open
   addressing table (0 marks an empty slot, so keys are stored plus one). */
typedef struct voxdagi_ref_set {
    uint64_t *slot;
    size_t cap, n;
} voxdagi_ref_set;

/* Adds KEY to S (growing it when half full). Returns 0 when out of memory. */
static int voxdagi_ref_set_add(voxdagi_mem *m, voxdagi_ref_set *s, uint64_t key);

/* Makes empty set S hold N keys without growing. Returns 0 when out of
   memory. */
static int voxdagi_ref_set_reserve(voxdagi_mem *m, voxdagi_ref_set *s, size_t n) {
    size_t cap = 64;
    while (cap < 2 * n && cap < ((size_t)-1 >> 4)) cap *= 2;
    if (s->n || cap <= s->cap) return 1;
    voxdagi_free(m, s->slot, s->cap * sizeof *s->slot);
    s->slot = (uint64_t *)voxdagi_alloc(m, cap * sizeof *s->slot);
    s->cap = s->slot ? cap : 0;
    if (s->slot) memset(s->slot, 0, cap * sizeof *s->slot);
    return s->slot != NULL;
}

static int voxdagi_ref_set_add(voxdagi_mem *m, voxdagi_ref_set *s, uint64_t key) {
    size_t i;
    if (2 * (s->n + 1) > s->cap) {
        voxdagi_ref_set g;
        g.cap = s->cap ? 2 * s->cap : 64, g.n = 0;
        g.slot = (uint64_t *)voxdagi_alloc(m, g.cap * sizeof *g.slot);
        if (!g.slot) return 0;
        memset(g.slot, 0, g.cap * sizeof *g.slot);
        for (i = 0; i < s->cap; i++)
            if (s->slot[i]) voxdagi_ref_set_add(m, &g, s->slot[i] - 1);
        voxdagi_free(m, s->slot, s->cap * sizeof *s->slot);
        *s = g;
    }
    for (i = (size_t)((key + 1) * 0x9E3779B97F4A7C15ull >> 20) & (s->cap - 1); s->slot[i]; i = (i + 1) & (s->cap - 1))
        if (s->slot[i] == key + 1) return 1;
    s->slot[i] = key + 1;
    s->n++;
    return 1;
}

static void voxdagi_ref_set_free(voxdagi_mem *m, voxdagi_ref_set *s) {
    voxdagi_free(m, s->slot, s->cap * sizeof *s->slot);
    memset(s, 0, sizeof *s);
}

/* The extreme coordinate along world axis A of the voxels of a non-empty,
   structurally valid DAG: the lowest (HIGH 0) or one past the highest (HIGH
   1). Walks only the extreme slab: at each level the distinct (node,
   transform) pairs whose cells lie in the lowest (highest) slab that holds a
   voxel, so the cost is that of the nodes on the scene's face, not of the
   scene. Returns 0 when out of memory. */
static int voxdagi_extreme(const voxdag *d, voxdagi_mem *m, unsigned a, unsigned high, uint32_t *out) {
    uint32_t brick_level = d->levels - 2, l, at = high ? 1u << d->levels : 0, best = high ? 0 : 4;
    voxdagi_ref_set cur, next;
    const unsigned lower = a == 0 ? 0x55 : a == 1 ? 0x33 : 0x0F; /* the world octants with bit A clear */
    size_t i;
    unsigned mi;
    memset(&cur, 0, sizeof cur);
    memset(&next, 0, sizeof next);
    if (!voxdagi_ref_set_add(m, &cur, voxdagi_cube_tables.inv[d->root_transform])) return 0;
    for (l = 0; l < brick_level; l++) {
        unsigned side; /* the half of each cell on the wanted side, then the other */
        for (side = 0; side < 2 && !next.n; side++) {
            unsigned half = high ^ side;
            if (!voxdagi_ref_set_reserve(m, &next, 4 * cur.n)) { /* 4 children each at most */
                voxdagi_ref_set_free(m, &cur);
                return 0;
            }
            for (i = 0; i < cur.cap; i++) {
                uint64_t key = cur.slot[i] - 1, off = key >> 6, ref[8];
                unsigned header, set, v;
                const uint8_t *rec;
                if (!cur.slot[i]) continue;
                mi = (unsigned)(key & 63);
                rec = d->level[l].data + off;
                header = voxdagi_le16(rec);
                /* the stored octants MI(w) of the world half: world and stored swap under MI^-1 */
                set = voxdagi_presence(header) & voxdagi_occupancy[voxdagi_cube_tables.inv[mi]][half ? 0xFF ^ lower : lower];
                if (!set) continue;
                voxdagi_child_refs(d, l, rec, header, set, ref);
                for (; set; set &= set - 1) {
                    v = voxdagi_lowest_bit(set);
                    if (!voxdagi_ref_set_add(m, &next, (ref[v] >> 6) << 6 | voxdagi_cube_tables.comp[ref[v] & 63][mi])) {
                        voxdagi_ref_set_free(m, &cur);
                        voxdagi_ref_set_free(m, &next);
                        return 0;
                    }
                }
            }
            if (!next.n) at = high ? at - (1u << (d->levels - 1 - l)) : at + (1u << (d->levels - 1 - l));
        }
        voxdagi_ref_set_free(m, &cur);
        cur = next;
        memset(&next, 0, sizeof next);
    }
    for (i = 0; i < cur.cap; i++) { /* the bricks of the slab, in world order */
        uint32_t box[6];
        if (!cur.slot[i]) continue;
        voxdagi_brick_box(voxdagi_brick_to_world(voxdagi_brick(d, (cur.slot[i] - 1) >> 6), (unsigned)((cur.slot[i] - 1) & 63)), box);
        if (high ? box[a + 3] > best : box[a] < best) best = high ? box[a + 3] : box[a];
    }
    voxdagi_ref_set_free(m, &cur);
    *out = high ? at - 4 + best : at + best;
    return 1;
}

/* Checks that the stored voxel box is the box of the voxels (queries clip
   rays to it, so a wrong box would make rays and lookups disagree). */
static voxdag_status voxdagi_validate_box(const voxdag *d, voxdagi_mem *m, voxdag_error *err) {
    unsigned k;
    if (!d->voxels) return VOXDAG_OK; /* the box is checked to be zero */
    for (k = 0; k < 6; k++) {
        uint32_t v;
        if (!voxdagi_extreme(d, m, k % 3, k / 3, &v))
            return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot allocate the voxel box check");
        if (v != d->voxel_box[k])
            return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "voxel box differs from the box of the voxels",
                                VOXDAG_FILE_OFF_VOXEL_BOX + 4 * k, UINT64_MAX);
    }
    return VOXDAG_OK;
}

static int voxdagi_all_zero(const uint8_t *p, uint64_t n) {
    while (n--)
        if (*p++) return 0;
    return 1;
}

/* The number of transforms of a symmetry group (a transform code is valid
   below it). */
static unsigned voxdagi_group_size(voxdag_symmetry s) {
    return s == VOXDAG_SYMMETRY_NONE ? 1 : s == VOXDAG_SYMMETRY_REFLECT ? 8 : VOXDAGI_TRANSFORMS;
}

/* Parses level entry L of a validated level table into D. Returns NULL, or
   what is wrong. */
static const char *voxdagi_parse_level(voxdag *d, uint32_t l, const uint8_t *e, uint64_t level_at,
                                       uint64_t nodes_size) {
    voxdagi_level *lv = &d->level[l];
    unsigned t, k, group = voxdagi_group_size(d->symmetry);
    lv->size = voxdagi_le(e + 8, 8);
    lv->nodes = voxdagi_le(e + 16, 4);
    lv->count_bits = e[20];
    lv->table_len = e[21];
    if (voxdagi_le(e, 8) != level_at || lv->size > nodes_size - level_at || lv->nodes > lv->size / 2)
        return "bad level entry";
    if (l + 3 == d->levels ? lv->count_bits != 0 : lv->count_bits > 64) return "bad level count width";
    if (l && !lv->count_bits && !d->level[l - 1].count_bits) /* derived counts sum stored ones */
        return "two levels in a row without counts";
    lv->private_children = e[28];
    lv->base_bits = e[29];
    if (lv->private_children > 1 || lv->base_bits > 57 || (!lv->private_children && lv->base_bits) ||
        (lv->private_children && (e[24] || e[27])))
        return "bad private child fields";
    if (e[30] || e[31]) return "reserved level bytes not zero";
    if (!lv->table_len || lv->table_len > VOXDAGI_TRANSFORMS ||
        !voxdagi_all_zero(e + 32 + lv->table_len, VOXDAGI_TRANSFORMS - lv->table_len))
        return "bad level transform table";
    memset(lv->table, 0, sizeof lv->table);
    memset(lv->table_inv, 0, sizeof lv->table_inv);
    for (k = 0; k < lv->table_len; k++) {
        if (e[32 + k] >= group) return "transform outside the file's symmetry group";
        lv->table[k] = e[32 + k];
        lv->table_inv[k] = voxdagi_cube_tables.inv[e[32 + k]];
    }
    lv->width[0] = lv->code_bits[0] = 0;
    lv->code_mask[0] = 0;
    for (t = 1; t <= 3; t++) {
        unsigned o = e[21 + t], c = e[24 + t];
        if (c > 6 || o + c > 57) return "bad pointer class";
        lv->width[t] = (unsigned char)(o + c);
        lv->code_bits[t] = (unsigned char)c;
        lv->code_mask[t] = (1ull << c) - 1;
    }
    voxdagi_ptr_bits_init(lv);
    return NULL;
}

/* Checks the header at IMG (its first VOXDAG_FILE_HEADER_SIZE bytes, when
   SIZE, the file's size, has them): magic, version, checksum and declared
   size, so that a file loader reads no more than the header of a file that
   is not one or whose size differs. */
static voxdag_status voxdagi_check_header(const uint8_t *img, uint64_t size, voxdag_error *err) {
    uint8_t h[VOXDAG_FILE_HEADER_SIZE];
    uint64_t version, end;
    if (size < VOXDAG_FILE_HEADER_SIZE)
        return voxdagi_fail(err, VOXDAG_ERR_TRUNCATED, "file shorter than its header", size, UINT64_MAX);
    if (memcmp(img, voxdagi_magic, 8)) return voxdagi_fail(err, VOXDAG_ERR_BAD_MAGIC, "bad magic bytes", 0, UINT64_MAX);
    version = voxdagi_le(img + VOXDAG_FILE_OFF_VERSION, 4);
    if (version != VOXDAG_FORMAT_VERSION)
        return voxdagi_fail(err, VOXDAG_ERR_VERSION,
                            version < VOXDAG_FORMAT_VERSION
                                ? "format version 1 or 2 (an older voxdag): rebuild the file, this reader needs version 3"
                                : "format version newer than 3 (a newer voxdag): this reader needs version 3",
                            VOXDAG_FILE_OFF_VERSION, UINT64_MAX);
    memcpy(h, img, sizeof h);
    voxdagi_put_le(h + VOXDAG_FILE_OFF_HEADER_CRC, 0, 4);
    if (voxdagi_crc32c(h, sizeof h) != voxdagi_le(img + VOXDAG_FILE_OFF_HEADER_CRC, 4))
        return voxdagi_fail(err, VOXDAG_ERR_CHECKSUM, "header checksum mismatch", VOXDAG_FILE_OFF_HEADER_CRC, UINT64_MAX);
    end = voxdagi_le(img + VOXDAG_FILE_OFF_FILE_SIZE, 8);
    if (end > size)
        return voxdagi_fail(err, VOXDAG_ERR_TRUNCATED, "file shorter than its declared size", size, UINT64_MAX);
    if (end < size) return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "bytes trail the file", end, UINT64_MAX);
    return VOXDAG_OK;
}

/* Parses header and sections of IMG into D. DEEP: also verify checksums and
   every record (skipped only for images this library just wrote). */
static voxdag_status voxdagi_open(voxdag *d, const uint8_t *img, size_t size, int deep,
                                  uint32_t max_levels, uint64_t max_nodes, voxdagi_mem *m,
                                  voxdag_error *err) {
    uint32_t count, i, l, brick_level, seen = 0;
    uint64_t end, node_sum = 0, level_at = 0;
    const uint8_t *levels = NULL, *nodes = NULL;
    uint64_t nodes_size = 0;
    voxdag_status st = voxdagi_check_header(img, size, err);
    d->image = img;
    d->image_size = size;
    if (st != VOXDAG_OK) return st;
    if (voxdagi_le(img + VOXDAG_FILE_OFF_ENDIAN, 4) != VOXDAG_FILE_ENDIAN_TAG ||
        voxdagi_le(img + VOXDAG_FILE_OFF_HEADER_SIZE, 4) != VOXDAG_FILE_HEADER_SIZE ||
        img[VOXDAG_FILE_OFF_SYMMETRY + 1] || !voxdagi_all_zero(img + VOXDAG_FILE_OFF_RESERVED, VOXDAG_FILE_HEADER_SIZE - VOXDAG_FILE_OFF_RESERVED))
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "bad header field", VOXDAG_FILE_OFF_ENDIAN, UINT64_MAX);
    if (voxdagi_le(img + VOXDAG_FILE_OFF_FLAGS, 4))
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "unknown header flags", VOXDAG_FILE_OFF_FLAGS, UINT64_MAX);
    d->symmetry = (voxdag_symmetry)img[VOXDAG_FILE_OFF_SYMMETRY];
    if (d->symmetry < VOXDAG_SYMMETRY_NONE || d->symmetry > VOXDAG_SYMMETRY_FULL)
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "unknown symmetry group", VOXDAG_FILE_OFF_SYMMETRY, UINT64_MAX);
    d->voxels = voxdagi_le(img + VOXDAG_FILE_OFF_VOXELS, 8);
    d->levels = img[VOXDAG_FILE_OFF_LEVELS];
    d->root_transform = img[VOXDAG_FILE_OFF_ROOT_TRANSFORM];
    if (d->levels < 2 || d->levels > max_levels)
        return voxdagi_fail(err, VOXDAG_ERR_LIMIT, "levels outside the accepted range",
                            VOXDAG_FILE_OFF_LEVELS, UINT64_MAX);
    if (d->root_transform >= voxdagi_group_size(d->symmetry) || d->voxels > (1ull << (3 * d->levels)))
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "bad root transform or voxel count",
                            VOXDAG_FILE_OFF_VOXELS, UINT64_MAX);
    for (i = 0; i < 6; i++) d->voxel_box[i] = (uint32_t)voxdagi_le(img + VOXDAG_FILE_OFF_VOXEL_BOX + 4 * i, 4);
    for (i = 0; i < 3; i++)
        if (d->voxels ? !(d->voxel_box[i] < d->voxel_box[i + 3] && d->voxel_box[i + 3] <= 1u << d->levels)
                      : d->voxel_box[i] || d->voxel_box[i + 3])
            return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "voxel box outside the grid or not matching the voxel count",
                                VOXDAG_FILE_OFF_VOXEL_BOX, UINT64_MAX);
    count = (uint32_t)voxdagi_le(img + VOXDAG_FILE_OFF_SECTION_COUNT, 4);
    if (count > VOXDAG_FILE_MAX_SECTIONS)
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "too many sections", VOXDAG_FILE_OFF_SECTION_COUNT, UINT64_MAX);
    end = VOXDAG_FILE_HEADER_SIZE + (uint64_t)count * VOXDAG_FILE_SECTION_ENTRY_SIZE;
    if (end > size)
        return voxdagi_fail(err, VOXDAG_ERR_TRUNCATED, "section table runs past the end", size, UINT64_MAX);
    if (voxdagi_crc32c(img + VOXDAG_FILE_HEADER_SIZE, end - VOXDAG_FILE_HEADER_SIZE) !=
        voxdagi_le(img + VOXDAG_FILE_OFF_TABLE_CRC, 4))
        return voxdagi_fail(err, VOXDAG_ERR_CHECKSUM, "section table checksum mismatch",
                            VOXDAG_FILE_OFF_TABLE_CRC, UINT64_MAX);
    for (i = 0; i < count; i++) {
        const uint8_t *e = img + VOXDAG_FILE_HEADER_SIZE + i * VOXDAG_FILE_SECTION_ENTRY_SIZE;
        uint32_t type = (uint32_t)voxdagi_le(e, 4), flags = (uint32_t)voxdagi_le(e + 4, 4);
        uint64_t off = voxdagi_le(e + 8, 8), sz = voxdagi_le(e + 16, 8);
        uint64_t at = (uint64_t)(e - img);
        const uint8_t *p;
        if ((flags & ~VOXDAG_FILE_SECTION_OPTIONAL) || voxdagi_le(e + 28, 4) || (off & 7) || off < end ||
            off > size || sz > size - off || !voxdagi_all_zero(img + end, off - end))
            return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "bad section entry", at, UINT64_MAX);
        if (type >= 1 && type <= VOXDAG_SECTION_LOD_COLORS) {
            if (seen >> type & 1)
                return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "duplicate section", at, UINT64_MAX);
            seen |= 1u << type;
        } else if (!(flags & VOXDAG_FILE_SECTION_OPTIONAL)) {
            return voxdagi_fail(err, VOXDAG_ERR_VERSION, "unknown required section", at, UINT64_MAX);
        }
        if (deep == 1 && voxdagi_crc32c(img + off, sz) != voxdagi_le(e + 24, 4)) /* 2: skip_checksums */
            return voxdagi_fail(err, VOXDAG_ERR_CHECKSUM, "section checksum mismatch", at + 24, UINT64_MAX);
        end = off + sz;
        p = img + off;
        switch (type) {
        case VOXDAG_SECTION_LEVELS: levels = p;
            if (sz != (uint64_t)(d->levels - 2) * VOXDAG_FILE_LEVEL_ENTRY_SIZE)
                return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "level table size", at, UINT64_MAX);
            break;
        case VOXDAG_SECTION_NODES: nodes = p; nodes_size = sz; break;
        case VOXDAG_SECTION_BRICKS:
            if (sz & 7) return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "brick section size", at, UINT64_MAX);
            d->bricks = p;
            d->brick_count = sz / 8;
            break;
        case VOXDAG_SECTION_COLORS_RGB8:
        case VOXDAG_SECTION_COLORS_VOXCOLOR:
            if (d->color_kind != VOXDAG_COLORS_NONE)
                return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "two colour sections", at, UINT64_MAX);
            if (type == VOXDAG_SECTION_COLORS_RGB8 && (d->voxels > UINT64_MAX / 3 || sz != 3 * d->voxels))
                return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "colour section size", at, UINT64_MAX);
            d->color_kind = type == VOXDAG_SECTION_COLORS_RGB8 ? VOXDAG_COLORS_RGB8 : VOXDAG_COLORS_VOXCOLOR;
            d->color = p;
            d->color_size = sz;
            break;
        case VOXDAG_SECTION_BOUNDS: {
            unsigned k;
            if (sz != 48) return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "bounds section size", at, UINT64_MAX);
            for (k = 0; k < 6; k++) {
                uint64_t bits = voxdagi_le(p + 8 * k, 8);
                memcpy(&d->bounds[k], &bits, 8);
            }
            for (k = 0; k < 3; k++)
                if (!(d->bounds[k] < d->bounds[k + 3]) || d->bounds[k + 3] - d->bounds[k] > 1e300)
                    return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "bounds not finite with min < max", off, UINT64_MAX);
            d->has_bounds = 1;
            break;
        }
        case VOXDAG_SECTION_LOD_COLORS:
            d->lod = p;
            d->lod_size = sz;
            break;
        default: break;
        }
    }
    if (end != size)
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "bytes trail the last section", end, UINT64_MAX);
    if (!levels || !nodes || !d->bricks)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_CORRUPT, "missing level, node or brick section");
    brick_level = d->levels - 2;
    if (brick_level) { /* what the file needs: most DAGs are far below VOXDAG_MAX_LEVELS */
        d->level = (voxdagi_level *)voxdagi_alloc(m, brick_level * sizeof *d->level);
        if (!d->level) return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot allocate the level table");
        d->level_count = brick_level;
        memset(d->level, 0, brick_level * sizeof *d->level);
    }
    for (l = 0; l < brick_level; l++) {
        const uint8_t *e = levels + l * VOXDAG_FILE_LEVEL_ENTRY_SIZE;
        voxdagi_level *lv = &d->level[l];
        const char *bad = voxdagi_parse_level(d, l, e, level_at, nodes_size);
        if (bad) return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, bad, (uint64_t)(e - img), l);
        lv->data = nodes + level_at;
        level_at += lv->size;
        node_sum += lv->nodes;
    }
    if (nodes_size != level_at + VOXDAG_FILE_NODE_PADDING ||
        !voxdagi_all_zero(nodes + level_at, VOXDAG_FILE_NODE_PADDING))
        return voxdagi_fail(err, VOXDAG_ERR_CORRUPT, "node section size or padding",
                            (uint64_t)(nodes - img), UINT64_MAX);
    d->node_bytes = level_at;
    if (max_nodes && (node_sum > max_nodes || d->brick_count > max_nodes - node_sum))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, "more nodes than max_nodes");
    if (voxdagi_open_colors(d, err) != VOXDAG_OK) return VOXDAG_ERR_CORRUPT;
    if (voxdagi_open_lod(d, err) != VOXDAG_OK) return VOXDAG_ERR_CORRUPT;
    if (!deep) return VOXDAG_OK;
    st = voxdagi_validate_nodes(d, m, err);
    return st == VOXDAG_OK ? voxdagi_validate_box(d, m, err) : st;
}

static voxdag_status voxdagi_new_dag(voxdagi_mem *m, voxdag **out) {
    *out = (voxdag *)voxdagi_alloc(m, sizeof **out);
    if (!*out) return VOXDAG_ERR_OUT_OF_MEMORY;
    memset(*out, 0, sizeof **out);
    (*out)->alloc = m->a;
    return VOXDAG_OK;
}

/* Copies OPTS (NULL: defaults) to O and checks what every loader needs. */
static voxdag_status voxdagi_load_opts(const voxdag_load_opts *opts, voxdag_load_opts *o,
                                       voxdag_error *err) {
    memset(o, 0, sizeof *o);
    if (opts) *o = *opts;
    if (o->zero_begin || o->zero_end)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "load options not zero-initialized");
    if ((o->allocator.alloc == NULL) != (o->allocator.free == NULL))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "allocator needs both alloc and free");
    return VOXDAG_OK;
}

VOXDAG_API voxdag_status voxdag_load_memory(const void *data, size_t size,
                                            const voxdag_load_opts *opts, voxdag **out,
                                            voxdag_error *err) {
    voxdag_load_opts o;
    voxdagi_mem m;
    voxdag *d;
    voxdag_status st;
    if (!out || (!data && size)) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "data or out is NULL");
    *out = NULL;
    st = voxdagi_load_opts(opts, &o, err);
    if (st != VOXDAG_OK) return st;
    if (o.max_input_bytes && size > o.max_input_bytes)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, "input larger than max_input_bytes");
    if (!o.max_levels || o.max_levels > VOXDAG_MAX_LEVELS) o.max_levels = VOXDAG_MAX_LEVELS;
    voxdagi_mem_init(&m, &o.allocator, o.max_memory);
    st = voxdagi_new_dag(&m, &d);
    if (st != VOXDAG_OK) {
        voxdagi_mem_destroy(&m);
        return voxdagi_mem_fail(&m, err, st, "cannot allocate the DAG");
    }
    if (o.copy) {
        d->owned = (uint8_t *)voxdagi_alloc(&m, size);
        if (!d->owned) {
            voxdag_free(d);
            voxdagi_mem_destroy(&m);
            return voxdagi_mem_fail(&m, err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot copy the input");
        }
        d->owned_size = size;
        if (size) memcpy(d->owned, data, size);
        data = d->owned;
    }
    st = voxdagi_open(d, (const uint8_t *)data, size, o.skip_checksums ? 2 : 1, o.max_levels, o.max_nodes, &m, err);
    voxdagi_mem_destroy(&m);
    if (st != VOXDAG_OK) {
        voxdag_free(d);
        return st == VOXDAG_ERR_OUT_OF_MEMORY ? voxdagi_mem_fail(&m, err, st, err ? err->message : NULL) : st;
    }
    *out = d;
    return voxdagi_ok(err);
}

// -- Level-of-detail colours (FORMAT.md, LOD_COLORS): averaging and the slots

/* Adds the colours of voxels [A, A + N) to SUM (decodable colours, A + N <=
   the voxel count), 64 at a time. */
static void voxdagi_sum_colors(const voxdag *d, uint64_t a, uint64_t n, uint64_t sum[3]) {
    uint8_t buf[3 * 64];
    while (n) {
        size_t k = n < 64 ? (size_t)n : 64, i;
        const uint8_t *c = buf;
        if (d->color_kind == VOXDAG_COLORS_RGB8) c = d->color + 3 * a;
#ifdef VOXDAGI_VOXCOLOR
        else voxcolor_view_get_range(&d->color_view, a, k, buf);
#endif
        for (i = 0; i < 3 * k; i += 3) sum[0] += c[i], sum[1] += c[i + 1], sum[2] += c[i + 2];
        a += k, n -= k;
    }
}

/* SUM / N per channel, rounded to the nearest (N > 0). */
static void voxdagi_mean_rgb(const uint64_t sum[3], uint64_t n, uint8_t rgb[3]) {
    unsigned k;
    for (k = 0; k < 3; k++) rgb[k] = (uint8_t)((sum[k] + n / 2) / n);
}

/* Whether voxdagi_sum_colors can read D's colours. */
static int voxdagi_colors_readable(const voxdag *d) {
#ifdef VOXDAGI_VOXCOLOR
    return d->color_kind != VOXDAG_COLORS_NONE;
#else
    return d->color_kind == VOXDAG_COLORS_RGB8;
#endif
}

/* A cell of the level-of-detail walk: the node at byte AT of its level in
   the frame MI, holding voxels [A, A + N), and the sums of their colours. */
typedef struct voxdagi_lod_cell {
    uint64_t at, a, n, sum[3];
    unsigned mi;
} voxdagi_lod_cell;

/* The level-of-detail walk over the cell TOP (of level DEPTH): its cells in
   voxel order down to level L-3, whose cells sum their colour ranges, each
   finished cell adding its sums to its parent's and writing its slots to
   SLOTS (3 bytes each, level by level, PER_LEVEL a level): slot j of level q
   is the mean colour of the level-q cell holding voxel 64 j. Cells of level
   CUT (> DEPTH; 0: none) are not entered: with COLLECT they are appended to
   CELLS (*NCELLS of them) unsummed, and their parents get no slots; else
   CELLS holds them, summed, in this order. Returns TOP's sums in TOP. */
static void voxdagi_lod_walk(const voxdag *d, uint8_t *slots, uint64_t per_level, voxdagi_lod_cell *top,
                             uint32_t depth0, uint32_t cut, int collect, voxdagi_lod_cell *cells, size_t *ncells) {
    struct frame {
        uint64_t at, a, end, sum[3]; /* END: the first voxel after the children done */
        unsigned mi, next;
    } stack[VOXDAG_MAX_LEVELS];
    uint32_t leaf = d->levels - 3, depth = depth0;
    memset(stack, 0, sizeof stack);
    stack[depth].at = top->at;
    stack[depth].mi = top->mi;
    stack[depth].a = stack[depth].end = top->a;
    for (;;) {
        struct frame *f = &stack[depth];
        uint64_t j, first, last;
        uint8_t rgb[3];
        if (cut && depth == cut) {
            voxdagi_lod_cell *c = &cells[(*ncells)++];
            if (collect) {
                c->at = f->at, c->mi = f->mi, c->a = f->a;
                c->n = voxdagi_node_count(d, depth, f->at);
            } else
                memcpy(f->sum, c->sum, sizeof f->sum);
            f->end = f->a + c->n;
        } else if (depth == leaf) {
            uint64_t n = voxdagi_node_count(d, leaf, f->at);
            voxdagi_sum_colors(d, f->a, n, f->sum);
            f->end = f->a + n;
        } else {
            const uint8_t *rec = d->level[depth].data + f->at;
            unsigned header = voxdagi_le16(rec);
            unsigned occ = voxdagi_occupancy[f->mi][voxdagi_presence(header)];
            while (f->next < 8 && !(occ >> f->next & 1)) f->next++;
            if (f->next < 8) {
                unsigned w = f->next++;
                uint64_t ref = voxdagi_child_ref(d, depth, rec, header, voxdagi_cube_tables.act[f->mi][w], 1);
                struct frame *c = &stack[depth + 1];
                memset(c, 0, sizeof *c);
                c->at = ref >> 6;
                c->mi = voxdagi_cube_tables.comp[ref & 63][f->mi];
                c->a = c->end = f->end;
                depth++;
                continue;
            }
        }
        /* the cell [a, end) of level DEPTH is done: its slots, then its parent */
        if (!cut || (collect ? depth > cut : depth != cut)) { /* cells of CUT: their jobs write them */
            voxdagi_mean_rgb(f->sum, f->end - f->a, rgb);
            first = (f->a + 63) >> 6, last = (f->end + 63) >> 6;
            for (j = first; j < last; j++) memcpy(slots + 3 * ((uint64_t)depth * per_level + j), rgb, 3);
        }
        if (depth == depth0) break;
        stack[depth - 1].sum[0] += f->sum[0], stack[depth - 1].sum[1] += f->sum[1];
        stack[depth - 1].sum[2] += f->sum[2];
        stack[depth - 1].end = f->end;
        depth--;
    }
    memcpy(top->sum, stack[depth0].sum, sizeof top->sum);
    top->n = stack[depth0].end - top->a;
}

/* A job of the level-of-detail means: the walks under cells [BEGIN, END). */
typedef struct voxdagi_lod_job {
    const voxdag *d;
    uint8_t *slots;
    uint64_t per_level;
    voxdagi_lod_cell *cells;
    size_t begin, end;
    uint32_t cut;
} voxdagi_lod_job;

static void *voxdagi_lod_run(void *arg) {
    voxdagi_lod_job *j = (voxdagi_lod_job *)arg;
    size_t i;
    for (i = j->begin; i < j->end; i++) voxdagi_lod_walk(j->d, j->slots, j->per_level, &j->cells[i], j->cut, 0, 0, NULL, NULL);
    return NULL;
}

/* Most jobs of the level-of-detail means. */
#define VOXDAGI_LOD_JOBS (4 * VOXDAGI_MAX_THREADS)

/* The level-of-detail slots of D (FORMAT.md, LOD_COLORS) for levels 0..L-3,
   to SLOTS (see voxdagi_lod_walk), on team T: one walk collects the cells of
   a level a few below the root, jobs of about equal voxel counts sum them
   and write their slots, and a last walk over the levels above them. The
   sums are integers, so the slots are the same whatever the threads. Returns
   0 when out of memory (from M). */
static int voxdagi_lod_means(const voxdag *d, uint8_t *slots, uint64_t per_level, voxdagi_team *t, voxdagi_mem *m) {
    voxdagi_lod_job job[VOXDAGI_LOD_JOBS];
    voxdagi_lod_cell root, *cells;
    uint32_t leaf = d->levels - 3, cut = leaf > 5 ? 5 : leaf ? leaf - 1 : 0; /* up to 8^5 cells */
    size_t ncells = 0, cap, i, jobs = 0;
    uint64_t per, load = 0;
    memset(&root, 0, sizeof root);
    root.mi = voxdagi_cube_tables.inv[d->root_transform];
    if (cut == 0 || t->threads < 2) {
        voxdagi_lod_walk(d, slots, per_level, &root, 0, 0, 0, NULL, NULL);
        return 1;
    }
    cap = (size_t)1 << (3 * cut);
    if (cap > d->voxels) cap = (size_t)d->voxels; /* each cell holds a voxel */
    cells = (voxdagi_lod_cell *)voxdagi_alloc(m, cap * sizeof *cells);
    if (!cells) return 0;
    voxdagi_lod_walk(d, slots, per_level, &root, 0, cut, 1, cells, &ncells);
    per = d->voxels / (VOXDAGI_LOD_JOBS < 8 * t->threads ? VOXDAGI_LOD_JOBS : 8 * t->threads) + 1;
    for (i = 0; i < ncells; i++) { /* runs of cells with about PER voxels */
        if (!jobs || (load >= per && jobs < VOXDAGI_LOD_JOBS)) {
            memset(&job[jobs], 0, sizeof job[jobs]);
            job[jobs].d = d, job[jobs].slots = slots, job[jobs].per_level = per_level;
            job[jobs].cells = cells, job[jobs].begin = i, job[jobs].cut = cut;
            jobs++, load = 0;
        }
        job[jobs - 1].end = i + 1;
        load += cells[i].n;
    }
    voxdagi_run_parallel(t, voxdagi_lod_run, job, sizeof job[0], (unsigned)jobs);
    ncells = 0;
    voxdagi_lod_walk(d, slots, per_level, &root, 0, cut, 0, cells, &ncells);
    voxdagi_free(m, cells, cap * sizeof *cells);
    return 1;
}

/* The level-of-detail colour section for D's colours (levels 0..L-3), in
   *OUT (allocated from M, *OUT_SIZE bytes), or *OUT = NULL when D gets none
   (no readable colours, L = 2 or at most 64 voxels). Returns 0 when out of
   memory or the voxcolor encoder fails. */
static int voxdagi_lod_section(const voxdag *d, voxdagi_mem *m, voxdagi_team *t, uint8_t **out, size_t *out_size) {
    uint64_t per_level, total;
    size_t cap;
    uint8_t *slots, *sec;
    *out = NULL, *out_size = 0;
    if (!voxdagi_colors_readable(d) || d->levels < 3 || d->voxels <= 64) return 1;
    per_level = (d->voxels + 63) >> 6;
    total = per_level * (d->levels - 2);
    if (total > ((size_t)-1 - VOXDAG_FILE_LOD_HEADER_SIZE) / 4) return 0;
    slots = (uint8_t *)voxdagi_alloc(m, (size_t)(3 * total));
    if (!slots) return 0;
    if (!voxdagi_lod_means(d, slots, per_level, t, m)) {
        voxdagi_free(m, slots, (size_t)(3 * total));
        return 0;
    }
    cap = VOXDAG_FILE_LOD_HEADER_SIZE + (size_t)(3 * total);
#ifdef VOXDAGI_VOXCOLOR
    if (d->color_kind == VOXDAG_COLORS_VOXCOLOR) {
        size_t bound = voxcolor_encode_bound((size_t)total);
        if (!bound || bound > (size_t)-1 - VOXDAG_FILE_LOD_HEADER_SIZE) cap = 0;
        else cap = VOXDAG_FILE_LOD_HEADER_SIZE + bound;
    }
#endif
    sec = cap ? (uint8_t *)voxdagi_alloc(m, cap) : NULL;
    if (!sec) {
        voxdagi_free(m, slots, (size_t)(3 * total));
        return 0;
    }
    memset(sec, 0, VOXDAG_FILE_LOD_HEADER_SIZE);
    sec[VOXDAG_FILE_LOD_OFF_KIND] = (uint8_t)d->color_kind;
    sec[VOXDAG_FILE_LOD_OFF_SLOT_SHIFT] = VOXDAG_FILE_LOD_SLOT_SHIFT;
    sec[VOXDAG_FILE_LOD_OFF_FIRST_LEVEL] = 0;
    sec[VOXDAG_FILE_LOD_OFF_LEVEL_COUNT] = (uint8_t)(d->levels - 2);
    voxdagi_put_le(sec + VOXDAG_FILE_LOD_OFF_SLOTS, per_level, 8);
    *out_size = cap;
    if (d->color_kind == VOXDAG_COLORS_RGB8) memcpy(sec + VOXDAG_FILE_LOD_HEADER_SIZE, slots, (size_t)(3 * total));
#ifdef VOXDAGI_VOXCOLOR
    else {
        /* 0.016 + the RGB8 rounding of the means (sqrt(3) * 0.5 / 255) < 0.02 */
        voxcolor_encode_opts vo;
        size_t len;
        memset(&vo, 0, sizeof vo);
        vo.max_error = 0.016;
        vo.threads = t->threads; /* the same bytes whatever the count */
        vo.thread_pool.run = voxdagi_team_voxcolor_run;
        vo.thread_pool.user = t;
        len = voxcolor_encode(sec + VOXDAG_FILE_LOD_HEADER_SIZE, cap - VOXDAG_FILE_LOD_HEADER_SIZE, slots,
                              (size_t)total, &vo, NULL);
        *out_size = VOXDAG_FILE_LOD_HEADER_SIZE + len;
        if (!len) {
            voxdagi_free(m, sec, cap);
            sec = NULL;
        }
    }
#endif
    voxdagi_free(m, slots, (size_t)(3 * total));
    if (!sec) return 0;
    /* the section keeps only what it uses; the rest of the encoder's bound goes back */
    if (*out_size < cap) {
        uint8_t *fit = (uint8_t *)voxdagi_alloc(m, *out_size);
        if (fit) {
            memcpy(fit, sec, *out_size);
            voxdagi_free(m, sec, cap);
            sec = fit;
        } else {
            voxdagi_free(m, sec, cap);
            return 0;
        }
    }
    *out = sec;
    return 1;
}

/* Frees D's parts through M (which allocated them). */
static void voxdagi_dag_release(voxdagi_mem *m, voxdag *d) {
    voxdagi_free(m, d->owned, d->owned_size);
    voxdagi_free(m, d->level, d->level_count * sizeof *d->level);
    voxdagi_free(m, d, sizeof *d);
}

/* The header's scene fields of D, for an image rewritten from it. */
static void voxdagi_scene_of(const voxdag *d, voxdagi_scene *sc) {
    sc->levels = d->levels;
    sc->root_transform = d->root_transform;
    sc->symmetry = d->symmetry;
    sc->voxels = d->voxels;
    memcpy(sc->voxel_box, d->voxel_box, sizeof sc->voxel_box);
}

/* Replaces *PD (an image D owns, allocated from M, opened) by a copy with
   its level-of-detail colour section, placed after the colour section (an
   old one is dropped), when its colours get one; *PD is kept otherwise.
   Returns VOXDAG_OK or VOXDAG_ERR_OUT_OF_MEMORY (*PD is then unchanged). */
static voxdag_status voxdagi_attach_lod(voxdag **pd, voxdagi_mem *m, voxdagi_team *t, voxdag_error *err) {
    voxdag *d = *pd, *n = NULL;
    voxdagi_layout lay;
    const uint8_t *from[VOXDAG_FILE_MAX_SECTIONS];
    uint8_t *sec, *img;
    size_t sec_size;
    uint32_t count, k;
    voxdagi_scene sc;
    voxdag_status st;
    if (!voxdagi_lod_section(d, m, t, &sec, &sec_size))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot make the level-of-detail colours");
    if (!sec) return VOXDAG_OK;
    memset(&lay, 0, sizeof lay);
    count = (uint32_t)voxdagi_le(d->image + VOXDAG_FILE_OFF_SECTION_COUNT, 4);
    for (k = 0; k < count && lay.count + 1 < VOXDAG_FILE_MAX_SECTIONS; k++) {
        const uint8_t *e = d->image + VOXDAG_FILE_HEADER_SIZE + k * VOXDAG_FILE_SECTION_ENTRY_SIZE;
        uint32_t type = (uint32_t)voxdagi_le(e, 4);
        if (type == VOXDAG_SECTION_LOD_COLORS) continue;
        from[lay.count] = d->image + voxdagi_le(e + 8, 8);
        voxdagi_layout_add(&lay, type, (uint32_t)voxdagi_le(e + 4, 4), voxdagi_le(e + 16, 8));
        if (type == VOXDAG_SECTION_COLORS_RGB8 || type == VOXDAG_SECTION_COLORS_VOXCOLOR) {
            from[lay.count] = sec;
            voxdagi_layout_add(&lay, VOXDAG_SECTION_LOD_COLORS, VOXDAG_FILE_SECTION_OPTIONAL, sec_size);
        }
    }
    st = voxdagi_new_dag(m, &n);
    img = st != VOXDAG_OK || !voxdagi_layout_place(&lay) ? NULL : (uint8_t *)voxdagi_alloc(m, (size_t)lay.total);
    if (!img) {
        if (n) voxdagi_free(m, n, sizeof *n);
        voxdagi_free(m, sec, sec_size);
        return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot allocate the file image");
    }
    memset(img, 0, (size_t)lay.total);
    for (k = 0; k < lay.count; k++)
        if (lay.size[k]) memcpy(img + lay.offset[k], from[k], (size_t)lay.size[k]);
    voxdagi_free(m, sec, sec_size);
    voxdagi_scene_of(d, &sc);
    voxdagi_layout_seal(img, &lay, &sc);
    n->owned = img;
    n->owned_size = (size_t)lay.total;
    st = voxdagi_open(n, img, n->owned_size, 0, VOXDAG_MAX_LEVELS, 0, m, err);
    if (st != VOXDAG_OK) {
        voxdagi_dag_release(m, n);
        return st;
    }
    voxdagi_dag_release(m, d);
    *pd = n;
    return VOXDAG_OK;
}

// -- Finishing a build: encode into a file image

static void voxdagi_write_bounds(uint8_t *p, const double *bounds) {
    unsigned k;
    for (k = 0; k < 6; k++) {
        uint64_t bits;
        memcpy(&bits, &bounds[k], 8);
        voxdagi_put_le(p + 8 * k, bits, 8);
    }
}

#ifndef VOXDAG_NO_BUILD /* the rest of this section */

/* Transforms the box B (min xyz, max xyz, half-open) of a cube of side SIDE
   by T: axis a moves to axis perm[a], then mirrored axes flip. */
static void voxdagi_box_transform(const voxdagi_cube *c, uint32_t b[6], unsigned tf, uint32_t side) {
    uint32_t t[6];
    unsigned a;
    for (a = 0; a < 3; a++) {
        unsigned to = (unsigned)voxdagi_popcount64(c->act[tf & ~7u][1u << a] - 1u); /* perm[a] */
        t[to] = b[a], t[to + 3] = b[a + 3];
    }
    for (a = 0; a < 3; a++) {
        if (tf >> a & 1) b[a] = side - t[a + 3], b[a + 3] = side - t[a];
        else b[a] = t[a], b[a + 3] = t[a + 3];
    }
}

/* A job of voxdagi_voxel_box: the boxes CUR of the nodes [BEGIN, END) of
   level L, from the boxes BELOW of the next level. */
typedef struct voxdagi_box_job {
    const voxdagi_reducer *r;
    const voxdagi_cube *c;
    const uint32_t *below;
    uint32_t *cur, l;
    size_t begin, end;
} voxdagi_box_job;

static void *voxdagi_box_run(void *arg) {
    const voxdagi_box_job *j = (const voxdagi_box_job *)arg;
    const voxdagi_store *s = &j->r->store[j->l];
    uint32_t half = 1u << (j->r->levels - j->l - 1), cb[6];
    size_t i, k;
    for (i = j->begin; i < j->end; i++) {
        uint32_t *o = j->cur + 6 * i;
        o[0] = o[1] = o[2] = UINT32_MAX;
        o[3] = o[4] = o[5] = 0;
        if (j->l == j->r->levels - 2) {
            voxdagi_brick_box(s->node[i].key, o);
            continue;
        }
        for (k = 0; k < 8; k++) { /* each child's box, transformed and moved to its octant */
            uint32_t x = s->child[8 * i + k];
            unsigned a;
            if (x == VOXDAGI_NONE) continue;
            memcpy(cb, j->below + 6 * (size_t)(x >> 6), sizeof cb);
            voxdagi_box_transform(j->c, cb, x & 63, half);
            for (a = 0; a < 3; a++) {
                if (k >> a & 1) cb[a] += half, cb[a + 3] += half;
                if (cb[a] < o[a]) o[a] = cb[a];
                if (cb[a + 3] > o[a + 3]) o[a + 3] = cb[a + 3];
            }
        }
    }
    return NULL;
}

/* The occupied voxel box of the scene, bottom-up over the unique nodes (each
   box in its node's canonical frame), a level's nodes split over team T.
   Returns 0 when out of memory. */
static int voxdagi_voxel_box(voxdagi_mem *m, voxdagi_team *t, const voxdagi_reducer *r, const voxdagi_cube *c,
                             uint32_t box[6]) {
    voxdagi_box_job job[VOXDAGI_ENCODE_JOBS];
    uint32_t brick_level = r->levels - 2, l, *below = NULL, *cur = NULL;
    size_t below_n = 0, k;
    memset(box, 0, 6 * sizeof *box);
    if (r->root == VOXDAGI_NONE) return 1;
    for (l = brick_level + 1; l-- > 0;) {
        const voxdagi_store *s = &r->store[l];
        unsigned jobs = t->threads < 2 || s->n < 4096 ? 1 : 4 * t->threads;
        if (jobs > VOXDAGI_ENCODE_JOBS) jobs = VOXDAGI_ENCODE_JOBS;
        cur = (uint32_t *)voxdagi_alloc(m, 6 * s->n * sizeof *cur);
        if (!cur) {
            voxdagi_free(m, below, 6 * below_n * sizeof *below);
            return 0;
        }
        for (k = 0; k < jobs; k++) {
            job[k].r = r, job[k].c = c, job[k].below = below, job[k].cur = cur, job[k].l = l;
            job[k].begin = s->n * k / jobs, job[k].end = s->n * (k + 1) / jobs;
        }
        voxdagi_run_parallel(t, voxdagi_box_run, job, sizeof job[0], jobs);
        voxdagi_free(m, below, 6 * below_n * sizeof *below);
        below = cur, below_n = s->n;
    }
    memcpy(box, below + 6 * (size_t)(r->root >> 6), 6 * sizeof *box);
    voxdagi_box_transform(c, box, r->root & 63, 1u << r->levels);
    voxdagi_free(m, below, 6 * below_n * sizeof *below);
    return 1;
}

static voxdag_status voxdagi_builder_encode(voxdag_builder *b, voxdag **out, voxdag_error *err) {
    const voxdagi_reducer *r = &b->red[0];
    voxdagi_encoder e;
    voxdagi_layout lay;
    voxdagi_scene sc;
    uint32_t brick_level = b->levels - 2, l;
    uint64_t node_bytes = 0;
    uint8_t *img;
    voxdag *d;
    voxdag_status st;
    memset(&e, 0, sizeof e);
    e.mem = &b->mem;
    e.team = &b->team;
    e.r = r;
    e.group = &b->group[0];
    e.levels = b->levels;
    for (l = 0; l < brick_level; l++) { /* what an empty scene's level table says */
        unsigned t;
        for (t = 1; t <= 3; t++) e.cls[l].target_bits[t] = (unsigned char)(8 * t);
        e.cls[l].classes = 3;
        e.count_bits[l] = l + 1 < brick_level;
        e.table_len[l] = 1;
    }
    if (r->root != VOXDAGI_NONE && !voxdagi_encoder_plan(&e)) {
        voxdagi_encoder_free(&e);
        return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory while encoding");
    }
    memset(&sc, 0, sizeof sc);
    sc.levels = b->levels;
    sc.root_transform = e.root_transform;
    sc.symmetry = b->symmetry;
    sc.voxels = b->voxels;
    if (!voxdagi_voxel_box(&b->mem, &b->team, r, &voxdagi_cube_tables, sc.voxel_box)) {
        voxdagi_encoder_free(&e);
        return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory while encoding");
    }
    for (l = 0; l < brick_level; l++) node_bytes += e.size[l];
    memset(&lay, 0, sizeof lay);
    voxdagi_layout_add(&lay, VOXDAG_SECTION_LEVELS, 0, (uint64_t)brick_level * VOXDAG_FILE_LEVEL_ENTRY_SIZE);
    voxdagi_layout_add(&lay, VOXDAG_SECTION_NODES, 0, node_bytes + VOXDAG_FILE_NODE_PADDING);
    voxdagi_layout_add(&lay, VOXDAG_SECTION_BRICKS, 0, 8 * (uint64_t)r->store[brick_level].n);
    if (b->opts.colors && !b->opts.color_sink) voxdagi_layout_add(&lay, VOXDAG_SECTION_COLORS_RGB8, 0, 3 * b->voxels);
    if (b->has_bounds) voxdagi_layout_add(&lay, VOXDAG_SECTION_BOUNDS, 0, 48);
    st = voxdagi_new_dag(&b->mem, &d);
    img = !voxdagi_layout_place(&lay) || st != VOXDAG_OK ? NULL
                                                        : (uint8_t *)voxdagi_alloc(&b->mem, (size_t)lay.total);
    if (!img) {
        voxdagi_encoder_free(&e);
        if (d) voxdag_free(d);
        return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot allocate the file image");
    }
    memset(img, 0, (size_t)lay.total);
    voxdagi_encoder_write(&e, voxdagi_layout_section(img, &lay, VOXDAG_SECTION_LEVELS),
                          voxdagi_layout_section(img, &lay, VOXDAG_SECTION_NODES),
                          voxdagi_layout_section(img, &lay, VOXDAG_SECTION_BRICKS));
    voxdagi_encoder_free(&e);
    if (b->opts.colors && !b->opts.color_sink && b->voxels)
        memcpy(voxdagi_layout_section(img, &lay, VOXDAG_SECTION_COLORS_RGB8), b->colors, 3 * (size_t)b->voxels);
    if (b->has_bounds) voxdagi_write_bounds(voxdagi_layout_section(img, &lay, VOXDAG_SECTION_BOUNDS), b->bounds);
    voxdagi_layout_seal(img, &lay, &sc);
    d->owned = img;
    d->owned_size = (size_t)lay.total;
    st = voxdagi_open(d, img, d->owned_size, 0, VOXDAG_MAX_LEVELS, 0, &b->mem, err);
    if (st == VOXDAG_OK && !b->opts.no_lod_colors) st = voxdagi_attach_lod(&d, &b->mem, &b->team, err);
    if (st != VOXDAG_OK) {
        voxdag_free(d);
        return st;
    }
    *out = d;
    return VOXDAG_OK;
}

VOXDAG_API voxdag_status voxdag_builder_finish(voxdag_builder *b, voxdag **out,
                                               voxdag_build_stats *stats, voxdag_error *err) {
    voxdag_status st;
    unsigned k;
    uint32_t l;
    if (!b || !out) {
        voxdag_builder_free(b);
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "builder or out is NULL");
    }
    *out = NULL;
    st = b->failed ? b->failed : voxdagi_builder_reduce(b, 1);
    if (st == VOXDAG_OK) st = voxdagi_builder_send_colors(b, (size_t)(b->voxels - b->colors_base), 0);
    if (st != VOXDAG_OK) {
        st = voxdagi_mem_fail(&b->mem, err, st, voxdagi_reduce_message(st));
        voxdag_builder_free(b);
        return st;
    }
    if ((st = voxdagi_progress(b, "reduce", 1.0)) != VOXDAG_OK) {
        st = VOXDAGI_FAIL(err, st, voxdagi_reduce_message(st));
        voxdag_builder_free(b);
        return st;
    }
    for (k = 0; k < b->red_count; k++) {
        voxdagi_reducer_finish(&b->red[k]);
        if (b->red[k].failed) {
            st = voxdagi_mem_fail(&b->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory while reducing voxels");
            voxdag_builder_free(b);
            return st;
        }
    }
    if (b->opts.max_nodes && voxdagi_builder_nodes(b) > b->opts.max_nodes) {
        voxdag_builder_free(b);
        return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, voxdagi_reduce_message(VOXDAG_ERR_LIMIT));
    }
    if (stats) {
        memset(stats, 0, sizeof *stats);
        stats->levels = b->levels;
        stats->voxels = b->voxels;
        for (l = 0; l + 1 < b->levels; l++) {
            stats->nodes[l] = b->red[0].store[l].n;
            stats->svo_nodes[l] = b->red[0].store[l].svo;
            for (k = 0; k < b->red_count; k++) {
                uint64_t n = b->red[k].store[l].n;
                switch (b->red[k].group->count) {
                case 1: stats->svdag_nodes[l] = n; break;
                case 8: stats->reflect_nodes[l] = n; break;
                default: stats->full_nodes[l] = n; break;
                }
            }
        }
    }
    /* The colour buffer is not needed past the encoder's copy; the pending
       buffer is empty now. */
    voxdagi_free(&b->mem, b->pend_code, b->pend_cap * sizeof *b->pend_code);
    voxdagi_free(&b->mem, b->pend_rgb, b->opts.colors ? b->pend_cap * sizeof *b->pend_rgb : 0);
    b->pend_code = NULL;
    b->pend_rgb = NULL;
    b->pend_cap = 0;
    if ((st = voxdagi_progress(b, "encode", 0.0)) != VOXDAG_OK) {
        st = VOXDAGI_FAIL(err, st, voxdagi_reduce_message(st));
        voxdag_builder_free(b);
        return st;
    }
    st = voxdagi_builder_encode(b, out, err);
    if (stats) stats->peak_memory = b->mem.peak;
    /* The DAG's memory came from the builder's allocator; keep it out of the
       builder's accounting so freeing the builder balances. */
    if (*out) b->mem.used -= sizeof(voxdag) + (*out)->owned_size;
    if (st == VOXDAG_OK && (st = voxdagi_progress(b, "encode", 1.0)) != VOXDAG_OK) {
        voxdag_free(*out);
        *out = NULL;
        st = VOXDAGI_FAIL(err, st, voxdagi_reduce_message(st));
    }
    if (st == VOXDAG_ERR_OUT_OF_MEMORY) st = voxdagi_mem_fail(&b->mem, err, st, err ? err->message : NULL);
    voxdag_builder_free(b);
    if (st == VOXDAG_OK) voxdagi_ok(err);
    return st;
}

#endif /* VOXDAG_NO_BUILD */

// -- Colours

VOXDAG_API voxdag_color_kind voxdag_colors(const voxdag *dag, const void **payload, size_t *size) {
    if (payload) *payload = dag ? dag->color : NULL;
    if (size) *size = dag ? (size_t)dag->color_size : 0;
    return dag ? dag->color_kind : VOXDAG_COLORS_NONE;
}

VOXDAG_API int voxdag_color(const voxdag *dag, uint64_t index, uint8_t rgb[3]) {
    if (!dag || !rgb || index >= dag->voxels) return 0;
    if (dag->color_kind == VOXDAG_COLORS_RGB8) {
        memcpy(rgb, dag->color + 3 * index, 3);
        return 1;
    }
#ifdef VOXDAGI_VOXCOLOR
    if (dag->color_kind == VOXDAG_COLORS_VOXCOLOR) { /* count = voxels: checked by voxdagi_open_colors */
        voxcolor_view_get(&dag->color_view, index, rgb);
        return 1;
    }
#else
    if (dag->color_kind == VOXDAG_COLORS_VOXCOLOR) { /* no decoder here: loud, see the declaration */
        rgb[0] = 255, rgb[1] = 0, rgb[2] = 255;
        return -1;
    }
#endif
    return 0;
}

VOXDAG_API voxdag_status voxdag_with_colors(const voxdag *src, voxdag_color_kind kind,
                                            const void *payload, size_t size, voxdag **out,
                                            voxdag_error *err) {
    return voxdag_with_colors_opts(src, kind, payload, size, NULL, out, err);
}

VOXDAG_API voxdag_status voxdag_with_colors_opts(const voxdag *src, voxdag_color_kind kind,
                                                 const void *payload, size_t size,
                                                 const voxdag_build_opts *opts, voxdag **out,
                                                 voxdag_error *err) {
    static const uint32_t copied[] = {VOXDAG_SECTION_LEVELS, VOXDAG_SECTION_NODES, VOXDAG_SECTION_BRICKS};
    voxdagi_layout lay;
    voxdagi_mem m;
    voxdag *d;
    uint8_t *img;
    const uint8_t *parts[3];
    uint64_t sizes[3];
    voxdag_status st;
    unsigned i;
    if (!src || !out || (size && !payload) || kind > VOXDAG_COLORS_VOXCOLOR)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "bad argument");
    *out = NULL;
    if (opts && (opts->zero_begin || opts->zero_end))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "build options not zero-initialized");
    if (opts && (opts->thread_pool.run == NULL) != (opts->thread_pool.wait == NULL))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "thread_pool needs both run and wait");
    if (kind == VOXDAG_COLORS_RGB8 && (src->voxels > UINT64_MAX / 3 || size != 3 * src->voxels))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "RGB8 colours need 3 bytes per voxel");
    parts[0] = src->image + VOXDAG_FILE_HEADER_SIZE; /* placeholder, replaced below */
    sizes[0] = (uint64_t)(src->levels - 2) * VOXDAG_FILE_LEVEL_ENTRY_SIZE;
    parts[1] = src->level_count ? src->level[0].data : NULL; /* no inner levels when L = 2 */
    sizes[1] = src->node_bytes + VOXDAG_FILE_NODE_PADDING;
    parts[2] = src->bricks;
    sizes[2] = 8 * src->brick_count;
    {   /* the level table and node section start where the source's do */
        uint32_t k, count = (uint32_t)voxdagi_le(src->image + VOXDAG_FILE_OFF_SECTION_COUNT, 4);
        for (k = 0; k < count; k++) {
            const uint8_t *e = src->image + VOXDAG_FILE_HEADER_SIZE + k * VOXDAG_FILE_SECTION_ENTRY_SIZE;
            uint32_t type = (uint32_t)voxdagi_le(e, 4);
            if (type == VOXDAG_SECTION_LEVELS) parts[0] = src->image + voxdagi_le(e + 8, 8);
            if (type == VOXDAG_SECTION_NODES) parts[1] = src->image + voxdagi_le(e + 8, 8);
        }
    }
    memset(&lay, 0, sizeof lay);
    for (i = 0; i < 3; i++) voxdagi_layout_add(&lay, copied[i], 0, sizes[i]);
    if (kind != VOXDAG_COLORS_NONE)
        voxdagi_layout_add(&lay, kind == VOXDAG_COLORS_RGB8 ? VOXDAG_SECTION_COLORS_RGB8 : VOXDAG_SECTION_COLORS_VOXCOLOR,
                           0, size);
    if (src->has_bounds) voxdagi_layout_add(&lay, VOXDAG_SECTION_BOUNDS, 0, 48);
    voxdagi_mem_init(&m, &src->alloc, 0);
    st = voxdagi_new_dag(&m, &d);
    img = st != VOXDAG_OK || !voxdagi_layout_place(&lay) ? NULL : (uint8_t *)voxdagi_alloc(&m, (size_t)lay.total);
    if (!img) {
        if (d) voxdag_free(d);
        voxdagi_mem_destroy(&m);
        return VOXDAGI_FAIL(err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot allocate the file image");
    }
    memset(img, 0, (size_t)lay.total);
    for (i = 0; i < 3; i++)
        if (sizes[i]) memcpy(img + lay.offset[i], parts[i], (size_t)sizes[i]);
    if (kind != VOXDAG_COLORS_NONE && size) memcpy(img + lay.offset[3], payload, size);
    if (src->has_bounds) voxdagi_write_bounds(voxdagi_layout_section(img, &lay, VOXDAG_SECTION_BOUNDS), src->bounds);
    {
        voxdagi_scene sc;
        voxdagi_scene_of(src, &sc);
        voxdagi_layout_seal(img, &lay, &sc);
    }
    d->owned = img;
    d->owned_size = (size_t)lay.total;
    st = voxdagi_open(d, img, d->owned_size, 0, VOXDAG_MAX_LEVELS, 0, &m, err);
    if (st == VOXDAG_OK && kind != VOXDAG_COLORS_NONE && !(opts && opts->no_lod_colors)) {
        voxdagi_team team;
        voxdagi_team_init(&team, &m, opts ? opts->threads : 1, opts ? &opts->thread_pool : NULL);
        st = voxdagi_attach_lod(&d, &m, &team, err);
        voxdagi_team_stop(&team);
    }
    voxdagi_mem_destroy(&m);
    if (st != VOXDAG_OK) {
        voxdag_free(d);
        return st;
    }
    *out = d;
    return voxdagi_ok(err);
}

// -- Queries

VOXDAG_API void voxdag_get_info(const voxdag *dag, voxdag_info *info) {
    uint32_t l, brick_level;
    if (!info) return;
    memset(info, 0, sizeof *info); /* all zero for a NULL DAG */
    if (!dag) return;
    brick_level = dag->levels - 2;
    info->levels = dag->levels;
    info->symmetry = dag->symmetry;
    info->voxels = dag->voxels;
    memcpy(info->voxel_box, dag->voxel_box, sizeof info->voxel_box);
    for (l = 0; l < brick_level; l++) {
        info->nodes[l] = dag->level[l].nodes;
        info->level_bytes[l] = dag->level[l].size;
    }
    info->nodes[brick_level] = dag->brick_count;
    info->level_bytes[brick_level] = 8 * dag->brick_count;
    info->file_bytes = dag->image_size;
    info->node_bytes = dag->node_bytes;
    info->brick_bytes = 8 * dag->brick_count;
    info->color_bytes = dag->color_size;
    info->color_kind = dag->color_kind;
#ifdef VOXDAGI_VOXCOLOR
    info->colors_decodable = dag->color_kind != VOXDAG_COLORS_NONE;
#else
    info->colors_decodable = dag->color_kind == VOXDAG_COLORS_RGB8;
#endif
    info->has_bounds = dag->has_bounds;
    memcpy(info->bounds, dag->bounds, sizeof info->bounds);
    info->lod_color_bytes = dag->lod_size;
}

/* Traversals carry MI, the transform from world to stored frame (the inverse
   of the transforms accumulated from the root): world octant w of a node is
   its stored octant MI(w), world brick position p is stored position MI(p),
   and a child reached through a pointer with transform t has MI' = t^-1 o MI.
   The voxel index (counts of the preceding siblings in world order) adds the
   stored children j with MI^-1(j) < w, and in a brick the voxels of the mask
   transformed to world order below the voxel. *CHILD (when not NULL and
   world octant w holds a child): that child, as voxdagi_child_ref with
   INVERSE, found in the same pass. */
static uint64_t voxdagi_preceding(const voxdag *d, uint32_t l, const uint8_t *rec, unsigned header, unsigned mi,
                                  unsigned w, uint64_t *child) {
    const uint8_t *to_world = voxdagi_cube_tables.act[voxdagi_cube_tables.inv[mi]];
    unsigned present = voxdagi_presence(header), set = 0, j, v = voxdagi_cube_tables.act[mi][w];
    uint64_t idx = 0, ref[8];
    for (j = 0; j < 8; j++)
        if (to_world[j] < w) set |= 1u << j;
    set &= present;
    if (child && (present >> v & 1)) set |= 1u << v;
    voxdagi_child_refs(d, l, rec, header, set, ref);
    for (j = 0; j < 8; j++)
        if ((set >> j & 1) && j != v) idx += voxdagi_node_count(d, l + 1, ref[j] >> 6);
    if (child && (present >> v & 1)) *child = ref[v];
    return idx;
}

VOXDAG_API int voxdag_lookup(const voxdag *dag, uint32_t x, uint32_t y, uint32_t z, uint64_t *index) {
    uint32_t nlevels, brick_level, l;
    unsigned mi, p;
    uint64_t at = 0, idx = 0, mask;
    if (!dag || !dag->voxels || (x | y | z) >> dag->levels) return 0;
    nlevels = dag->levels, brick_level = nlevels - 2, mi = voxdagi_cube_tables.inv[dag->root_transform];
    for (l = 0; l < brick_level; l++) {
        const voxdagi_level *lv = &dag->level[l];
        const uint8_t *rec = lv->data + at;
        unsigned header = voxdagi_le16(rec), sh = nlevels - 1 - l, v;
        unsigned w = (x >> sh & 1) | (y >> sh & 1) << 1 | (z >> sh & 1) << 2;
        uint64_t ref = 0; /* set by either call: the child is present */
        v = voxdagi_cube_tables.act[mi][w];
        if (!(header >> (2 * v) & 3)) return 0;
        if (index) idx += voxdagi_preceding(dag, l, rec, header, mi, w, &ref);
        else ref = voxdagi_child_ref(dag, l, rec, header, v, 1);
        mi = voxdagi_cube_tables.comp[ref & 63][mi];
        at = ref >> 6;
    }
    mask = voxdagi_brick_to_world(voxdagi_brick(dag, at), mi);
    p = (unsigned)(voxdag_morton_encode(x & 3, y & 3, z & 3));
    if (!(mask >> p & 1)) return 0;
    if (index) *index = idx + (uint64_t)voxdagi_popcount64(mask & ((1ull << p) - 1));
    return 1;
}

/* Morton position inside a 4^3 brick of the voxel with coordinates C. */
VOXDAGI_INLINE unsigned voxdagi_brick_pos(const uint32_t c[3]) {
    return (c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2 | (c[0] & 2) << 2 | (c[1] & 2) << 3 |
           (c[2] & 2) << 4;
}

/* The cells of level Q holding points XYZ[0 .. COUNT): for each, its voxel
   count (into COUNT_OUT, or FULL as 0/1 when Q = L, each when not NULL) and
   first voxel index (into FIRST, when not NULL and the cell is not empty).
   Returns the sum of the counts. The path of the previous point is kept per
   node level (its node, the transform into it and the index of its first
   voxel); the next point starts at the deepest node both paths share: below
   the highest bit in which their coordinates differ, and no deeper than the
   previous point got. */
static uint64_t voxdagi_cells_many(const voxdag *dag, uint32_t q, const uint32_t *xyz, size_t count, uint8_t *full,
                                   uint64_t *count_out, uint64_t *first) {
    uint64_t at[VOXDAG_MAX_LEVELS], idx[VOXDAG_MAX_LEVELS], mask = 0, total = 0;
    unsigned mi[VOXDAG_MAX_LEVELS];
    uint32_t nlevels, brick_level, stop, reached = 1, prev[3] = {0, 0, 0}; /* reached: levels of the path known */
    int have_mask = 0; /* MASK: the brick at the end of the path, in world order */
    size_t i;
    if (!dag || !xyz || q > dag->levels) return 0;
    nlevels = dag->levels, brick_level = nlevels - 2, stop = q < brick_level ? q : brick_level;
    at[0] = 0, idx[0] = 0, mi[0] = voxdagi_cube_tables.inv[dag->root_transform];
    for (i = 0; i < count; i++) {
        uint32_t x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2], diff, l, shared;
        uint64_t n = 0, a;
        if (!dag->voxels || (x | y | z) >> nlevels) goto answer;
        diff = (x ^ prev[0]) | (y ^ prev[1]) | (z ^ prev[2]);
        shared = diff ? nlevels - voxdagi_bit_length(diff) : nlevels; /* levels choosing the same octant */
        l = shared < reached - 1 ? shared : reached - 1;
        prev[0] = x, prev[1] = y, prev[2] = z;
        if (l < brick_level) have_mask = 0;
        for (; l < stop; l++) {
            const uint8_t *rec = dag->level[l].data + at[l];
            unsigned header = voxdagi_le16(rec), sh = nlevels - 1 - l, w, v;
            uint64_t ref = 0, before = 0;
            w = (x >> sh & 1) | (y >> sh & 1) << 1 | (z >> sh & 1) << 2;
            v = voxdagi_cube_tables.act[mi[l]][w];
            reached = l + 1;
            if (!(header >> (2 * v) & 3)) goto answer;
            if (first) before = voxdagi_preceding(dag, l, rec, header, mi[l], w, &ref);
            else ref = voxdagi_child_ref(dag, l, rec, header, v, 1);
            mi[l + 1] = voxdagi_cube_tables.comp[ref & 63][mi[l]];
            at[l + 1] = ref >> 6;
            idx[l + 1] = idx[l] + before;
        }
        a = idx[stop], reached = stop + 1; /* the path now ends at level STOP's node */
        if (q < brick_level) {
            n = voxdagi_node_count(dag, q, at[q]);
        } else {
            unsigned low = 3 * (nlevels - q); /* Morton bits inside the cell: 6 (the brick), 3 or 0 */
            uint32_t in_brick[3];
            unsigned p;
            in_brick[0] = x, in_brick[1] = y, in_brick[2] = z;
            p = voxdagi_brick_pos(in_brick) >> low << low;
            uint64_t cell = low == 6 ? ~0ull : ((1ull << (1u << low)) - 1) << p; /* 8 bits or 1 from P */
            if (!have_mask) mask = voxdagi_brick_to_world(voxdagi_brick(dag, at[brick_level]), mi[brick_level]);
            have_mask = 1;
            n = (uint64_t)voxdagi_popcount64(mask & cell);
            a += (uint64_t)voxdagi_popcount64(mask & ((1ull << p) - 1));
        }
        if (n && first) first[i] = a;
    answer:
        total += n;
        if (count_out) count_out[i] = n;
        if (full) full[i] = (uint8_t)n;
    }
    return total;
}

VOXDAG_API uint64_t voxdag_lookup_many(const voxdag *dag, const uint32_t *xyz, size_t count, uint8_t *full,
                                       uint64_t *index) {
    return dag ? voxdagi_cells_many(dag, dag->levels, xyz, count, full, NULL, index) : 0;
}

VOXDAG_API uint64_t voxdag_cell_count_many(const voxdag *dag, uint32_t level, const uint32_t *xyz, size_t count,
                                           uint64_t *count_out, uint64_t *first) {
    return voxdagi_cells_many(dag, level, xyz, count, NULL, count_out, first);
}

VOXDAG_API uint64_t voxdag_cell_count(const voxdag *dag, uint32_t level, uint32_t x, uint32_t y, uint32_t z,
                                      uint64_t *first) {
    uint32_t p[3];
    uint64_t a = 0, n;
    p[0] = x, p[1] = y, p[2] = z;
    n = voxdagi_cells_many(dag, level, p, 1, NULL, NULL, first ? &a : NULL);
    if (n && first) *first = a;
    return n;
}

/* Depth-first walk in world Morton order with an explicit stack. */
VOXDAG_API uint64_t voxdag_for_each_voxel(const voxdag *dag, voxdag_voxel_fn fn, void *user) {
    struct frame {
        uint64_t at;
        uint32_t x, y, z;
        unsigned mi, next;
    } stack[VOXDAG_MAX_LEVELS];
    uint32_t nlevels, brick_level;
    uint64_t index = 0;
    int depth = 0;
    if (!dag || !dag->voxels) return 0;
    nlevels = dag->levels, brick_level = nlevels - 2;
    stack[0].at = 0;
    stack[0].x = stack[0].y = stack[0].z = 0;
    stack[0].mi = voxdagi_cube_tables.inv[dag->root_transform];
    stack[0].next = 0;
    while (depth >= 0) {
        struct frame *f = &stack[depth];
        if ((uint32_t)depth == brick_level) { /* a brick, in world order */
            uint64_t mask = voxdagi_brick_to_world(voxdagi_brick(dag, f->at), f->mi);
            while (mask) {
                unsigned p = voxdagi_lowest_bit(mask);
                uint32_t bx, by, bz;
                voxdag_morton_decode(p, &bx, &by, &bz);
                if (fn && fn(user, f->x + bx, f->y + by, f->z + bz, index)) return index + 1;
                index++;
                mask &= mask - 1;
            }
            depth--;
            continue;
        }
        {
            const voxdagi_level *lv = &dag->level[depth];
            const uint8_t *rec = lv->data + f->at;
            const uint8_t *to_stored = voxdagi_cube_tables.act[f->mi];
            unsigned header = voxdagi_le16(rec);
            uint32_t half = 1u << (nlevels - 1 - (uint32_t)depth);
            unsigned occ = voxdagi_occupancy[f->mi][voxdagi_presence(header)];
            while (f->next < 8 && !(occ >> f->next & 1)) f->next++;
            if (f->next == 8) {
                depth--;
                continue;
            }
            {
                unsigned w = f->next++;
                uint64_t ref = voxdagi_child_ref(dag, (uint32_t)depth, rec, header, to_stored[w], 1);
                struct frame *c = &stack[depth + 1];
                c->at = ref >> 6;
                c->mi = voxdagi_cube_tables.comp[ref & 63][f->mi];
                c->x = f->x + (w & 1 ? half : 0);
                c->y = f->y + (w & 2 ? half : 0);
                c->z = f->z + (w & 4 ? half : 0);
                c->next = 0;
                depth++;
            }
        }
    }
    return index;
}

// -- World space

/* The grid's world origin LO and a voxel's world size CELL per axis (world =
   LO + grid * CELL; the division by 2^L is exact). */
static void voxdagi_grid_map(const voxdag *d, double lo[3], double cell[3]) {
    unsigned k;
    for (k = 0; k < 3; k++) {
        lo[k] = d->has_bounds ? d->bounds[k] : 0;
        cell[k] = d->has_bounds ? (d->bounds[k + 3] - d->bounds[k]) / (double)(1u << d->levels) : 1;
    }
}

VOXDAG_API voxdag_status voxdag_world_to_grid(const voxdag *dag, const double world[3], double grid[3]) {
    double lo[3], cell[3];
    unsigned k;
    if (!dag || !world || !grid) return VOXDAG_ERR_INVALID_ARGUMENT;
    voxdagi_grid_map(dag, lo, cell);
    for (k = 0; k < 3; k++) grid[k] = (world[k] - lo[k]) / cell[k];
    return VOXDAG_OK;
}

VOXDAG_API voxdag_status voxdag_grid_to_world(const voxdag *dag, const double grid[3], double world[3]) {
    double lo[3], cell[3];
    unsigned k;
    if (!dag || !grid || !world) return VOXDAG_ERR_INVALID_ARGUMENT;
    voxdagi_grid_map(dag, lo, cell);
    for (k = 0; k < 3; k++) world[k] = lo[k] + grid[k] * cell[k];
    return VOXDAG_OK;
}

// -- Ray casting
#ifndef VOXDAG_NO_RAYTRACE
//
// A hierarchical integer DDA over the encoded DAG (SSVDAG Listing 1), in
// world space: cell w of a node reached with world-to-stored transform MI is
// its stored octant MI(w); entering a node maps its children's presence to
// world octants (one table lookup), entering a brick transforms its mask to
// world order, so the ray itself is never transformed and every t is exact.
// State: the current cell's integer coordinates c at cell level q (2^q cells
// per axis) and the event (te, ae) at which the ray entered it (ae = 3 for
// the start). Every t comes from a plane as (plane - origin) * (1 / dir), so
// a plane has one t at every level: coarse and fine steps agree bit for bit
// and ties follow the axis order. Entering a node picks the child cell from
// the mid planes the ray has crossed by (te, ae). After a step, the highest
// bit that changed in c names the ancestor whose child changed (a carry), so
// the walk jumps straight there, like the paper's conditional push but with
// no push: per node level it keeps only the record, header and transform to
// return to, which also give the voxel index at the hit in one pass.
// A brick is walked as 4^3 voxels in one level, or, when level of detail can
// stop inside it, as 2^3 cells (a byte of the mask each) and then voxels.

#include <float.h>
#include <math.h>

/* Exact doubles on x87 (32-bit x86 without SSE2 maths, FLT_EVAL_METHOD 2).
   x87 registers hold 64-bit mantissas and a wider exponent, so a t could be
   rounded twice or kept past the double range, and a ray could pick another
   voxel at a near-tie than on other processors. While tracing, the
   precision control is set to 53 bits (each operation then rounds as a
   double would, but for the exponent range), every product, quotient and
   difference is stored as a double (overflow then gives infinity), and the
   products and quotients that fall below DBL_MIN (where the store would
   round a second time) are rounded once in integer arithmetic. */
#if defined(FLT_EVAL_METHOD) && (FLT_EVAL_METHOD > 1 || FLT_EVAL_METHOD < 0)
#if (defined(__GNUC__) || defined(__clang__)) && defined(__i386__)
#define VOXDAGI_X87 1
#elif defined(_MSC_VER) && defined(_M_IX86)
#define VOXDAGI_X87 2
#else
#error "voxdag.h: exact ray casting needs double arithmetic without excess precision (FLT_EVAL_METHOD 0 or 1): compile with SSE2 maths (-msse2 -mfpmath=sse) or define VOXDAG_NO_RAYTRACE"
#endif
#elif defined(_MSC_VER) && defined(_M_IX86) && (!defined(_M_IX86_FP) || _M_IX86_FP < 2)
#define VOXDAGI_X87 2
#endif

#ifdef VOXDAGI_X87
static unsigned voxdagi_x87_begin(void) { /* returns the control word to restore */
#if VOXDAGI_X87 == 1
    unsigned short cw, pc53;
    __asm__ __volatile__("fnstcw %0" : "=m"(cw));
    pc53 = (unsigned short)((cw & ~0x300u) | 0x200u);
    __asm__ __volatile__("fldcw %0" : : "m"(pc53));
    return cw;
#else
    unsigned cw = _control87(0, 0);
    _control87(_PC_53, _MCW_PC);
    return cw;
#endif
}

static void voxdagi_x87_end(unsigned saved) {
#if VOXDAGI_X87 == 1
    unsigned short cw = (unsigned short)saved;
    __asm__ __volatile__("fldcw %0" : : "m"(cw));
#else
    _control87(saved, _MCW_PC);
#endif
}

/* Bits K.. of the 128-bit HI:LO, and whether any bit below K is set. */
static uint64_t voxdagi_shr128(uint64_t hi, uint64_t lo, int k) {
    return k == 0 ? lo : k < 64 ? lo >> k | hi << (64 - k) : k < 128 ? hi >> (k - 64) : 0;
}
static int voxdagi_below128(uint64_t hi, uint64_t lo, int k) {
    if (k <= 0) return 0;
    if (k < 64) return (lo & ((1ull << k) - 1)) != 0;
    return lo != 0 || (k > 64 && (hi & (k >= 128 ? ~0ull : (1ull << (k - 64)) - 1)) != 0);
}

/* The double with sign SIGN and magnitude M * 2^-1074 (M < 2^53). */
static double voxdagi_tiny(uint64_t sign, uint64_t m) {
    uint64_t u = sign | m;
    double r;
    memcpy(&r, &u, sizeof r);
    return r;
}

/* A * B rounded once (to nearest, ties to even) for finite nonzero A and B
   whose product is at most DBL_MIN in magnitude. */
static double voxdagi_mul_tiny(double a, double b) {
    uint64_t ua, ub, ma, mb, lo, m1, m2, hi, t, p0, p1, m;
    int ea, eb, s;
    memcpy(&ua, &a, sizeof ua);
    memcpy(&ub, &b, sizeof ub);
    ea = (int)(ua >> 52 & 0x7FF), eb = (int)(ub >> 52 & 0x7FF);
    ma = ua & 0xFFFFFFFFFFFFFull, mb = ub & 0xFFFFFFFFFFFFFull;
    if (ea) ma |= 1ull << 52; else ea = 1;
    if (eb) mb |= 1ull << 52; else eb = 1;
    /* |A B| = P 2^(ea + eb - 2150) = (P >> s) 2^-1074 */
    lo = (ma & 0xFFFFFFFFu) * (mb & 0xFFFFFFFFu), m1 = (ma >> 32) * (mb & 0xFFFFFFFFu);
    m2 = (ma & 0xFFFFFFFFu) * (mb >> 32), hi = (ma >> 32) * (mb >> 32);
    t = (lo >> 32) + (m1 & 0xFFFFFFFFu) + (m2 & 0xFFFFFFFFu);
    p0 = t << 32 | (lo & 0xFFFFFFFFu);
    p1 = hi + (m1 >> 32) + (m2 >> 32) + (t >> 32);
    s = 1076 - ea - eb;
    if (s <= 0) return a * b; /* a multiple of 2^-1074: exact */
    m = voxdagi_shr128(p1, p0, s);
    if (s <= 128 && (voxdagi_shr128(p1, p0, s - 1) & 1) && (voxdagi_below128(p1, p0, s - 1) || (m & 1))) m++;
    return voxdagi_tiny((ua ^ ub) & (1ull << 63), m);
}

/* 1 / D rounded once for finite D of magnitude at least 2^1022. */
static double voxdagi_recip_tiny(double d) {
    uint64_t u, md, q = 0, r = 0;
    int k, kr;
    memcpy(&u, &d, sizeof u);
    md = (u & 0xFFFFFFFFFFFFFull) | 1ull << 52;
    kr = 2149 - (int)(u >> 52 & 0x7FF); /* 1 / D = (2^K / md) 2^-1074 */
    for (k = kr; k >= 0; k--) { /* long division of 2^K */
        r = r << 1 | (k == kr);
        q <<= 1;
        if (r >= md) r -= md, q |= 1;
    }
    if (2 * r > md || (2 * r == md && (q & 1))) q++;
    return voxdagi_tiny(u & (1ull << 63), q);
}

static double voxdagi_fsub(double a, double b) {
    volatile double r = a - b; /* a difference below DBL_MIN is exact */
    return r;
}

static double voxdagi_fmul(double a, double b) {
    volatile double r = a * b;
    double v = r;
    if (v < DBL_MIN && v > -DBL_MIN && a != 0 && b != 0 && a - a == 0 && b - b == 0) v = voxdagi_mul_tiny(a, b);
    return v;
}

static double voxdagi_frecip(double d) {
    volatile double r = 1.0 / d;
    double v = r;
    if (v <= DBL_MIN && v >= -DBL_MIN && d - d == 0) v = voxdagi_recip_tiny(d);
    return v;
}
#else
#define voxdagi_fsub(a, b) ((a) - (b))
#define voxdagi_fmul(a, b) ((a) * (b))
#define voxdagi_frecip(d) (1.0 / (d))
#endif

/* The t at which a ray with origin O and inverse direction IX meets PLANE. */
#define voxdagi_plane_t(plane, o, ix) voxdagi_fmul(voxdagi_fsub((plane), (o)), (ix))

typedef struct voxdagi_frame {
    const uint8_t *rec;
    unsigned header, mi, occ; /* occ: which world octants hold a child */
} voxdagi_frame;

/* The octants of a 2^3 block a ray can still reach from octant W, moving only
   towards the AHEAD halves (bit b set: it has yet to cross mid plane b):
   [W][AHEAD], W with each subset of AHEAD's bits flipped. */
static const uint8_t voxdagi_reach8[8][8] = {
    {0x01, 0x03, 0x05, 0x0F, 0x11, 0x33, 0x55, 0xFF}, {0x02, 0x03, 0x0A, 0x0F, 0x22, 0x33, 0xAA, 0xFF},
    {0x04, 0x0C, 0x05, 0x0F, 0x44, 0xCC, 0x55, 0xFF}, {0x08, 0x0C, 0x0A, 0x0F, 0x88, 0xCC, 0xAA, 0xFF},
    {0x10, 0x30, 0x50, 0xF0, 0x11, 0x33, 0x55, 0xFF}, {0x20, 0x30, 0xA0, 0xF0, 0x22, 0x33, 0xAA, 0xFF},
    {0x40, 0xC0, 0x50, 0xF0, 0x44, 0xCC, 0x55, 0xFF}, {0x80, 0xC0, 0xA0, 0xF0, 0x88, 0xCC, 0xAA, 0xFF}};

/* The positions of a 4^3 brick a ray can still reach along axis A from
   coordinate V: [A][V][0] for a ray that does not move along A (coordinate
   V), [1] moving up (at least V), [2] moving down (at most V). */
static const uint64_t voxdagi_brick_reach[3][4][3] = {
    {{0x0055005500550055ull, 0xFFFFFFFFFFFFFFFFull, 0x0055005500550055ull},
     {0x00AA00AA00AA00AAull, 0xFFAAFFAAFFAAFFAAull, 0x00FF00FF00FF00FFull},
     {0x5500550055005500ull, 0xFF00FF00FF00FF00ull, 0x55FF55FF55FF55FFull},
     {0xAA00AA00AA00AA00ull, 0xAA00AA00AA00AA00ull, 0xFFFFFFFFFFFFFFFFull}},
    {{0x0000333300003333ull, 0xFFFFFFFFFFFFFFFFull, 0x0000333300003333ull},
     {0x0000CCCC0000CCCCull, 0xFFFFCCCCFFFFCCCCull, 0x0000FFFF0000FFFFull},
     {0x3333000033330000ull, 0xFFFF0000FFFF0000ull, 0x3333FFFF3333FFFFull},
     {0xCCCC0000CCCC0000ull, 0xCCCC0000CCCC0000ull, 0xFFFFFFFFFFFFFFFFull}},
    {{0x000000000F0F0F0Full, 0xFFFFFFFFFFFFFFFFull, 0x000000000F0F0F0Full},
     {0x00000000F0F0F0F0ull, 0xFFFFFFFFF0F0F0F0ull, 0x00000000FFFFFFFFull},
     {0x0F0F0F0F00000000ull, 0xFFFFFFFF00000000ull, 0x0F0F0F0FFFFFFFFFull},
     {0xF0F0F0F000000000ull, 0xF0F0F0F000000000ull, 0xFFFFFFFFFFFFFFFFull}}};

/* Whether a full cell of brick MASK (world order) lies on the ray's side of
   every mid plane it has yet to cross from cell C, the cells being the
   brick's voxels (WHAT 0), its 2^3 cells (1) or the voxels of C's 2^3 cell
   (2). MOVING: the axes along which the ray moves (bits), DOWN: those along
   which it moves down; KIND: per axis, 0 still, 1 up, 2 down. */
static int voxdagi_brick_full_ahead(int what, uint64_t mask, const uint32_t c[3], unsigned moving, unsigned down,
                                    const unsigned kind[3]) {
    unsigned w = (c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2, occ = 0, k;
    if (what == 0) /* a box of the brick's voxels */
        return (mask & voxdagi_brick_reach[0][c[0] & 3][kind[0]] & voxdagi_brick_reach[1][c[1] & 3][kind[1]] &
                voxdagi_brick_reach[2][c[2] & 3][kind[2]]) != 0;
    if (what == 1) {
        for (k = 0; k < 8; k++) occ |= (unsigned)((mask >> 8 * k & 0xFF) != 0) << k;
    } else {
        occ = (unsigned)(mask >> 8 * ((c[0] >> 1 & 1) | (c[1] >> 1 & 1) << 1 | (c[2] >> 1 & 1) << 2) & 0xFF);
    }
    /* ahead along b: the lower half moving up, the upper half moving down */
    return (occ & voxdagi_reach8[w][~(w ^ down) & moving & 7]) != 0;
}

/* Index of the first voxel of cell C at cell level Q: the voxels of all
   preceding siblings on the path (FORMAT.md, Voxel index), read from the frames. */
static uint64_t voxdagi_ray_index(const voxdag *d, const voxdagi_frame *f, uint64_t mask,
                                  const uint32_t c[3], uint32_t q) {
    uint32_t brick_level = d->levels - 2, top = q < brick_level ? q : brick_level, k;
    uint64_t idx = 0;
    for (k = 0; k < top; k++) {
        unsigned sh = q - 1 - k;
        unsigned w = (c[0] >> sh & 1) | (c[1] >> sh & 1) << 1 | (c[2] >> sh & 1) << 2;
        idx += voxdagi_preceding(d, k, f[k].rec, f[k].header, f[k].mi, w, NULL);
    }
    if (q > brick_level) { /* a voxel or a 2^3 cell of the brick: from its first voxel */
        uint32_t v[3];
        for (k = 0; k < 3; k++) v[k] = c[k] << (d->levels - q);
        idx += (uint64_t)voxdagi_popcount64(mask & ((1ull << voxdagi_brick_pos(v)) - 1)); /* MASK: world order */
    }
    return idx;
}

/* The largest double below V (V itself when NaN or -infinity). */
static double voxdagi_below(double v) {
    uint64_t u;
    if (!(v > -HUGE_VAL)) return v;
    memcpy(&u, &v, sizeof u);
    u = v > 0 ? u - 1 : v < 0 ? u + 1 : 1ull << 63 | 1; /* 0: minus the smallest denormal */
    memcpy(&v, &u, sizeof v);
    return v;
}

/* The traversal shared by both queries; HIT NULL means any hit will do.
   OPEN: the range is [t_min, t_max) with t_max as given, else [t_min,
   t_max] with 0 for no limit. *STEPS counts the cells stepped through (for
   tests; the queries pass a local that the compiler drops). */
VOXDAGI_INLINE int voxdagi_trace(const voxdag *d, const voxdag_ray *ray, double lod, int want_index, int open,
                                 voxdag_hit *hit, uint64_t *steps) {
    const uint32_t nlevels = d->levels, brick_level = nlevels - 2, side = 1u << nlevels;
    voxdagi_frame f[VOXDAG_MAX_LEVELS];
    double ox[3], ix[3], te = -HUGE_VAL, tx = HUGE_VAL, t_stop;
    uint32_t c[3] = {0, 0, 0}, up[3], step[3], q = 0, l = 0;
    int sgn[3];
    unsigned ae = 0, ax = 0, a, mi = voxdagi_cube_tables.inv[d->root_transform], header = 0, occ = 0;
    int split, probe;
    unsigned moving = 0, down = 0, kind[3]; /* for voxdagi_brick_full_ahead */
    const uint8_t *rec = NULL;
    uint64_t mask = 0, at = 0;

    /* 0: a zeroed ray has no limit; t < t_max is t <= the double below it */
    double t_max = open ? voxdagi_below(ray->t_max) : ray->t_max == 0 ? HUGE_VAL : ray->t_max;
    if (!d->voxels || !(ray->t_min <= t_max)) return 0;
    /* The entry and exit events of the voxel box, without level of detail
       (a hit is then a voxel, inside the box, entered through a plane of the
       grid), else of the grid (a coarse cell may reach outside the box). */
    for (a = 0; a < 3; a++) {
        double o = ray->origin[a], dir = ray->dir[a], lo, hi;
        double box_lo = lod > 0 ? 0.0 : (double)d->voxel_box[a], box_hi = lod > 0 ? (double)side : (double)d->voxel_box[a + 3];
        if (o - o != 0 || dir - dir != 0) return 0; /* NaN or infinite */
        if (dir == 0) {
            if (!(o >= box_lo && o < box_hi)) return 0;
            sgn[a] = 0, up[a] = 0, step[a] = 0, ox[a] = -HUGE_VAL, ix[a] = 1; /* t = +inf */
            continue;
        }
        sgn[a] = dir > 0 ? 1 : -1, up[a] = dir > 0, step[a] = dir > 0 ? 1u : ~0u;
        moving |= 1u << a, down |= (unsigned)(dir < 0) << a;
        ox[a] = o, ix[a] = voxdagi_frecip(dir);
        lo = voxdagi_plane_t(dir > 0 ? box_lo : box_hi, o, ix[a]);
        hi = voxdagi_plane_t(dir > 0 ? box_hi : box_lo, o, ix[a]);
        if (lo >= te) te = lo, ae = a; /* on ties the last axis enters last */
        if (hi < tx) tx = hi, ax = a;  /* and the first axis leaves first */
    }
    for (a = 0; a < 3; a++) kind[a] = (unsigned)(sgn[a] > 0 ? 1 : sgn[a] < 0 ? 2 : 0);
    if (ray->t_min >= te) te = ray->t_min, ae = 3;
    if (tx < te || (tx == te && ax < ae) || te > t_max) return 0;
    t_stop = tx == HUGE_VAL ? te : t_max < tx ? t_max : tx;
    /* Level of detail may stop at a 2^3 cell of a brick before t_stop: then
       bricks are walked as two levels (l = B: 2^3 cells, l = B + 1: voxels),
       else as one level of 4^3 voxels. */
    split = 2.0 < voxdagi_fmul(lod, t_stop);

    for (;;) {
        /* Enter node (l, at, M), which is cell c of level q. */
        unsigned halves = 1, b;
        if (l < brick_level) {
            rec = d->level[l].data + at;
            header = voxdagi_le16(rec);
            occ = voxdagi_occupancy[mi][voxdagi_presence(header)];
            f[l].rec = rec;
            f[l].header = header;
            f[l].occ = occ;
        } else if (l == brick_level) { /* the brick in world order */
            mask = voxdagi_brick_to_world(voxdagi_brick(d, at), mi);
            f[l].rec = NULL;
            f[l].header = f[l].occ = 0;
            halves = split ? 1 : 2;
        } /* else l == B + 1: a 2^3 cell of the same brick */
        f[l].mi = mi;
        while (halves--) { /* the child cell: which mid planes are crossed by (te, ae) */
            uint32_t sh = nlevels - q - 1;
            for (b = 0; b < 3; b++) {
                uint32_t mid = (2 * c[b] + 1) << sh;
                unsigned h;
                if (!sgn[b]) {
                    h = ray->origin[b] >= (double)mid;
                } else {
                    double tm = voxdagi_plane_t((double)mid, ox[b], ix[b]);
                    unsigned crossed = tm < te || (tm == te && b <= ae); /* b = ae: the box entered there */
                    h = sgn[b] > 0 ? crossed : !crossed;
                }
                c[b] = 2 * c[b] + h;
            }
            q++;
        }
        /* Step through the node's cells until a full one. */
        for (probe = 1;; probe = 0) {
            double t, t1, t2;
            uint32_t old, sh;
            int k;
            ++*steps;
            if (l < brick_level) {
                if (occ >> ((c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2) & 1) break;
            } else if (q == nlevels) {
                if (mask >> voxdagi_brick_pos(c) & 1) break;
            } else if (mask >> 8 * ((c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2) & 0xFF) {
                break; /* a 2^3 cell: one byte of the brick, any bit */
            }
            /* A brick (or 2^3 cell) entered through an empty cell with no
               full cell on the ray's side of the mid planes it has yet to
               cross is left from its own cell one level up, at the plane and
               t at which stepping through its empty cells would leave it
               (those steps change only bits that the move up drops): a miss
               then costs a step per brick, not up to ten. Nodes, at most
               four steps each, are not probed: on surfaces the probe would
               cost more than it saves. */
            if (probe && l >= brick_level &&
                !voxdagi_brick_full_ahead(l > brick_level ? 2 : q < nlevels, mask, c, moving, down, kind)) {
                uint32_t up_by = l == brick_level && q == nlevels ? 2 : 1;
                if (l == 0) return 0;
                c[0] >>= up_by, c[1] >>= up_by, c[2] >>= up_by;
                q -= up_by, l--;
                rec = f[l].rec, header = f[l].header, mi = f[l].mi, occ = f[l].occ;
            }
            sh = nlevels - q;
            t = voxdagi_plane_t((double)((c[0] + up[0]) << sh), ox[0], ix[0]);
            t1 = voxdagi_plane_t((double)((c[1] + up[1]) << sh), ox[1], ix[1]);
            t2 = voxdagi_plane_t((double)((c[2] + up[2]) << sh), ox[2], ix[2]);
            a = 0;
            if (t1 < t) t = t1, a = 1;
            if (t2 < t) t = t2, a = 2;
            if (!(t <= t_stop)) return 0;
            old = c[a];
            c[a] += step[a];
            te = t, ae = a;
            sh = voxdagi_bit_length(old ^ c[a]) - 1;
            k = (int)q - 1 - (int)sh; /* the node level whose child changed */
            if (k < (int)l) {
                if (k < 0) return 0; /* left the grid */
                c[0] >>= sh, c[1] >>= sh, c[2] >>= sh;
                q -= sh, l = (uint32_t)k;
                rec = f[l].rec, header = f[l].header, mi = f[l].mi, occ = f[l].occ;
            }
        }
        /* Cell c of level q is full: a hit, or go down into it. */
        if (q == nlevels || (double)(1u << (nlevels - q)) < voxdagi_fmul(lod, te)) {
            if (!hit) return 1;
            hit->t = te;
            for (b = 0; b < 3; b++) {
                hit->xyz[b] = c[b] << (nlevels - q);
                hit->normal[b] = b == ae ? -sgn[b] : 0;
            }
            hit->level = q;
            hit->index = want_index ? voxdagi_ray_index(d, f, mask, c, q) : 0;
            return 1;
        }
        if (l < brick_level) {
            uint64_t ref = voxdagi_child_ref(d, l, rec, header,
                                             voxdagi_cube_tables.act[mi][(c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2], 1);
            mi = voxdagi_cube_tables.comp[ref & 63][mi];
            at = ref >> 6;
        }
        l++;
    }
}

/* A finite value >= 0 (not NaN). */
static int voxdagi_finite_nonneg(double v) { return v >= 0 && v <= 1.7976931348623157e308; }

/* The level-of-detail product lod_factor * lod_pixels of OPTS (NULL:
   defaults, 0); 0 when OPTS is invalid. */
static int voxdagi_ray_opts_ok(const voxdag_ray_opts *opts, double *lod) {
    *lod = 0;
    if (!opts) return 1;
    if (opts->zero_begin || opts->zero_end || !voxdagi_finite_nonneg(opts->lod_factor) ||
        !voxdagi_finite_nonneg(opts->lod_pixels))
        return 0;
    if (opts->lod_pixels > 0) *lod = voxdagi_fmul(opts->lod_factor, opts->lod_pixels);
    return 1;
}

/* Both queries with OPTS checked (-1 when invalid), in x87 double
   precision where needed. HIT NULL: any hit. */
static int voxdagi_query(const voxdag *d, const voxdag_ray *ray, const voxdag_ray_opts *opts, voxdag_hit *hit) {
    uint64_t steps = 0;
    double lod;
    int r = -1;
#ifdef VOXDAGI_X87
    unsigned cw = voxdagi_x87_begin();
#endif
    if (voxdagi_ray_opts_ok(opts, &lod))
        r = voxdagi_trace(d, ray, lod, opts && opts->want_index, opts && opts->t_max_exclusive, hit, &steps);
#ifdef VOXDAGI_X87
    voxdagi_x87_end(cw);
#endif
    return r;
}

VOXDAG_API int voxdag_raycast(const voxdag *dag, const voxdag_ray *ray, const voxdag_ray_opts *opts,
                              voxdag_hit *hit) {
    return dag && ray && hit ? voxdagi_query(dag, ray, opts, hit) : -1;
}

VOXDAG_API int voxdag_occluded(const voxdag *dag, const voxdag_ray *ray) {
    return dag && ray ? voxdagi_query(dag, ray, NULL, NULL) : -1;
}

VOXDAG_API int voxdag_occluded_opts(const voxdag *dag, const voxdag_ray *ray, const voxdag_ray_opts *opts) {
    return dag && ray ? voxdagi_query(dag, ray, opts, NULL) : -1;
}

VOXDAG_API int voxdag_cell_color(const voxdag *dag, const voxdag_hit *hit, uint8_t rgb[3]) {
    uint32_t q;
    uint64_t a = 0, n, sum[3] = {0, 0, 0};
    if (!dag || !hit || !rgb || dag->color_kind == VOXDAG_COLORS_NONE) return 0;
    q = hit->level;
    if (q > dag->levels || (hit->xyz[0] | hit->xyz[1] | hit->xyz[2]) >> dag->levels) return 0;
    if (!voxdagi_colors_readable(dag)) return voxdag_color(dag, 0, rgb); /* -1 and magenta */
    if (!(n = voxdagi_cells_many(dag, q, hit->xyz, 1, NULL, NULL, &a))) return 0;
    if (n <= 64) { /* a voxel, every 2^3 cell and brick: exact from the colours */
        voxdagi_sum_colors(dag, a, n, sum);
        voxdagi_mean_rgb(sum, n, rgb);
        return 1;
    }
    if (dag->lod && q >= dag->lod_first && q - dag->lod_first < dag->lod_levels) {
        /* the level's slot at the first multiple of 64 in [a, a + n), which
           exists since n > 64, so the slot is below ceil(voxels / 64) */
        uint64_t slot = (q - dag->lod_first) * dag->lod_per_level + ((a + 63) >> 6);
        if (dag->color_kind == VOXDAG_COLORS_RGB8) memcpy(rgb, dag->lod_slots + 3 * slot, 3);
#ifdef VOXDAGI_VOXCOLOR
        else voxcolor_view_get(&dag->lod_view, slot, rgb);
#endif
        return 1;
    }
    return voxdag_color(dag, a, rgb); /* no slot for this level: the first voxel's colour */
}

VOXDAG_API int voxdag_ray_from_hit(const voxdag *dag, const voxdag_ray *ray, const voxdag_hit *hit,
                                   const double dir[3], voxdag_ray *out) {
    double o[3], d[3], size;
    int k, leaves = 0, on_face;
#ifdef VOXDAGI_X87
    unsigned cw;
#endif
    if (!dag || !ray || !hit || !dir || !out || hit->level > dag->levels) return -1;
    size = (double)(1u << (dag->levels - hit->level));
    on_face = (hit->normal[0] | hit->normal[1] | hit->normal[2]) != 0;
#ifdef VOXDAGI_X87
    cw = voxdagi_x87_begin(); /* the same origin as on other processors */
#endif
    for (k = 0; k < 3; k++) {
        double lo = hit->xyz[k], hi = lo + size, v = ray->origin[k] + voxdagi_fmul(hit->t, ray->dir[k]);
        if (hit->normal[k]) { /* exactly on the entry face's plane */
            v = hit->normal[k] < 0 ? lo : hi;
            leaves = dir[k] * hit->normal[k] > 0;
        } else if (on_face) { /* inside the face's square */
            v = v < lo ? lo : v > hi ? hi : v;
        }
        o[k] = v, d[k] = dir[k];
    }
#ifdef VOXDAGI_X87
    voxdagi_x87_end(cw);
#endif
    memcpy(out->origin, o, sizeof o);
    memcpy(out->dir, d, sizeof d);
    out->t_min = 0, out->t_max = 0;
    return leaves;
}

VOXDAG_API voxdag_status voxdag_world_ray(const voxdag *dag, const voxdag_ray *world_ray, voxdag_ray *grid_ray) {
    double o[3], d[3], lo[3], cell[3];
    unsigned k;
    if (!dag || !world_ray || !grid_ray) return VOXDAG_ERR_INVALID_ARGUMENT;
    voxdagi_grid_map(dag, lo, cell);
    for (k = 0; k < 3; k++) {
        o[k] = (world_ray->origin[k] - lo[k]) / cell[k];
        d[k] = world_ray->dir[k] / cell[k];
    }
    grid_ray->t_min = world_ray->t_min;
    grid_ray->t_max = world_ray->t_max;
    memcpy(grid_ray->origin, o, sizeof o);
    memcpy(grid_ray->dir, d, sizeof d);
    return VOXDAG_OK;
}

// -- Ray batches
//
// A run of coherent rays (a packet) is first checked as one beam (SSVDAG
// 6's beam optimization, made exact): the space the packet sweeps (every
// origin within r0 of a centre o, every unit direction within angle a of an
// axis: a cone from o widened by r0) is walked down the DAG once, and the
// nearest full 2^3 cell of a brick it meets gives each ray a distance t_s
// before which it meets nothing full. A ray then traces from t_s, which
// gives the same answer bit for bit: the traversal's t are plane t's, the
// same whatever cell a trace starts from, so a trace started at t_s in
// front of every full cell walks the cells that the whole ray walks from
// t_s on. Margins far above rounding (1e-6 voxel plus 1e-9 of the distance)
// keep the bound safe; without level of detail only, since a
// level-of-detail stop depends on where a trace enters a cell.

enum { VOXDAGI_PACKET = 64, VOXDAGI_BEAM_VISITS = 16 * VOXDAGI_PACKET };

typedef struct voxdagi_beam {
    double o[3], axis[3]; /* the centre of the origins, the unit mean direction */
    double r0, cos_a, sin_a; /* origins within r0 of o, directions within angle a of axis */
} voxdagi_beam;

static double voxdagi_dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double voxdagi_cross_len(const double *a, const double *b) {
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    return sqrt(x * x + y * y + z * z);
}

/* Whether RAY may join a packet: finite, nonzero direction, t_min >= 0. */
static int voxdagi_beam_ray(const voxdag_ray *ray) {
    unsigned k;
    double len = 0;
    for (k = 0; k < 3; k++) {
        if (ray->origin[k] - ray->origin[k] != 0 || ray->dir[k] - ray->dir[k] != 0) return 0;
        len += ray->dir[k] * ray->dir[k];
    }
    return len > 1e-200 && len < 1e200 && ray->t_min >= 0;
}

/* The beam of the N rays (all voxdagi_beam_ray); 0 when it is too wide to
   pay (a cone wider than about 17 degrees). */
static int voxdagi_beam_make(const voxdag_ray *rays, size_t n, voxdagi_beam *b) {
    double sum[3] = {0, 0, 0}, len, angle = 0;
    size_t i;
    unsigned k;
    for (k = 0; k < 3; k++) b->o[k] = 0;
    for (i = 0; i < n; i++) {
        len = sqrt(voxdagi_dot3(rays[i].dir, rays[i].dir));
        for (k = 0; k < 3; k++) b->o[k] += rays[i].origin[k] / (double)n, sum[k] += rays[i].dir[k] / len;
    }
    len = sqrt(voxdagi_dot3(sum, sum));
    if (!(len > 0.5 * (double)n)) return 0;
    for (k = 0; k < 3; k++) b->axis[k] = sum[k] / len;
    b->r0 = 0;
    for (i = 0; i < n; i++) {
        double v[3], r, dot = voxdagi_dot3(rays[i].dir, b->axis), a;
        for (k = 0; k < 3; k++) v[k] = rays[i].origin[k] - b->o[k];
        r = sqrt(voxdagi_dot3(v, v));
        a = atan2(voxdagi_cross_len(rays[i].dir, b->axis), dot);
        if (r > b->r0) b->r0 = r;
        if (a > angle) angle = a;
    }
    b->r0 += 1e-6 + 1e-9 * sqrt(voxdagi_dot3(b->o, b->o));
    angle += 1e-9;
    if (angle > 0.3) return 0;
    b->cos_a = cos(angle), b->sin_a = sin(angle);
    return 1;
}

/* The sphere of centre C and radius RAD against beam B: 0 when it lies
   outside the swept space, else 1 with *LOWER, a lower bound on the
   distance from B's centre to its points. The distance from a point to the
   cone's surface line in their common plane is at most its distance to
   the cone (s along the axis, p across it): p cos a - s sin a. */
static int voxdagi_beam_meets(const voxdagi_beam *b, const double c[3], double rad, double *lower) {
    double v[3], dv, reach;
    unsigned k;
    for (k = 0; k < 3; k++) v[k] = c[k] - b->o[k];
    dv = sqrt(voxdagi_dot3(v, v));
    rad += 1e-6 + 1e-9 * dv;
    reach = rad + b->r0;
    *lower = dv - rad;
    return dv <= reach || voxdagi_cross_len(v, b->axis) * b->cos_a - voxdagi_dot3(v, b->axis) * b->sin_a <= reach;
}

/* A lower bound on the distance from beam B's centre to the full 2^3
   cells of bricks that B meets: HUGE_VAL when it meets none. Returns 0 when
   the walk would cost more than it saves (VOXDAGI_BEAM_VISITS nodes), or
   as soon as a full cell lies within r0 (no ray would start later). A
   depth-first walk, children nearest first, so that the bound found early
   prunes the rest. */
static int voxdagi_beam_bound(const voxdag *d, const voxdagi_beam *b, double *bound) {
    struct item {
        uint64_t at;
        uint32_t xyz[3], l;
        unsigned mi;
    } stack[7 * VOXDAG_MAX_LEVELS + 1];
    const uint32_t nlevels = d->levels, brick_level = nlevels - 2;
    unsigned first = 0, k, visits = 0; /* first: the octant nearest along the axis */
    size_t n = 1; /* items on the stack: at most 7 per level and the root */
    double best = HUGE_VAL;
    for (k = 0; k < 3; k++) first |= (unsigned)(b->axis[k] < 0) << k;
    stack[0].at = 0, stack[0].l = 0, stack[0].mi = voxdagi_cube_tables.inv[d->root_transform];
    stack[0].xyz[0] = stack[0].xyz[1] = stack[0].xyz[2] = 0;
    while (n > 0) {
        struct item it = stack[--n];
        double size = (double)(1u << (nlevels - it.l)), c[3], lower;
        if (++visits > VOXDAGI_BEAM_VISITS) return 0;
        for (k = 0; k < 3; k++) c[k] = it.xyz[k] + size / 2;
        if (!voxdagi_beam_meets(b, c, size * 0.8660254037844387, &lower) || lower >= best) continue;
        if (it.l == brick_level) { /* its 2^3 cells: one byte of the mask each */
            uint64_t mask = voxdagi_brick_to_world(voxdagi_brick(d, it.at), it.mi);
            for (k = 0; k < 8; k++) {
                c[0] = it.xyz[0] + (k & 1 ? 3 : 1), c[1] = it.xyz[1] + (k & 2 ? 3 : 1);
                c[2] = it.xyz[2] + (k & 4 ? 3 : 1);
                if ((mask >> 8 * k & 0xFF) && voxdagi_beam_meets(b, c, 1.7320508075688774, &lower) && lower < best)
                    best = lower;
            }
            if (best <= b->r0) return 0; /* a full cell within reach of an origin: no ray gains */
        } else {
            const uint8_t *rec = d->level[it.l].data + it.at;
            unsigned header = voxdagi_le16(rec), occ = voxdagi_occupancy[it.mi][voxdagi_presence(header)], j;
            uint32_t half = 1u << (nlevels - 1 - it.l);
            for (j = 8; j-- > 0;) { /* pushed farthest first: popped nearest first */
                unsigned w = j ^ first;
                uint64_t ref;
                struct item *ch = &stack[n];
                if (!(occ >> w & 1)) continue;
                ref = voxdagi_child_ref(d, it.l, rec, header, voxdagi_cube_tables.act[it.mi][w], 1);
                ch->at = ref >> 6, ch->l = it.l + 1, ch->mi = voxdagi_cube_tables.comp[ref & 63][it.mi];
                ch->xyz[0] = it.xyz[0] + (w & 1 ? half : 0), ch->xyz[1] = it.xyz[1] + (w & 2 ? half : 0);
                ch->xyz[2] = it.xyz[2] + (w & 4 ? half : 0);
                n++;
            }
        }
    }
    *bound = best;
    return 1;
}

/* Raises RAY's t_min to where it is still nearer than any full cell that
   beam B meets, by BOUND (voxdagi_beam_bound). Returns 0 when the ray
   meets nothing full. */
static int voxdagi_beam_narrow(const voxdagi_beam *b, double bound, voxdag_ray *ray) {
    double t = (bound - b->r0) / sqrt(voxdagi_dot3(ray->dir, ray->dir)) * (1 - 1e-9);
    if (bound == HUGE_VAL) return 0;
    if (t > ray->t_min) ray->t_min = t;
    return 1;
}

/* Whether any of the 2^3 voxels nearest RAY's origin is full: a ray that
   leaves a surface (a shadow or reflection ray) cannot start later, so its
   packet is traced without a beam. */
static int voxdagi_starts_at_surface(const voxdag *d, const voxdag_ray *ray) {
    uint32_t xyz[24], k, j;
    for (j = 0; j < 8; j++)
        for (k = 0; k < 3; k++) {
            double v = floor(ray->origin[k] - 0.5) + (double)(j >> k & 1);
            xyz[3 * j + k] = v >= 0 && v < 4294967295.0 ? (uint32_t)v : UINT32_MAX; /* outside: empty */
        }
    return voxdag_lookup_many(d, xyz, 8, NULL, NULL) > 0;
}

/* Both batch queries (HITS NULL: any hit), OPTS checked: packets of
   consecutive rays that may join one, each narrowed by its beam, and the
   rays that may not traced alone. A packet that starts at a surface gets
   no beam, and a beam that narrows none of its rays (incoherent rays) is
   not tried again for the next 1, 2, 4 ... 64 packets, so that such
   batches cost about what single calls do. */
static int64_t voxdagi_query_many(const voxdag *d, const voxdag_ray *rays, size_t count, const voxdag_ray_opts *opts,
                                  voxdag_hit *hits, uint8_t *result) {
    uint64_t steps = 0;
    int64_t found = 0;
    size_t i = 0, n, j;
    unsigned skip = 0, backoff = 1; /* packets left without a beam; the next such run */
    double lod;
    int want_index = opts && opts->want_index, open = opts && opts->t_max_exclusive, ok;
#ifdef VOXDAGI_X87
    unsigned cw = voxdagi_x87_begin();
#endif
    ok = voxdagi_ray_opts_ok(opts, &lod);
    while (ok && i < count) {
        voxdagi_beam b;
        double bound = 0;
        int beam = 0, tried = 0, narrowed = 0;
        for (n = 0; i + n < count && n < VOXDAGI_PACKET && lod == 0 && d->voxels && voxdagi_beam_ray(&rays[i + n]);) n++;
        if (n > 0 && skip > 0) skip--;
        else if (n > 0 && !voxdagi_starts_at_surface(d, &rays[i]))
            tried = 1, beam = voxdagi_beam_make(rays + i, n, &b) && voxdagi_beam_bound(d, &b, &bound);
        if (n == 0) n = 1;
        for (j = i; j < i + n; j++) {
            voxdag_ray ray = rays[j];
            int got = 0, meets = !beam || voxdagi_beam_narrow(&b, bound, &ray);
            narrowed += !meets || ray.t_min != rays[j].t_min;
            if (meets && hits) got = voxdagi_trace(d, &ray, lod, want_index, open, &hits[j], &steps);
            else if (meets) got = voxdagi_trace(d, &ray, lod, 0, open, NULL, &steps); /* any hit: a lighter copy */
            result[j] = (uint8_t)got;
            found += got;
        }
        if (tried && narrowed) backoff = 1;
        else if (tried) skip = backoff, backoff = backoff < 64 ? 2 * backoff : 64;
        i += n;
    }
#ifdef VOXDAGI_X87
    voxdagi_x87_end(cw);
#endif
    return ok ? found : -1;
}

VOXDAG_API int64_t voxdag_raycast_many(const voxdag *dag, const voxdag_ray *rays, size_t count,
                                       const voxdag_ray_opts *opts, voxdag_hit *hits, uint8_t *result) {
    if (!dag || (count && (!rays || !hits || !result))) return -1;
    return voxdagi_query_many(dag, rays, count, opts, hits, result);
}

VOXDAG_API int64_t voxdag_occluded_many(const voxdag *dag, const voxdag_ray *rays, size_t count,
                                        const voxdag_ray_opts *opts, uint8_t *occluded) {
    if (!dag || (count && (!rays || !occluded))) return -1;
    return voxdagi_query_many(dag, rays, count, opts, NULL, occluded);
}

#endif /* VOXDAG_NO_RAYTRACE */

// -- Files

#ifndef VOXDAG_NO_STDIO
VOXDAG_API voxdag_status voxdag_load_file(const char *path, const voxdag_load_opts *opts,
                                          voxdag **out, voxdag_error *err) {
    voxdag_load_opts o;
    voxdagi_mem m;
    FILE *f;
    long len;
    uint8_t *buf;
    voxdag_status st;
    if (!path || !out) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "path or out is NULL");
    *out = NULL;
    st = voxdagi_load_opts(opts, &o, err);
    if (st != VOXDAG_OK) return st;
    f = fopen(path, "rb");
    if (!f) return voxdagi_fail_io(err, "cannot open the file");
    if ((fgetc(f) == EOF && ferror(f)) || fseek(f, 0, SEEK_END) || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET)) {
        st = voxdagi_fail_io(err, "cannot read the file"); /* e.g. a directory */
        fclose(f);
        return st;
    }
    if (o.max_input_bytes && (uint64_t)len > o.max_input_bytes) {
        fclose(f);
        return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, "input larger than max_input_bytes");
    }
    { /* the header first: nothing more is read of a file that is not one */
        uint8_t h[VOXDAG_FILE_HEADER_SIZE];
        size_t got = fread(h, 1, sizeof h, f);
        if (got < sizeof h && ferror(f)) st = voxdagi_fail_io(err, "cannot read the file");
        else st = voxdagi_check_header(h, got < sizeof h ? got : (uint64_t)len, err);
        if (st == VOXDAG_OK && fseek(f, 0, SEEK_SET)) st = voxdagi_fail_io(err, "cannot read the file");
        if (st != VOXDAG_OK) {
            fclose(f);
            return st;
        }
    }
    voxdagi_mem_init(&m, &o.allocator, o.max_memory); /* the buffer counts against max_memory */
    buf = (uint8_t *)voxdagi_alloc(&m, (size_t)len);
    if (!buf) {
        fclose(f);
        voxdagi_mem_destroy(&m);
        return voxdagi_mem_fail(&m, err, VOXDAG_ERR_OUT_OF_MEMORY, "cannot allocate the file buffer");
    }
    if (len && fread(buf, 1, (size_t)len, f) != (size_t)len) {
        fclose(f);
        voxdagi_free(&m, buf, (size_t)len);
        voxdagi_mem_destroy(&m);
        return voxdagi_fail_io(err, "cannot read the file");
    }
    fclose(f);
    o.copy = 0;
    if (o.max_memory) /* what validation may still use (0 would mean no limit) */
        o.max_memory = o.max_memory > m.used ? o.max_memory - m.used : 1;
    st = voxdag_load_memory(buf, (size_t)len, &o, out, err);
    if (st != VOXDAG_OK) {
        voxdagi_free(&m, buf, (size_t)len);
    } else {
        (*out)->owned = buf; /* the DAG takes the buffer */
        (*out)->owned_size = (size_t)len;
    }
    voxdagi_mem_destroy(&m);
    return st;
}

/* Saving: the temporary file is created exclusively where the platform
   allows it (POSIX open, Windows _open), else with stdio. */
#if defined(_WIN32)
#define VOXDAGI_SAVE_WIN32 1
#elif defined(__unix__) || defined(__APPLE__)
#define VOXDAGI_SAVE_POSIX 1
#endif

VOXDAG_API voxdag_status voxdag_save_temp_path(const char *path, char *buf, size_t size) {
    size_t n;
    if (!path || !buf) return VOXDAG_ERR_INVALID_ARGUMENT;
    n = strlen(path);
    if (size < 32 || n > size - 32) return VOXDAG_ERR_INVALID_ARGUMENT;
#if defined(VOXDAGI_SAVE_WIN32)
    sprintf(buf, "%s.vdag-tmp-%lu", path, (unsigned long)_getpid());
#elif defined(VOXDAGI_SAVE_POSIX)
    sprintf(buf, "%s.vdag-tmp-%lu", path, (unsigned long)getpid());
#else
    sprintf(buf, "%s.vdag-tmp", path);
#endif
    return VOXDAG_OK;
}

#if defined(VOXDAGI_SAVE_POSIX)
#define voxdagi_write(fd, p, n) write(fd, p, n)
#define voxdagi_close(fd) close(fd)
#define voxdagi_unlink(path) unlink(path)
#elif defined(VOXDAGI_SAVE_WIN32)
#define voxdagi_write(fd, p, n) _write(fd, p, (unsigned)(n))
#define voxdagi_close(fd) _close(fd)
#define voxdagi_unlink(path) _unlink(path)
#endif

/* Writes SIZE bytes at DATA to the new file TMP. Returns 1, or 0 with errno
   set, TMP then removed, or never made (EEXIST: not ours, left alone).
   MODE: the permission bits to give it, or -1 for the default. */
static int voxdagi_write_new(const char *tmp, const uint8_t *data, size_t size, long mode) {
#if defined(VOXDAGI_SAVE_POSIX) || defined(VOXDAGI_SAVE_WIN32)
    int ok = 1, e, fd;
#if defined(VOXDAGI_SAVE_POSIX)
    int flags = O_WRONLY | O_CREAT | O_EXCL; /* O_EXCL: never through a link at TMP */
#ifdef O_NOFOLLOW
    flags |= O_NOFOLLOW;
#endif
#ifdef O_CLOEXEC
    flags |= O_CLOEXEC;
#endif
    fd = open(tmp, flags, 0666);
    if (fd >= 0 && mode >= 0) ok = !fchmod(fd, (mode_t)mode);
#else
    fd = _open(tmp, _O_WRONLY | _O_CREAT | _O_EXCL | _O_BINARY | _O_NOINHERIT, _S_IREAD | _S_IWRITE);
    (void)mode;
#endif
    if (fd < 0) return 0;
    while (ok && size) {
        size_t n = size < ((size_t)1 << 30) ? size : ((size_t)1 << 30);
        long got = (long)voxdagi_write(fd, data, n);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) {
            if (got == 0) errno = EIO;
            ok = 0;
            break;
        }
        data += got;
        size -= (size_t)got;
    }
    e = errno;
    if (voxdagi_close(fd) && ok) ok = 0, e = errno;
    if (!ok) voxdagi_unlink(tmp);
    errno = e;
    return ok;
#else
    FILE *f = fopen(tmp, "rb");
    int ok, e;
    (void)mode;
    if (f) { /* taken (the caller may remove a stale temporary and try again) */
        fclose(f);
#ifdef EEXIST
        errno = EEXIST;
#endif
        return 0;
    }
    if (!(f = fopen(tmp, "wb"))) return 0;
    ok = fwrite(data, 1, size, f) == size && !fflush(f);
    e = errno;
    if (fclose(f) && ok) ok = 0, e = errno;
    if (!ok) remove(tmp);
    errno = e;
    return ok;
#endif
}

/* Writes the image to voxdag_save_temp_path's name beside PATH, created
   exclusively, and renames it over PATH (see the declaration). */
VOXDAG_API voxdag_status voxdag_save_file(const voxdag *dag, const char *path, voxdag_error *err) {
    char tmp[4096];
    long mode = -1;
    int written;
    if (!dag || !path) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "dag or path is NULL");
    if (voxdag_save_temp_path(path, tmp, sizeof tmp) != VOXDAG_OK)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "path longer than 4064 bytes");
#if defined(VOXDAGI_SAVE_POSIX) || defined(VOXDAGI_SAVE_WIN32)
    {
#if defined(VOXDAGI_SAVE_POSIX)
        struct stat st;
        int got = !stat(path, &st), dir = got && S_ISDIR(st.st_mode);
        if (got && S_ISREG(st.st_mode)) mode = (long)(st.st_mode & 0777);
#else
        struct _stat st;
        int dir = !_stat(path, &st) && (st.st_mode & _S_IFMT) == _S_IFDIR;
#endif
        if (dir) {
            errno = EISDIR;
            return voxdagi_fail_io(err, "the target is a directory");
        }
    }
#endif
    written = voxdagi_write_new(tmp, (const uint8_t *)dag->image, dag->image_size, mode);
#ifdef EEXIST
    /* A taken name is a stale temporary (a save that was killed, in a
       process of this id): the name is removed (a link itself, never its
       target) and the file created exclusively once more, so whatever
       appears there in between makes the save fail, not follow it. */
    if (!written && errno == EEXIST && !remove(tmp))
        written = voxdagi_write_new(tmp, (const uint8_t *)dag->image, dag->image_size, mode);
#endif
    if (!written) return voxdagi_fail_io(err, "cannot write a temporary file beside the target (PATH.vdag-tmp-PID)");
    if (rename(tmp, path)) {
        int e = errno;
#if !defined(VOXDAGI_SAVE_POSIX)
        /* where rename does not replace a file: remove it first, when it is
           one (never a directory: that does not open for writing) */
        FILE *old = fopen(path, "r+b");
        if (old) fclose(old);
        if (!old || remove(path) || rename(tmp, path))
#endif
        {
            remove(tmp);
            errno = e;
            return voxdagi_fail_io(err, "cannot move the temporary file over the target");
        }
    }
    return voxdagi_ok(err);
}
#endif

// -- Editing: the builder's node tables, changed path by path
#ifndef VOXDAG_NO_BUILD
//
// The scene is a reference into a voxdagi_reducer's unique-node stores, which
// never change once a node is interned: an edit builds new nodes along the
// edited region bottom-up through voxdagi_reduce_node / _brick (the builder's
// canonical forms and hash-consing), so old roots stay valid and undo is a
// root swap. Colours live in 64-colour blocks, one per 4^3 brick, found by
// the brick's Morton key; an edit writes only into blocks it made itself and
// copies any other block first, logging (brick, block before, block after),
// which is what undo and redo replay. Blocks live in fixed chunks (growing
// never copies them); the blocks of edits that can no longer be redone, or
// of a failed edit, are reused. Nodes are kept until the editor is freed.

#define VOXDAGI_NO_BLOCK 0xFFFFFFFFu
#define VOXDAGI_EDIT_COORD_MAX ((int64_t)1 << 28)
#define VOXDAGI_WHITE 0xFFFFFFu
#define VOXDAGI_ED_CHUNK_BITS 10 /* 1024 blocks (256 KB) a chunk */
#define VOXDAGI_ED_NO_GROUP (~0ull) /* group keys have at most 3 (21 - 4) bits */

/* The block map: a hash of groups of 4^3 bricks (brick key >> 6), each
   holding its 64 bricks' blocks, so that bricks met in Morton order share
   a lookup and its cache lines. */
typedef struct voxdagi_ed_slot {
    uint64_t group;  /* VOXDAGI_ED_NO_GROUP: a free slot */
    uint32_t record; /* its 64 blocks: group_block + 64 * record */
} voxdagi_ed_slot;

typedef struct voxdagi_color_change {
    uint64_t brick;
    uint32_t before, after; /* blocks, VOXDAGI_NO_BLOCK when none */
} voxdagi_color_change;

typedef struct voxdagi_edit_record {
    uint32_t root_before, root_after;
    size_t change_begin, change_end; /* its colour changes */
} voxdagi_edit_record;

struct voxdag_editor {
    voxdagi_mem mem;
    uint32_t levels;
    voxdag_symmetry symmetry;
    int colors, has_bounds;
    double bounds[6];
    voxdagi_group group;
    voxdagi_reducer red;                /* the unique nodes of every level */
    uint32_t root;                      /* the scene now; VOXDAGI_NONE: empty */
    uint32_t full[VOXDAG_MAX_LEVELS];   /* a full subtree per level, once made */
    uint32_t **chunk;                   /* colour blocks: 64 packed 0xRRGGBB each */
    size_t chunk_n, chunk_cap;
    uint64_t *block_serial;             /* the edit that made each block */
    size_t block_n, serial_cap;
    uint32_t *spare;                    /* blocks no state reaches, to reuse */
    size_t spare_n, spare_cap;
    voxdagi_ed_slot *map;               /* brick group -> record, open addressing */
    size_t map_n, map_cap;              /* map_cap: a power of two or 0 */
    uint32_t *group_block;              /* 64 blocks (VOXDAGI_NO_BLOCK: none) per record */
    size_t group_cap;                   /* map_n records are used */
    voxdagi_color_change *change;
    size_t change_n, change_cap;
    voxdagi_edit_record *history;       /* [0, done) applied, [done, kept) undone */
    size_t done, kept, history_cap;
    uint64_t serial;                    /* the edit being made */
    size_t edit_change_begin;
    voxdag *traced;                     /* a commit of the scene now, for rays */
};

static uint64_t voxdagi_ed_count(const voxdag_editor *ed, uint32_t level, uint32_t ref) {
    return ref == VOXDAGI_NONE ? 0 : ed->red.store[level].node[ref >> 6].count;
}

/* The mask of brick reference REF in world orientation. */
static uint64_t voxdagi_ed_brick(const voxdag_editor *ed, uint32_t ref) {
    if (ref == VOXDAGI_NONE) return 0;
    return voxdagi_transform_brick(&ed->group, ed->red.store[ed->levels - 2].node[ref >> 6].key, ref & 63);
}

/* The lowest corner C of child J of the node of side SIZE at corner O. */
static void voxdagi_ed_child_corner(const int64_t o[3], int64_t size, unsigned j, int64_t c[3]) {
    int64_t half = size / 2;
    c[0] = o[0] + (j & 1) * half;
    c[1] = o[1] + (j >> 1 & 1) * half;
    c[2] = o[2] + (j >> 2 & 1) * half;
}

/* The world-oriented child references of inner reference REF of LEVEL: the
   stored child of octant j lands in octant T(j), transformed by T. */
static void voxdagi_ed_children(const voxdag_editor *ed, uint32_t level, uint32_t ref, uint32_t child[8]) {
    unsigned j, tf = ref & 63;
    const uint32_t *slot;
    for (j = 0; j < 8; j++) child[j] = VOXDAGI_NONE;
    if (ref == VOXDAGI_NONE) return;
    slot = ed->red.store[level].child + 8 * (size_t)(ref >> 6);
    for (j = 0; j < 8; j++)
        if (slot[j] != VOXDAGI_NONE) child[voxdagi_cube_tables.act[tf][j]] = voxdagi_ref_compose(tf, slot[j]);
}

/* The node of LEVEL with world children CHILD (all absent: none). */
static uint32_t voxdagi_ed_node(voxdag_editor *ed, uint32_t level, const uint32_t child[8]) {
    unsigned j;
    for (j = 0; j < 8; j++)
        if (child[j] != VOXDAGI_NONE) return voxdagi_reduce_node(&ed->red, level, child);
    return VOXDAGI_NONE;
}

static uint32_t voxdagi_ed_brick_ref(voxdag_editor *ed, uint64_t mask) {
    return mask ? voxdagi_reduce_brick(&ed->red, mask) : VOXDAGI_NONE;
}

/* The full subtree of LEVEL (VOXDAGI_NONE when out of memory). */
static uint32_t voxdagi_ed_full(voxdag_editor *ed, uint32_t level) {
    uint32_t child[8];
    unsigned j;
    if (ed->full[level] != VOXDAGI_NONE) return ed->full[level];
    if (level == ed->levels - 2) {
        ed->full[level] = voxdagi_reduce_brick(&ed->red, ~0ull);
    } else {
        uint32_t c = voxdagi_ed_full(ed, level + 1);
        if (c == VOXDAGI_NONE) return c;
        for (j = 0; j < 8; j++) child[j] = c;
        ed->full[level] = voxdagi_reduce_node(&ed->red, level, child);
    }
    return ed->full[level];
}

// -- Editing: colour blocks (per brick, copy on write)

static uint32_t *voxdagi_ed_block(const voxdag_editor *ed, uint32_t block) {
    return ed->chunk[block >> VOXDAGI_ED_CHUNK_BITS] + 64 * (size_t)(block & ((1u << VOXDAGI_ED_CHUNK_BITS) - 1));
}

/* The block entry of BRICK, NULL when its group has none. */
static uint32_t *voxdagi_ed_map_find(const voxdag_editor *ed, uint64_t brick) {
    size_t i, mask = ed->map_cap - 1;
    uint64_t group = brick >> 6;
    if (!ed->map_cap) return NULL;
    for (i = (size_t)voxdagi_mix64(group) & mask; ed->map[i].group != VOXDAGI_ED_NO_GROUP; i = (i + 1) & mask)
        if (ed->map[i].group == group) return ed->group_block + 64 * (size_t)ed->map[i].record + (brick & 63);
    return NULL;
}

/* The block entry of BRICK, its group made when missing. NULL when out of memory. */
static uint32_t *voxdagi_ed_map_slot(voxdag_editor *ed, uint64_t brick) {
    uint32_t *at = voxdagi_ed_map_find(ed, brick);
    size_t i, mask, k;
    if (at) return at;
    if (!voxdagi_grow(&ed->mem, (void **)&ed->group_block, &ed->group_cap, 64 * (ed->map_n + 1),
                      sizeof *ed->group_block))
        return NULL;
    if ((ed->map_n + 1) * 2 > ed->map_cap) { /* rehash at half load */
        size_t cap = ed->map_cap ? ed->map_cap * 2 : 256, j;
        voxdagi_ed_slot *map = (voxdagi_ed_slot *)voxdagi_alloc(&ed->mem, cap * sizeof *map);
        if (!map) return NULL;
        for (j = 0; j < cap; j++) map[j].group = VOXDAGI_ED_NO_GROUP;
        for (j = 0; j < ed->map_cap; j++) {
            if (ed->map[j].group == VOXDAGI_ED_NO_GROUP) continue;
            for (i = (size_t)voxdagi_mix64(ed->map[j].group) & (cap - 1); map[i].group != VOXDAGI_ED_NO_GROUP;
                 i = (i + 1) & (cap - 1)) {}
            map[i] = ed->map[j];
        }
        voxdagi_free(&ed->mem, ed->map, ed->map_cap * sizeof *ed->map);
        ed->map = map;
        ed->map_cap = cap;
    }
    mask = ed->map_cap - 1;
    for (i = (size_t)voxdagi_mix64(brick >> 6) & mask; ed->map[i].group != VOXDAGI_ED_NO_GROUP; i = (i + 1) & mask) {}
    ed->map[i].group = brick >> 6;
    ed->map[i].record = (uint32_t)ed->map_n;
    at = ed->group_block + 64 * ed->map_n++;
    for (k = 0; k < 64; k++) at[k] = VOXDAGI_NO_BLOCK;
    return at + (brick & 63);
}

/* The colours of BRICK (packed 0xRRGGBB), NULL when it has none. */
static const uint32_t *voxdagi_ed_colors(const voxdag_editor *ed, uint64_t brick) {
    const uint32_t *at = voxdagi_ed_map_find(ed, brick);
    return at && *at != VOXDAGI_NO_BLOCK ? voxdagi_ed_block(ed, *at) : NULL;
}

/* A block for this edit: a spare one, or one more. VOXDAGI_NO_BLOCK when out of memory. */
static uint32_t voxdagi_ed_new_block(voxdag_editor *ed) {
    uint32_t made;
    if (ed->spare_n) {
        made = ed->spare[--ed->spare_n];
    } else {
        size_t c = ed->block_n >> VOXDAGI_ED_CHUNK_BITS;
        if (ed->block_n + 1 >= VOXDAGI_NO_BLOCK ||
            !voxdagi_grow(&ed->mem, (void **)&ed->block_serial, &ed->serial_cap, ed->block_n + 1,
                          sizeof *ed->block_serial))
            return VOXDAGI_NO_BLOCK;
        if (c == ed->chunk_n) {
            if (!voxdagi_grow(&ed->mem, (void **)&ed->chunk, &ed->chunk_cap, c + 1, sizeof *ed->chunk))
                return VOXDAGI_NO_BLOCK;
            ed->chunk[c] = (uint32_t *)voxdagi_alloc(&ed->mem, (64u << VOXDAGI_ED_CHUNK_BITS) * sizeof **ed->chunk);
            if (!ed->chunk[c]) return VOXDAGI_NO_BLOCK;
            ed->chunk_n++;
        }
        made = (uint32_t)ed->block_n++;
    }
    ed->block_serial[made] = ed->serial;
    return made;
}

/* Gives the blocks made by changes [BEGIN, END) back for reuse (kept until
   the editor is freed when there is no memory to note them). */
static void voxdagi_ed_spare(voxdag_editor *ed, size_t begin, size_t end) {
    size_t k;
    if (end <= begin ||
        !voxdagi_grow(&ed->mem, (void **)&ed->spare, &ed->spare_cap, ed->spare_n + (end - begin), sizeof *ed->spare))
        return;
    for (k = begin; k < end; k++) ed->spare[ed->spare_n++] = ed->change[k].after;
}

/* The colours of BRICK for this edit to write: its own block, or a new copy
   of the current one (logged; no copy when WHOLE: every colour will be
   written). NULL when out of memory. */
static uint32_t *voxdagi_ed_colors_to_write(voxdag_editor *ed, uint64_t brick, int whole) {
    uint32_t *at = voxdagi_ed_map_slot(ed, brick), old, made, *c;
    size_t k;
    if (!at) return NULL;
    old = *at;
    if (old != VOXDAGI_NO_BLOCK && ed->block_serial[old] == ed->serial) return voxdagi_ed_block(ed, old);
    if (!voxdagi_grow(&ed->mem, (void **)&ed->change, &ed->change_cap, ed->change_n + 1, sizeof *ed->change))
        return NULL;
    made = voxdagi_ed_new_block(ed);
    if (made == VOXDAGI_NO_BLOCK) return NULL;
    c = voxdagi_ed_block(ed, made);
    if (!whole && old != VOXDAGI_NO_BLOCK) memcpy(c, voxdagi_ed_block(ed, old), 64 * sizeof *c);
    else if (!whole) for (k = 0; k < 64; k++) c[k] = VOXDAGI_WHITE;
    ed->change[ed->change_n].brick = brick;
    ed->change[ed->change_n].before = old;
    ed->change[ed->change_n].after = made;
    ed->change_n++;
    *at = made;
    return c;
}

/* Points every brick of changes [BEGIN, END) at its block before (or after). */
static void voxdagi_ed_replay(voxdag_editor *ed, size_t begin, size_t end, int after) {
    size_t k;
    if (after) {
        for (k = begin; k < end; k++) *voxdagi_ed_map_find(ed, ed->change[k].brick) = ed->change[k].after;
    } else {
        for (k = end; k-- > begin;) *voxdagi_ed_map_find(ed, ed->change[k].brick) = ed->change[k].before;
    }
}

static uint32_t voxdagi_pack_rgb(const uint8_t rgb[3]) {
    return (uint32_t)rgb[0] << 16 | (uint32_t)rgb[1] << 8 | rgb[2];
}

static void voxdagi_unpack_rgb(uint32_t c, uint8_t rgb[3]) {
    rgb[0] = (uint8_t)(c >> 16);
    rgb[1] = (uint8_t)(c >> 8);
    rgb[2] = (uint8_t)c;
}

/* Colours the voxels BITS of brick BRICK with BRUSH (NULL: white). Returns 0
   when out of memory. */
static int voxdagi_ed_paint_bits(voxdag_editor *ed, uint64_t brick, uint64_t bits, const voxdag_brush *brush) {
    uint32_t *c, fixed = brush ? voxdagi_pack_rgb(brush->rgb) : VOXDAGI_WHITE, x, y, z;
    if (!ed->colors || !bits) return 1;
    c = voxdagi_ed_colors_to_write(ed, brick, bits == ~0ull);
    if (!c) return 0;
    if (!brush || !brush->fn) {
        for (; bits; bits &= bits - 1) c[voxdagi_lowest_bit(bits)] = fixed;
        return 1;
    }
    voxdag_morton_decode(brick << 6, &x, &y, &z); /* the brick's lowest voxel */
    for (; bits; bits &= bits - 1) {
        unsigned p = voxdagi_lowest_bit(bits);
        uint8_t rgb[3] = {0, 0, 0};
        brush->fn(brush->user, x + (p & 1) + (p >> 2 & 2), y + (p >> 1 & 1) + (p >> 3 & 2),
                  z + (p >> 2 & 1) + (p >> 4 & 2), rgb);
        c[p] = voxdagi_pack_rgb(rgb);
    }
    return 1;
}

// -- Editing: transactions and history

static void voxdagi_ed_drop_traced(voxdag_editor *ed) {
    voxdag_free(ed->traced);
    ed->traced = NULL;
}

/* Starts an edit: room for its record, a serial of its own. */
static voxdag_status voxdagi_ed_begin(voxdag_editor *ed, voxdag_error *err) {
    if (!voxdagi_grow(&ed->mem, (void **)&ed->history, &ed->history_cap, ed->kept + 1, sizeof *ed->history))
        return voxdagi_mem_fail(&ed->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory");
    ed->serial++;
    ed->red.failed = 0;
    ed->edit_change_begin = ed->change_n;
    return VOXDAG_OK;
}

/* Ends an edit that made ROOT: applies it, or (after a failure) undoes its
   colour changes and keeps the scene as it was. The edits that could be
   redone are discarded only by an edit that succeeds. */
static voxdag_status voxdagi_ed_end(voxdag_editor *ed, uint32_t root, int failed, voxdag_error *err) {
    size_t begin = ed->edit_change_begin, n = ed->change_n - begin, at;
    voxdagi_edit_record *rec;
    if (failed || ed->red.failed) {
        voxdagi_ed_replay(ed, begin, ed->change_n, 0);
        voxdagi_ed_spare(ed, begin, ed->change_n);
        ed->change_n = begin;
        ed->red.failed = 0;
        return voxdagi_mem_fail(&ed->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    at = ed->done ? ed->history[ed->done - 1].change_end : 0;
    voxdagi_ed_spare(ed, at, begin); /* the edits that could be redone */
    if (n && at != begin) memmove(ed->change + at, ed->change + begin, n * sizeof *ed->change);
    ed->change_n = at + n;
    rec = &ed->history[ed->done];
    rec->root_before = ed->root;
    rec->root_after = root;
    rec->change_begin = at;
    rec->change_end = at + n;
    ed->kept = ++ed->done;
    ed->root = root;
    voxdagi_ed_drop_traced(ed);
    return voxdagi_ok(err);
}

VOXDAG_API int voxdag_editor_undo(voxdag_editor *ed) {
    voxdagi_edit_record *rec;
    if (!ed || !ed->done) return 0;
    rec = &ed->history[--ed->done];
    voxdagi_ed_replay(ed, rec->change_begin, rec->change_end, 0);
    ed->root = rec->root_before;
    voxdagi_ed_drop_traced(ed);
    return 1;
}

VOXDAG_API int voxdag_editor_redo(voxdag_editor *ed) {
    voxdagi_edit_record *rec;
    if (!ed || ed->done == ed->kept) return 0;
    rec = &ed->history[ed->done++];
    voxdagi_ed_replay(ed, rec->change_begin, rec->change_end, 1);
    ed->root = rec->root_after;
    voxdagi_ed_drop_traced(ed);
    return 1;
}

static void voxdagi_ed_free_chunks(voxdag_editor *ed, uint32_t **chunk, size_t n, size_t cap) {
    size_t c;
    for (c = 0; c < n; c++) voxdagi_free(&ed->mem, chunk[c], (64u << VOXDAGI_ED_CHUNK_BITS) * sizeof **chunk);
    voxdagi_free(&ed->mem, chunk, cap * sizeof *chunk);
}

VOXDAG_API voxdag_status voxdag_editor_forget_history(voxdag_editor *ed, voxdag_error *err) {
    uint32_t **chunk = NULL;
    size_t i, n = 0, chunks, made = 0;
    if (!ed) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "no editor");
    for (i = 0; i < 64 * ed->map_n; i++) n += ed->group_block[i] != VOXDAGI_NO_BLOCK;
    chunks = (n + (1u << VOXDAGI_ED_CHUNK_BITS) - 1) >> VOXDAGI_ED_CHUNK_BITS;
    if (chunks && (chunk = (uint32_t **)voxdagi_alloc(&ed->mem, chunks * sizeof *chunk)) != NULL)
        for (; made < chunks; made++)
            if (!(chunk[made] = (uint32_t *)voxdagi_alloc(&ed->mem, (64u << VOXDAGI_ED_CHUNK_BITS) * sizeof **chunk))) break;
    if (made < chunks) {
        if (chunk) voxdagi_ed_free_chunks(ed, chunk, made, chunks);
        return voxdagi_mem_fail(&ed->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory");
    }
    for (i = 0, n = 0; i < 64 * ed->map_n; i++) { /* the blocks the scene uses now, packed */
        uint32_t *to;
        if (ed->group_block[i] == VOXDAGI_NO_BLOCK) continue;
        to = chunk[n >> VOXDAGI_ED_CHUNK_BITS] + 64 * (n & ((1u << VOXDAGI_ED_CHUNK_BITS) - 1));
        memcpy(to, voxdagi_ed_block(ed, ed->group_block[i]), 64 * sizeof *to);
        ed->block_serial[n] = 0; /* no edit's: the next one copies before writing */
        ed->group_block[i] = (uint32_t)n++;
    }
    voxdagi_ed_free_chunks(ed, ed->chunk, ed->chunk_n, ed->chunk_cap);
    ed->chunk = chunk;
    ed->chunk_n = ed->chunk_cap = chunks;
    ed->block_n = n;
    ed->spare_n = 0;
    ed->change_n = 0;
    ed->done = ed->kept = 0;
    return voxdagi_ok(err);
}

// -- Editing: shapes

enum { VOXDAGI_OUTSIDE, VOXDAGI_PARTLY, VOXDAGI_INSIDE };
enum { VOXDAGI_FILL, VOXDAGI_CARVE, VOXDAGI_PAINT };

/* A shape edit: what it does, where (integers, spheres doubled), with what. */
typedef struct voxdagi_ed_op {
    int action;
    voxdag_shape_kind kind;
    int64_t lo[3], hi[3];       /* box */
    int64_t c2[3], r2;          /* sphere: 2 centre, 4 radius^2 */
    const voxdag_brush *brush;
} voxdagi_ed_op;

/* The smallest and largest (2v+1-c2)^2 over v in [o, o+size). */
static void voxdagi_ed_sq_range(int64_t o, int64_t size, int64_t c2, int64_t *lo, int64_t *hi) {
    int64_t a = 2 * o + 1 - c2, b = 2 * (o + size - 1) + 1 - c2;
    int64_t aa = a < 0 ? -a : a, bb = b < 0 ? -b : b;
    *hi = aa > bb ? aa * aa : bb * bb;
    *lo = a <= 0 && b >= 0 ? 1 : aa < bb ? aa * aa : bb * bb;
}

/* Where the cube [o, o+size)^3 lies against the op's shape. */
static int voxdagi_ed_classify(const voxdagi_ed_op *op, const int64_t o[3], int64_t size) {
    unsigned a;
    if (op->kind == VOXDAG_SHAPE_BOX) {
        int inside = 1;
        for (a = 0; a < 3; a++) {
            if (op->hi[a] <= op->lo[a] || o[a] + size <= op->lo[a] || o[a] >= op->hi[a]) return VOXDAGI_OUTSIDE;
            if (o[a] < op->lo[a] || o[a] + size > op->hi[a]) inside = 0;
        }
        return inside ? VOXDAGI_INSIDE : VOXDAGI_PARTLY;
    } else {
        int64_t least = 0, most = 0, lo, hi; /* the squared distance's range over the cell */
        for (a = 0; a < 3; a++) {
            voxdagi_ed_sq_range(o[a], size, op->c2[a], &lo, &hi);
            least += lo;
            most += hi;
        }
        return least > op->r2 ? VOXDAGI_OUTSIDE : most <= op->r2 ? VOXDAGI_INSIDE : VOXDAGI_PARTLY;
    }
}

/* The voxels of the brick at O that lie in the op's shape. */
static uint64_t voxdagi_ed_shape_mask(const voxdagi_ed_op *op, const int64_t o[3]) {
    uint64_t mask = 0;
    unsigned p;
    int cls = voxdagi_ed_classify(op, o, 4);
    if (cls != VOXDAGI_PARTLY) return cls == VOXDAGI_INSIDE ? ~0ull : 0;
    for (p = 0; p < 64; p++) {
        int64_t v[3];
        v[0] = o[0] + (p & 1) + (p >> 2 & 2);
        v[1] = o[1] + (p >> 1 & 1) + (p >> 3 & 2);
        v[2] = o[2] + (p >> 2 & 1) + (p >> 4 & 2);
        if (voxdagi_ed_classify(op, v, 1) == VOXDAGI_INSIDE) mask |= 1ull << p;
    }
    return mask;
}

/* Applies OP to the subtree REF of LEVEL whose lowest voxel is O (Morton
   prefix KEY); returns the new reference. Depth at most L - 1. */
static uint32_t voxdagi_ed_apply(voxdag_editor *ed, const voxdagi_ed_op *op, uint32_t level, uint32_t ref,
                                 const int64_t o[3], uint64_t key) {
    int64_t size = (int64_t)1 << (ed->levels - level);
    int cls = voxdagi_ed_classify(op, o, size);
    int colored = ed->colors && (op->action == VOXDAGI_PAINT || op->action == VOXDAGI_FILL);
    uint32_t child[8], made[8];
    unsigned j, same = 1;
    if (cls == VOXDAGI_OUTSIDE || ed->red.failed) return ref;
    if (op->action == VOXDAGI_PAINT && ref == VOXDAGI_NONE) return ref;
    if (op->action == VOXDAGI_CARVE && (ref == VOXDAGI_NONE || cls == VOXDAGI_INSIDE)) return VOXDAGI_NONE;
    if (op->action == VOXDAGI_FILL && cls == VOXDAGI_INSIDE) {
        uint32_t full = voxdagi_ed_full(ed, level);
        if (full == VOXDAGI_NONE) return ref;
        if (!colored || (full == ref && !op->brush)) return full;
    }
    if (level == ed->levels - 2) {
        uint64_t old = voxdagi_ed_brick(ed, ref), in = voxdagi_ed_shape_mask(op, o), now = old, bits = 0;
        if (op->action == VOXDAGI_FILL) now = old | in, bits = op->brush ? in : in & ~old;
        if (op->action == VOXDAGI_CARVE) now = old & ~in;
        if (op->action == VOXDAGI_PAINT) bits = old & in;
        if (colored && !voxdagi_ed_paint_bits(ed, key, bits, op->brush)) ed->red.failed = 1;
        return now == old ? ref : voxdagi_ed_brick_ref(ed, now);
    }
    voxdagi_ed_children(ed, level, ref, child);
    for (j = 0; j < 8; j++) {
        int64_t c[3];
        voxdagi_ed_child_corner(o, size, j, c);
        made[j] = voxdagi_ed_apply(ed, op, level + 1, child[j], c, key << 3 | j);
        same &= made[j] == child[j];
    }
    return same ? ref : voxdagi_ed_node(ed, level, made);
}

/* Checks a shape and turns it into an op. */
static voxdag_status voxdagi_ed_op_make(voxdagi_ed_op *op, int action, const voxdag_shape *shape,
                                        const voxdag_brush *brush, voxdag_error *err) {
    unsigned a;
    memset(op, 0, sizeof *op);
    if (!shape || (shape->kind != VOXDAG_SHAPE_BOX && shape->kind != VOXDAG_SHAPE_SPHERE))
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "no shape, or an unknown shape kind");
    op->action = action;
    op->kind = shape->kind;
    op->brush = brush;
    for (a = 0; a < 3; a++) {
        const int64_t *v = shape->kind == VOXDAG_SHAPE_BOX ? shape->lo : shape->center;
        const int64_t *w = shape->kind == VOXDAG_SHAPE_BOX ? shape->hi : shape->center;
        if (v[a] < -VOXDAGI_EDIT_COORD_MAX || v[a] > VOXDAGI_EDIT_COORD_MAX ||
            w[a] < -VOXDAGI_EDIT_COORD_MAX || w[a] > VOXDAGI_EDIT_COORD_MAX)
            return VOXDAGI_FAIL(err, VOXDAG_ERR_COORDINATE, "a shape coordinate is beyond +-2^28");
        op->lo[a] = shape->lo[a];
        op->hi[a] = shape->hi[a];
        op->c2[a] = 2 * shape->center[a];
    }
    if (shape->kind == VOXDAG_SHAPE_SPHERE) {
        if (shape->radius < 0) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "a negative radius");
        if (shape->radius > VOXDAGI_EDIT_COORD_MAX)
            return VOXDAGI_FAIL(err, VOXDAG_ERR_COORDINATE, "a radius beyond 2^28");
        op->r2 = 4 * shape->radius * shape->radius;
    }
    return VOXDAG_OK;
}

/* One shape edit, as a whole edit of the history. */
static voxdag_status voxdagi_ed_shape_edit(voxdag_editor *ed, int action, const voxdag_shape *shape,
                                           const voxdag_brush *brush, voxdag_error *err) {
    voxdagi_ed_op op;
    int64_t o[3] = {0, 0, 0};
    voxdag_status st;
    uint32_t root;
    if (!ed) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "no editor");
    if ((st = voxdagi_ed_op_make(&op, action, shape, brush, err)) != VOXDAG_OK) return st;
    if ((st = voxdagi_ed_begin(ed, err)) != VOXDAG_OK) return st;
    root = voxdagi_ed_apply(ed, &op, 0, ed->root, o, 0);
    return voxdagi_ed_end(ed, root, 0, err);
}

VOXDAG_API voxdag_status voxdag_editor_fill(voxdag_editor *ed, const voxdag_shape *shape,
                                            const voxdag_brush *brush, voxdag_error *err) {
    return voxdagi_ed_shape_edit(ed, VOXDAGI_FILL, shape, brush, err);
}

VOXDAG_API voxdag_status voxdag_editor_carve(voxdag_editor *ed, const voxdag_shape *shape, voxdag_error *err) {
    return voxdagi_ed_shape_edit(ed, VOXDAGI_CARVE, shape, NULL, err);
}

VOXDAG_API voxdag_status voxdag_editor_paint(voxdag_editor *ed, const voxdag_shape *shape,
                                             const voxdag_brush *brush, voxdag_error *err) {
    if (!brush) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "paint needs a brush");
    return voxdagi_ed_shape_edit(ed, VOXDAGI_PAINT, shape, brush, err);
}

// -- Editing: voxel lists

/* One voxel of a list edit: its Morton code, whether it becomes full, its
   colour (HAS_RGB 0: white when new, else kept) and its order in the call. */
typedef struct voxdagi_ed_voxel {
    uint64_t code;
    uint32_t rgb;
    uint8_t full, has_rgb;
    size_t order;
} voxdagi_ed_voxel;

static int voxdagi_ed_voxel_cmp(const void *a, const void *b) {
    const voxdagi_ed_voxel *u = (const voxdagi_ed_voxel *)a, *v = (const voxdagi_ed_voxel *)b;
    if (u->code != v->code) return u->code < v->code ? -1 : 1;
    return u->order < v->order ? -1 : u->order > v->order;
}

/* Applies the voxels V[0..N) (sorted by code, all inside this subtree) to
   subtree REF of LEVEL with Morton prefix KEY. */
static uint32_t voxdagi_ed_apply_list(voxdag_editor *ed, uint32_t level, uint32_t ref, uint64_t key,
                                      const voxdagi_ed_voxel *v, size_t n) {
    uint32_t child[8], made[8];
    unsigned j, same = 1, shift;
    size_t i = 0;
    if (!n || ed->red.failed) return ref;
    if (level == ed->levels - 2) {
        uint64_t old = voxdagi_ed_brick(ed, ref), now = old;
        uint32_t *c = NULL;
        for (i = 0; i < n; i++) {
            uint64_t bit = 1ull << (v[i].code & 63);
            int fresh = v[i].full && !(now & bit);
            now = v[i].full ? now | bit : now & ~bit;
            if (ed->colors && v[i].full && (v[i].has_rgb || fresh)) {
                if (!c && !(c = voxdagi_ed_colors_to_write(ed, key, 0))) {
                    ed->red.failed = 1;
                    return ref;
                }
                c[v[i].code & 63] = v[i].has_rgb ? v[i].rgb : VOXDAGI_WHITE;
            }
        }
        return now == old ? ref : voxdagi_ed_brick_ref(ed, now);
    }
    shift = 3 * (ed->levels - level - 1);
    voxdagi_ed_children(ed, level, ref, child);
    for (j = 0; j < 8; j++) {
        size_t begin = i;
        while (i < n && (v[i].code >> shift & 7) == j) i++;
        made[j] = voxdagi_ed_apply_list(ed, level + 1, child[j], key << 3 | j, v + begin, i - begin);
        same &= made[j] == child[j];
    }
    return same ? ref : voxdagi_ed_node(ed, level, made);
}

/* Applies the list V (N voxels, sorted here) as part of the current edit. */
static uint32_t voxdagi_ed_list(voxdag_editor *ed, uint32_t root, voxdagi_ed_voxel *v, size_t n) {
    size_t i = 1;
    while (i < n && v[i - 1].code < v[i].code) i++; /* lists in Morton order need no sort */
    if (i < n) qsort(v, n, sizeof *v, voxdagi_ed_voxel_cmp);
    return voxdagi_ed_apply_list(ed, 0, root, 0, v, n);
}

static voxdag_status voxdagi_ed_list_edit(voxdag_editor *ed, const uint32_t *xyz, const uint8_t *rgb,
                                          size_t n, int full, voxdag_error *err) {
    voxdagi_ed_voxel *v;
    voxdag_status st;
    uint32_t root;
    size_t i, bytes;
    if (!ed || (n && !xyz)) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "no editor or no voxels");
    for (i = 0; i < n; i++)
        if ((xyz[3 * i] | xyz[3 * i + 1] | xyz[3 * i + 2]) >> ed->levels)
            return voxdagi_fail(err, VOXDAG_ERR_COORDINATE, "a voxel outside the grid", UINT64_MAX, i);
    if (n > (size_t)-1 / sizeof *v) return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, "too many voxels");
    bytes = n * sizeof *v;
    v = (voxdagi_ed_voxel *)voxdagi_alloc(&ed->mem, bytes);
    if (!v) return voxdagi_mem_fail(&ed->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory");
    for (i = 0; i < n; i++) {
        v[i].code = voxdag_morton_encode(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
        v[i].full = (uint8_t)full;
        v[i].has_rgb = (uint8_t)(full && rgb);
        v[i].rgb = full && rgb ? voxdagi_pack_rgb(rgb + 3 * i) : 0;
        v[i].order = i;
    }
    st = voxdagi_ed_begin(ed, err);
    if (st == VOXDAG_OK) {
        root = voxdagi_ed_list(ed, ed->root, v, n);
        st = voxdagi_ed_end(ed, root, 0, err);
    }
    voxdagi_free(&ed->mem, v, bytes);
    return st;
}

VOXDAG_API voxdag_status voxdag_editor_set(voxdag_editor *ed, const uint32_t *xyz, const uint8_t *rgb,
                                           size_t n, voxdag_error *err) {
    return voxdagi_ed_list_edit(ed, xyz, rgb, n, 1, err);
}

VOXDAG_API voxdag_status voxdag_editor_clear(voxdag_editor *ed, const uint32_t *xyz, size_t n, voxdag_error *err) {
    return voxdagi_ed_list_edit(ed, xyz, NULL, n, 0, err);
}

// -- Editing: queries

/* Visits the full voxels of subtree REF (LEVEL, lowest voxel O, prefix KEY)
   inside BOX (an op, NULL: all) in Morton order, counting *INDEX; stops
   when FN returns nonzero (returns 1 then). */
typedef int (*voxdagi_ed_visit_fn)(void *user, const voxdag_editor *ed, uint64_t code, uint64_t index);

static int voxdagi_ed_visit(const voxdag_editor *ed, const voxdagi_ed_op *box, uint32_t level, uint32_t ref,
                            const int64_t o[3], uint64_t key, uint64_t *index, voxdagi_ed_visit_fn fn, void *user) {
    int64_t size = (int64_t)1 << (ed->levels - level);
    uint32_t child[8];
    unsigned j;
    if (ref == VOXDAGI_NONE) return 0;
    if (box && voxdagi_ed_classify(box, o, size) == VOXDAGI_OUTSIDE) {
        *index += voxdagi_ed_count(ed, level, ref);
        return 0;
    }
    if (level == ed->levels - 2) {
        uint64_t mask = voxdagi_ed_brick(ed, ref), in = box ? voxdagi_ed_shape_mask(box, o) : ~0ull;
        for (; mask; mask &= mask - 1) {
            unsigned p = voxdagi_lowest_bit(mask);
            if ((in >> p & 1) && fn && fn(user, ed, key << 6 | p, *index)) return 1;
            ++*index;
        }
        return 0;
    }
    voxdagi_ed_children(ed, level, ref, child);
    for (j = 0; j < 8; j++) {
        int64_t c[3];
        voxdagi_ed_child_corner(o, size, j, c);
        if (voxdagi_ed_visit(ed, box, level + 1, child[j], c, key << 3 | j, index, fn, user)) return 1;
    }
    return 0;
}

static uint32_t voxdagi_ed_color_at(const voxdag_editor *ed, uint64_t code) {
    const uint32_t *c = voxdagi_ed_colors(ed, code >> 6);
    return c ? c[code & 63] : VOXDAGI_WHITE;
}

VOXDAG_API uint64_t voxdag_editor_voxels(const voxdag_editor *ed) {
    return ed ? voxdagi_ed_count(ed, 0, ed->root) : 0;
}

VOXDAG_API uint64_t voxdag_editor_memory(const voxdag_editor *ed) { return ed ? ed->mem.used : 0; }

VOXDAG_API int voxdag_editor_lookup(const voxdag_editor *ed, uint32_t x, uint32_t y, uint32_t z,
                                    uint64_t *index) {
    uint32_t level, ref, child[8];
    uint64_t code, at = 0, mask;
    unsigned j, p;
    if (!ed || (x | y | z) >> ed->levels) return 0;
    code = voxdag_morton_encode(x, y, z);
    ref = ed->root;
    for (level = 0; level + 2 < ed->levels && ref != VOXDAGI_NONE; level++) {
        unsigned w = (unsigned)(code >> 3 * (ed->levels - level - 1) & 7);
        voxdagi_ed_children(ed, level, ref, child);
        for (j = 0; j < w; j++) at += voxdagi_ed_count(ed, level + 1, child[j]);
        ref = child[w];
    }
    if (ref == VOXDAGI_NONE) return 0;
    mask = voxdagi_ed_brick(ed, ref);
    p = (unsigned)(code & 63);
    if (!(mask >> p & 1)) return 0;
    if (index) *index = at + (uint64_t)voxdagi_popcount64(mask & ((1ull << p) - 1));
    return 1;
}

VOXDAG_API int voxdag_editor_color(const voxdag_editor *ed, uint64_t index, uint8_t rgb[3]) {
    uint32_t level, ref, child[8];
    uint64_t code = 0, mask;
    unsigned j;
    if (!ed || !rgb || !ed->colors || index >= voxdag_editor_voxels(ed)) return 0;
    ref = ed->root;
    for (level = 0; level + 2 < ed->levels; level++) { /* the voxel of rank INDEX */
        voxdagi_ed_children(ed, level, ref, child);
        for (j = 0; j < 8; j++) {
            uint64_t c = voxdagi_ed_count(ed, level + 1, child[j]);
            if (index < c) break;
            index -= c;
        }
        code = code << 3 | j;
        ref = child[j];
    }
    mask = voxdagi_ed_brick(ed, ref);
    while (index--) mask &= mask - 1;
    voxdagi_unpack_rgb(voxdagi_ed_color_at(ed, code << 6 | voxdagi_lowest_bit(mask)), rgb);
    return 1;
}

typedef struct voxdagi_ed_each {
    voxdag_voxel_fn fn;
    void *user;
} voxdagi_ed_each;

static int voxdagi_ed_each_voxel(void *user, const voxdag_editor *ed, uint64_t code, uint64_t index) {
    voxdagi_ed_each *e = (voxdagi_ed_each *)user;
    uint32_t x, y, z;
    (void)ed;
    voxdag_morton_decode(code, &x, &y, &z);
    return e->fn(e->user, x, y, z, index);
}

VOXDAG_API uint64_t voxdag_editor_for_each_voxel(const voxdag_editor *ed, voxdag_voxel_fn fn, void *user) {
    voxdagi_ed_each e;
    uint64_t index = 0;
    int64_t o[3] = {0, 0, 0};
    if (!ed) return 0;
    if (!fn) return voxdag_editor_voxels(ed);
    e.fn = fn;
    e.user = user;
    if (voxdagi_ed_visit(ed, NULL, 0, ed->root, o, 0, &index, voxdagi_ed_each_voxel, &e)) index++;
    return index;
}

VOXDAG_API voxdag_status voxdag_editor_nodes(voxdag_editor *ed, uint64_t nodes[VOXDAG_LEVEL_CAPACITY],
                                             voxdag_error *err) {
    uint8_t *seen[VOXDAG_MAX_LEVELS];
    voxdag_status st = VOXDAG_OK;
    uint32_t l, last;
    if (!ed || !nodes) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "a NULL argument");
    memset(nodes, 0, VOXDAG_LEVEL_CAPACITY * sizeof *nodes);
    memset(seen, 0, sizeof seen);
    last = ed->levels - 2;
    for (l = 0; l <= last && st == VOXDAG_OK; l++) {
        seen[l] = (uint8_t *)voxdagi_alloc(&ed->mem, ed->red.store[l].n);
        if (!seen[l]) st = voxdagi_mem_fail(&ed->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory");
        else memset(seen[l], 0, ed->red.store[l].n);
    }
    if (st == VOXDAG_OK && ed->root != VOXDAGI_NONE) { /* marks level by level, top down */
        seen[0][ed->root >> 6] = 1;
        for (l = 0; l <= last; l++) {
            size_t id;
            unsigned j;
            for (id = 0; id < ed->red.store[l].n; id++) {
                if (!seen[l][id]) continue;
                nodes[l]++;
                if (l == last) continue;
                for (j = 0; j < 8; j++) {
                    uint32_t c = ed->red.store[l].child[8 * id + j];
                    if (c != VOXDAGI_NONE) seen[l + 1][c >> 6] = 1;
                }
            }
        }
    }
    for (l = 0; l <= last; l++) voxdagi_free(&ed->mem, seen[l], ed->red.store[l].n);
    return st == VOXDAG_OK ? voxdagi_ok(err) : st;
}

// -- Editing: copy a box

/* The full voxels of the copy's source, moved, with their colours. */
typedef struct voxdagi_ed_gather {
    voxdagi_ed_voxel *v;
    size_t n, cap;
    int64_t offset[3];
    voxdagi_mem *mem;
    int failed;
} voxdagi_ed_gather;

static int voxdagi_ed_gather_voxel(void *user, const voxdag_editor *ed, uint64_t code, uint64_t index) {
    voxdagi_ed_gather *g = (voxdagi_ed_gather *)user;
    uint32_t xyz[3];
    int64_t d[3];
    unsigned a;
    (void)index;
    voxdag_morton_decode(code, &xyz[0], &xyz[1], &xyz[2]);
    for (a = 0; a < 3; a++) {
        d[a] = (int64_t)xyz[a] + g->offset[a];
        if (d[a] < 0 || d[a] >> ed->levels) return 0; /* dropped */
    }
    if (!voxdagi_grow(g->mem, (void **)&g->v, &g->cap, g->n + 1, sizeof *g->v)) {
        g->failed = 1;
        return 1;
    }
    g->v[g->n].code = voxdag_morton_encode((uint32_t)d[0], (uint32_t)d[1], (uint32_t)d[2]);
    g->v[g->n].rgb = voxdagi_ed_color_at(ed, code);
    g->v[g->n].full = 1;
    g->v[g->n].has_rgb = (uint8_t)ed->colors;
    g->v[g->n].order = g->n;
    g->n++;
    return 0;
}

VOXDAG_API voxdag_status voxdag_editor_copy(voxdag_editor *ed, const int64_t lo[3], const int64_t hi[3],
                                            const int64_t offset[3], voxdag_error *err) {
    voxdagi_ed_op src, dst;
    voxdagi_ed_gather g;
    voxdag_shape box;
    voxdag_status st;
    int64_t o[3] = {0, 0, 0};
    uint64_t index = 0;
    uint32_t root;
    unsigned a;
    if (!ed || !lo || !hi || !offset) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "a NULL argument");
    memset(&box, 0, sizeof box);
    box.kind = VOXDAG_SHAPE_BOX;
    for (a = 0; a < 3; a++) {
        if (offset[a] < -VOXDAGI_EDIT_COORD_MAX || offset[a] > VOXDAGI_EDIT_COORD_MAX)
            return VOXDAGI_FAIL(err, VOXDAG_ERR_COORDINATE, "an offset beyond +-2^28");
        box.lo[a] = lo[a];
        box.hi[a] = hi[a];
    }
    if ((st = voxdagi_ed_op_make(&src, VOXDAGI_CARVE, &box, NULL, err)) != VOXDAG_OK) return st;
    /* the destination: the source's part inside the grid, moved */
    dst = src;
    for (a = 0; a < 3; a++) {
        int64_t l = lo[a] < 0 ? 0 : lo[a], h = hi[a] > ((int64_t)1 << ed->levels) ? (int64_t)1 << ed->levels : hi[a];
        dst.lo[a] = l + offset[a];
        dst.hi[a] = h + offset[a];
    }
    memset(&g, 0, sizeof g);
    memcpy(g.offset, offset, sizeof g.offset);
    g.mem = &ed->mem;
    voxdagi_ed_visit(ed, &src, 0, ed->root, o, 0, &index, voxdagi_ed_gather_voxel, &g);
    st = g.failed ? voxdagi_mem_fail(&ed->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory")
                  : voxdagi_ed_begin(ed, err);
    if (st == VOXDAG_OK) {
        root = voxdagi_ed_apply(ed, &dst, 0, ed->root, o, 0);
        root = voxdagi_ed_list(ed, root, g.v, g.n);
        st = voxdagi_ed_end(ed, root, 0, err);
    }
    voxdagi_free(&ed->mem, g.v, g.cap * sizeof *g.v);
    return st;
}

// -- Editing: opening and committing

typedef struct voxdagi_ed_open {
    voxdag_editor *ed;
    const voxdag *dag;
    int failed; /* 1 memory, 2 colours */
} voxdagi_ed_open;

static int voxdagi_ed_open_voxel(void *user, uint32_t x, uint32_t y, uint32_t z, uint64_t index) {
    voxdagi_ed_open *op = (voxdagi_ed_open *)user;
    uint64_t code = voxdag_morton_encode(x, y, z);
    voxdagi_reducer_voxel(&op->ed->red, code);
    if (op->ed->colors) {
        uint8_t rgb[3];
        uint32_t *c;
        if (voxdag_color(op->dag, index, rgb) != 1) {
            op->failed = 2;
            return 1;
        }
        c = voxdagi_ed_colors_to_write(op->ed, code >> 6, 0);
        if (!c) {
            op->failed = 1;
            return 1;
        }
        c[code & 63] = voxdagi_pack_rgb(rgb);
    }
    return op->ed->red.failed;
}

VOXDAG_API voxdag_status voxdag_editor_create(const voxdag *dag, const voxdag_editor_opts *opts,
                                              voxdag_editor **out, voxdag_error *err) {
    voxdag_editor_opts o;
    voxdag_editor *ed;
    voxdagi_mem mem;
    uint32_t l;
    if (!out) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "OUT is NULL");
    *out = NULL;
    memset(&o, 0, sizeof o);
    if (opts) o = *opts;
    if (o.zero_begin || o.zero_end)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "options not initialised (zero_begin/zero_end)");
    if (!o.levels) o.levels = 10;
    if (o.levels < 2 || o.levels > VOXDAG_MAX_LEVELS)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_LIMIT, "levels outside 2..VOXDAG_MAX_LEVELS");
    if ((unsigned)o.symmetry >= VOXDAG_SYMMETRY_COUNT)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "unknown symmetry");
    if (!o.allocator.alloc != !o.allocator.free)
        return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "allocator: give alloc and free, or neither");
    voxdagi_mem_init(&mem, &o.allocator, o.max_memory);
    ed = (voxdag_editor *)voxdagi_alloc(&mem, sizeof *ed);
    if (!ed) {
        voxdag_status st = voxdagi_mem_fail(&mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory");
        voxdagi_mem_destroy(&mem);
        return st;
    }
    memset(ed, 0, sizeof *ed);
    ed->mem = mem;
    if (dag) {
        voxdag_info info;
        voxdag_get_info(dag, &info);
        o.levels = info.levels;
        o.symmetry = info.symmetry;
        o.colors = info.color_kind != VOXDAG_COLORS_NONE;
        ed->has_bounds = info.has_bounds;
        memcpy(ed->bounds, info.bounds, sizeof ed->bounds);
    }
    ed->levels = o.levels;
    ed->symmetry = o.symmetry ? o.symmetry : VOXDAG_SYMMETRY_FULL;
    ed->colors = o.colors != 0;
    ed->root = VOXDAGI_NONE;
    for (l = 0; l < VOXDAG_MAX_LEVELS; l++) ed->full[l] = VOXDAGI_NONE;
    voxdagi_group_init(&ed->group, ed->symmetry);
    voxdagi_reducer_init(&ed->red, &ed->mem, &ed->group, ed->levels, 0);
    if (dag) {
        voxdagi_ed_open op;
        op.ed = ed;
        op.dag = dag;
        op.failed = 0;
        voxdag_for_each_voxel(dag, voxdagi_ed_open_voxel, &op);
        if (!op.failed && !ed->red.failed) voxdagi_reducer_finish(&ed->red);
        if (op.failed || ed->red.failed) {
            voxdag_status st = op.failed == 2 ? VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT,
                                                             "the colours cannot be decoded (voxcolor.h not compiled in)")
                                              : voxdagi_mem_fail(&ed->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory");
            voxdag_editor_free(ed);
            return st;
        }
        ed->root = ed->red.root;
        ed->change_n = 0; /* the colours read are the start, not an edit */
    }
    *out = ed;
    return voxdagi_ok(err);
}

VOXDAG_API void voxdag_editor_free(voxdag_editor *ed) {
    voxdagi_mem mem;
    if (!ed) return;
    voxdagi_ed_drop_traced(ed);
    voxdagi_reducer_free(&ed->red);
    voxdagi_ed_free_chunks(ed, ed->chunk, ed->chunk_n, ed->chunk_cap);
    voxdagi_free(&ed->mem, ed->block_serial, ed->serial_cap * sizeof *ed->block_serial);
    voxdagi_free(&ed->mem, ed->spare, ed->spare_cap * sizeof *ed->spare);
    voxdagi_free(&ed->mem, ed->map, ed->map_cap * sizeof *ed->map);
    voxdagi_free(&ed->mem, ed->group_block, ed->group_cap * sizeof *ed->group_block);
    voxdagi_free(&ed->mem, ed->change, ed->change_cap * sizeof *ed->change);
    voxdagi_free(&ed->mem, ed->history, ed->history_cap * sizeof *ed->history);
    mem = ed->mem;
    voxdagi_free(&mem, ed, sizeof *ed);
    voxdagi_mem_destroy(&mem);
}

/* The commit feeds the builder whole bricks in Morton order (its fast path,
   the same file as voxel by voxel), a chunk at a time. */
#define VOXDAGI_COMMIT_CHUNK 1024
typedef struct voxdagi_ed_feeder {
    voxdag_builder *b;
    uint64_t brick[2 * VOXDAGI_COMMIT_CHUNK]; /* key, mask */
    uint8_t rgb[3 * 64 * VOXDAGI_COMMIT_CHUNK];
    size_t n, colors;
    voxdag_status st;
    voxdag_error *err;
} voxdagi_ed_feeder;

static void voxdagi_ed_feed_flush(voxdagi_ed_feeder *f) {
    if (f->n && f->st == VOXDAG_OK) f->st = voxdag_builder_add_bricks(f->b, f->brick, f->rgb, f->n, f->err);
    f->n = f->colors = 0;
}

/* Feeds the bricks of subtree REF of LEVEL (Morton prefix KEY). */
static void voxdagi_ed_feed(const voxdag_editor *ed, voxdagi_ed_feeder *f, uint32_t level, uint32_t ref,
                            uint64_t key) {
    uint32_t child[8];
    unsigned j;
    if (ref == VOXDAGI_NONE || f->st != VOXDAG_OK) return;
    if (level == ed->levels - 2) {
        uint64_t mask = voxdagi_ed_brick(ed, ref), bits;
        const uint32_t *c = ed->colors ? voxdagi_ed_colors(ed, key) : NULL;
        f->brick[2 * f->n] = key;
        f->brick[2 * f->n + 1] = mask;
        for (bits = ed->colors ? mask : 0; bits; bits &= bits - 1)
            voxdagi_unpack_rgb(c ? c[voxdagi_lowest_bit(bits)] : VOXDAGI_WHITE, f->rgb + 3 * f->colors++);
        if (++f->n == VOXDAGI_COMMIT_CHUNK) voxdagi_ed_feed_flush(f);
        return;
    }
    voxdagi_ed_children(ed, level, ref, child);
    for (j = 0; j < 8; j++) voxdagi_ed_feed(ed, f, level + 1, child[j], key << 3 | j);
}

VOXDAG_API voxdag_status voxdag_editor_commit(voxdag_editor *ed, voxdag **out, voxdag_error *err) {
    voxdag_build_opts o;
    voxdagi_ed_feeder *f;
    voxdag_status st;
    if (!ed || !out) return VOXDAGI_FAIL(err, VOXDAG_ERR_INVALID_ARGUMENT, "a NULL argument");
    *out = NULL;
    memset(&o, 0, sizeof o);
    o.levels = ed->levels;
    o.symmetry = ed->symmetry;
    o.colors = ed->colors;
    o.bounds = ed->has_bounds ? ed->bounds : NULL;
    o.allocator = ed->mem.a;
    if (ed->mem.limit) o.max_memory = ed->mem.limit > ed->mem.used ? ed->mem.limit - ed->mem.used : 1;
    f = (voxdagi_ed_feeder *)voxdagi_alloc(&ed->mem, sizeof *f);
    if (!f) return voxdagi_mem_fail(&ed->mem, err, VOXDAG_ERR_OUT_OF_MEMORY, "out of memory");
    f->n = f->colors = 0;
    f->err = err;
    f->st = voxdag_builder_create(&o, &f->b, err);
    if (f->st == VOXDAG_OK) {
        voxdagi_ed_feed(ed, f, 0, ed->root, 0);
        voxdagi_ed_feed_flush(f);
        if (f->st == VOXDAG_OK) f->st = voxdag_builder_finish(f->b, out, NULL, err);
        else voxdag_builder_free(f->b);
    }
    st = f->st;
    voxdagi_free(&ed->mem, f, sizeof *f);
    return st;
}

#ifndef VOXDAG_NO_RAYTRACE
static int voxdagi_ed_trace_ready(voxdag_editor *ed) {
    return ed->traced || voxdag_editor_commit(ed, &ed->traced, NULL) == VOXDAG_OK;
}

VOXDAG_API int voxdag_editor_raycast(voxdag_editor *ed, const voxdag_ray *ray, const voxdag_ray_opts *opts,
                                     voxdag_hit *hit) {
    if (!ed || !voxdagi_ed_trace_ready(ed)) return -1;
    return voxdag_raycast(ed->traced, ray, opts, hit);
}

VOXDAG_API int voxdag_editor_occluded(voxdag_editor *ed, const voxdag_ray *ray, const voxdag_ray_opts *opts) {
    if (!ed || !voxdagi_ed_trace_ready(ed)) return -1;
    return voxdag_occluded_opts(ed->traced, ray, opts);
}
#endif
#endif /* VOXDAG_NO_BUILD */

#endif /* VOXDAG_IMPLEMENTED */
#endif /* VOXDAG_IMPLEMENTATION */

/*
MIT License. Copyright (c) 2026 The voxdag authors.
Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies of
the Software, and to permit persons to whom the Software is furnished to do so,
subject to the following conditions: The above copyright notice and this
permission notice shall be included in all copies or substantial portions of
the Software. THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND,
EXPRESS OR IMPLIED. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT HOLDERS BE LIABLE
FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY ARISING FROM THE SOFTWARE.
*/
