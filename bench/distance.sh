#!/bin/sh
# Pictures at a distance: how close one-sample, antialiased (--samples N)
# and level-of-detail (--lod P) renders come to the supersampled picture of
# the same view. The reference is `vdag render --samples 64` (the 8x8 larger
# full-detail picture with its 8x8 blocks averaged, exactly); PSNR by
# OpenImageIO's idiff over the whole picture. Views are fixed here, in grid
# units of a G^3 grid scaled to the file's 2^L, far enough that a voxel is
# about a pixel or less. Prints a markdown section.
#   bench/distance.sh quick|full VDAG DATA_DIR
set -eu
usage="usage: bench/distance.sh quick|full VDAG DATA_DIR"
mode=${1:?$usage} vdag=${2:?$usage} data=${3:?$usage}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
size=800x500
X=x/supertuxkart-data/usr/share/games/supertuxkart/data/tracks/abyss/abyss_track.spm
C=x/flightgear-data-models/usr/share/games/flightgear/Models/Maritime/Military/CG-57-high-detail/CG-57.ac
# name|input (demo: the built-in scene)|L|G|eye|target|fov
scenes="demo|demo|10|1024|2600 -1800 1500|512 512 200|30
tree|tree.vox|0|256|1850 -1110 1060|128 128 100|30"
[ "$mode" = full ] && scenes="$scenes
abyss|$X|11|1024|1900 -600 1200|512 412 40|40
CG-57|$C|11|1024|2300 -1500 900|512 61 110|30"

echo "## Pictures at a distance"
echo
echo "Each scene built by \`vdag build\` (default colours: lossless voxcolor), rendered by \`vdag render --size $size --shadows\` from a far view fixed here. Reference: \`--samples 64\`, which is exactly the full-detail picture 8x as wide and high with its 8x8 blocks averaged. PSNR (dB) of each render against it by OpenImageIO \`idiff\` (RGB, whole picture, background included); higher is closer. A level-of-detail cell is drawn as the voxels it holds: their mean colour (the file's level-of-detail colour section for cells of more than 64 voxels), lit as a voxel staircase facing the normal of the occupancy around it, over the share of the pixel's 4 x 4 sub-rays its finer cells stop, the ray going on past it for the rest (README, \`vdag render\`); \`--lod-opaque\` (the GPU kernel's model) draws a cell over the whole pixel, lit from the occupancy gradient of its six neighbours. The tree's view puts about two voxels in a pixel (a nearer one, with voxels larger than pixels, has no cell for \`--lod 1\` to stop at). CPU-s: the render's CPU seconds on one thread (\`--threads 1\`, as \`vdag render\` reports them: loading excluded). Last two columns: the level-of-detail colour section of the same scene built with \`--color-error 0.02\`, in bytes and as a share of that file's colour section."
echo
echo "| scene | L | 1 sample | --samples 4 | --samples 16 | --lod 1 | --lod 2 | --lod 1 --lod-opaque | --samples 4 gain (dB) | --lod 1 gain (dB) | CPU-s 1 sample | CPU-s --samples 4 | CPU-s --lod 1 | CPU-s --lod 1 --lod-opaque | LOD colours (bytes) | share of colours at e_t 0.02 |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
echo "$scenes" | while IFS='|' read -r name in L grid eye target fov; do
    echo "distance: $name" >&2
    if [ "$in" = demo ]; then
        "$vdag" gen demo "$work/demo.xyz" --levels "$L" >/dev/null 2>&1
        "$vdag" build "$work/demo.xyz" "$work/s.vdag" --quiet
        "$vdag" build "$work/demo.xyz" "$work/e.vdag" --color-error 0.02 --quiet
    else
        [ -s "$data/$in" ] || { echo "distance: $data/$in missing (bench/fetch.sh DATA scenes)" >&2; continue; }
        lv=""; [ "$L" = 0 ] || lv="--levels $L"
        # shellcheck disable=SC2086
        "$vdag" build "$data/$in" "$work/s.vdag" $lv --quiet
        # shellcheck disable=SC2086
        "$vdag" build "$data/$in" "$work/e.vdag" $lv --color-error 0.02 --quiet
    fi
    levels=$("$vdag" info "$work/s.vdag" --json | sed -n 's/.*"levels": \([0-9]*\).*/\1/p')
    lodb=$("$vdag" info "$work/e.vdag" --json | sed -n 's/.*"lod_colors": \([0-9]*\).*/\1/p')
    colb=$("$vdag" info "$work/e.vdag" --json | sed -n 's/.*"colors": \([0-9]*\).*/\1/p')
    cam=$(echo "$eye $target" | awk -v n="$levels" -v g="$grid" '{ s = 2 ^ n / g; for (i = 1; i <= 6; i++) printf "%g ", $i * s }')
    # shellcheck disable=SC2086
    set -- $cam
    shot() { # shot OUT OPTIONS...; the render's CPU seconds on one thread into $work/OUT.cpu
        out=$1
        shift
        "$vdag" render "$work/s.vdag" "$work/$out.png" --size $size --eye "$c1" "$c2" "$c3" --target "$c4" "$c5" "$c6" \
            --fov "$fov" --shadows --threads 1 "$@" 2>&1 | sed -n 's/.*(\([0-9.]*\) CPU-s).*/\1/p' >"$work/$out.cpu"
    }
    c1=$1 c2=$2 c3=$3 c4=$4 c5=$5 c6=$6
    shot ref --samples 64
    psnr() {
        idiff -a "$work/ref.png" "$work/$1.png" >"$work/diff.txt" 2>&1 || true
        sed -n 's/.*Peak SNR = \([0-9.inf]*\).*/\1/p' "$work/diff.txt" | head -n 1
    }
    shot one && p1=$(psnr one)
    shot s4 --samples 4 && p4=$(psnr s4)
    shot s16 --samples 16 && p16=$(psnr s16)
    shot l1 --lod 1 && pl1=$(psnr l1)
    shot l2 --lod 2 && pl2=$(psnr l2)
    shot o1 --lod 1 --lod-opaque && po1=$(psnr o1)
    awk -v n="$name" -v L="$levels" -v a="$p1" -v b="$p4" -v c="$p16" -v d="$pl1" -v e="$pl2" -v o="$po1" -v lb="$lodb" -v cb="$colb" \
        -v t1="$(cat "$work/one.cpu")" -v t4="$(cat "$work/s4.cpu")" -v tl="$(cat "$work/l1.cpu")" -v to="$(cat "$work/o1.cpu")" \
        'BEGIN { printf "| %s | %s | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %+.1f | %+.1f | %.2f | %.2f | %.2f | %.2f | %d | %.1f %% |\n", n, L, a, b, c, d, e, o, b - a, d - a, t1, t4, tl, to, lb, 100 * lb / cb }'
done
echo
