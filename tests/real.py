"""Independent answers for tests/real.sh, computed from the third-party files
themselves (never from vdag's output):

  polygons FILE DUMP   FILE an .ac or .obj, DUMP what import_dump printed for
                       it: maps the triangles to the file's polygons (n - 2
                       each, in file order) and, for every planar polygon that
                       is simple in its plane, compares the triangles' area
                       with the polygon's (half the length of Newell's normal;
                       a fan of a concave polygon overlaps itself and covers
                       more). Prints "polygons P concave C fan_wrong W bad B
                       wrong X": C simple planar polygons with a reflex corner,
                       W of them whose fan from the first corner covers more
                       than the polygon, B polygons degenerate or
                       self-intersecting in the plane of their Newell normal's
                       dominant axis, X simple planar polygons whose triangles
                       do not cover their area (the lines after it name them).
  obj-area FILE L      one-polygon .obj: the polygon's area and perimeter in
                       voxels of the 2^L grid fitted to the bounding box's
                       largest extent, and its corner count: "A P N".
  ac-tris FILE         the triangles an .ac file's polygons give unsubdivided
                       (n - 2 per polygon of n >= 3 corners, lines left out).
  vox FILE             a MagicaVoxel file's models: "MODELS N" then the voxel
                       count of each XYZI chunk, and "GRAPH 0|1" (nTRN chunks).
  vox-same FILE K EXPORTED   exit 0 when the voxels of EXPORTED (vdag
                       export-voxels) are model K's (its XYZI chunk) up to a
                       translation.
  spacing FILE         a point cloud (.xyz, or an ASCII .ply of vertices):
                       README's rule by brute force, "S N L": the median
                       (upper) distance S from every (n / 2000)-th point to
                       its nearest other point (duplicates aside; N of them),
                       and the largest L <= 10 (at least 2) with
                       extent / 2^L >= S.
  isolated             voxels "x y z ..." on stdin: "I N", the voxels without
                       any of their 26 neighbours and all of them.
  stl-binary FILE      exit 0 when FILE is a binary STL: 84 + 50 * count
                       bytes, the count at byte 80.
"""
import math, struct, sys


def newell(pts):
    n = [0.0, 0.0, 0.0]
    for i, a in enumerate(pts):
        b = pts[(i + 1) % len(pts)]
        for j in range(3):
            u, v = (j + 1) % 3, (j + 2) % 3
            n[j] += (a[u] - b[u]) * (a[v] + b[v])
    return n


def tri_area(a, b, c):
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    x = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    return 0.5 * math.sqrt(sum(t * t for t in x))


def ac_polygons(path):
    """The polygons (corner positions) of every SURF of type 0 with >= 3
    corners, in file order; objects' own coordinates (loc and the importer's
    turn move and rotate, which keeps areas; no file here has rot)."""
    lines = open(path, encoding="latin-1").read().split("\n")
    polys, verts, i, kind = [], [], 0, 0
    while i < len(lines):
        w = lines[i].split()
        i += 1
        if not w:
            continue
        if w[0] == "data":  # a string of that many characters, maybe over lines
            need, got = int(w[1]), 0
            while got < need and i < len(lines):
                got += len(lines[i]) + 1
                i += 1
        elif w[0] == "numvert":
            verts = [tuple(map(float, lines[i + k].split()[:3])) for k in range(int(w[1]))]
            i += int(w[1])
        elif w[0] == "SURF":
            kind = int(w[1], 16) & 15
        elif w[0] == "rot":
            sys.exit("%s: rot is not handled here" % path)
        elif w[0] == "refs":
            refs = [int(lines[i + k].split()[0]) for k in range(int(w[1]))]
            i += int(w[1])
            if kind == 0 and len(refs) >= 3:
                polys.append([verts[r] for r in refs])
    return polys


def obj_polygons(path):
    verts, polys = [], []
    for line in open(path, encoding="latin-1"):
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            verts.append(tuple(map(float, w[1:4])))
        elif w[0] == "f":
            idx = [int(t.split("/")[0]) for t in w[1:]]
            polys.append([verts[k - 1] if k > 0 else verts[len(verts) + k] for k in idx])
    return polys


def read_polygons(path):
    return ac_polygons(path) if path.lower().endswith(".ac") else obj_polygons(path)


