#!/bin/sh
# The .spm importer on SuperTuxKart's own files (Debian's supertuxkart-data,
# unpacked at STK_DIR: STK_DIR/usr/share/games/supertuxkart/data), through
# the vdag tool in BUILD:
# (a) foliage drawn with the game's grass shader (materials.xml says
#     shader="grass": its vertex colours are wind weights) gets its
#     texture's colours: the mean colour of the voxels is within TOL of the
#     mean of the texture's opaque texels (alpha >= 128, those the build's
#     alpha test keeps), per channel. These meshes map their whole texture,
#     so the two means agree up to sampling (measured: within 2 of 255 at
#     --levels 8); TOL = 8 leaves room for that, while the wind weights
#     applied as a tint (13 to 64 of 255 in these files) put the voxels 48
#     to 129 below the texture.
# (b) every kart .spm imports (the animated ones in their bind pose), and
#     Tux's kart has a kart's size: its occupied box is the bounding box the
#     file itself records (within one voxel), about 0.8 m wide, 1.4 m long
#     and 0.7 m high, longest front to back.
# Prints "N passed, M failed"; exits non-zero on a failure.
# Usage: tests/real_stk.sh BUILD STK_DIR
set -u
build=${1:-build}
vdag=$build/vdag
D=${2:-bench/data/x/supertuxkart-data}/usr/share/games/supertuxkart/data
TOL=8
pass=0
fail=0
ok() { pass=$((pass + 1)); }
ko() { fail=$((fail + 1)); echo "  FAIL: $*" >&2; }
if [ ! -x "$vdag" ] || [ ! -d "$D/karts" ]; then
    echo "real_stk.sh: need $vdag and SuperTuxKart's data at $D" >&2
    echo "0 passed, 1 failed"
    exit 1
fi
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# The mean of the opaque texels (alpha >= 128) of an 8-bit PNG: "r g b".
texmean() {
    python3 - "$1" <<'EOF'
import struct, sys, zlib
d = open(sys.argv[1], 'rb').read()
if d[:8] != b'\x89PNG\r\n\x1a\n':
    sys.exit('not a PNG')
p, idat, pal, trns = 8, b'', b'', b''
while p < len(d):
    n, t = struct.unpack('>I4s', d[p:p + 8])
    c = d[p + 8:p + 8 + n]
    p += 12 + n
    if t == b'IHDR':
        w, h, depth, ctype, _, _, interlace = struct.unpack('>IIBBBBB', c)
    elif t == b'PLTE':
        pal = c
    elif t == b'tRNS':
        trns = c
    elif t == b'IDAT':
        idat += c
if depth != 8 or interlace:
    sys.exit('only 8-bit non-interlaced PNGs')
ch = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}[ctype]
raw, stride = zlib.decompress(idat), w * ch
prev, s, n = bytearray(stride), [0, 0, 0], 0
for y in range(h):
    f = raw[y * (stride + 1)]
    line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
    for i in range(stride):
        a = line[i - ch] if i >= ch else 0
        b = prev[i]
        c = prev[i - ch] if i >= ch else 0
        if f == 1: line[i] = (line[i] + a) & 255
        elif f == 2: line[i] = (line[i] + b) & 255
        elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
        elif f == 4:
            pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
            line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
    prev = line
    for x in range(w):
        px = line[x * ch:(x + 1) * ch]
        if ctype == 3:
            rgb, al = pal[3 * px[0]:3 * px[0] + 3], trns[px[0]] if px[0] < len(trns) else 255
        elif ctype in (0, 4):
            rgb, al = (px[0],) * 3, px[1] if ctype == 4 else 255
        else:
            rgb, al = px[:3], px[3] if ctype == 6 else 255
        if al >= 128:
            n += 1
            for k in range(3):
                s[k] += rgb[k]
print('%.1f %.1f %.1f' % tuple(v / n for v in s))
EOF
}

# The mean colour of the voxels of a .vdag file: "r g b".
voxmean() {
    "$vdag" export-voxels "$1" | awk '{ n++; r += $4; g += $5; b += $6 }
        END { if (n) printf "%.1f %.1f %.1f\n", r / n, g / n, b / n; else print "none" }'
}

