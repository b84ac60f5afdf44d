#!/bin/sh
# Prints the headline table of BENCHMARKS.md: the ratios the project targets,
# taken from the CSV files of the same run (bench/md2csv.awk).
#   bench/headline.sh CSV_DIR
set -eu
csv=${1:?usage: bench/headline.sh CSV_DIR}
. bench/csv.sh
# tsv NAME: the rows of CSV_DIR/NAME.csv without the header, or nothing.
tsv() { [ -s "$csv/$1.csv" ] && csv_fields "$csv/$1.csv" | tail -n +2 || true; }

echo "## Headline"
echo
echo "The ratios the project targets, from the tables below (same run)."
echo
echo "| measure | measured | target |"
echo "|---|---|---|"
# From the format comparison (least CPU time of 3 runs) when it ran, else
# from the throughput table (one run above 4 M voxels).
if [ -n "$(tsv build_build-from-voxels-format-3-vs-2)" ]; then
    tsv build_build-from-voxels-format-3-vs-2 | awk -F'\t' '{ s = s (s ? ", " : "") sprintf("%s L=%s: %s (%sx format 2)", $1, $2, $7, $8) }
        END { if (s) print "| Build from Morton-sorted voxels, 1 thread, least of 3 runs: M voxels per CPU-second (speed / format 2) | " s " | 30 |" }'
else
    tsv build_build-throughput | awk -F'\t' '$4 == "Morton-sorted" && $5 == 1 {
        s = s (s ? ", " : "") sprintf("%s L=%s: %s", $1, $2, $13) }
        END { if (s) print "| Build from Morton-sorted voxels, 1 thread: M voxels per CPU-second | " s " | 30 |" }'
fi
tsv build_triangle-scenes | awk -F'\t' '$5 == 1 { if (!($1 in best)) ord[++n] = $1; best[$1] = $0 }
    END { for (i = 1; i <= n; i++) { split(best[ord[i]], f, "\t")
          s = s (s ? ", " : "") sprintf("%s L=%s: %s (reduction alone %s)", f[1], f[2], f[14], f[15]) }
          if (s) print "| Build from triangles (voxelize + reduce), 1 thread, largest L: M voxels per CPU-second | " s " | 30 |" }'
tsv build_build-from-triangles-format-3-vs-2 | awk -F'\t' '{ s = s (s ? ", " : "") sprintf("%s L=%s: %s", $1, $2, $9) }
    END { if (s) print "| Build from triangles, v3 / v2 speed (CPU seconds, same meshes), 1 thread | " s " | >= 0.9 |" }'
tsv geometry_geometry-size | awk -F'\t' '{ r = $15 + 0; n++; if (r <= 1) le++
    if (!lo || r < lo) lo = r; if (r > hi) hi = r }
    END { if (n) printf "| Geometry bytes: ours (with voxel counts) / SSVDAG paper layout (without counts) | %.3f to %.3f; <= 1 on %d of %d scenes | <= 1 |\n", lo, hi, le, n }'
tsv geometry_format-version-3-against-version-2 | awk -F'\t' '{ s = s (s ? ", " : "") sprintf("%s L=%s: %s", $1, $2, $7) }
    END { if (s) print "| Geometry bytes with counts, format version 3 / version 2 (same voxels) | " s " | <= 0.66 at L=12, <= 0.75 at L=10 |" }'
tsv rays_primary-rays | awk -F'\t' '$4 == "NanoVDB" { n = n (n ? ", " : "") sprintf("%s L=%s: %s (%s with all threads)", $1, $2, $11, $12) }
    $4 ~ /^Embree/ { e = e (e ? ", " : "") sprintf("%s L=%s: %s (%s)", $1, $2, $11, $12) }
    END { if (n) print "| Primary rays per CPU-second, voxdag / NanoVDB, 1 thread | " n " | >= 1 |"
          if (e) print "| Primary rays per CPU-second, voxdag / Embree on the triangles, 1 thread | " e " | - |" }'
for f in "$csv"/color_*.csv; do
    [ -s "$f" ] && head -n 1 "$f" | grep -q '^codec,setting,size' || continue
    set=$(basename "$f" .csv)
    csv_fields "$f" | awk -F'\t' -v set="${set#color_}" '
        $1 == "voxcolor" { ord[++n] = $2; v[$2] = $3; venc[$2] = $7; vlook[$2] = $8 }
        $1 ~ /^Dolonius/ { d[$2] = $3; denc[$2] = $7; dlook[$2] = $8 }
        $1 ~ /^HashDAG/ { h[$2] = $3 }
        END {
            for (i = 1; i <= n; i++) {
                k = ord[i]
                if (k in d) dd = dd sprintf("%s%s: %.2f", dd ? ", " : "", k, v[k] / d[k])
                if (k in h) hh = hh sprintf("%s%s: %.2f", hh ? ", " : "", k, v[k] / h[k])
            }
            if (dd) print "| Colour size, voxcolor / Dolonius Alg. 1 at equal e_t (" set ") | " dd " | < 1 |"
            if (hh) print "| Colour size, voxcolor / HashDAG 64-bit-header layout at equal e_t (" set ") | " hh " | < 1 |"
            k = "e_t 0.05"
            if ((k in v) && (k in d))
                printf "| Colour encode / random lookup at e_t 0.05 (%s), M colours per CPU-second | voxcolor %s / %s; Alg. 1 %s / %s | - |\n", set, venc[k], vlook[k], denc[k], dlook[k]
        }'
done
tsv image_image-quality | awk -F'\t' '$4 != "raw" { s = s (s ? ", " : "") sprintf("%s e_t %s: %s dB, SSIM %s (voxels %s dB) at %s bits/colour", $1, $4, $9, $10, $8, $6) }
    END { if (s) print "| Rendered image PSNR and SSIM (voxel colour PSNR), compressed vs raw colours | " s " | - |" }'
echo
