/* Game-scene importers for the vdag tool: .spm (SuperTuxKart static mesh) and
   .ac (AC3D). This file is part of import.c's translation unit (import.c
   includes it), so both formats share its error messages, growable arrays,
   text cursor, bounds-checked binary reader and texture cache; it is not
   compiled on its own.

   - .spm: "SP", a byte version << 3 | kind (kind 1: animated, "skinned";
     kind 2: static; others are refused), a flags byte (1 normals, 2 vertex
     colours, 4 tangents), a bounding box of 6 f32 (ignored). A u16
     material count, each material two texture names (u8 length + bytes); a
     u16 mesh count, each mesh a u16 buffer count, each buffer a u32 vertex
     count, a u32 index count (a multiple of 3) and a u16 material. Per
     vertex: 3 f32 position, a u32 normal if flagged, a colour if flagged
     (one byte: 128 is white, any other value is followed by R G B), 2 f16
     texture coordinates if the material has a first texture (then 2 more
     f16 if it has a second, and a u32 tangent if flagged), and in animated
     files 4 i16 joint indices (-1: none) and 4 f16 weights. Indices are u8
     for buffers of at most 255 vertices, else u16. An animated file ends
     with its armatures: a u8 count and a u16 (unused), then per armature a
     u16 count of joints used, a u16 joint count N (at least the former), N
     names (u8 length + bytes), N transforms of 10 f32 (location, rotation
     quaternion, scale), N i16 parents (-1 or a joint below N), and a u16
     keyframe count, each keyframe a u16 frame and N transforms. Every
     joint a vertex names must exist (numbered across the armatures in
     order). Animated meshes are imported in their bind pose: the vertex
     positions as stored, no joint transform or keyframe applied.
     Little-endian; nothing may follow the last buffer (static) or armature
     (animated).
     One scene material per file material, white, textured by its first
     texture: looked up beside the file, then in ../../textures/ and
     ../../library/<any>/ (a SuperTuxKart data tree). Vertex colours, when
     present, tint the texture, except in materials that SuperTuxKart draws
     with its grass shader (trees, bushes, grass, flags), whose vertex
     colours are wind weights: its grass vertex shader moves vertices by
     them and its fragment shader ignores them, so those vertices get white
     (the texture's own colours). A material is drawn so when the first
     <material> element named as its texture (outside XML comments, the
     name matched byte for byte) says shader="grass", looked up in the
     materials.xml beside the file, else in ../../textures/materials.xml
     (the track's or object's own file first, then the game's shared one).
     No base directory (an import from memory): no look-up, colours tint.
     Positions (x, y, z), y up and left-handed, become (x, z, y): z up and
     right-handed, the vdag tool's axes.
   - .ac: "AC3D" header, MATERIAL lines (their rgb is the Kd colour), then
     OBJECT blocks: loc (translation) and rot (3x3, row-major) place the
     object's own vertices and, composed, its kids; texture (the first one;
     "empty_texture_no_mapping" is none), texrep and texoff scale and shift
     its texture coordinates; data blocks are skipped by their byte count;
     numvert vertex lines; numsurf surfaces (SURF flags, mat, refs n, then n
     "index u v" lines). Polygons (type nibble 0) are triangulated as in
     .obj (import.h), each corner its own vertex; lines (types 1, 2) and
     other types are skipped. "subdiv N" with N > 0 gets a warning: the
     object is imported unsubdivided, as its control mesh.
     One scene material per distinct (MATERIAL, texture) pair, in order of
     first use. Textures are read beside the file. Unknown object lines are
     ignored; kids nest at most VI_AC_MAX_DEPTH deep. Placed positions
     (x, y, z), y up, become (x, -z, y): z up, the vdag tool's axes. */

#include <dirent.h>

// -- Shared: texture lookup, little-endian scalars

/* 1 if something is at PATH (a file that vi_texture then opens, or refuses
   if it is not a regular file): looked up without opening it, as opening a
   FIFO would wait for a writer. */
static int vs_exists(const char *path) {
#ifdef _WIN32
    struct _stat64 st;
    return _stat64(path, &st) == 0;
#else
    struct stat st;
    return stat(path, &st) == 0;
#endif
}

/* DIR/SUB/NAME if that file exists (malloc'd in *FOUND), else *FOUND = NULL.
   Returns 0 only on allocation failure. */
static int vs_try(vi_ctx *c, const char *dir, const char *sub, vi_span name, char **found) {
    size_t dn = strlen(dir), sn = strlen(sub);
    char *d = (char *)vi_alloc(c, dn + sn + 2, 1), *p;
    *found = NULL;
    if (!d) return 0;
    memcpy(d, dir, dn);
    d[dn] = '/';
    memcpy(d + dn + 1, sub, sn + 1);
    p = vi_path(c, d, name);
    free(d);
    if (!p) return 0;
    if (vs_exists(p)) *found = p;
    else free(p);
    return 1;
}

/* Finds SuperTuxKart texture NAME for a mesh in DIR: DIR, DIR/../../textures,
   then DIR/../../library/ANY (first match in directory order). */
