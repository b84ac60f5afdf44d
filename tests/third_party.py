"""Compares the triangles of the vdag importers (import_dump) with those
Debian's assimp reads from the same file (`assimp export F OUT -fassjson`,
no post-processing): the same number of triangles, and the same triangles as
a multiset of corner positions (each triangle up to a rotation of its
corners), positions equal within 1e-5 of the model's size. Assimp's meshes
are placed by their node transforms and its polygons fan-triangulated here
(as the importers do); lines and points are not triangles.
Usage: third_party.py ASSIMP_JSON DUMP AXES
AXES: "same", or "ac" (the AC3D importer turns y up to z up: (x, y, z) ->
(x, -z, y))."""
import json, sys

def mat_mul(a, b):
    return [sum(a[4 * i + k] * b[4 * k + j] for k in range(4)) for i in range(4) for j in range(4)]

def assimp_triangles(path):
    d = json.load(open(path, encoding="latin-1"))  # names may be in any encoding
    tris = []
    def walk(node, parent):
        m = mat_mul(parent, node.get("transformation", [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]))
        for mi in node.get("meshes", []):
            mesh = d["meshes"][mi]
            v = mesh["vertices"]
            def at(i):
                p = v[3 * i:3 * i + 3]
                return tuple(m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3] for r in range(3))
            for f in mesh.get("faces", []):
                for k in range(1, len(f) - 1):
                    tris.append((at(f[0]), at(f[k]), at(f[k + 1])))
        for c in node.get("children", []):
            walk(c, m)
    walk(d["rootnode"], [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])
    return tris

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

theirs = assimp_triangles(sys.argv[1])
ours = dump_triangles(sys.argv[2])
if sys.argv[3] == "ac":
    theirs = [tuple((p[0], -p[2], p[1]) for p in t) for t in theirs]
assert len(ours) == len(theirs), ("triangle counts differ", len(ours), len(theirs))
size = max([abs(x) for t in theirs for p in t for x in p] + [1e-30])
q = size * 1e-5
def multiset(tris):
    out = {}
    for t in tris:
        k = key(t, q)
        out[k] = out.get(k, 0) + 1
    return out
a, b = multiset(ours), multiset(theirs)
if a != b:
    # a coordinate next to a rounding step may round the other way: match the
    # leftovers within the tolerance, corner by corner
    la = [k for k in a for _ in range(max(0, a[k] - b.get(k, 0)))]
    lb = [k for k in b for _ in range(max(0, b[k] - a.get(k, 0)))]
    def near(s, t):
        return any(all(abs(s[(i + k) % 3][j] - t[k][j]) <= 1 for k in range(3) for j in range(3)) for i in range(3))
    left = list(lb)
    for s in la:
        m = next((i for i, t in enumerate(left) if near(s, t)), None)
        assert m is not None, ("a triangle differs", [tuple(x * q for x in p) for p in s], len(la))
        left.pop(m)
print("%d triangles agree" % len(ours))
