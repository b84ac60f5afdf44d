#!/bin/sh
# The importers' and the tool's fixes on the real third-party files they
# were found on (`make test-real`, not part of `make test`): each check
# compares what vdag does with an answer computed from the file itself
# (tests/real.py, od), with a bound justified here, or with vdag's own
# answer under the option that should give the same (--up, --raw-colors),
# never with a figure copied from an earlier run. Every check is printed.
#
# The files are fetched once, nothing installed: Debian packages with
# apt-get download and dpkg-deb -x into BUILD/cache/x/PACKAGE (a package
# already unpacked by bench/fetch.sh under bench/data/x is used as it is),
# npm packages with npm pack into BUILD/cache/npm. supertuxkart-data (628 MB)
# goes to tests/real_stk.sh, when it is there, whose counts are added.
# Usage: tests/real.sh BUILD   (BUILD/vdag and BUILD/import_dump built)
set -u
build=${1:-build}
VDAG=$build/vdag
DUMP=$build/import_dump
cache=$build/cache
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
pass=0
fail=0
ok() { pass=$((pass + 1)); }
ko() { fail=$((fail + 1)); echo "  FAIL: $*" >&2; }
check() { # check DESCRIPTION COMMAND...: passes when COMMAND succeeds (each printed)
    d=$1; shift
    if "$@"; then ok; echo "  ok: $d" >&2; else ko "$d"; fi
}
say() { echo "real.sh: $*" >&2; }
for p in "$VDAG" "$DUMP"; do
    [ -x "$p" ] || { say "$p is not built (make test-real builds it)"; echo "0 passed, 1 failed"; exit 1; }
done

# deb PACKAGE: prints the root its files were unpacked into, fetching and
# unpacking it first when neither bench/data/x nor the cache holds it.
deb() {
    for r in "bench/data/x/$1" "$cache/x/$1"; do
        [ -d "$r/usr" ] && { echo "$r"; return 0; }
    done
    mkdir -p "$cache/debs" "$cache/x"
    set -- "$1" "$(ls bench/data/debs/"$1"_*.deb "$cache"/debs/"$1"_*.deb 2>/dev/null | head -n 1)"
    if [ -z "$2" ]; then
        say "fetching $1"
        ( cd "$cache/debs" && apt-get download -q "$1" >/dev/null 2>&1 ) ||
            ( apt-get update -q >/dev/null 2>&1; cd "$cache/debs" && apt-get download -q "$1" >/dev/null 2>&1 ) ||
            { say "cannot download $1"; return 1; }
        set -- "$1" "$(ls "$cache"/debs/"$1"_*.deb | head -n 1)"
    fi
    rm -rf "$cache/x/$1.part"
    dpkg-deb -x "$2" "$cache/x/$1.part" && mv "$cache/x/$1.part" "$cache/x/$1" || { say "cannot unpack $2"; return 1; }
    echo "$cache/x/$1"
}
# npmpkg NAME@VERSION: the unpacked package folder (its files under package/).
npmpkg() {
    d=$cache/npm/$1
    if [ ! -d "$d/package" ]; then
        say "fetching $1 (npm)"
        mkdir -p "$d" &&
            f=$(cd "$d" && npm pack -q "$1" 2>/dev/null | tail -n 1) && [ -n "$f" ] &&
            tar xzf "$d/$f" -C "$d" || { say "cannot fetch $1"; return 1; }
    fi
    echo "$d"
}
# build IN OUT [OPTIONS]: vdag build, stderr kept in $T/err; its status.
build() {
    in=$1 out=$2; shift 2
    rm -f "$out"
    "$VDAG" build "$in" "$out" "$@" 2>"$T/err" </dev/null
}
voxels() { "$VDAG" info "$1" --json | sed -n 's/.*"voxels": \([0-9]*\),.*/\1/p'; }
levels() { "$VDAG" info "$1" --json | sed -n 's/.*"levels": \([0-9]*\),.*/\1/p'; }
# The number in vdag's "voxelizing N triangles" line of $T/err.
triangles() { sed -n 's/^vdag: voxelizing \([0-9]*\) triangles.*/\1/p' "$T/err"; }

