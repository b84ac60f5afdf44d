#!/bin/sh
# Image quality of compressed colours: each scene is built by `vdag build`
# with raw 24-bit colours (--raw-colors) and with --color-error E for a few E, every file is
# rendered from the same camera, and OpenImageIO's idiff compares each
# compressed render with the raw one; the voxels' own colours are compared
# too (vdag export-voxels), and bench/ssim.c gives the renders' SSIM. Prints
# a markdown section.
#   bench/image_quality.sh quick|full VDAG SSIM DATA_DIR PICTURE_DIR
# Writes one mosaic per scene, PICTURE_DIR/quality_NAME.png:
# raw | largest E | |difference| x 16. Also the cost of colours in a render:
# the same view rendered from the same voxels built with --no-colors, raw
# colours and each E, primary rays per CPU-second of the render (vdag
# render's own count, one thread, best of 3).
set -eu
usage="usage: bench/image_quality.sh quick|full VDAG SSIM DATA_DIR PICTURE_DIR"
mode=${1:?$usage} vdag=${2:?$usage} ssim=${3:?$usage} data=${4:?$usage} pics=${5:?$usage}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$pics"
size=720x450
rate_size=1440x900 # the cost table: 4x the rays, so a render lasts about a second
if [ "$mode" = quick ]; then errors="0.02 0.05"; else errors="0.01 0.02 0.05"; fi
last=${errors##* }
X=x/supertuxkart-data/usr/share/games/supertuxkart/data/tracks/abyss/abyss_track.spm
C=x/flightgear-data-models/usr/share/games/flightgear/Models/Maritime/Military/CG-57-high-detail/CG-57.ac
# name|input|L (0: the file's own)|G|eye|target|fov; eye and target in units
# of a G^3 grid, scaled to the file's 2^L.
scenes="tree|tree.vox|0|256|420 -200 260|128 128 100|40"
[ "$mode" = full ] && scenes="$scenes
abyss|$X|11|1024|1100 -150 650|512 412 40|45
CG-57|$C|11|1024|1250 -700 550|512 61 110|40"

echo "## Image quality"
echo
echo "Each scene built by \`vdag build IN OUT.vdag [--levels L]\` with raw 24-bit colours (\`--raw-colors\`) and with \`--color-error E\`, rendered by \`vdag render --size $size --shadows\` from the same camera; PSNR of each compressed render against the raw one by OpenImageIO \`idiff\` (over the whole picture, RGB, background included); SSIM: mean structural similarity of the two renders' luma (\`bench/ssim.c\`: 11x11 Gaussian window, sigma 1.5, the usual constants; whole picture). Voxel PSNR: over the voxels' decoded colours (\`vdag export-voxels\`, RGB, as in the colour tables). Colour bytes: the colour section of the file (\`vdag info --json\`)."
echo
echo "| scene | L | voxels | e_t | colour bytes | bits/colour | % of raw | voxel PSNR (dB) | image PSNR (dB) | image SSIM | max pixel error | pixels differing |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
json() { sed -n "s/.*\"$2\": \\([0-9.]*\\).*/\\1/p" "$1"; }
echo "$scenes" | while IFS='|' read -r name in L grid eye target fov; do
    [ -s "$data/$in" ] || { echo "image_quality: $data/$in missing (bench/fetch.sh DATA scenes)" >&2; continue; }
    lv=""; [ "$L" = 0 ] || lv="--levels $L"
    echo "image_quality: $name raw" >&2
    # shellcheck disable=SC2086
    "$vdag" build "$data/$in" "$work/raw.vdag" $lv --raw-colors 2>/dev/null
    "$vdag" info "$work/raw.vdag" --json >"$work/raw.json"
    levels=$(json "$work/raw.json" levels) voxels=$(json "$work/raw.json" voxels) raw=$(json "$work/raw.json" colors)
    cam=$(echo "$eye $target" | awk -v n="$levels" -v g="$grid" '{ s = 2 ^ n / g; for (i = 1; i <= 6; i++) printf "%g ", $i * s }')
    set -- $cam
    render() { "$vdag" render "$1" "$2" --size $size --eye "$3" "$4" "$5" --target "$6" "$7" "$8" --fov "$fov" --shadows 2>/dev/null; }
    render "$work/raw.vdag" "$work/raw.png" "$@"
    # rate FILE LABEL: a row of the render-cost table (ratio to no colours).
    rate() {
        best=$(for k in 1 2 3 4 5; do
            "$vdag" render "$1" "$work/rate.png" --size $rate_size --eye "$c1" "$c2" "$c3" --target "$c4" "$c5" "$c6" \
                --fov "$fov" --shadows --threads 1 2>&1 | sed -n 's/.*, \([0-9.]*\) Mrays\/CPU-s.*/\1/p'
        done | sort -g | tail -n 1)
        [ "$2" = none ] && none=$best
        awk -v n="$name" -v L="$levels" -v v="$voxels" -v c="$2" -v r="$best" -v z="$none" \
            'BEGIN { printf "| %s | %s | %s | %s | %.2f | %.3f |\n", n, L, v, c, r, z / r }' >>"$work/rates.md"
    }
    c1=$1 c2=$2 c3=$3 c4=$4 c5=$5 c6=$6
    # shellcheck disable=SC2086
    "$vdag" build "$data/$in" "$work/none.vdag" $lv --no-colors 2>/dev/null
    rate "$work/none.vdag" none
    rate "$work/raw.vdag" "raw (24 bits)"
    "$vdag" export-voxels "$work/raw.vdag" >"$work/raw.xyz"
    oiiotool "$work/raw.png" --ch R,G,B -d uint8 -o "$work/raw.ppm"
    echo "| $name | $levels | $voxels | raw | $raw | 24.00 | 100.0 | - | - | - | - | - |"
    for e in $errors; do
        echo "image_quality: $name e_t $e" >&2
        # shellcheck disable=SC2086
        "$vdag" build "$data/$in" "$work/e.vdag" $lv --color-error "$e" 2>/dev/null
        "$vdag" info "$work/e.vdag" --json >"$work/e.json"
        render "$work/e.vdag" "$work/e$e.png" "$@"
        rate "$work/e.vdag" "e_t $e"
        "$vdag" export-voxels "$work/e.vdag" >"$work/e.xyz"
        vpsnr=$(paste "$work/raw.xyz" "$work/e.xyz" | awk '!/^#/ { for (i = 4; i <= 6; i++) { d = $i - $(i + 6); s += d * d } n += 3 }
            END { if (s) printf "%.1f", 10 * log(255 * 255 * n / s) / log(10); else printf "lossless" }')
        idiff -a "$work/raw.png" "$work/e$e.png" >"$work/diff.txt" 2>&1 || true
        oiiotool "$work/e$e.png" --ch R,G,B -d uint8 -o "$work/e.ppm"
        ss=$("$ssim" "$work/raw.ppm" "$work/e.ppm")
        bytes=$(json "$work/e.json" colors)
        psnr=$(sed -n 's/.*Peak SNR = \([0-9.inf]*\).*/\1/p' "$work/diff.txt")
        maxe=$(sed -n 's/.*Max error *= \([0-9.e-]*\).*/\1/p' "$work/diff.txt")
        differ=$(sed -n 's/.*pixels (\([0-9.]*\)%) over.*/\1/p' "$work/diff.txt" | head -n 1)
        set -- $cam
        awk -v n="$name" -v L="$levels" -v v="$voxels" -v e="$e" -v b="$bytes" -v r="$raw" -v p="${psnr:-inf}" \
            -v m="${maxe:-0}" -v d="${differ:-0}" -v vp="$vpsnr" -v ss="$ss" 'BEGIN {
            bits = 8 * b / v; pct = 100 * b / r; me = m * 255
            if (p != "inf") p = sprintf("%.1f", p)
            printf "| %s | %s | %s | %s | %s | %.2f | %.1f | %s | %s | %.4f | %.0f/255 | %s%% |\n", n, L, v, e, b, bits, pct, vp, p, ss, me, d }'
    done
    oiiotool "$work/raw.png" "$work/e$last.png" --absdiff --mulc 16 -o "$work/diff.png"
    oiiotool "$work/raw.png" --resize 360x225 "$work/e$last.png" --resize 360x225 "$work/diff.png" --resize 360x225 \
        --mosaic 3x1 -d uint8 -o "$pics/quality_$name.png"
done
echo
echo "Pictures (left to right: raw colours, e_t $last, absolute difference x 16):"
echo
echo "$scenes" | while IFS='|' read -r name rest; do
    [ -s "$pics/quality_$name.png" ] && echo "![$name, raw and e_t $last]($pics/quality_$name.png)"
done
echo
echo "### Rendering with colours against without"
echo
echo "The same view of each scene as above (\`vdag render --size $rate_size --shadows --threads 1\`), rendered from files of the same voxels built with \`--no-colors\` (every hit white: no colour lookup), raw colours and \`--color-error E\`: primary rays per CPU-second of the render alone (vdag render's report: CPU time of the process while it renders; loading and validating the file excluded), best of 5. Cost: rays per CPU-second without colours divided by those with them (target: at most 1.15)."
echo
echo "| scene | L | voxels | colours | Mrays/CPU-s | cost vs no colours |"
echo "|---|---:|---:|---|---:|---:|"
cat "$work/rates.md" 2>/dev/null || true
echo
