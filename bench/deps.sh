#!/bin/sh
# Installs the Debian packages `make bench` uses when they are missing (root):
# the ray-casting peers (NanoVDB, Embree), OpenImageIO (its tools convert and
# compare images; with its headers `vdag` decodes textures), gnuplot (plots),
# npm (bench/fetch.sh). Without them the benchmarks still run and leave out
# what needs them.
set -u
need=""
[ -f /usr/include/nanovdb/NanoVDB.h ] || need="$need libnanovdb-dev"
[ -f /usr/include/embree3/rtcore.h ] || need="$need libembree-dev"
command -v oiiotool >/dev/null 2>&1 || need="$need openimageio-tools"
[ -f /usr/include/OpenImageIO/imageio.h ] || need="$need libopenimageio-dev"
command -v gnuplot >/dev/null 2>&1 || need="$need gnuplot-nox"
command -v npm >/dev/null 2>&1 || need="$need npm"
command -v c++ >/dev/null 2>&1 || need="$need g++"
[ -z "$need" ] && exit 0
if [ "$(id -u)" != 0 ]; then
    echo "bench/deps.sh: not root, not installing:$need" >&2
    exit 0
fi
echo "bench/deps.sh: installing$need" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -q >/dev/null 2>&1
# shellcheck disable=SC2086
apt-get install -y -q $need >/dev/null 2>&1 || echo "bench/deps.sh: could not install all of$need" >&2
exit 0