ASSIMP=$(deb assimp-testmodels) && M=$ASSIMP/usr/share/assimp/models || ko "assimp-testmodels not fetched"
FG=$(deb flightgear-data-models) && FG=$FG/usr/share/games/flightgear/Models || ko "flightgear-data-models not fetched"
CGAL=$(deb libcgal-demo) || ko "libcgal-demo not fetched"
MT=$(deb minetest-data) && MT=$MT/usr/share/games/minetest/games/minetest_game/mods || ko "minetest-data not fetched"
PMV=$(npmpkg parse-magica-voxel@2.1.2) || ko "parse-magica-voxel not fetched"
VR=$(npmpkg vox-reader@4.0.1) || ko "vox-reader not fetched"
# CGAL's sample data is a tarball inside the package: its point clouds.
if [ -n "$CGAL" ]; then
    C=$CGAL/usr/share/doc/libcgal-dev
    if [ -f "$C/data/points_3/radar.xyz" ]; then
        PC=$C/data/points_3
    else
        PC=$cache/cgal/data/points_3
        [ -f "$PC/radar.xyz" ] || { mkdir -p "$cache/cgal" &&
            tar xzf "$C/data.tar.gz" -C "$cache/cgal" data/points_3/building.ply data/points_3/radar.xyz; } ||
            ko "CGAL's data.tar.gz not unpacked"
    fi
fi

# -- 1. Polygons of more than 3 corners are triangulated in their plane:
# concave ones by ear clipping, not by a fan (which overlaps itself and
# covers more than the polygon).
if [ -n "${M:-}" ]; then
    # Assimp's concave_polygon.obj: one 66-corner ring cut open (a corner
    # repeats), flat in the plane x = min x. Its voxels: every voxel the ring
    # touches, in one layer, so at least its area in voxels A and at most A
    # plus what its boundary crosses (at most 2 voxels per voxel of length P,
    # 3 more per edge); the fan gave 820,308.
    f=$M/OBJ/concave_polygon.obj
    read -r A P N <<EOF
$(python3 tests/real.py obj-area "$f" 10)
EOF
    check "concave_polygon.obj builds" build "$f" "$T/cp.vdag"
    v=$(voxels "$T/cp.vdag")
    check "concave_polygon.obj: $v voxels in one layer, between its area $A and $((A + 2 * P + 3 * N)) (area + boundary)" \
        sh -c "[ '${v:-0}' -ge $A ] && [ '${v:-0}' -le $((A + 2 * P + 3 * N)) ] &&
               '$VDAG' info '$T/cp.vdag' --json | grep -q '\"voxel_box\": \[0, 0, 0, 1, '"
    "$DUMP" "$f" >"$T/dump" 2>/dev/null
    python3 tests/real.py polygons "$f" "$T/dump" >"$T/poly" 2>&1
    check "concave_polygon.obj: its triangles cover the ring's area ($(head -n 1 "$T/poly"))" \
        grep -q '^polygons 1 concave 1 fan_wrong 1 bad 0 wrong 0$' "$T/poly"
fi
# FlightGear's KC-135 and CG-57 (AC3D): both build; every planar polygon
# that is simple in its plane is covered by its triangles exactly (some are
# concave with a fan that covers more: the files test the fix), and the
# tool's warning counts the polygons that are degenerate or self-intersecting
# in their plane, as real.py counts them.
if [ -n "${FG:-}" ]; then
    for f in Geometry/KC135/KC135.ac Maritime/Military/CG-57-high-detail/CG-57.ac; do
        b=$(basename "$f")
        check "$b builds" build "$FG/$f" "$T/fg.vdag" --quiet
        bad=$(sed -n 's/.*: \([0-9]*\) polygons* w[ae][sr]e* degenerate or self-intersecting.*/\1/p' "$T/err")
        "$DUMP" "$FG/$f" >"$T/dump" 2>/dev/null
        python3 tests/real.py polygons "$FG/$f" "$T/dump" >"$T/poly" 2>&1
        set -- $(head -n 1 "$T/poly") # polygons P concave C fan_wrong W bad B wrong X
        check "$b: concave polygons, some of which a fan gets wrong, and every planar simple polygon covered exactly by its triangles ($(head -n 2 "$T/poly" | tr '\n' ' '))" \
            test "${4:-0}" -gt 0 -a "${6:-0}" -gt 0 -a "${10:-}" = 0
        check "$b: the warning counts ${bad:-no} bad polygons, real.py ${8:-?}" test "${bad:-0}" = "${8:-}"
    done
