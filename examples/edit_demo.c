/* A short editing session with voxdag_editor: opens a .vdag file (or starts
   from an empty 256^3 scene), adds a planet, digs a tunnel through it, paints
   a band, copies the planet, undoes and redoes, asks about a voxel, and saves
   the result, whose bytes are those of a fresh build of the same voxels.
     edit_demo [IN.vdag] OUT.vdag
   Then: vdag render OUT.vdag OUT.png */
#define VOXDAG_IMPLEMENTATION
#include "voxdag.h"
#define VOXCOLOR_IMPLEMENTATION
#include "voxcolor.h"

#include <stdio.h>
#include <string.h>

/* Colours for the planet: blue oceans below a height, green land above. */
static void planet_color(void *user, uint32_t x, uint32_t y, uint32_t z, uint8_t rgb[3]) {
    (void)user, (void)x, (void)y;
    rgb[0] = (uint8_t)(z % 7 ? 40 : 90);
    rgb[1] = (uint8_t)(z > 100 ? 170 : 80);
    rgb[2] = (uint8_t)(z > 100 ? 60 : 200);
}

static int fail(const voxdag_error *err) {
    fprintf(stderr, "edit_demo: %s\n", err->message);
    return 1;
}

int main(int argc, char **argv) {
    voxdag *dag = NULL;
    voxdag_editor *ed;
    voxdag_editor_opts opts;
    voxdag_error err;
    voxdag_shape ball, tunnel;
    voxdag_brush earth, gold;
    int64_t lo[3], hi[3], offset[3] = {96, 0, 0};
    uint64_t index;
    uint8_t rgb[3];
    const char *out = argv[argc - 1];
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: edit_demo [IN.vdag] OUT.vdag\n");
        return 2;
    }
    memset(&opts, 0, sizeof opts);
    opts.levels = 8; /* an empty scene: 256^3 voxels with colours */
    opts.colors = 1;
    if (argc == 3 && voxdag_load_file(argv[1], NULL, &dag, &err) != VOXDAG_OK) return fail(&err);
    if (voxdag_editor_create(dag, &opts, &ed, &err) != VOXDAG_OK) return fail(&err);
    voxdag_free(dag); /* the editor holds the voxels and colours itself */

    memset(&ball, 0, sizeof ball);
    ball.kind = VOXDAG_SHAPE_SPHERE;
    ball.center[0] = 80, ball.center[1] = 128, ball.center[2] = 96;
    ball.radius = 40;
    memset(&earth, 0, sizeof earth);
    earth.fn = planet_color;
    memset(&tunnel, 0, sizeof tunnel);
    tunnel.kind = VOXDAG_SHAPE_BOX;
    tunnel.lo[0] = 30, tunnel.lo[1] = 120, tunnel.lo[2] = 88;
    tunnel.hi[0] = 130, tunnel.hi[1] = 136, tunnel.hi[2] = 104;
    memset(&gold, 0, sizeof gold);
    gold.rgb[0] = 255, gold.rgb[1] = 200, gold.rgb[2] = 40;
    if (voxdag_editor_fill(ed, &ball, &earth, &err) != VOXDAG_OK ||
        voxdag_editor_carve(ed, &tunnel, &err) != VOXDAG_OK)
        return fail(&err);
    tunnel.lo[0] = 0, tunnel.lo[1] = 0, tunnel.lo[2] = 120; /* a golden band: the voxels of a thin slab */
    tunnel.hi[0] = 256, tunnel.hi[1] = 256, tunnel.hi[2] = 124;
    if (voxdag_editor_paint(ed, &tunnel, &gold, &err) != VOXDAG_OK) return fail(&err);
    lo[0] = 40, lo[1] = 88, lo[2] = 56;  /* the planet's bounding box ... */
    hi[0] = 121, hi[1] = 169, hi[2] = 137;
    if (voxdag_editor_copy(ed, lo, hi, offset, &err) != VOXDAG_OK) return fail(&err); /* ... moved along x */
    printf("after 4 edits: %llu voxels\n", (unsigned long long)voxdag_editor_voxels(ed));
    voxdag_editor_undo(ed); /* the copy */
    printf("undo the copy: %llu voxels\n", (unsigned long long)voxdag_editor_voxels(ed));
    voxdag_editor_redo(ed);
    if (voxdag_editor_lookup(ed, 80, 128, 121, &index) && voxdag_editor_color(ed, index, rgb))
        printf("voxel (80, 128, 121): index %llu, colour %u %u %u (the golden band)\n", (unsigned long long)index,
               rgb[0], rgb[1], rgb[2]);

    if (voxdag_editor_commit(ed, &dag, &err) != VOXDAG_OK) return fail(&err);
    voxdag_editor_free(ed);
    if (voxdag_save_file(dag, out, &err) != VOXDAG_OK) return fail(&err);
    printf("wrote %s\n", out);
    voxdag_free(dag);
    return 0;
}
