#!/bin/sh
# Thread scaling of a mesh build with colours: `vdag build --timings` on 1
# and 2 threads, RUNS pairs run alternately (1 then 2, then 2 then 1, ...),
# the median of each phase's wall, CPU and main-thread CPU seconds. Prints
# a markdown section: every phase, the serial share (from the CPU seconds
# the building thread spent alone, which other processes on the machine do
# not skew), the CPU of 2 threads against 1, and an Amdahl projection to 16
# threads (labelled projected: this machine may have fewer cores).
#   bench/threads.sh quick|full VDAG DATA_DIR
# full: the abyss track at 4096^3 (--levels 12) with --color-error 0.02, 5
# pairs; quick: the same at 1024^3 (or the tool's demo cloud when the game
# data is missing), 3 pairs.
set -eu
usage="usage: bench/threads.sh quick|full VDAG DATA_DIR"
mode=${1:?$usage} vdag=${2:?$usage} data=${3:?$usage}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
X=x/supertuxkart-data/usr/share/games/supertuxkart/data/tracks/abyss/abyss_track.spm
if [ "$mode" = full ]; then levels=12 runs=5; else levels=10 runs=3; fi
input=$data/$X
name="abyss track (.spm, textured)"
if [ ! -s "$input" ]; then
    [ "$mode" = full ] && { echo "threads: $input missing (bench/fetch.sh DATA scenes)" >&2; exit 1; }
    input=$work/demo.xyz
    name="demo cloud (.xyz, coloured)"
    "$vdag" gen demo "$input" --levels "$levels" >/dev/null 2>&1
fi
side=$(( 1 << levels ))
NPROC=$(nproc)
export NPROC

# One build: "THREADS RUN PHASE|WALL|CPU" lines to $work/rows.
build() { # build THREADS RUN
    "$vdag" build "$input" "$work/out$1.vdag" --levels "$levels" --color-error 0.02 --threads "$1" --timings \
        --quiet 2>"$work/log" || { cat "$work/log" >&2; exit 1; }
    awk -v t="$1" -v r="$2" '
        /timings +wall s/ { on = 1; next }
        on && NF >= 6 {
            n = NF; name = $2
            for (i = 3; i <= n - 4; i++) name = name " " $i
            print t " " r " " name "|" $(n - 3) "|" $(n - 2) "|" $n
        }' "$work/log" >>"$work/rows"
}
: >"$work/rows"
k=1
while [ "$k" -le "$runs" ]; do
    echo "threads: pair $k of $runs" >&2
    if [ $((k % 2)) = 1 ]; then build 1 "$k"; build 2 "$k"; else build 2 "$k"; build 1 "$k"; fi
    cmp -s "$work/out1.vdag" "$work/out2.vdag" || { echo "threads: 1 and 2 threads wrote different files" >&2; exit 1; }
    k=$((k + 1))
done

echo "### Thread scaling: every phase of a build with colours"
echo
echo "\`vdag build\` of the $name at ${side}^3 (\`--levels $levels --color-error 0.02\`, voxcolor colours with their level-of-detail means) with \`--timings\`, on 1 and 2 threads: $runs pairs of runs, alternating which goes first, median of each phase (the phases \`--timings\` names: read = import with texture decoding, voxelize = voxelization and DAG reduction, encode = the file image, colours = voxcolor compression of the spilled colours, colour attach = level-of-detail means and the final image, save). The two files are the same bytes. CPU seconds are the whole process's (all threads); CPU/wall above 1 is the phase's parallelism."
echo
awk -F'|' -v runs="$runs" '
    function median(key,   n, i, j, t, v) {
        n = cnt[key]
        for (i = 1; i <= n; i++) v[i] = val[key, i]
        for (i = 2; i <= n; i++) for (j = i; j > 1 && v[j - 1] > v[j]; j--) { t = v[j]; v[j] = v[j - 1]; v[j - 1] = t }
        return n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
    }
    {
        split($1, h, " "); t = h[1]; phase = substr($1, length(h[1]) + length(h[2]) + 3)
        if (!(phase in seen)) { seen[phase] = 1; order[++np] = phase }
        key = t SUBSEP phase SUBSEP "wall"; val[key, ++cnt[key]] = $2
        key = t SUBSEP phase SUBSEP "cpu"; val[key, ++cnt[key]] = $3
        key = t SUBSEP phase SUBSEP "main"; val[key, ++cnt[key]] = $4
    }
    END {
        print "| phase | 1 thread: wall s | CPU s | 2 threads: wall s | CPU s | CPU/wall | main-thread CPU s | alone s | speed-up | CPU 2 / CPU 1 |"
        print "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        for (p = 1; p <= np; p++) {
            ph = order[p]
            w1 = median(1 SUBSEP ph SUBSEP "wall"); c1 = median(1 SUBSEP ph SUBSEP "cpu")
            w2 = median(2 SUBSEP ph SUBSEP "wall"); c2 = median(2 SUBSEP ph SUBSEP "cpu")
            m2 = median(2 SUBSEP ph SUBSEP "main")
            if (ph == "total") { W1 = w1; C1 = c1; W2 = w2; C2 = c2; M2 = m2; continue }
            # what the building thread did alone: its CPU less the other thread'"'"'s
            a = m2 - (c2 - m2); if (a < 0) a = 0
            alone += a
            # a phase where the other thread did under 5% of the CPU ran on one thread
            if (c2 - m2 < 0.05 * c2) single += c1
            printf "| %s | %.3f | %.3f | %.3f | %.3f | %.2f | %.3f | %.3f | %s | %s |\n", ph, w1, c1, w2, c2, (w2 > 0 ? c2 / w2 : 0), m2, a,
                   (w2 > 0 ? sprintf("%.2fx", w1 / w2) : "-"), (c1 > 0 ? sprintf("%.2fx", c2 / c1) : "-")
        }
        printf "| **total** | **%.3f** | **%.3f** | **%.3f** | **%.3f** | **%.2f** | **%.3f** | **%.3f** | **%.2fx** | **%.2fx** |\n",
               W1, C1, W2, C2, C2 / W2, M2, alone, W1 / W2, C2 / C1
        f = alone / C1
        print ""
        print "Main-thread CPU: the building (calling) thread'"'"'s CPU seconds in the phase; alone: that less the other thread'"'"'s, the CPU seconds it spent with the other thread idle (at most; clipped at 0). CPU seconds count only the time a thread ran, so unlike the speed-up they hold when other processes share the cores."
        print ""
        printf "- Serial share, by phase (the CPU seconds, on 1 thread, of the phases where the second thread did under 5%% of the CPU, over one thread'"'"'s total): **%.1f%%** (%.3f of %.3f s).\n", 100 * single / C1, single, C1
        printf "- Serial share, by part (the alone seconds, over one thread'"'"'s total CPU seconds): **%.1f%%** (%.3f of %.3f s).\n", 100 * f, alone, C1
        printf "- CPU seconds of 2 threads over 1 thread'"'"'s: **%.2fx** (%.3f / %.3f s).\n", C2 / C1, C2, C1
        printf "- *Projected*, not measured (Amdahl from the serial share by part, this machine having %s logical CPUs): 16 threads %.1fx faster than 1 (a %.2f s build), 8 threads %.1fx.\n", ENVIRON["NPROC"], 1 / (f + (1 - f) / 16), W1 * (f + (1 - f) / 16), 1 / (f + (1 - f) / 8)
    }' "$work/rows"
echo