fi

# -- 4. A .vox of several models and no scene graph (animation frames):
# model 0 with a warning naming the count, --vox-model N picks model N
# (its voxels are the file's XYZI chunk N, up to a translation), past the
# last an error; a file with a scene graph refuses --vox-model 1.
if [ -n "${PMV:-}" ]; then
    f=$PMV/package/example/deer.vox
    python3 tests/real.py vox "$f" >"$T/vox"
    n=$(sed -n 's/^MODELS //p' "$T/vox")
    check "deer.vox holds several models ($n) and no scene graph" sh -c "[ '${n:-0}' -gt 1 ] && grep -q '^GRAPH 0' '$T/vox'"
    check "deer.vox builds" build "$f" "$T/deer.vdag"
    check "deer.vox: one warning naming $n models and --vox-model" \
        sh -c "[ \$(grep -c 'warning: .*$n models and no scene graph.*model 0 imported; --vox-model' '$T/err') = 1 ]"
    "$VDAG" export-voxels "$T/deer.vdag" 2>/dev/null >"$T/got"
    check "deer.vox: the voxels are model 0's" python3 tests/real.py vox-same "$f" 0 "$T/got"
    k=1
    while [ "$k" -lt "${n:-0}" ]; do
        build "$f" "$T/deer.vdag" --vox-model $k --quiet && "$VDAG" export-voxels "$T/deer.vdag" >"$T/got" 2>/dev/null
        check "deer.vox --vox-model $k: model $k's voxels" python3 tests/real.py vox-same "$f" $k "$T/got"
        k=$((k + 1))
    done
    check "deer.vox --vox-model $n (past the last): an error naming the count, no file" \
        sh -c "rm -f '$T/deer.vdag' && ! '$VDAG' build '$f' '$T/deer.vdag' --vox-model $n --quiet 2>'$T/err' </dev/null &&
               [ ! -e '$T/deer.vdag' ] &&
               grep -q 'holds $n models' '$T/err' && [ \$(wc -l <'$T/err') = 1 ]"
fi
if [ -n "${VR:-}" ]; then
    f=$VR/package/test/tree.vox
    check "tree.vox has a scene graph" grep -q '^GRAPH 1' <<EOF
$(python3 tests/real.py vox "$f")
EOF
    check "tree.vox (scene graph) builds without the frames warning" sh -c "
        '$VDAG' build '$f' '$T/tree.vdag' 2>'$T/err' </dev/null && ! grep -q 'vox-model' '$T/err'"
    check "tree.vox --vox-model 1 refused: its scene graph places the models" \
        sh -c "! '$VDAG' build '$f' '$T/tree.vdag' --vox-model 1 2>'$T/err' </dev/null && grep -q 'scene graph' '$T/err'"
fi

# -- 5. AC3D subdiv: the tool subdivides (its triangles then are Assimp's,
# which subdivides) or warns, importing the control mesh (its triangles are
# the file's polygons', n - 2 each).
if [ -n "${M:-}" ]; then
    for f in SphereWithLight.ac sample_subdiv.ac; do
        want=$(python3 tests/real.py ac-tris "$M/AC/$f")
        check "$f says subdiv" grep -q '^subdiv [1-9]' "$M/AC/$f"
        check "$f builds" build "$M/AC/$f" "$T/sub.vdag"
        got=$(triangles)
        if grep -q 'subdiv > 0.*unsubdivided' "$T/err"; then
            check "$f: warns, and voxelizes the control mesh's $want triangles (got ${got:-none})" [ "${got:-}" = "$want" ]
        elif command -v assimp >/dev/null 2>&1; then
            a=$(assimp info "$M/AC/$f" 2>/dev/null | sed -n 's/^Faces: *//p')
            check "$f: no warning, so subdivided as Assimp does: $a triangles (got ${got:-none})" [ "${got:-}" = "$a" ]
        else
            check "$f: no warning, so subdivided: more than the control mesh's $want triangles (got ${got:-none})" \
                [ "${got:-0}" -gt "$want" ]
        fi
    done