static int vs_stk_texture(vi_ctx *c, const char *dir, vi_span name, char **found) {
    static const char *const subs[] = {".", "../../textures"};
    size_t i, dn = strlen(dir);
    int ok = 1;
    char *lib;
    DIR *d;
    struct dirent *e;
    for (i = 0; i < 2; i++) {
        if (!vs_try(c, dir, subs[i], name, found)) return 0;
        if (*found) return 1;
    }
    if (!(lib = (char *)vi_alloc(c, dn + 16, 1))) return 0;
    memcpy(lib, dir, dn);
    memcpy(lib + dn, "/../../library", 15);
    d = opendir(lib);
    while (ok && !*found && d && (e = readdir(d)) != NULL) {
        size_t n = strlen(e->d_name);
        char *sub;
        if (e->d_name[0] == '.') continue;
        if (!(sub = (char *)vi_alloc(c, n + 16, 1))) {
            ok = 0;
            break;
        }
        memcpy(sub, "../../library/", 14);
        memcpy(sub + 14, e->d_name, n + 1);
        ok = vs_try(c, dir, sub, name, found);
        free(sub);
    }
    if (d) closedir(d);
    free(lib);
    return ok;
}

static int vs_u16(vi_reader *r, uint32_t *v) {
    const uint8_t *b = vi_take(r, 2);
    if (b) *v = (uint32_t)vi_uint(b, 2, 0);
    return b != NULL;
}

static int vs_f32(vi_reader *r, double *v) {
    const uint8_t *b = vi_take(r, 4);
    uint32_t u;
    float f;
    if (!b) return 0;
    u = (uint32_t)vi_uint(b, 4, 0);
    memcpy(&f, &u, 4);
    *v = f;
    return 1;
}

/* IEEE half H as a double; 0 for infinities and NaN. */
static int vs_half(uint32_t h, double *v) {
    uint32_t e = (h >> 10) & 31, m = h & 1023;
    if (e == 31) return 0;
    *v = e ? ldexp((double)(1024 + m), (int)e - 25) : ldexp((double)m, -24);
    if (h & 0x8000) *v = -*v;
    return 1;
}

// -- .spm: SuperTuxKart static meshes

typedef struct vs_spm_mat {
    vi_span tex1, tex2;
    int wind; /* 1: SuperTuxKart's grass shader: vertex colours are wind weights */
} vs_spm_mat;

