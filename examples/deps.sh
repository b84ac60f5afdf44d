#!/bin/sh
# Installs what building the vdag tool needs when it is missing (Debian;
# root): libstb-dev, whose stb_image.h decodes textures inside the tool, and,
# for the GPU path, libvulkan-dev (the headers; the loader is opened at run
# time) and glslang-tools (shaders to SPIR-V). Only a missing libstb-dev
# fails: without the Vulkan packages the tool is built without the GPU path.
set -eu
stb=""
[ -f /usr/include/stb/stb_image.h ] || stb=libstb-dev
gpu=""
[ -f /usr/include/vulkan/vulkan.h ] || gpu="$gpu libvulkan-dev"
command -v glslangValidator >/dev/null 2>&1 || gpu="$gpu glslang-tools"
[ -z "$stb$gpu" ] && exit 0
if [ "$(id -u)" != 0 ]; then
    [ -z "$gpu" ] || echo "examples/deps.sh: need root to install$gpu (the tool is built without the GPU path)" >&2
    [ -z "$stb" ] && exit 0
    echo "examples/deps.sh: need root to install libstb-dev (or install it yourself)" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -q >/dev/null || [ -z "$stb" ] || exit 1
if [ -n "$stb" ]; then
    echo "examples/deps.sh: installing libstb-dev (stb_image.h, compiled into the tool)" >&2
    apt-get install -y -q libstb-dev >/dev/null
fi
if [ -n "$gpu" ]; then
    echo "examples/deps.sh: installing$gpu (the tool's GPU path)" >&2
    apt-get install -y -q $gpu >/dev/null ||
        echo "examples/deps.sh: could not install$gpu; the tool is built without the GPU path" >&2
fi
exit 0
