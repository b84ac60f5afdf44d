#!/bin/sh
# Ray casting on the GPU next to the CPU tracer, in the same run: each bench
# mesh built by `vdag build --levels L`, rendered at 1920x1080 from the
# default camera by `vdag render` on the CPU (all threads), with --gpu
# (Vulkan; the GPU time of the dispatch from timestamp queries), with
# --gpu --beam (both passes) and with --gpu-emulate (the GPU kernel's C build on the CPU), without and with
# shadows. Prints a markdown section. When the only Vulkan device is a CPU
# implementation (Mesa's lavapipe) its numbers are labelled a CPU fallback:
# they are not GPU speed.
#   bench/gpu.sh quick|full VDAG DATA_DIR
set -eu
usage="usage: bench/gpu.sh quick|full VDAG DATA_DIR"
mode=${1:?$usage} vdag=${2:?$usage} data=${3:?$usage}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
size=1920x1080
levels="10 12"
[ "$mode" = quick ] && levels=10
echo "## Ray casting on the GPU"
echo
if ! "$vdag" render "$data/bunny.off" "$work/probe.png" --size 2x2 --gpu --quiet 2>"$work/err"; then
    "$vdag" build "$data/bunny.off" "$work/probe.vdag" --levels 6 --quiet 2>/dev/null || :
    if ! "$vdag" render "$work/probe.vdag" "$work/probe.png" --size 2x2 --gpu 2>"$work/err"; then
        echo "No Vulkan device here: $(cat "$work/err")"
        echo
        exit 0
    fi
fi
device=$(sed -n 's/^render: [0-9x]* on \(.*\) in [0-9.]* s.*/\1/p' "$work/err")
case $device in
*llvmpipe* | *lavapipe* | *SwiftShader*) label="a CPU implementation of Vulkan ($device): a **CPU fallback**, not GPU speed" ;;
*) label="$device" ;;
esac
echo "\`vdag render FILE OUT.png --size $size\` from the default camera: primary rays (and one shadow ray per lit pixel with \`--shadows\`), voxel index and colour per hit. CPU: the exact double-precision tracer on all $(nproc) logical CPUs (wall time). GPU: the float32 traversal of \`voxdag_gpu.h\` through Vulkan on $label, the dispatch's time from timestamp queries. Emulated: the same kernel's C build on the CPU's threads (wall time). Megapixels per second (one primary ray a pixel)."
echo
echo "| scene | L | shadows | CPU tracer (Mpixel/s) | GPU (Mpixel/s) | GPU, beam pass (Mpixel/s) | emulated kernel (Mpixel/s) | GPU / CPU |"
echo "|---|---:|---|---:|---:|---:|---:|---:|"
rate() { sed -n 's/.*, \([0-9.]*\) Mrays\/s.*/\1/p' "$1" | head -n 1; }
for name in bunny armadillo dragon; do
    for L in $levels; do
        f=$work/$name-$L.vdag
        "$vdag" build "$data/$name.off" "$f" --levels "$L" --quiet 2>/dev/null || continue
        for shadows in "" --shadows; do
            best_cpu=0 best_gpu=0 best_emu=0 best_beam=0
            for run in 1 2 3; do
                "$vdag" render "$f" "$work/c.png" --size $size $shadows 2>"$work/c.txt"
                "$vdag" render "$f" "$work/g.png" --size $size $shadows --gpu 2>"$work/g.txt"
                "$vdag" render "$f" "$work/e.png" --size $size $shadows --gpu-emulate 2>"$work/e.txt"
                "$vdag" render "$f" "$work/b.png" --size $size $shadows --gpu --beam 2>"$work/b.txt"
                best_cpu=$(awk -v a="$best_cpu" -v b="$(rate "$work/c.txt")" 'BEGIN { print (b > a ? b : a) }')
                best_gpu=$(awk -v a="$best_gpu" -v b="$(rate "$work/g.txt")" 'BEGIN { print (b > a ? b : a) }')
                best_emu=$(awk -v a="$best_emu" -v b="$(rate "$work/e.txt")" 'BEGIN { print (b > a ? b : a) }')
                best_beam=$(awk -v a="$best_beam" -v b="$(rate "$work/b.txt")" 'BEGIN { print (b > a ? b : a) }')
            done
            printf '| %s | %s | %s | %s | %s | %s | %s | %s |\n' "$name" "$L" "$([ -n "$shadows" ] && echo yes || echo no)" "$best_cpu" \
                "$best_gpu" "$best_beam" "$best_emu" "$(awk -v g="$best_gpu" -v c="$best_cpu" 'BEGIN { printf "%.2f", (c > 0 ? g / c : 0) }')"
        done
    done
done
echo
echo "Best of 3 runs each. The beam pass (\`--beam\`: a safe start depth per 8x8 block, then the rays) is timed as both dispatches together."
echo
