#!/bin/sh
# Installs the packages the tests need when they are missing (Debian; root).
set -eu
need=""
command -v oiiotool >/dev/null 2>&1 || need="$need openimageio-tools"
[ -f /usr/include/OpenImageIO/imageio.h ] || need="$need libopenimageio-dev"
[ -f /usr/include/stb/stb_image.h ] || need="$need libstb-dev"
command -v assimp >/dev/null 2>&1 || need="$need assimp-utils"
command -v clang >/dev/null 2>&1 || need="$need clang"
command -v g++ >/dev/null 2>&1 || need="$need g++"
[ -z "$need" ] && exit 0
echo "tests/deps.sh: installing$need" >&2
if [ "$(id -u)" != 0 ]; then
    echo "tests/deps.sh: need root to install:$need" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -q >/dev/null
apt-get install -y -q $need >/dev/null
