#!/bin/sh
# Installs what building the vdag tool needs when it is missing (Debian;
# root): libstb-dev, whose stb_image.h decodes textures inside the tool.
set -eu
[ -f /usr/include/stb/stb_image.h ] && exit 0
echo "examples/deps.sh: installing libstb-dev (stb_image.h, compiled into the tool)" >&2
if [ "$(id -u)" != 0 ]; then
    echo "examples/deps.sh: need root to install libstb-dev (or install it yourself)" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -q >/dev/null
apt-get install -y -q libstb-dev >/dev/null