def classify(poly):
    """(planar, simple, concave): planar when no corner lies further from
    its plane than 1e-3 of the polygon's width (area / diameter; a twisted
    quad's triangles then cover its area within 1e-6); simple (edges meet
    only at corners; a corner may repeat, as where a ring is cut open) and
    concave (a reflex corner) in the plane of the Newell normal's dominant
    axis."""
    n = newell(poly)
    ln = math.sqrt(sum(t * t for t in n))
    d = max(math.dist(a, b) for a in poly for b in poly)
    if ln <= 1e-12 * d * d:
        return False, False, False
    c = [sum(p[k] for p in poly) / len(poly) for k in range(3)]
    width = 0.5 * ln / d  # area / diameter: a sliver's width
    planar = max(abs(sum((p[k] - c[k]) * n[k] for k in range(3))) / ln for p in poly) <= 1e-3 * width
    ax = max(range(3), key=lambda k: abs(n[k]))
    u, v = (ax + 1) % 3, (ax + 2) % 3
    s = 1 if n[ax] > 0 else -1
    xy = [(s * p[u], p[v]) for p in poly]  # counter-clockwise
    m = len(xy)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def hit(a, b, c_, d_):
        d1, d2, d3, d4 = cross(c_, d_, a), cross(c_, d_, b), cross(a, b, c_), cross(a, b, d_)
        return (d1 > 0) != (d2 > 0) and (d3 > 0) != (d4 > 0) and d1 and d2 and d3 and d4

    simple = True
    for i in range(m):
        for j in range(i + 2, m):
            if i == 0 and j == m - 1:
                continue
            if hit(xy[i], xy[(i + 1) % m], xy[j], xy[(j + 1) % m]):
                simple = False
    concave = any(cross(xy[i - 1], xy[i], xy[(i + 1) % m]) < -1e-9 * d * d for i in range(m))
    return planar, simple, concave


def polygons(path, dump):
    polys = read_polygons(path)
    rows = open(dump).read().split("\n")
    ntri = int(rows[0].split()[1])
    tris = [tuple(map(float, r.split())) for r in rows[1:1 + ntri]]
    if ntri != sum(len(p) - 2 for p in polys):
        print("polygons %d concave 0 fan_wrong 0 bad 0 wrong -1" % len(polys))
        print("triangle counts differ: %d read, %d from the polygons" % (ntri, sum(len(p) - 2 for p in polys)))
        return
    scale = max(abs(x) for p in polys for q in p for x in q)
    at, concave, fan_wrong, bad, wrong = 0, 0, 0, 0, []
    for k, poly in enumerate(polys):
        mine = tris[at:at + len(poly) - 2]
        at += len(poly) - 2
        if len(poly) == 3:
            continue
        planar, simple, conc = classify(poly)
        if not simple:
            bad += 1
        if not (planar and simple):
            continue
        want = 0.5 * math.sqrt(sum(t * t for t in newell(poly)))
        got = sum(tri_area(t[0:3], t[3:6], t[6:9]) for t in mine)
        fan = sum(tri_area(poly[0], poly[i], poly[i + 1]) for i in range(1, len(poly) - 1))
        per = sum(math.dist(poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly)))
        tol = 1e-6 * want + 1e-7 * scale * per  # coordinates printed to 9 digits
        if conc:
            concave += 1
            if fan - want > tol:
                fan_wrong += 1
        if abs(got - want) > tol:
            wrong.append("polygon %d (%d corners): triangles cover %.9g, the polygon %.9g" % (k, len(poly), got, want))
    print("polygons %d concave %d fan_wrong %d bad %d wrong %d" % (len(polys), concave, fan_wrong, bad, len(wrong)))
    for w in wrong[:5]:
        print(w)


def obj_area(path, levels):
    pts = [tuple(map(float, l.split()[1:4])) for l in open(path, encoding="latin-1") if l.startswith("v ")]
    (poly,) = obj_polygons(path)
    ext = max(max(p[k] for p in pts) - min(p[k] for p in pts) for k in range(3))
    vs = ext / 2 ** levels
    a = 0.5 * math.sqrt(sum(t * t for t in newell(poly))) / vs / vs
    per = sum(math.dist(poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly))) / vs
    print("%d %d %d" % (a, math.ceil(per), len(poly)))


def ac_tris(path):
    print(sum(len(p) - 2 for p in ac_polygons(path)))