fi

# -- 6. Point clouds: without --levels, the level from the point spacing
# (README: the largest L <= 10 whose voxel, extent / 2^L, is at least the
# median nearest-neighbour distance over every (n / 2000)-th point), by
# brute force here; printed; fewer isolated voxels (dust) than at L = 10,
# and under 5 % on the building scan (a surface sampled densely: a point's
# neighbours lie around it on the surface). --levels overrides.
if [ -n "${PC:-}" ]; then
    for f in building.ply radar.xyz; do
        read -r s m l <<EOF
$(python3 tests/real.py spacing "$PC/$f")
EOF
        check "$f builds" build "$PC/$f" "$T/pc.vdag"
        check "$f: prints spacing $s of $m points and --levels $l (brute force), and the file has level $l" sh -c "
            grep -q '^vdag: point cloud: median spacing $s (of $m sampled points), extent .*: --levels $l (' '$T/err' &&
            [ '$(levels "$T/pc.vdag")' = '$l' ]"
        "$VDAG" export-voxels "$T/pc.vdag" | python3 tests/real.py isolated >"$T/iso"
        read -r i n <"$T/iso"
        build "$PC/$f" "$T/pc10.vdag" --levels 10
        check "$f --levels 10 overrides, no spacing line" \
            sh -c "! grep -q 'point cloud' '$T/err' && [ '$(levels "$T/pc10.vdag" 2>/dev/null)' = 10 ]"
        "$VDAG" export-voxels "$T/pc10.vdag" 2>/dev/null | python3 tests/real.py isolated >"$T/iso"
        read -r i10 n10 <"$T/iso"
        check "$f: isolated voxels $i of $n at level $l, fewer (as a share) than $i10 of $n10 at level 10" \
            [ $((i * n10)) -lt $((i10 * n)) ]
        [ "$f" = building.ply ] && check "building.ply: isolated voxels $i of $n, under 5 %" [ $((i * 20)) -lt "$n" ]
    done
fi

