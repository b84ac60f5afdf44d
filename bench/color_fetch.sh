#!/bin/sh
# Fetches and converts the colour arrays bench_color reads: real textures and
# a photograph from Debian packages (downloaded and unpacked with dpkg-deb -x,
# nothing installed), converted to binary PPM with oiiotool. Safe to run again.
#   bench/color_fetch.sh DEST       (the Makefile uses bench/data/color)
# Prints the bench_color arguments, NAME=IMAGE.ppm[,...] per data set:
#   terrains  44 game terrain textures, 256x256 (extremetuxracer-data, GPL-2+)
#   skybox    a 1024x768 sky box face (extremetuxracer-data)
#   photo     a wood photograph, 4096x4096 resized to 2048x2048 (gnome-backgrounds;
#             licence in its debian/copyright)
set -eu
DEST=${1:?usage: bench/color_fetch.sh DEST}
mkdir -p "$DEST/debs" "$DEST/x" "$DEST/ppm"
cd "$DEST"
command -v oiiotool >/dev/null || { echo "color_fetch.sh: oiiotool (openimageio-tools) is needed" >&2; exit 1; }
for p in extremetuxracer-data gnome-backgrounds; do
    if ! ls debs/${p}_*.deb >/dev/null 2>&1; then
        apt-get update -q >/dev/null 2>&1 || true
        ( cd debs && apt-get download -q "$p" >/dev/null 2>&1 )
    fi
    [ -d "x/$p" ] || dpkg-deb -x debs/${p}_*.deb "x/$p"
done
E=x/extremetuxracer-data/usr/share/games/etr
ppm() { [ -s "$2" ] || oiiotool "$1" --ch R,G,B $3 -d uint8 -o "$2"; }
terrains=""
for f in "$E"/terrains/*.png; do
    out=ppm/terrain_$(basename "$f" .png).ppm
    ppm "$f" "$out" ""
    terrains="$terrains${terrains:+,}$PWD/$out"
done
ppm "$E/env/etr/sunny/frontH.png" ppm/skybox.ppm ""
ppm x/gnome-backgrounds/usr/share/backgrounds/gnome/wood-l.webp ppm/photo.ppm "--resize 2048x2048"
echo "terrains=$terrains skybox=$PWD/ppm/skybox.ppm photo=$PWD/ppm/photo.ppm"
