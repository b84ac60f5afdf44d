#!/bin/sh
# Fetches the third-party scenes the benchmarks read, without installing
# anything system-wide: Debian packages are downloaded and unpacked with
# dpkg-deb -x, npm packages with npm pack. Safe to run again (skips what is
# already there).
#   bench/fetch.sh DEST        (the Makefile uses bench/data)
#   bench/fetch.sh DEST scenes (also the game scenes of bench/real_scenes.md)
# Result, under DEST:
#   tree.vox      MagicaVoxel scene (npm vox-reader, MIT)
#   liver.inr     CGAL liver label volume, decompressed (Debian libcgal-demo, CC0)
#   bunny.off, armadillo.off, dragon.off   CGAL triangle meshes (CC0)
set -eu
DEST=${1:?usage: bench/fetch.sh DEST}
mkdir -p "$DEST/debs" "$DEST/x" "$DEST/npm"
cd "$DEST"

need_cgal=0
for f in liver.inr bunny.off armadillo.off dragon.off; do [ -s "$f" ] || need_cgal=1; done
if [ "$need_cgal" = 1 ]; then
    if ! ls debs/libcgal-demo_*.deb >/dev/null 2>&1; then
        apt-get update -q >/dev/null 2>&1 || true
        ( cd debs && apt-get download -q libcgal-demo )
    fi
    [ -d x/libcgal-demo ] || dpkg-deb -x debs/libcgal-demo_*.deb x/libcgal-demo
    C=x/libcgal-demo/usr/share/doc/libcgal-dev
    [ -d "$C/data" ] || tar xzf "$C/data.tar.gz" -C "$C"
    gzip -dc "$C/data/images/liver.inr.gz" > liver.inr
    cp "$C/data/meshes/bunny00.off" bunny.off
    cp "$C/data/meshes/armadillo.off" armadillo.off
    cp "$C/data/meshes/ChineseDragon-10kv.off" dragon.off
fi

if [ ! -s tree.vox ]; then
    ( cd npm
      [ -d vox-reader ] || {
          f=$(npm pack -q vox-reader@4.0.1 2>/dev/null | tail -n 1)
          mkdir -p vox-reader && tar xzf "$f" -C vox-reader
      } )
    cp npm/vox-reader/package/test/tree.vox tree.vox
fi
# Game scenes, left in their package trees so that their textures are found:
# x/supertuxkart-data/.../tracks/abyss/abyss_track.spm (CC-BY-SA-4.0),
# x/flightgear-data-models/.../CG-57-high-detail/CG-57.ac (GPL-2+), the DTC
# hull x/openfoam-examples/.../resources/geometry/DTC-scaled.stl.gz (an STL,
# GPL-3+; unpacked to DTC-scaled.stl) and assimp's Wuson rabbit
# x/assimp-testmodels/.../models/OBJ/WusonOBJ.obj (a y-up OBJ); ~1 GB.
if [ "${2:-}" = scenes ]; then
    for p in supertuxkart-data flightgear-data-models openfoam-examples assimp-testmodels; do
        [ -d "x/$p" ] && continue
        ls debs/${p}_*.deb >/dev/null 2>&1 || ( cd debs && apt-get download -q "$p" ) || { echo "cannot fetch $p" >&2; continue; }
        dpkg-deb -x debs/${p}_*.deb "x/$p"
    done
    G=x/openfoam-examples/usr/share/doc/openfoam-examples/examples/resources/geometry
    [ -s DTC-scaled.stl ] || { [ -f "$G/DTC-scaled.stl.gz" ] && gzip -dc "$G/DTC-scaled.stl.gz" > DTC-scaled.stl; } || true
fi
ls -l tree.vox liver.inr bunny.off armadillo.off dragon.off
