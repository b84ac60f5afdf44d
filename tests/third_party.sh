#!/bin/sh
# The importers against an independent reader on real third-party files:
# Debian's assimp-testmodels (models saved by many exporters) read by our
# importers (BUILD/import_dump) and by Debian's assimp (assimp-utils,
# installed by tests/deps.sh), compared by tests/third_party.py: triangle
# counts and positions. The package is fetched once into BUILD/cache with
# apt-get download and unpacked there with dpkg-deb -x (nothing installed).
# Files that are malformed must be refused with a one-line reason.
# Usage: tests/third_party.sh BUILD
set -u
build=${1:-build}
dump=$build/import_dump
cache=$build/cache
M=$cache/x/assimp-testmodels/usr/share/assimp/models
pass=0
fail=0
ok() { pass=$((pass + 1)); }
ko() { fail=$((fail + 1)); echo "  FAIL: $*" >&2; }
if [ ! -d "$M" ]; then
    mkdir -p "$cache/debs" "$cache/x"
    ls "$cache"/debs/assimp-testmodels_*.deb >/dev/null 2>&1 ||
        ( cd "$cache/debs" && apt-get download -q assimp-testmodels >/dev/null 2>&1 ) ||
        ( apt-get update -q >/dev/null 2>&1; cd "$cache/debs" && apt-get download -q assimp-testmodels >/dev/null )
    dpkg-deb -x "$cache"/debs/assimp-testmodels_*.deb "$cache/x/assimp-testmodels" || true
fi
if [ ! -d "$M" ] || ! command -v assimp >/dev/null 2>&1; then
    echo "third_party.sh: need assimp-testmodels (fetched into $cache) and assimp (assimp-utils)" >&2
    echo "0 passed, 1 failed"
    exit 1
fi
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

# Files both readers take: OBJ, PLY, STL, OFF and AC from several exporters
# (3ds Max, Blender, ASCII and binary STL, a UTF-8 byte order mark, ...).
for f in OBJ/WusonOBJ.obj OBJ/spider.obj OBJ/regr01.obj OBJ/box.obj OBJ/concave_polygon.obj OBJ/cube_usemtl.obj \
    OBJ/cube_with_vertexcolors.obj PLY/Wuson.ply PLY/cube_binary.ply PLY/cube_uv.ply PLY/float-color.ply \
    STL/Spider_ascii.stl STL/Spider_binary.stl STL/3DSMaxExport.STL STL/sphereWithHole.stl STL/Wuson.stl \
    STL/triangle_with_two_solids.stl OFF/Wuson.off OFF/Cube.off AC/Wuson.ac AC/SphereWithLight_UTF8BOM.ac; do
    b=$(echo "$f" | tr / _)
    axes=same
    case $f in *.ac) axes=ac ;; esac
    if ! assimp export "$M/$f" "$T/$b.json" -fassjson >/dev/null 2>&1; then
        ko "$f: assimp cannot read it"
    elif ! "$dump" "$M/$f" >"$T/$b.dump"; then
        ko "$f: our importer refuses it"
    elif python3 tests/third_party.py "$T/$b.json" "$T/$b.dump" $axes >"$T/out" 2>&1; then
        ok
    else
        ko "$f: $(tail -n 1 "$T/out")"
    fi
done
# Malformed files, refused with one line: a truncated binary PLY (assimp
# crashes on it), numbers like "3.1+e2", a list property on the vertex
# element with no lists in the data, UTF-16 text.
for f in PLY/pond.0.ply OBJ/number_formats.obj PLY/issue623.ply OBJ/box_UTF16BE.obj; do
    if ! "$dump" "$M/$f" >/dev/null 2>"$T/err" && [ "$(wc -l <"$T/err")" = 1 ]; then ok; else ko "$f is not refused with one line"; fi
done
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