static int vs_xml_space(char ch) { return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\n'; }

/* The value of attribute NAME in TAG, the text of an XML start tag after its
   element name (up to its '>'), into *VALUE (quoted with " or '). Returns 1
   when TAG has it; 0 when it has not, or when TAG stops being attributes. */
static int vs_xml_attr(vi_span tag, const char *name, vi_span *value) {
    const char *p = tag.s, *e = tag.e;
    while (p < e) {
        vi_span key;
        char q;
        while (p < e && (vs_xml_space(*p) || *p == '/')) p++;
        key.s = p;
        while (p < e && !vs_xml_space(*p) && *p != '=') p++;
        key.e = p;
        while (p < e && vs_xml_space(*p)) p++;
        if (p == e || *p++ != '=') return 0;
        while (p < e && vs_xml_space(*p)) p++;
        if (p == e || (*p != '"' && *p != '\'')) return 0;
        q = *p++;
        value->s = p;
        while (p < e && *p != q) p++;
        if (p == e) return 0;
        value->e = p++;
        if (vi_is(key, name)) return 1;
    }
    return 0;
}

/* Looks up texture NAME in XML, the text of a SuperTuxKart materials.xml:
   the first <material> element (outside comments) whose name attribute is
   NAME, byte for byte (an unterminated last tag is no element). Returns 1
   when there is one, with its shader attribute in *SHADER (empty when it
   has none); 0 when there is none. */
static int vs_xml_material(vi_span xml, vi_span name, vi_span *shader) {
    const char *p = xml.s, *e = xml.e;
    while (p < e) {
        const char *lt = (const char *)memchr(p, '<', (size_t)(e - p)), *q;
        vi_span tag, value;
        char quote = 0;
        if (!lt) return 0;
        p = lt + 1;
        if (e - p >= 3 && !memcmp(p, "!--", 3)) { /* a comment: up to its "-->" */
            for (p += 3; e - p >= 3 && memcmp(p, "-->", 3); p++) {}
            p = e - p >= 3 ? p + 3 : e;
            continue;
        }
        if (e - p < 9 || memcmp(p, "material", 8) || !(vs_xml_space(p[8]) || p[8] == '/' || p[8] == '>')) continue;
        tag.s = p + 8;
        for (q = tag.s; q < e && (quote || *q != '>'); q++) /* the tag's '>', outside quoted values */
            if (*q == '"' || *q == '\'') quote = quote == *q ? 0 : quote ? quote : *q;
        if (q == e) return 0; /* an unterminated tag */
        tag.e = q;
        p = q;
        if (!vs_xml_attr(tag, "name", &value) || vi_len(value) != vi_len(name) ||
            memcmp(value.s, name.s, vi_len(name)))
            continue;
        if (!vs_xml_attr(tag, "shader", shader)) shader->s = shader->e = tag.s;
        return 1;
    }
    return 0;
}

/* SuperTuxKart's materials.xml in DIR/SUB, read whole into *DATA and *SIZE
   (malloc'd), or *DATA = NULL when there is none or it cannot be opened (a
   warning). Returns 0 on an error (refused, too large, out of memory). */
static int vs_stk_materials(vi_ctx *c, const char *dir, const char *sub, char **data, size_t *size) {
    vi_span name;
    char *path = NULL, why[512];
    int r;
    name.s = "materials.xml";
    name.e = name.s + 13;
    *data = NULL;
    *size = 0;
    if (!vs_try(c, dir, sub, name, &path)) return 0;
    if (!path) return 1;
    if (!vi_may_read(c, path)) {
        free(path);
        return 0;
    }
    r = vi_read_side(c, path, data, size, why, sizeof why);
    if (r < 0 && !c->limits.quiet) fprintf(stderr, "vdag: warning: %s; its shaders are not applied\n", why);
    free(path);
    return r != 0;
}

/* Marks the materials of MATS whose first texture SuperTuxKart draws with
   its grass shader, which reads vertex colours as wind weights, never as
   colours: the material in the materials.xml beside the file, else in
   ../../textures/materials.xml (a SuperTuxKart data tree). Returns 0 on an
   error. */
static int vs_spm_wind(vi_ctx *c, vi_buf *mats) {
    static const char *const subs[2] = {".", "../../textures"};
    char *xml[2] = {NULL, NULL};
    size_t n[2] = {0, 0}, i;
    int ok = 1, k;
    for (k = 0; k < 2 && ok; k++) ok = vs_stk_materials(c, c->base_dir, subs[k], &xml[k], &n[k]);
    for (i = 0; ok && i < mats->count; i++) {
        vs_spm_mat *m = &((vs_spm_mat *)mats->data)[i];
        vi_span shader;
        shader.s = shader.e = NULL;
        for (k = 0; k < 2 && m->tex1.s != m->tex1.e; k++) {
            vi_span whole;
            if (!xml[k]) continue;
            whole.s = xml[k];
            whole.e = xml[k] + n[k];
            if (vs_xml_material(whole, m->tex1, &shader)) break;
        }
        m->wind = k < 2 && vi_is(shader, "grass");
    }
    free(xml[0]);
    free(xml[1]);
    return ok;
}

/* The armature section of a skinned file, after its meshes: read and checked
   (every joint a vertex names must exist), not applied (the bind pose is the
   vertices as stored). MAX_JOINT: the largest joint index the vertices name,
   or -1. */
static int vs_spm_armatures(vi_ctx *c, vi_reader *r, int32_t max_joint) {
    const uint8_t *b;
    uint32_t narm, a, total = 0;
    if (!(b = vi_take(r, 3))) return vi_fail(c, "truncated armature count");
    narm = b[0];
    for (a = 0; a < narm; a++) {
        uint32_t used, n, j, keys;
        if (!vs_u16(r, &used) || !vs_u16(r, &n)) return vi_fail(c, "armature %u: truncated joint count", (unsigned)a);
        if (used > n) return vi_fail(c, "armature %u: %u joints used of %u", (unsigned)a, (unsigned)used, (unsigned)n);
        for (j = 0; j < n; j++) {
            const uint8_t *len = vi_take(r, 1);
            if (!len || !vi_take(r, *len))
                return vi_fail(c, "armature %u joint %u: truncated name", (unsigned)a, (unsigned)j);
        }
        if (!vi_take(r, 40 * (size_t)n)) return vi_fail(c, "armature %u: truncated joint transforms", (unsigned)a);
        for (j = 0; j < n; j++) {
            uint32_t parent;
            if (!vs_u16(r, &parent)) return vi_fail(c, "armature %u: truncated joint parents", (unsigned)a);
            if (parent != 0xffff && parent >= n)
                return vi_fail(c, "armature %u joint %u: parent %u of %u joints", (unsigned)a, (unsigned)j,
                               (unsigned)parent, (unsigned)n);
        }
        if (!vs_u16(r, &keys)) return vi_fail(c, "armature %u: truncated keyframe count", (unsigned)a);
        if ((uint64_t)keys * (2 + 40 * (uint64_t)n) > r->size - r->pos)
            return vi_fail(c, "armature %u: %u keyframes of %u joints need more bytes than remain", (unsigned)a,
                           (unsigned)keys, (unsigned)n);
        r->pos += (size_t)keys * (2 + 40 * (size_t)n);
        total += n;
    }
    if (max_joint >= (int32_t)total)
        return vi_fail(c, "a vertex names joint %d of %u (the joints of all armatures)", (int)max_joint,
                       (unsigned)total);
    return 1;
}

static int vi_parse_spm(vi_ctx *c, const uint8_t *data, size_t size, vdag_scene *out) {
    vi_reader r;
    vi_buf mats = {NULL, 0, 0}, pos = {NULL, 0, 0}, uv = {NULL, 0, 0}, rgb = {NULL, 0, 0};
    vi_buf tris = {NULL, 0, 0}, tmat = {NULL, 0, 0};
    vi_texcache cache = {{NULL, 0, 0}, 0};
    const uint8_t *h;
    uint32_t nmat, nmesh, mesh, flags, i;
    int32_t max_joint = -1;
    int ok = 0, any_tex = 0, skinned;
    r.data = data;
    r.size = size;
    r.pos = 0;
    r.big_endian = 0;
    if (!(h = vi_take(&r, 28)) || h[0] != 'S' || h[1] != 'P') return vi_fail(c, "not an SPM file (no \"SP\" header)");
    if ((h[2] & 7) != 1 && (h[2] & 7) != 2)
        return vi_fail(c, "unknown mesh kind %u (known: 1, animated; 2, static)", (unsigned)(h[2] & 7));
    skinned = (h[2] & 7) == 1;
    flags = h[3];
    if (!vs_u16(&r, &nmat)) return vi_fail(c, "truncated material count");
    for (i = 0; i < nmat; i++) {
        vs_spm_mat *m = (vs_spm_mat *)vi_push(c, &mats, sizeof *m, 1);
        vi_span *t[2];
        int k;
        if (!m) goto done;
        t[0] = &m->tex1;
        t[1] = &m->tex2;
        for (k = 0; k < 2; k++) {
            const uint8_t *len = vi_take(&r, 1), *s = len ? vi_take(&r, *len) : NULL;
            if (!s) {
                vi_fail(c, "material %u: truncated texture name", (unsigned)i);
                goto done;
            }
            t[k]->s = (const char *)s;
            t[k]->e = (const char *)s + *len;
        }
        m->wind = 0;
        any_tex |= m->tex1.s != m->tex1.e;
    }
    if (c->base_dir && (flags & 2) && any_tex && !vs_spm_wind(c, &mats)) goto done;
    if (!vs_u16(&r, &nmesh)) {
        vi_fail(c, "truncated mesh count");
        goto done;
    }
    for (mesh = 0; mesh < nmesh; mesh++) {
        uint32_t nbuf, buf;
        if (!vs_u16(&r, &nbuf)) {
            vi_fail(c, "mesh %u: truncated buffer count", (unsigned)mesh);
            goto done;
        }
        for (buf = 0; buf < nbuf; buf++) {
            uint32_t vc, ic, mid, v, base = (uint32_t)(pos.count / 3);
            const vs_spm_mat *m;
            uint64_t vbytes, ibytes;
            int tex1, tex2;
            if (!vi_u32(&r, &vc) || !vi_u32(&r, &ic) || !vs_u16(&r, &mid)) {
                vi_fail(c, "mesh %u buffer %u: truncated header", (unsigned)mesh, (unsigned)buf);
                goto done;
            }
            if (mid >= nmat) {
                vi_fail(c, "mesh %u buffer %u: material %u of %u", (unsigned)mesh, (unsigned)buf, (unsigned)mid,
                        (unsigned)nmat);
                goto done;
            }
            m = &((const vs_spm_mat *)mats.data)[mid];
            tex1 = m->tex1.s != m->tex1.e;
            tex2 = tex1 && m->tex2.s != m->tex2.e;
            vbytes = (uint64_t)vc * (uint64_t)(12 + (flags & 1 ? 4 : 0) + (flags & 2 ? 1 : 0) +
                                               (tex1 ? 4 + (tex2 ? 4 : 0) + (flags & 4 ? 4 : 0) : 0) +
                                               (skinned ? 16 : 0));
            ibytes = (uint64_t)ic * (vc > 255 ? 2 : 1);
            if (ic % 3) {
                vi_fail(c, "mesh %u buffer %u: %u indices, not whole triangles", (unsigned)mesh, (unsigned)buf,
                        (unsigned)ic);
                goto done;
            }
            if (vbytes + ibytes > r.size - r.pos) {
                vi_fail(c, "mesh %u buffer %u: %u vertices and %u indices need more bytes than remain",
                        (unsigned)mesh, (unsigned)buf, (unsigned)vc, (unsigned)ic);
                goto done;
            }
            if ((uint64_t)base + vc > VI_NONE) {
                vi_fail(c, "more than 2^32 - 1 vertices");
                goto done;
            }
            for (v = 0; v < vc; v++) {
                double *p = (double *)vi_push(c, &pos, sizeof(double), 3);
                float *t = any_tex ? (float *)vi_push(c, &uv, sizeof(float), 2) : NULL;
                uint8_t *col = flags & 2 ? (uint8_t *)vi_push(c, &rgb, 1, 3) : NULL;
                int k, bad = 0;
                if (!p || (any_tex && !t) || ((flags & 2) && !col)) goto done;
                for (k = 0; k < 3; k++) bad |= !vs_f32(&r, &p[k ? 3 - k : 0]) || !vi_coord_ok(p[k ? 3 - k : 0]);
                if (flags & 1) bad |= !vi_take(&r, 4);
                if (flags & 2) {
                    const uint8_t *ci = vi_take(&r, 1), *c3 = ci && *ci != 128 ? vi_take(&r, 3) : NULL;
                    bad |= !ci || (*ci != 128 && !c3);
                    if (!bad) memcpy(col, c3 && !m->wind ? c3 : (const uint8_t *)"\377\377\377", 3);
                }
                if (t) t[0] = t[1] = 0;
                if (tex1) {
                    uint32_t hu = 0, hv = 0;
                    double du = 0, dv = 0;
                    bad |= !vs_u16(&r, &hu) || !vs_u16(&r, &hv) || !vs_half(hu, &du) || !vs_half(hv, &dv);
                    t[0] = (float)du;
                    t[1] = (float)dv;
                    if (tex2) bad |= !vi_take(&r, 4);
                    if (flags & 4) bad |= !vi_take(&r, 4);
                }
                if (skinned && !bad) { /* 4 i16 joints (-1: none), 4 f16 weights: not needed for the bind pose */
                    const uint8_t *jw = vi_take(&r, 16);
                    for (k = 0; jw && k < 4; k++) {
                        int32_t j = (int32_t)vi_signed(vi_uint(jw + 2 * k, 2, 0), 16);
                        if (j < -1) {
                            vi_fail(c, "mesh %u buffer %u vertex %u: joint %d", (unsigned)mesh, (unsigned)buf,
                                    (unsigned)v, (int)j);
                            goto done;
                        }
                        if (j > max_joint) max_joint = j;
                    }
                    bad = !jw;
                }
                if (bad) {
                    vi_fail(c, "mesh %u buffer %u vertex %u: %s", (unsigned)mesh, (unsigned)buf, (unsigned)v,
                            r.pos >= r.size ? "truncated" : "not a finite number");
                    goto done;
                }
            }
            for (v = 0; v < ic; v++) {
                const uint8_t *b = vi_take(&r, vc > 255 ? 2 : 1);
                uint32_t idx, *out_idx = (uint32_t *)vi_push(c, &tris, sizeof(uint32_t), 1);
                if (!out_idx) goto done;
                if (!b) {
                    vi_fail(c, "mesh %u buffer %u: truncated indices", (unsigned)mesh, (unsigned)buf);
                    goto done;
                }
                idx = (uint32_t)vi_uint(b, vc > 255 ? 2 : 1, 0);
                if (idx >= vc) {
                    vi_fail(c, "mesh %u buffer %u: index %u of %u vertices", (unsigned)mesh, (unsigned)buf,
                            (unsigned)idx, (unsigned)vc);
                    goto done;
                }
                *out_idx = base + idx;
                if (v % 3 == 2) {
                    int32_t *tm = (int32_t *)vi_push(c, &tmat, sizeof(int32_t), 1);
                    if (!tm) goto done;
                    *tm = (int32_t)mid;
                }
            }
        }
    }
    if (skinned && !vs_spm_armatures(c, &r, max_joint)) goto done;
    if (r.pos != r.size) {
        vi_fail(c, "%llu bytes after the last %s", (vi_ull)(r.size - r.pos), skinned ? "armature" : "mesh");
        goto done;
    }
    if (!(out->materials = (vdag_material *)vi_alloc(c, nmat, sizeof *out->materials))) goto done;
    out->material_count = nmat;
    for (i = 0; i < nmat; i++) {
        const vs_spm_mat *m = &((const vs_spm_mat *)mats.data)[i];
        char *path = NULL;
        out->materials[i].rgb[0] = out->materials[i].rgb[1] = out->materials[i].rgb[2] = 255;
        out->materials[i].image = -1;
        if (!c->base_dir || m->tex1.s == m->tex1.e) continue;
        if (!vs_stk_texture(c, c->base_dir, m->tex1, &path)) goto done;
        if (!path) {
            if (!c->limits.quiet)
                fprintf(stderr, "vdag: warning: texture %.*s not found; using white\n", (int)vi_len(m->tex1), m->tex1.s);
            continue;
        }
        {
            vi_span whole;
            whole.s = path;
            whole.e = path + strlen(path);
            ok = vi_texture(c, out, &cache, "", whole, &out->materials[i].image);
        }
        free(path);
        if (!ok) goto done;
        ok = 0;
    }
    out->vertex_count = pos.count / 3;
    out->positions = (double *)pos.data;
    pos.data = NULL;
    if (flags & 2) {
        out->vertex_rgb = (uint8_t *)rgb.data;
        rgb.data = NULL;
    }
    if (any_tex) {
        out->uv = (float *)uv.data;
        uv.data = NULL;
    }
    out->triangle_material = (int32_t *)tmat.data;
    tmat.data = NULL;
    vi_set_triangles(out, &tris);
    if (!out->triangle_count) {
        free(out->triangle_material);
        out->triangle_material = NULL;
    }
    ok = 1;
done:
    vi_buf_free(&mats);
    vi_buf_free(&pos);
    vi_buf_free(&uv);
    vi_buf_free(&rgb);
    vi_buf_free(&tris);
    vi_buf_free(&tmat);
    vi_tex_free(&cache);
    return ok;
}

// -- .ac: AC3D text scenes

#define VI_AC_MAX_DEPTH 256

typedef struct vs_ac {
    vi_ctx *c;
    vi_text t;
    vdag_scene *out;
    vi_buf mats;  /* 3 bytes per MATERIAL line */
    vi_buf pairs; /* per scene material: int32 MATERIAL index (-1 none), int32 image */
    vi_buf pos, uv, tris, tmat, verts, poly;
    vi_texcache cache;
    int32_t last; /* scene material of the last surface, or -1 */
    uint64_t subdiv, subdiv_line; /* objects with subdiv N > 0, the first one's line */
} vs_ac;

/* The next line of T (no comment syntax); 0 at the end. */
static int vs_line(vi_text *t, vi_span *line) {
    const char *nl;
    if (t->p == t->end) return 0;
    nl = (const char *)memchr(t->p, '\n', (size_t)(t->end - t->p));
    line->s = t->p;
    line->e = nl ? nl : t->end;
    t->p = nl ? nl + 1 : t->end;
    t->line++;
    return 1;
}

/* Reads N numbers from LINE into V, each finite and in range. */
static int vs_numbers(vi_span *line, double *v, int n) {
    vi_span tok;
    int i;
    for (i = 0; i < n; i++)
        if (!vi_tok(line, &tok) || !vi_real(tok, &v[i]) || !vi_coord_ok(v[i])) return 0;
    return 1;
}

/* A count token: an integer 0..MAX. */
static int vs_count(vi_span *line, int64_t max, uint32_t *n) {
    vi_span tok;
    int64_t v;
    if (!vi_tok(line, &tok) || !vi_int(tok, &v) || v < 0 || v > max) return 0;
    *n = (uint32_t)v;
    return 1;
}

/* Scene material for (MATERIAL MAT, IMAGE), added on first use. */
static int vs_ac_material(vs_ac *a, int32_t mat, int32_t image, int32_t *index) {
    int32_t *p = (int32_t *)a->pairs.data;
    size_t i;
    if (a->last >= 0 && p[2 * a->last] == mat && p[2 * a->last + 1] == image) {
        *index = a->last;
        return 1;
    }
    for (i = 0; i < a->pairs.count / 2; i++)
        if (p[2 * i] == mat && p[2 * i + 1] == image) break;
    if (i == a->pairs.count / 2) {
        if (i >= (size_t)INT32_MAX || !(p = (int32_t *)vi_push(a->c, &a->pairs, sizeof(int32_t), 2))) return 0;
        p[0] = mat;
        p[1] = image;
    }
    *index = a->last = (int32_t)i;
    return 1;
}

static int vs_ac_fail(vs_ac *a, const char *what) {
    return vi_fail(a->c, "line %llu: %s", (vi_ull)a->t.line, what);
}

/* One surface after its SURF line (flags FLAGS): mat, refs and ref lines. */
static int vs_ac_surface(vs_ac *a, uint32_t flags, int32_t image, const double rep[4]) {
    vi_span line, kw;
    int32_t mat = a->mats.count ? 0 : -1;
    uint32_t n, i, base, *q;
    int32_t *tm;
    size_t nv = a->verts.count / 3;
    for (;;) {
        if (!vs_line(&a->t, &line)) return vi_fail(a->c, "surface without refs at the end of the file");
        if (!vi_tok(&line, &kw)) continue;
        if (vi_is(kw, "mat")) {
            uint32_t m;
            if (!vs_count(&line, INT32_MAX, &m) || m >= a->mats.count) return vs_ac_fail(a, "material out of range");
            mat = (int32_t)m;
        } else if (vi_is(kw, "refs")) {
            break;
        } else {
            return vs_ac_fail(a, "expected mat or refs");
        }
    }
    if (!vs_count(&line, (int64_t)(a->t.end - a->t.p) / 2 + 1, &n)) return vs_ac_fail(a, "bad refs count");
    base = (uint32_t)(a->pos.count / 3);
    if ((flags & 15) != 0 || n < 3) { /* lines, or a degenerate polygon */
        for (i = 0; i < n; i++)
            if (!vs_line(&a->t, &line)) return vi_fail(a->c, "truncated refs at the end of the file");
        return 1;
    }
    if ((uint64_t)base + n > VI_NONE) return vi_fail(a->c, "more than 2^32 - 1 vertices");
    for (i = 0; i < n; i++) {
        uint32_t idx;
        double t[2] = {0, 0}, *p;
        float *uv;
        vi_span tok;
        if (!vs_line(&a->t, &line)) return vi_fail(a->c, "truncated refs at the end of the file");
        if (!vs_count(&line, INT32_MAX, &idx) || idx >= nv) return vs_ac_fail(a, "vertex index out of range");
        if (vi_tok(&line, &tok) && (!vi_real(tok, &t[0]) || !vi_coord_ok(t[0]) || !vs_numbers(&line, &t[1], 1)))
            return vs_ac_fail(a, "bad texture coordinates");
        if (!(p = (double *)vi_push(a->c, &a->pos, sizeof(double), 3))) return 0;
        if (!(uv = (float *)vi_push(a->c, &a->uv, sizeof(float), 2))) return 0;
        memcpy(p, (const double *)a->verts.data + 3 * (size_t)idx, 3 * sizeof(double));
        uv[0] = (float)(t[0] * rep[0] + rep[2]);
        uv[1] = (float)(t[1] * rep[1] + rep[3]);
    }
    a->poly.count = 0;
    if (!(q = (uint32_t *)vi_push(a->c, &a->poly, sizeof(uint32_t), n))) return 0;
    if (!(tm = (int32_t *)vi_push(a->c, &a->tmat, sizeof(int32_t), n - 2))) return 0;
    for (i = 0; i < n; i++) q[i] = base + i;
    for (i = 0; i < n - 2; i++)
        if (!vs_ac_material(a, mat, image, &tm[i])) return 0;
    return vi_poly(a->c, &a->tris, q, n, sizeof(uint32_t), (const double *)a->pos.data);
}

/* M' = PM * ROT, T' = PM * LOC + PT. */
static void vs_compose(const double pm[9], const double pt[3], const double rot[9], const double loc[3], double m[9],
                       double t[3]) {
    int i, j, k;
    for (i = 0; i < 3; i++) {
        t[i] = pt[i];
        for (j = 0; j < 3; j++) {
            m[3 * i + j] = 0;
            for (k = 0; k < 3; k++) m[3 * i + j] += pm[3 * i + k] * rot[3 * k + j];
            t[i] += pm[3 * i + j] * loc[j];
        }
    }
}

/* One OBJECT block (its OBJECT line read), placed by PM and PT, and its kids. */
static int vs_ac_object(vs_ac *a, const double pm[9], const double pt[3], int depth) {
    double rot[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, loc[3] = {0, 0, 0}, m[9], t[3];
    double rep[4] = {1, 1, 0, 0}; /* texrep u v, texoff u v */
    int32_t image = -1;
    int textured = 0;
    vi_span line, kw;
    a->verts.count = 0;
    if (depth > VI_AC_MAX_DEPTH) return vs_ac_fail(a, "objects nested too deep");
    while (vs_line(&a->t, &line)) {
        if (!vi_tok(&line, &kw)) continue;
        if (vi_is(kw, "rot")) {
            if (!vs_numbers(&line, rot, 9)) return vs_ac_fail(a, "rot needs 9 numbers");
        } else if (vi_is(kw, "loc")) {
            if (!vs_numbers(&line, loc, 3)) return vs_ac_fail(a, "loc needs 3 numbers");
        } else if (vi_is(kw, "texrep")) {
            if (!vs_numbers(&line, rep, 2)) return vs_ac_fail(a, "texrep needs 2 numbers");
        } else if (vi_is(kw, "texoff")) {
            if (!vs_numbers(&line, rep + 2, 2)) return vs_ac_fail(a, "texoff needs 2 numbers");
        } else if (vi_is(kw, "texture")) {
            vi_span name = vi_trim(line);
            if (textured++) continue;
            if (vi_len(name) && *name.s == '"') {
                const char *q = (const char *)memchr(name.s + 1, '"', vi_len(name) - 1);
                if (!q) return vs_ac_fail(a, "unterminated texture name");
                name.s++;
                name.e = q;
            } else if (vi_tok(&name, &kw)) {
                name = kw;
            }
            if (!vi_len(name) || vi_is(name, "empty_texture_no_mapping") || !a->c->base_dir) continue;
            if (!vi_texture(a->c, a->out, &a->cache, a->c->base_dir, name, &image)) return 0;
        } else if (vi_is(kw, "subdiv")) {
            uint32_t n;
            if (!vs_count(&line, INT32_MAX, &n)) return vs_ac_fail(a, "bad subdiv count");
            if (n && !a->subdiv++) a->subdiv_line = a->t.line;
        } else if (vi_is(kw, "data")) {
            uint32_t n;
            if (!vs_count(&line, (int64_t)(a->t.end - a->t.p), &n)) return vs_ac_fail(a, "bad data length");
            a->t.p += n;
            vs_line(&a->t, &line); /* the rest of the last data line */
        } else if (vi_is(kw, "numvert")) {
            uint32_t n, i;
            double *v;
            if (!vs_count(&line, (int64_t)(a->t.end - a->t.p) / 6 + 1, &n)) return vs_ac_fail(a, "bad numvert count");
            vs_compose(pm, pt, rot, loc, m, t);
            a->verts.count = 0;
            if (!(v = (double *)vi_push(a->c, &a->verts, sizeof(double), 3 * (size_t)n))) return 0;
            for (i = 0; i < n; i++, v += 3) {
                double p[3], w[3];
                int k;
                if (!vs_line(&a->t, &line)) return vi_fail(a->c, "truncated vertices at the end of the file");
                if (!vs_numbers(&line, p, 3)) return vs_ac_fail(a, "a vertex needs 3 numbers");
                for (k = 0; k < 3; k++) {
                    w[k] = t[k] + m[3 * k] * p[0] + m[3 * k + 1] * p[1] + m[3 * k + 2] * p[2];
                    if (!vi_coord_ok(w[k])) return vs_ac_fail(a, "vertex out of range once placed");
                }
                v[0] = w[0]; /* y up to z up */
                v[1] = -w[2];
                v[2] = w[1];
            }
        } else if (vi_is(kw, "numsurf")) {
            uint32_t n, i;
            if (!vs_count(&line, (int64_t)(a->t.end - a->t.p) / 6 + 1, &n)) return vs_ac_fail(a, "bad numsurf count");
            for (i = 0; i < n; i++) {
                vi_span tok;
                int64_t flags = 0;
                do {
                    if (!vs_line(&a->t, &line)) return vi_fail(a->c, "truncated surfaces at the end of the file");
                } while (!vi_tok(&line, &kw));
                if (!vi_is(kw, "SURF") || !vi_tok(&line, &tok)) return vs_ac_fail(a, "expected SURF flags");
                if (vi_len(tok) > 2 && tok.s[0] == '0' && (tok.s[1] == 'x' || tok.s[1] == 'X')) {
                    const char *s;
                    for (s = tok.s + 2; s < tok.e && vi_len(tok) <= 10; s++) {
                        int d = *s >= '0' && *s <= '9' ? *s - '0' : (*s | 32) >= 'a' && (*s | 32) <= 'f' ? (*s | 32) - 'a' + 10 : -1;
                        if (d < 0) break;
                        flags = flags * 16 + d;
                    }
                    if (s != tok.e || vi_len(tok) > 10) return vs_ac_fail(a, "bad SURF flags");
                } else if (!vi_int(tok, &flags) || flags < 0) {
                    return vs_ac_fail(a, "bad SURF flags");
                }
                if (!vs_ac_surface(a, (uint32_t)(flags & 15), image, rep)) return 0;
            }
        } else if (vi_is(kw, "kids")) {
            uint32_t n, i;
            if (!vs_count(&line, (int64_t)(a->t.end - a->t.p) / 7 + 1, &n)) return vs_ac_fail(a, "bad kids count");
            vs_compose(pm, pt, rot, loc, m, t);
            for (i = 0; i < n; i++) {
                do {
                    if (!vs_line(&a->t, &line)) return vi_fail(a->c, "missing kids at the end of the file");
                } while (!vi_tok(&line, &kw));
                if (!vi_is(kw, "OBJECT")) return vs_ac_fail(a, "expected OBJECT");
                if (!vs_ac_object(a, m, t, depth + 1)) return 0;
            }
            return 1;
        } else if (vi_is(kw, "OBJECT") || vi_is(kw, "MATERIAL")) {
            return vs_ac_fail(a, "object without kids line");
        }
    }
    return vi_fail(a->c, "object without kids line at the end of the file");
}

static int vi_parse_ac(vi_ctx *c, vi_text *text, vdag_scene *out) {
    static const double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, zero[3] = {0, 0, 0};
    vs_ac a;
    vi_span line, kw;
    int ok = 0, any_image = 0;
    size_t i;
    memset(&a, 0, sizeof a);
    a.c = c;
    a.t = *text;
    a.out = out;
    a.last = -1;
    if (!vs_line(&a.t, &line) || vi_len(line) < 4 || memcmp(line.s, "AC3D", 4) != 0) {
        vi_fail(c, "not an AC3D file (no \"AC3D\" header)");
        goto done;
    }
    while (vs_line(&a.t, &line)) {
        if (!vi_tok(&line, &kw)) continue;
        if (vi_is(kw, "MATERIAL")) {
            uint8_t *rgb = (uint8_t *)vi_push(c, &a.mats, 3, 1);
            double v[3];
            vi_span tok;
            int k;
            if (!rgb) goto done;
            while (vi_tok(&line, &tok) && !vi_is(tok, "rgb")) {}
            if (!vi_is(tok, "rgb") || !vs_numbers(&line, v, 3)) {
                vs_ac_fail(&a, "MATERIAL without rgb");
                goto done;
            }
            for (k = 0; k < 3; k++) vi_channel(v[k], 255.0, &rgb[k]);
        } else if (vi_is(kw, "OBJECT")) {
            if (!vs_ac_object(&a, id, zero, 0)) goto done;
        } else {
            vs_ac_fail(&a, "expected MATERIAL or OBJECT");
            goto done;
        }
    }
    if (!(out->materials = (vdag_material *)vi_alloc(c, a.pairs.count / 2, sizeof *out->materials))) goto done;
    out->material_count = a.pairs.count / 2;
    for (i = 0; i < out->material_count; i++) {
        const int32_t *p = (const int32_t *)a.pairs.data + 2 * i;
        if (p[0] >= 0) memcpy(out->materials[i].rgb, (const uint8_t *)a.mats.data + 3 * (size_t)p[0], 3);
        else memset(out->materials[i].rgb, 255, 3);
        out->materials[i].image = p[1];
        any_image |= p[1] >= 0;
    }
    out->vertex_count = a.pos.count / 3;
    out->positions = (double *)a.pos.data;
    a.pos.data = NULL;
    if (any_image) {
        out->uv = (float *)a.uv.data;
        a.uv.data = NULL;
    }
    out->triangle_material = (int32_t *)a.tmat.data;
    a.tmat.data = NULL;
    vi_set_triangles(out, &a.tris);
    if (!out->triangle_count) {
        free(out->triangle_material);
        out->triangle_material = NULL;
    }
    if (a.subdiv)
        vi_warn(c, "%llu object%s subdiv > 0 (the first on line %llu): subdivision surfaces are imported "
                "unsubdivided, as their control mesh", (vi_ull)a.subdiv, a.subdiv == 1 ? " has" : "s have",
                (vi_ull)a.subdiv_line);
    ok = 1;
done:
    vi_buf_free(&a.mats);
    vi_buf_free(&a.pairs);
    vi_buf_free(&a.pos);
    vi_buf_free(&a.uv);
    vi_buf_free(&a.tris);
    vi_buf_free(&a.tmat);
    vi_buf_free(&a.verts);
    vi_buf_free(&a.poly);
    vi_tex_free(&a.cache);
    return ok;
}
