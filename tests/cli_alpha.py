"""Alpha testing oracle for tests/cli.sh: a textured .obj whose texture's
alpha masks half of it, and the voxels (and colours) `vdag build` must give,
computed here by brute force: every voxel against every triangle with an
exact separating-axis test, the texel looked up at the documented point (the
voxel centre's projection, barycentrics clamped into the triangle, nearest
texel, wrapping), in exact rationals. A voxel where a point lands exactly on
a texel edge (rounding decides) is not checked.
Usage: cli_alpha.py DIR write | cli_alpha.py DIR alpha|nocolor|plain
(reads DIR/alpha_MODE.txt, the export of the build with the defaults,
--no-colors or --no-alpha-test)."""
import random, struct, sys, zlib
from fractions import Fraction as F
t, mode = sys.argv[1], sys.argv[2]
S = 16                      # vertices are multiples of 1/S, in grid units
n = 16                      # grid of 2^4 voxels; the bounding box is pinned to [0, 16]^3
W = H = 8                   # texture size
random.seed(11)
if mode == "write":
    tris = []
    for i in range(36):
        c = [random.randrange(0, 16 * S) for _ in range(3)]
        tris.append([[min(16 * S, max(0, c[k] + random.randrange(-5 * S, 5 * S))) for k in range(3)] for _ in range(3)])
    tris[0][0] = [0, 0, 0]
    tris[1][0] = [16 * S, 16 * S, 16 * S]
    uvs = [[(random.randrange(-64, 128), random.randrange(-64, 128)) for _ in range(3)] for _ in tris]  # /64
    tex = [[(random.randrange(256), random.randrange(256), random.randrange(256), 255 if (x + 2 * y) % 4 < 2 else 0)
            for x in range(W)] for y in range(H)]
    raw = b"".join(b"\0" + bytes(v for px in row for v in px) for row in tex)
    def chunk(k, d): return struct.pack(">I", len(d)) + k + d + struct.pack(">I", zlib.crc32(k + d) & 0xffffffff)
    open(t + "/alpha.png", "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 6, 0, 0, 0))
                                       + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
    open(t + "/alpha.mtl", "w").write("newmtl leaf\nKd 1 1 1\nmap_Kd alpha.png\n")
    with open(t + "/alpha.obj", "w") as f:
        f.write("mtllib alpha.mtl\nusemtl leaf\n")
        for i, tri in enumerate(tris):
            for v in tri: f.write("v %r %r %r\n" % tuple(c / S for c in v))
            for u in uvs[i]: f.write("vt %r %r\n" % (u[0] / 64, u[1] / 64))
        for i in range(len(tris)):
            f.write("f %d/%d %d/%d %d/%d\n" % tuple(x for c in range(3) for x in (3 * i + c + 1, 3 * i + c + 1)))
    import json
    json.dump({"tris": tris, "uvs": uvs, "tex": tex}, open(t + "/alpha.json", "w"))
    sys.exit(0)

import json
d = json.load(open(t + "/alpha.json"))
tris, uvs, tex = d["tris"], d["uvs"], d["tex"]
def sub(a, b): return [a[k] - b[k] for k in range(3)]
def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def cross(a, b): return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
def touches(tri, lo):  # exact separating-axis test, closed boxes, integers scaled by S
    e = [sub(tri[(i + 1) % 3], tri[i]) for i in range(3)]
    units = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    axes = units + [cross(e[0], e[1])] + [cross(e[i], u) for i in range(3) for u in units]
    corners = [[lo[0] + (c & 1) * S, lo[1] + (c >> 1 & 1) * S, lo[2] + (c >> 2 & 1) * S] for c in range(8)]
    for a in axes:
        tp = [dot(a, v) for v in tri]
        bp = [dot(a, c) for c in corners]
        if min(tp) > max(bp) or max(tp) < min(bp): return False
    return True
def texel(tri, uv, centre):  # the documented point: clamped barycentrics of the centre's projection
    nn = cross(sub(tri[1], tri[0]), sub(tri[2], tri[0]))
    num = []
    for i in range(3):
        a, b = sub(tri[(i + 1) % 3], centre), sub(tri[(i + 2) % 3], centre)
        w = dot(nn, cross(a, b))
        num.append(w if w > 0 else 0)
    if dot(nn, nn) == 0 or sum(num) == 0: num = [1, 1, 1]
    bary = [F(x, sum(num)) for x in num]
    u = sum(bary[i] * F(uv[i][0], 64) for i in range(3))
    v = sum(bary[i] * F(uv[i][1], 64) for i in range(3))
    u -= u.numerator // u.denominator
    v -= v.numerator // v.denominator
    fx, fy = u * W, (1 - v) * H
    if fx.denominator == 1 or fy.denominator == 1: return None  # on a texel edge: rounding decides
    return min(W - 1, int(fx)), min(H - 1, int(fy))
alpha_test = mode != "plain"
want, ties, cut = {}, 0, 0
for z in range(n):
    for y in range(n):
        for x in range(n):
            lo = [x * S, y * S, z * S]
            centre = [x * S + S // 2, y * S + S // 2, z * S + S // 2]
            last, tie = None, False
            for i, tri in enumerate(tris):
                if any(max(v[k] for v in tri) < lo[k] or min(v[k] for v in tri) > lo[k] + S for k in range(3)): continue
                if not touches(tri, lo): continue
                p = texel(tri, uvs[i], centre)
                if p is None: tie = True; continue
                px = tex[p[1]][p[0]]
                if alpha_test and px[3] < 128: cut += 1; continue
                last = px
            if tie: ties += 1; want[(x, y, z)] = "tie"
            elif last is not None: want[(x, y, z)] = tuple(last[:3])
got = {}
for line in open(t + "/alpha_" + mode + ".txt"):
    v = list(map(int, line.split()))
    got[tuple(v[:3])] = tuple(v[3:])
bad = [k for k in set(want) | set(got) if want.get(k) != "tie" and (k in want) != (k in got)]
assert not bad, ("voxel set differs", len(bad), sorted(bad)[:5])
if mode != "nocolor":
    badc = [k for k in got if want.get(k, "tie") != "tie" and want[k] != got[k]]
    assert not badc, ("colours differ", len(badc), [(k, want[k], got[k]) for k in sorted(badc)[:3]])
full = sum(1 for v in want.values() if v != "tie")
assert ties < full // 20 and (not alpha_test or cut > full // 4), (ties, cut, full)
print(mode, "ok:", full, "voxels,", cut, "cut,", ties, "ties", file=sys.stderr)