def vox(path):
    b = open(path, "rb").read()
    assert b[:4] == b"VOX " and b[8:12] == b"MAIN", path
    pos, counts, graph = 20, [], 0
    while pos + 12 <= len(b):
        tag, n, _ = struct.unpack_from("<4sii", b, pos)
        if tag == b"XYZI":
            counts.append(struct.unpack_from("<i", b, pos + 12)[0])
        graph |= tag == b"nTRN"
        pos += 12 + n  # children follow inside MAIN, chunk after chunk
    print("MODELS %d" % len(counts))
    for c in counts:
        print(c)
    print("GRAPH %d" % graph)


def vox_same(path, k, exported):
    """Exit 0 when the voxels of EXPORTED ("x y z ..." lines) are those of
    the file's XYZI chunk K (colour index 0 is no voxel), up to a
    translation."""
    b = open(path, "rb").read()
    pos, chunks = 20, []
    while pos + 12 <= len(b):
        tag, n, _ = struct.unpack_from("<4sii", b, pos)
        if tag == b"XYZI":
            c = struct.unpack_from("<i", b, pos + 12)[0]
            chunks.append(set(tuple(b[pos + 16 + 4 * i:pos + 19 + 4 * i]) for i in range(c) if b[pos + 19 + 4 * i]))
        pos += 12 + n
    want = chunks[k]
    got = set(tuple(map(int, l.split()[:3])) for l in open(exported) if l.strip())

    def moved(v):
        lo = [min(p[a] for p in v) for a in range(3)] if v else [0, 0, 0]
        return set(tuple(p[a] - lo[a] for a in range(3)) for p in v)
    ok = len(got) == len(want) and moved(got) == moved(want)
    if not ok:
        print("%d voxels, model %d has %d" % (len(got), k, len(want)))
    sys.exit(0 if ok else 1)


def cloud(path):
    pts = []
    f = open(path, encoding="latin-1")
    if path.lower().endswith(".ply"):
        n = 0
        for line in f:
            w = line.split()
            if w[:2] == ["element", "vertex"]:
                n = int(w[2])
            if w[:1] == ["end_header"]:
                break
        for _ in range(n):
            pts.append(tuple(map(float, f.readline().split()[:3])))
    else:
        for line in f:
            w = line.split()
            if len(w) >= 3 and not w[0].startswith("#"):
                pts.append(tuple(map(float, w[:3])))
    return pts


def spacing(path):
    pts = cloud(path)
    n = len(pts)
    ext = max(max(p[k] for p in pts) - min(p[k] for p in pts) for k in range(3))
    m = min(n, 2000)
    step = n // m
    byx = sorted(pts)
    xs = [p[0] for p in byx]
    import bisect
    near = []
    for i in range(m):
        q = pts[i * step]
        best = math.inf
        j = bisect.bisect_left(xs, q[0])
        for rng in (range(j, n), range(j - 1, -1, -1)):  # outward along x until no nearer point can follow
            for k in rng:
                o = byx[k]
                if (o[0] - q[0]) ** 2 >= best:
                    break
                d = (o[0] - q[0]) ** 2 + (o[1] - q[1]) ** 2 + (o[2] - q[2]) ** 2
                if 0 < d < best:
                    best = d
        if best < math.inf:
            near.append(math.sqrt(best))
    s = sorted(near)[len(near) // 2]
    lv = 2
    while lv < 10 and ext / 2 ** (lv + 1) >= s:
        lv += 1
    print("%.3g %d %d" % (s, len(near), lv))


def isolated():
    v = set(tuple(map(int, l.split()[:3])) for l in sys.stdin if l.strip())
    i = sum(1 for (x, y, z) in v if not any((x + a, y + b, z + c) in v
            for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if a or b or c))
    print("%d %d" % (i, len(v)))


def stl_binary(path):
    b = open(path, "rb").read(84)
    import os
    size = os.path.getsize(path)
    sys.exit(0 if len(b) == 84 and 84 + 50 * struct.unpack_from("<I", b, 80)[0] == size else 1)


cmd = sys.argv[1]
if cmd == "polygons":
    polygons(sys.argv[2], sys.argv[3])
elif cmd == "obj-area":
    obj_area(sys.argv[2], int(sys.argv[3]))
elif cmd == "ac-tris":
    ac_tris(sys.argv[2])
elif cmd == "vox":
    vox(sys.argv[2])
elif cmd == "vox-same":
    vox_same(sys.argv[2], int(sys.argv[3]), sys.argv[4])
elif cmd == "spacing":
    spacing(sys.argv[2])
elif cmd == "isolated":
    isolated()
elif cmd == "stl-binary":
    stl_binary(sys.argv[2])
else:
    sys.exit("real.py: unknown command " + cmd)
