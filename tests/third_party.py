"""Compares the triangles of the vdag importers (import_dump) with those
Debian's assimp reads from the same file (`assimp export F OUT -fassjson`,
no post-processing): the same number of triangles, and the same triangles as
a multiset of corner positions (each triangle up to a rotation of its
corners), positions equal within 1e-5 of the model's size. Assimp's meshes
are placed by their node transforms and its polygons fan-triangulated here;
lines and points are not triangles. The importers fan convex polygons but
clip ears off concave ones, so when the fans differ, Assimp's triangles
must all be among ours, and the rest of ours must triangulate Assimp's
polygons: n - 2 triangles per polygon of n corners, every corner a polygon
corner, and their areas summing to the polygons' (a fan of a concave
polygon overlaps itself and covers more).
Usage: third_party.py ASSIMP_JSON DUMP AXES
AXES: "same", or "ac" (the AC3D importer turns y up to z up: (x, y, z) ->
(x, -z, y))."""
import json, sys

def mat_mul(a, b):
    return [sum(a[4 * i + k] * b[4 * k + j] for k in range(4)) for i in range(4) for j in range(4)]

def assimp_triangles(path):
    """The triangles of 3-corner faces, and the polygons (lists of corners)."""
    d = json.load(open(path, encoding="latin-1"))  # names may be in any encoding
    tris, polys = [], []
    def walk(node, parent):
        m = mat_mul(parent, node.get("transformation", [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]))
        for mi in node.get("meshes", []):
            mesh = d["meshes"][mi]
            v = mesh["vertices"]
            def at(i):
                p = v[3 * i:3 * i + 3]
                return tuple(m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3] for r in range(3))
            for f in mesh.get("faces", []):
                if len(f) == 3:
                    tris.append((at(f[0]), at(f[1]), at(f[2])))
                elif len(f) > 3:
                    polys.append([at(i) for i in f])
        for c in node.get("children", []):
            walk(c, m)
    walk(d["rootnode"], [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])
    return tris, polys

def dump_triangles(path):
    lines = open(path).read().split("\n")
    head = lines[0].split()
    n = int(head[1])
    tris = []
    for l in lines[1:1 + n]:
        x = list(map(float, l.split()))
        tris.append((tuple(x[0:3]), tuple(x[3:6]), tuple(x[6:9])))
    return tris

def key(tri, q):
    c = [tuple(round(x / q) for x in p) for p in tri]
    return min(tuple(c[(i + k) % 3] for k in range(3)) for i in range(3))

def area(corners):  # half the length of Newell's normal
    n = [0.0, 0.0, 0.0]
    for i, a in enumerate(corners):
        b = corners[(i + 1) % len(corners)]
        for j in range(3):
            u, v = (j + 1) % 3, (j + 2) % 3
            n[j] += (a[u] - b[u]) * (a[v] + b[v])
    return 0.5 * sum(x * x for x in n) ** 0.5

tris3, polys = assimp_triangles(sys.argv[1])
ours = dump_triangles(sys.argv[2])
if sys.argv[3] == "ac":
    turn = lambda p: (p[0], -p[2], p[1])
    tris3 = [tuple(turn(p) for p in t) for t in tris3]
    polys = [[turn(p) for p in c] for c in polys]
fans = [(c[0], c[k], c[k + 1]) for c in polys for k in range(1, len(c) - 1)]
theirs = tris3 + fans
assert len(ours) == len(theirs), ("triangle counts differ", len(ours), len(theirs))
size = max([abs(x) for t in theirs for p in t for x in p] + [1e-30])
q = size * 1e-5
def multiset(tris):
    out = {}
    for t in tris:
        k = key(t, q)
        out[k] = out.get(k, 0) + 1
    return out
def near(s, t):
    return any(all(abs(s[(i + k) % 3][j] - t[k][j]) <= 1 for k in range(3) for j in range(3)) for i in range(3))
def leftover(ours, theirs):
    """Our triangles (as keys) left once each of theirs is matched, or the
    first of theirs that has no match (as positions)."""
    a, b = multiset(ours), multiset(theirs)
    la = [k for k in a for _ in range(max(0, a[k] - b.get(k, 0)))]
    lb = [k for k in b for _ in range(max(0, b[k] - a.get(k, 0)))]
    # a coordinate next to a rounding step may round the other way: match the
    # leftovers within the tolerance, corner by corner
    for t in lb:
        m = next((i for i, s in enumerate(la) if near(s, t)), None)
        if m is None:
            return None, [tuple(x * q for x in p) for p in t]
        la.pop(m)
    return la, None
rest, missing = leftover(ours, theirs)
if rest is not None:
    print("%d triangles agree" % len(ours))
    sys.exit(0)
rest, missing = leftover(ours, tris3)
assert rest is not None, ("a triangle differs", missing, len(ours))
assert len(rest) == len(fans), ("polygon triangle counts differ", len(rest), len(fans))
corners = set(key((p, p, p), q)[0] for c in polys for p in c)
for t in rest:
    for p in t:
        assert p in corners or any(all(abs(p[j] - c[j]) <= 1 for j in range(3)) for c in corners), \
            ("a corner is no polygon corner", tuple(x * q for x in p))
def tri_area(t):
    return area([tuple(x * q for x in p) for p in t])
got, want = sum(tri_area(t) for t in rest), sum(area(c) for c in polys)
assert abs(got - want) <= 1e-4 * size * size * max(1, len(polys)), ("polygon areas differ", got, want)
print("%d triangles agree; %d polygons triangulated with their areas" % (len(ours), len(polys)))