# (a) Foliage: library objects with one grass-shader texture each (declared
# in data/textures/materials.xml), vertex colours of 13 to 64 of 255.
for m in stklib_accacia_a/stklib_accacia_a_high.spm:textures/stk_accacia_a.png \
    stklib_agave_a/stklib_agave_main.spm:textures/stktex_agave_a.png \
    stklib_cabbage_a/stklib_cabbage_a_main.spm:textures/stk_cabbage_a.png \
    stklib_lowPineTree_a/stklib_lowPineTree_a_main.spm:textures/stklib_conifer_a_low.png \
    stklib_fern_a/stklib_fern_a_a.spm:library/stklib_fern_a/stktex_fern_diff_a.png; do
    spm=$D/library/${m%%:*}
    tex=$D/${m#*:}
    name=$(basename "$spm" .spm)
    if ! "$vdag" build "$spm" "$T/f.vdag" --levels 8 --quiet 2>"$T/err"; then
        ko "foliage $name: build failed: $(cat "$T/err")"
        continue
    fi
    got=$(voxmean "$T/f.vdag")
    want=$(texmean "$tex") || { ko "foliage $name: cannot read $tex"; continue; }
    if echo "$got $want" | awk -v t=$TOL '{ for (k = 1; k <= 3; k++) { d = $k - $(k + 3); if (d < -t || d > t) exit 1 } }'
    then
        ok
        echo "  foliage $name: voxels ($got), texture ($want)"
    else
        ko "foliage $name: voxel mean ($got), texture mean ($want): more than $TOL apart"
    fi
done

# (b) Every kart .spm imports; count them and the animated ones.
n=0
animated=0
bad=0
for spm in "$D"/karts/*/*.spm; do
    [ -f "$spm" ] || continue
    n=$((n + 1))
    [ "$(od -An -tu1 -j2 -N1 "$spm" | tr -d ' ')" = 9 ] && animated=$((animated + 1))
    if ! "$vdag" build "$spm" "$T/k.vdag" --levels 6 --quiet 2>"$T/err"; then
        bad=$((bad + 1))
        echo "  refused: ${spm#"$D"/}: $(cat "$T/err")" >&2
    fi
done
if [ "$n" -gt 0 ] && [ "$bad" = 0 ]; then
    ok
    echo "  karts: $n .spm files imported, $animated of them animated"
else
    ko "karts: $bad of $n .spm files refused"
fi

# Tux's kart in its bind pose, at --levels 8: the occupied box against the
# box in the file's header (6 f32 at byte 4: min x y z, max x y z, y up,
# turned z up as the importer does) and a kart's size.
tux=$D/karts/tux/tux.spm
if "$vdag" build "$tux" "$T/tux.vdag" --levels 8 --quiet 2>"$T/err" &&
    "$vdag" info "$T/tux.vdag" >"$T/info" 2>"$T/err"; then
    if python3 - "$tux" "$T/info" <<'EOF'
import re, struct, sys
b = struct.unpack_from('<6f', open(sys.argv[1], 'rb').read(), 4)
want = [b[0], b[2], b[1], b[3], b[5], b[4]]  # (x, y, z) y up -> (x, z, y)
info = open(sys.argv[2]).read()
num = r'(-?[0-9.e+-]+)'
m = re.search(r'occupied world box\s+\(%s, %s, %s\) - \(%s, %s, %s\)' % ((num,) * 6), info)
got = [float(v) for v in m.groups()]
voxel = max(want[k + 3] - want[k] for k in range(3)) / 256
size = [got[k + 3] - got[k] for k in range(3)]
print('  tux kart: occupied box %s, size %.2f x %.2f x %.2f m; header box %s' %
      (' '.join('%.3f' % v for v in got), size[0], size[1], size[2], ' '.join('%.3f' % v for v in want)))
ok = all(abs(got[k] - want[k]) <= 1.01 * voxel for k in range(6))
ok &= 0.4 <= size[0] <= 1.5 and 0.9 <= size[1] <= 2.5 and 0.4 <= size[2] <= 1.5 and size[1] == max(size)
sys.exit(0 if ok else 1)
EOF
    then
        ok
    else
        ko "tux kart: occupied box not the file's own box, or not a kart's size"
    fi
else
    ko "tux kart: $(cat "$T/err")"
fi

echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
