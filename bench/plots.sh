#!/bin/sh
# Draws the BENCHMARKS.md plots with gnuplot from the CSV files report.sh
# wrote (bench/md2csv.awk) in the same run, and prints their markdown.
#   bench/plots.sh CSV_DIR PICTURE_DIR [geometry|rays|color]   (default: all three)
#   PICTURE_DIR/plot_geometry.png  bits per voxel vs L per structure (mesh scenes)
#   PICTURE_DIR/plot_rays.png      primary rays per CPU-second per scene and engine
#   PICTURE_DIR/plot_color.png     colour size vs PSNR per codec, one panel per data set
set -eu
csv=${1:?usage: bench/plots.sh CSV_DIR PICTURE_DIR}
pics=${2:?usage: bench/plots.sh CSV_DIR PICTURE_DIR}
what=${3:-geometry rays color}
want() { case " $what " in *" $1 "*) return 0 ;; esac; return 1; }
command -v gnuplot >/dev/null 2>&1 || { echo "(gnuplot not installed: no plots; bench/deps.sh installs gnuplot-nox)"; exit 0; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$pics"
term="set terminal pngcairo size"
gnuplot -e 'set terminal pngcairo' >/dev/null 2>&1 || term="set terminal png size"
. bench/csv.sh

# Bits per voxel vs L: one panel per mesh scene, one line per structure.
g=$csv/geometry_bits-per-voxel.csv
if want geometry && [ -s "$g" ]; then
    csv_fields "$g" >"$work/g.tsv"
    scenes=$(awk -F'\t' 'NR > 1 && $1 ~ /\.off$/ && !seen[$1]++ { print $1 }' "$work/g.tsv")
    n=$(echo "$scenes" | grep -c . || true)
    if [ "$n" -gt 0 ]; then
        {
            echo "$term $((420 * n)),380 font ',10'"
            echo "set output '$pics/plot_geometry.png'"
            echo "set datafile separator '\t'"
            echo "set multiplot layout 1,$n title 'Geometry: bits per voxel vs grid level L (lower is better)'"
            echo "set xlabel 'L (grid 2^L)'; set ylabel 'bits per voxel'; set xtics 1; set grid; set key top right font ',8'"
            for s in $scenes; do
                awk -F'\t' -v s="$s" '$1 == s' "$work/g.tsv" >"$work/g_$s.tsv"
                echo "set title '$s'"
                printf "plot '%s' using 2:3 with linespoints title 'SVO', '' using 2:4 with linespoints title 'SVDAG (Kampe)', " "$work/g_$s.tsv"
                printf "'' using 2:5 with linespoints title 'SSVDAG (Kampe)', '' using 2:6 with linespoints title 'SVDAG (paper layout)', "
                printf "'' using 2:7 with linespoints title 'SSVDAG (paper layout)', '' using 2:9 with linespoints lw 2 title 'ours'\n"
            done
            echo "unset multiplot"
        } >"$work/g.gp"
        gnuplot "$work/g.gp" && echo "![bits per voxel vs L]($pics/plot_geometry.png)" && echo
    fi
fi

# Rays per CPU-second, one thread: clustered bars per scene.
r=$csv/rays_primary-rays.csv
if want rays && [ -s "$r" ]; then
    csv_fields "$r" | awk -F'\t' 'NR > 1 {
        k = $1 " L=" $2; if (!(k in row)) { order[++n] = k; row[k] = 1 }
        e = $4 ~ /^voxdag/ ? 1 : $4 ~ /^NanoVDB/ ? 2 : 3; v[k, e] = $8 }
        END { for (i = 1; i <= n; i++) { k = order[i]; printf "\"%s\"", k
              for (e = 1; e <= 3; e++) printf " %s", ((k, e) in v) ? v[k, e] : "-"; printf "\n" } }' >"$work/r.dat"
    {
        echo "$term 900,420 font ',10'"
        echo "set output '$pics/plot_rays.png'"
        echo "set title 'Primary rays: million rays per CPU-second, 1 thread (higher is better)'"
        echo "set style data histograms; set style histogram clustered gap 1; set style fill solid 0.8 border -1"
        echo "set datafile missing '-'; set ylabel 'Mrays / CPU-s'; set grid ytics; set key top left; set yrange [0:*]"
        echo "plot '$work/r.dat' using 2:xtic(1) title 'voxdag', '' using 3 title 'NanoVDB', '' using 4 title 'Embree (triangles)'"
    } >"$work/r.gp"
    gnuplot "$work/r.gp" && echo "![rays per CPU-second]($pics/plot_rays.png)" && echo
fi

# Colour: size vs PSNR per codec (lossy settings), one panel per data set.
sets=""
want color && for f in "$csv"/color_*.csv; do
    [ -s "$f" ] && head -n 1 "$f" | grep -q '^codec,setting,size' && sets="$sets $f"
done
n=$(echo $sets | wc -w)
if [ "$n" -gt 0 ]; then
    {
        echo "$term $((480 * n)),440 font ',10'"
        echo "set output '$pics/plot_color.png'"
        echo "set multiplot layout 1,$n title 'Colour: PSNR vs size (% of 24-bit RGB); up and left is better'"
        echo "set xlabel 'size (% of 24-bit)'; set ylabel 'PSNR (dB)'; set grid; set key bottom right font ',8'; set logscale x"
        # One line type per codec over all panels, in order of appearance.
        csv_fields $sets | awk -F'\t' '$1 != "codec" && $5 ~ /^[0-9.]+$/ && !seen[$1]++ { print ++n "\t" $1 }' >"$work/codecs"
        for f in $sets; do
            name=$(basename "$f" .csv); name=${name#color_}
            # One block per codec: size, PSNR; voxcolor: only its plain e_t curve.
            csv_fields "$f" | awk -F'\t' -v out="$work/c_$name" 'FNR == NR { id[$2] = $1; next }
                FNR > 1 && $5 ~ /^[0-9.]+$/ {
                if ($1 == "voxcolor" && $2 !~ /^e_t [0-9.]+$/) next
                if (!($1 in used)) { used[$1] = 1; print id[$1] "\t" $1 > (out ".list") }
                print $3, $5 > (out "_" id[$1] ".dat") }' "$work/codecs" -
            echo "set title '$name'"
            printf "plot "
            sep=""
            while IFS='	' read -r i codec; do
                w="linespoints lt $i"; [ "$codec" = voxcolor ] && w="$w lw 3"
                printf "%s'%s' using 1:2 with %s title '%s'" "$sep" "$work/c_${name}_$i.dat" "$w" "$codec"
                sep=", "
            done <"$work/c_$name.list"
            printf "\n"
        done
        echo "unset multiplot"
    } >"$work/c.gp"
    gnuplot "$work/c.gp" && echo "![colour size vs PSNR]($pics/plot_color.png)" && echo
fi
exit 0
