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
command -v strace >/dev/null 2>&1 || need="$need strace" # signals during a save (tests/cli.sh)
# The Vulkan runner (tests/test_vk.c) on lavapipe, the shaders' compiler and
# the SPIR-V checks (tests/spirv_check.sh).
ls /usr/share/vulkan/icd.d/lvp_icd.*.json >/dev/null 2>&1 || need="$need mesa-vulkan-drivers"
[ -f /usr/include/vulkan/vulkan.h ] || need="$need libvulkan-dev"
command -v glslangValidator >/dev/null 2>&1 || need="$need glslang-tools"
command -v spirv-val >/dev/null 2>&1 || need="$need spirv-tools"
matrix=""
# The portability matrix (tests/check_all.sh): 32-bit x86 and big-endian
# s390x cross compilers run under qemu-user, MinGW-w64 under Wine. (Debian's
# gcc-multilib conflicts with the cross compilers: -m32 is not used.)
command -v i686-linux-gnu-gcc >/dev/null 2>&1 || matrix="$matrix gcc-i686-linux-gnu libc6-dev-i386-cross"
command -v s390x-linux-gnu-gcc >/dev/null 2>&1 || matrix="$matrix gcc-s390x-linux-gnu libc6-dev-s390x-cross"
{ command -v qemu-i386 && command -v qemu-s390x; } >/dev/null 2>&1 || matrix="$matrix qemu-user"
command -v x86_64-w64-mingw32-gcc >/dev/null 2>&1 || matrix="$matrix gcc-mingw-w64-x86-64"
[ -x /usr/lib/wine/wine64 ] || command -v wine64 >/dev/null 2>&1 || matrix="$matrix wine64"
[ -z "$need$matrix" ] && exit 0
echo "tests/deps.sh: installing$need$matrix" >&2
if [ "$(id -u)" != 0 ]; then
    echo "tests/deps.sh: need root to install:$need$matrix" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
t0=$(date +%s)
apt-get update -q >/dev/null
[ -z "$need" ] || apt-get install -y -q $need >/dev/null
[ -z "$matrix" ] || apt-get install -y -q --no-install-recommends $matrix >/dev/null
echo "tests/deps.sh: installed in $(($(date +%s) - t0)) s" >&2
