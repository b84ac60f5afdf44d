#!/bin/sh
# Runs external image codecs on a colour array mapped to a 2D Morton image
# (bench_color writes it with voxcolor_to_image) and decodes their output
# with the codecs' own tools, so that bench_color can measure what comes back.
#   bench/color_peers.sh WORKDIR IMAGE.ppm [quick]
# Prints one line per codec setting:
#   codec|setting|bytes|decoded.ppm     bytes: the compressed file's size
#   codec|setting|skip|why              the tool is not available
# Missing Debian packages are installed with apt-get (as root); BC1 and BC7
# come from the npm package @gpu-tex-enc/bc (bc7enc), installed into WORKDIR.
set -u
work=${1:?usage: bench/color_peers.sh WORKDIR IMAGE.ppm [quick]}
src=${2:?usage: bench/color_peers.sh WORKDIR IMAGE.ppm [quick]}
quick=${3:-}
mkdir -p "$work"
work=$(cd "$work" && pwd)

need() { # need COMMAND DEBIAN_PACKAGE: 0 when COMMAND is (or becomes) available
    command -v "$1" >/dev/null 2>&1 && return 0
    [ "$(id -u)" = 0 ] || return 1
    apt-get install -y -q "$2" >/dev/null 2>&1 ||
        { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q "$2" >/dev/null 2>&1; }
    command -v "$1" >/dev/null 2>&1
}
size() { wc -c <"$1" | tr -d ' '; }
to_ppm() { oiiotool "$1" --ch R,G,B -d uint8 -o "$2" >/dev/null 2>&1; }
emit() { # emit CODEC SETTING COMPRESSED DECODED
    if [ -s "$3" ] && [ -s "$4" ]; then echo "$1|$2|$(size "$3")|$4"
    else echo "$1|$2|skip|the tool failed"; fi
}

if ! need oiiotool openimageio-tools; then
    echo "all|-|skip|oiiotool (openimageio-tools) is needed to read and write PNG"
    exit 0
fi
png=$work/image.png
oiiotool "$src" -o "$png" >/dev/null 2>&1

# PNG, lossless: the PNG itself, read back.
to_ppm "$png" "$work/png.ppm"
emit "PNG (oiiotool)" "lossless" "$png" "$work/png.ppm"

# JPEG without chroma subsampling.
if need cjpeg libjpeg-turbo-progs && need djpeg libjpeg-turbo-progs; then
    for q in 50 75 90 95 100; do
        cjpeg -quality "$q" -sample 1x1 -outfile "$work/q$q.jpg" "$src" 2>/dev/null &&
            djpeg -pnm -outfile "$work/jpeg_q$q.ppm" "$work/q$q.jpg" 2>/dev/null
        emit "JPEG (libjpeg-turbo, 4:4:4)" "quality $q" "$work/q$q.jpg" "$work/jpeg_q$q.ppm"
    done
else
    echo "JPEG (libjpeg-turbo, 4:4:4)|-|skip|cjpeg/djpeg (libjpeg-turbo-progs) unavailable"
fi

# PNG after palette quantization.
if need pngquant pngquant; then
    for k in 256 64 16; do
        pngquant --force --output "$work/pq$k.png" "$k" "$png" 2>/dev/null &&
            to_ppm "$work/pq$k.png" "$work/pngquant_$k.ppm"
        emit "PNG + pngquant" "$k colours" "$work/pq$k.png" "$work/pngquant_$k.ppm"
    done
else
    echo "PNG + pngquant|-|skip|pngquant unavailable"
fi

# ASTC, LDR, medium preset.
if need astcenc astcenc; then
    blocks="4x4 6x6 8x8"
    [ -n "$quick" ] && blocks="4x4 8x8"
    for b in $blocks; do
        astcenc -cl "$png" "$work/a$b.astc" "$b" -medium >/dev/null 2>&1 &&
            astcenc -dl "$work/a$b.astc" "$work/a$b.png" >/dev/null 2>&1 &&
            to_ppm "$work/a$b.png" "$work/astc_$b.ppm"
        emit "ASTC (astcenc -medium)" "$b blocks" "$work/a$b.astc" "$work/astc_$b.ppm"
    done
else
    echo "ASTC (astcenc -medium)|-|skip|astcenc unavailable"
fi

# BC1 and BC7 with bc7enc; its unpacked PNG is the decoded image.
bc7enc=$(ls "$work"/npm/node_modules/@gpu-tex-enc/bc/bin/linux/bc7enc 2>/dev/null)
if [ -z "$bc7enc" ] && command -v npm >/dev/null 2>&1; then
    npm install -q --prefix "$work/npm" @gpu-tex-enc/bc@1.0.11 >/dev/null 2>&1
    bc7enc=$(ls "$work"/npm/node_modules/@gpu-tex-enc/bc/bin/linux/bc7enc 2>/dev/null)
fi
if [ -n "$bc7enc" ]; then
    chmod +x "$bc7enc"
    (cd "$work" && "$bc7enc" -q -1 "$png" bc1.dds bc1.png >/dev/null 2>&1) && to_ppm "$work/bc1.png" "$work/bc1.ppm"
    emit "BC1 (bc7enc)" "highest quality" "$work/bc1.dds" "$work/bc1.ppm"
    (cd "$work" && "$bc7enc" -q "$png" bc7.dds bc7.png >/dev/null 2>&1) && to_ppm "$work/bc7.png" "$work/bc7.ppm"
    emit "BC7 (bc7enc)" "highest quality" "$work/bc7.dds" "$work/bc7.ppm"
else
    echo "BC1 (bc7enc)|-|skip|npm package @gpu-tex-enc/bc unavailable"
    echo "BC7 (bc7enc)|-|skip|npm package @gpu-tex-enc/bc unavailable"
fi
exit 0
