#!/bin/sh
# Editing (voxdag_editor, bench/bench_edit.c) on two scenes built here by
# `vdag build`: the bunny (bunny.off, no colours: bench_edit gives it colours
# from position) and the abyss track with its textures' colours (voxcolor at
# e_t 0.02; the editor decodes them). Full: the bunny at 4096^3 and the abyss
# at 16384^3; quick: 1024^3 and 2048^3, fewer edits. Prints a markdown section.
#   bench/edit.sh quick|full VDAG BENCH_EDIT DATA_DIR
set -eu
usage="usage: bench/edit.sh quick|full VDAG BENCH_EDIT DATA_DIR"
mode=${1:?$usage} vdag=${2:?$usage} prog=${3:?$usage} data=${4:?$usage}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
X=$data/x/supertuxkart-data/usr/share/games/supertuxkart/data/tracks/abyss/abyss_track.spm
if [ "$mode" = full ]; then lb=12 la=14 quick=; else lb=10 la=11 quick=--quick; fi

echo "## Editing"
echo
"$vdag" build "$data/bunny.off" "$work/bunny.vdag" --levels $lb --quiet
set -- "bunny-$((1 << lb))=$work/bunny.vdag"
if [ -s "$X" ]; then
    echo "edit: building the abyss track at $((1 << la))^3" >&2
    "$vdag" build "$X" "$work/abyss.vdag" --levels $la --color-error 0.02 --quiet
    set -- "$@" "abyss-$((1 << la))=$work/abyss.vdag"
else
    echo "edit: $X missing (bench/fetch.sh DATA scenes)" >&2
fi
echo "Scenes built by \`vdag build\`: \`bunny.off --levels $lb\` (colours from position, r g b = x y z mod 256, set in one edit on an empty editor), and the SuperTuxKart abyss track with its textures' colours (\`--levels $la --color-error 0.02\`; the editor holds them decoded). One thread. *Edited voxels* are those whose state or colour an edit sets: a fill, the shape's voxels inside the grid; a carve or a paint, the full voxels in the shape. The second table: the editor's memory against the loaded file and against the same scene committed with raw RGB8 colours (what the editor holds), then random edits (carve, fill, paint and copy of boxes and spheres of 1 to 64 voxels at voxels of the scene, with undo and redo among them), the commit, and a fresh \`voxdag_builder\` run on the resulting voxels and colours, which must give the same bytes."
echo
# shellcheck disable=SC2086
"$prog" $quick "$@"