# -- 7. The up axis is printed with its reason: what a Blender exporter
# named in the file writes (its PLY add-on up to 3.5: z; its OBJ exporter:
# y), else the format's default (y for .obj .ply .off, z for .stl .ac .vox
# .xyz), and `--up` names itself. A file read as z or y up from its
# comment gives the same voxels as that --up.
upline() { # upline IN AXIS WHY: the build's one up-axis line
    "$VDAG" build "$1" "$T/up.vdag" --levels 6 --no-colors 2>"$T/err" </dev/null &&
        [ "$(grep -c '^vdag: up axis: ' "$T/err")" = 1 ] && grep -q "^vdag: up axis: $2 ($3" "$T/err"
}
same_as_up() { # same_as_up IN AXIS: the build without --up equals --up AXIS
    "$VDAG" build "$1" "$T/a.vdag" --levels 6 --quiet </dev/null 2>/dev/null &&
        "$VDAG" build "$1" "$T/b.vdag" --levels 6 --quiet --up "$2" </dev/null 2>/dev/null &&
        cmp -s "$T/a.vdag" "$T/b.vdag"
}
if [ -n "${M:-}" ]; then
    check "cube_uv.ply says 'comment Created by Blender 2.77'" grep -q '^comment Created by Blender 2' "$M/PLY/cube_uv.ply"
    check "cube_uv.ply: up axis z, from the file" upline "$M/PLY/cube_uv.ply" z 'from the file: "comment Created by Blender 2.77'
    check "cube_uv.ply: the same file as --up z" same_as_up "$M/PLY/cube_uv.ply" z
    check "empty_mat.obj says '# Blender v2.61'" grep -q '^# Blender v2' "$M/OBJ/empty_mat.obj"
    check "empty_mat.obj: up axis y, from the file" upline "$M/OBJ/empty_mat.obj" y 'from the file: "# Blender v2.61'
    check "empty_mat.obj: the same file as --up y" same_as_up "$M/OBJ/empty_mat.obj" y
    for f in OBJ/WusonOBJ.obj:y PLY/Wuson.ply:y OFF/Wuson.off:y STL/Spider_binary.stl:z AC/Wuson.ac:z; do
        ext=${f%:*}
        ext=.${ext##*.}
        check "${f%:*}: up axis ${f#*:} (default for $ext)" upline "$M/${f%:*}" "${f#*:}" "default for $ext;"
    done
    check "--up x is printed as such" sh -c "
        '$VDAG' build '$M/OBJ/WusonOBJ.obj' '$T/up.vdag' --levels 6 --up x 2>'$T/err' </dev/null &&
        grep -q '^vdag: up axis: x (--up)' '$T/err'"
fi
[ -n "${PC:-}" ] && check "radar.xyz: up axis z (default for .xyz)" upline "$PC/radar.xyz" z 'default for .xyz;'
[ -n "${PMV:-}" ] && check "deer.vox: up axis z (default for .vox)" upline "$PMV/package/example/deer.vox" z 'default for .vox;'

# -- 9. Colours are lossless voxcolor by default: Minetest's boat names a
# material library its package lacks and `usemtl None`, so every voxel is
# white. Raw RGB8 (--raw-colors) is 3 bytes a voxel, the issue's 5.96 MB;
# the default decodes to the same colours in under 1 bit a voxel.
if [ -n "${MT:-}" ]; then
    f=$MT/boats/models/boats_boat.obj
    check "boats_boat.obj names boat.mtl, which its package lacks, and usemtl None" sh -c "
        grep -q '^mtllib boat.mtl' '$f' && [ ! -e '$MT/boats/models/boat.mtl' ] && grep -q '^usemtl None' '$f'"
    check "boats_boat.obj builds" build "$f" "$T/boat.vdag"
    check "boats_boat.obj: a warning names the undefined material None" grep -q 'warning: .*usemtl .*"None"' "$T/err"
    check "boats_boat.obj --raw-colors builds" build "$f" "$T/boat_raw.vdag" --raw-colors --quiet
    v=$(voxels "$T/boat_raw.vdag")
    "$VDAG" info "$T/boat.vdag" --json >"$T/info"
    "$VDAG" info "$T/boat_raw.vdag" --json >"$T/info_raw"
    cb=$(sed -n 's/.*"colors": \([0-9]*\)}.*/\1/p' "$T/info")
    cr=$(sed -n 's/.*"colors": \([0-9]*\)}.*/\1/p' "$T/info_raw")
    check "boats_boat.obj --raw-colors: RGB8, 3 bytes a voxel ($v voxels, $cr bytes)" \
        sh -c "grep -q '\"color_format\": \"rgb8\"' '$T/info_raw' && [ '${cr:-}' = $((3 * ${v:-0})) ]"
    check "boats_boat.obj: voxcolor by default, under 1 bit a voxel ($cb bytes for $v voxels)" \
        sh -c "grep -q '\"color_format\": \"voxcolor\"' '$T/info' && [ $((8 * ${cb:-999999999})) -lt '${v:-0}' ]"
    check "boats_boat.obj: the default file's colours equal the raw file's, all white" sh -c "
        '$VDAG' export-voxels '$T/boat.vdag' >'$T/ea' && '$VDAG' export-voxels '$T/boat_raw.vdag' | cmp -s - '$T/ea' &&
        [ \"\$(cut -d' ' -f4-6 '$T/ea' | sort -u)\" = '255 255 255' ] && [ \$(wc -l <'$T/ea') = '${v:-}' ]"
fi

# -- 11. Input that is no model exits non-zero, writing nothing, with one
# line saying what it looks like: a binary STL and a PNG under .obj, an .mtl,
# Assimp's empty files, an AC3D file of lines; --allow-empty builds an empty
# scene from an empty file, with a warning.
refused() { # refused IN WORDS: non-zero exit, one line matching WORDS, no file
    rm -f "$T/no.vdag"
    ! "$VDAG" build "$1" "$T/no.vdag" --quiet 2>"$T/err" </dev/null && [ ! -e "$T/no.vdag" ] &&
        [ "$(wc -l <"$T/err")" = 1 ] && grep -q "$2" "$T/err"
}
if [ -n "${M:-}" ]; then
    cp "$M/STL/Spider_binary.stl" "$T/spider.obj"
    check "Spider_binary.stl is a binary STL (84 + 50 * count bytes)" python3 tests/real.py stl-binary "$T/spider.obj"
    check "a binary STL named .obj is refused as one" refused "$T/spider.obj" 'binary STL'
    check "spider.mtl (a material library) is refused as one" refused "$M/OBJ/spider.mtl" 'material library'
    for e in obj off ply; do
        check "invalid/empty.$e is 0 bytes" test -f "$M/invalid/empty.$e" -a ! -s "$M/invalid/empty.$e"
        check "invalid/empty.$e: refused, saying it is empty" refused "$M/invalid/empty.$e" 'empty'
    done
    build "$M/invalid/empty.obj" "$T/empty.vdag" --allow-empty
    check "invalid/empty.obj --allow-empty: an empty scene, with a warning" \
        test "$(grep -c 'warning' "$T/err")" = 1 -a "$(voxels "$T/empty.vdag")" = 0
    check "AC/nosurfaces.ac (lines only) is refused: no triangles and no points" \
        refused "$M/AC/nosurfaces.ac" 'no triangles and no points'
fi
if [ -n "${FG:-}" ]; then
    png=$FG/Maritime/Military/CG-57-high-detail/nets.png
    cp "$png" "$T/nets.obj"
    check "nets.png starts with the PNG signature" sh -c "
        [ \"\$(od -An -tx1 -N8 '$png' | tr -d ' \n')\" = 89504e470d0a1a0a ]"
    check "a PNG named .obj is refused as one" refused "$T/nets.obj" 'PNG image'
fi

# -- README's walk-through ("Convert a model and look at it"): its vdag
# commands, as written, on the model it names (Assimp's spider, its .mtl and
# textures beside it): no warning, and a 640x480 PNG.
if [ -n "${M:-}" ]; then
    mkdir -p "$T/walk" && cp "$M"/OBJ/spider.obj "$M"/OBJ/spider.mtl "$M"/OBJ/*.jpg "$T/walk/"
    vabs=$(cd "$(dirname "$VDAG")" && pwd)/vdag
    awk '/^### Convert a model/ { w = 1 } w && /^```sh$/ { c = 1; next } c && /^```/ { exit }
         c && /^build\/vdag / { sub(/ *#.*/, ""); print }' README.md | sed "s|^build/vdag |'$vabs' |" >"$T/walk.sh"
    check "README's walk-through has its 3 vdag commands" test "$(wc -l <"$T/walk.sh")" = 3
    check "README's walk-through runs as written, without a warning" \
        sh -c "cd '$T/walk' && sh -e '$T/walk.sh' >/dev/null 2>'$T/err' && ! grep -q warning '$T/err'"
    check "README's walk-through renders a 640x480 PNG" \
        test "$(od -An -tu1 -N24 "$T/walk/spider.png" 2>/dev/null | tr -s ' \n' ' ')" = \
        " 137 80 78 71 13 10 26 10 0 0 0 13 73 72 68 82 0 0 2 128 0 0 1 224 "
fi

# -- 2 and 3. SuperTuxKart's foliage and karts (tests/real_stk.sh), on the
# unpacked supertuxkart-data (628 MB).
if [ -f tests/real_stk.sh ]; then
    if STK=$(deb supertuxkart-data); then
        out=$(sh tests/real_stk.sh "$build" "$STK")
        status=$?
        printf '%s\n' "$out" | sed '$d' >&2
        line=$(printf '%s\n' "$out" | tail -n 1)
        p=$(printf '%s\n' "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed.*/\1/p')
        f=$(printf '%s\n' "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed.*/\2/p')
        if [ -z "$p" ]; then
            ko "real_stk.sh: no result line (exit $status)"
        else
            say "real_stk.sh: $line"
            pass=$((pass + p))
            fail=$((fail + f))
            [ "$status" != 0 ] && [ "$f" = 0 ] && ko "real_stk.sh: exit status $status"
        fi
    else
        ko "supertuxkart-data not fetched"
    fi
fi

echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
