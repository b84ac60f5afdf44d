#!/bin/sh
# Runs every test program and prints the combined "N passed, N failed" line.
# Usage: tests/run.sh BUILD_DIR [--full]
# The fuzz corpora are replayed with sweeps (tests/fuzz_replay.h): every
# truncation, every byte patched to +1, -1, 0x00 and 0xff, and every
# allocation failing in turn. --full (make test-full) patches every byte to
# each of its 255 other values, here and in the unit tests' sweeps.
set -u
build=${1:-build}
sweep=--sweep
unit_args=
if [ "${2:-}" = --full ]; then
    sweep=--sweep-full
    unit_args=--full
fi
export VDAG="$build/vdag" # the tool the tests run, from the same build
total_pass=0
total_fail=0
start=$(date +%s)
run() {  # run NAME COMMAND...: a program whose last line is "N passed, N failed"
    name=$1; shift
    echo "== $name" >&2
    t0=$(date +%s)
    out=$("$@")
    tally "$name" $? "$out" "$t0"
}
tally() {  # tally NAME EXIT_STATUS OUTPUT START_SECONDS
    name=$1 status=$2 out=$3 t0=$4
    line=$(printf '%s\n' "$out" | tail -n 1)
    p=$(printf '%s\n' "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed.*/\1/p')
    f=$(printf '%s\n' "$line" | sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed.*/\2/p')
    if [ -z "$p" ]; then
        echo "$name: no result line (exit $status)" >&2
        p=0; f=1
    elif [ "$status" != 0 ] && [ "$f" = 0 ]; then
        echo "$name: exit status $status" >&2
        f=1
    fi
    echo "$name: $line ($(( $(date +%s) - t0 )) s)" >&2
    total_pass=$((total_pass + p))
    total_fail=$((total_fail + f))
}
# The unit tests (one thread, the longest program) run beside the programs
# up to the fuzz corpora, on the second CPU; their log follows when they end.
# check-all, which keeps two CPUs busy, runs after both.
echo "== unit (beside the next programs)" >&2
unit_t0=$(date +%s)
("$build/test" $unit_args >"$build/unit.out" 2>"$build/unit.log"; echo $? >"$build/unit.status") &
unit_job=$!
run voxcolor-ndebug "$build/test_voxcolor_ndebug"
run voxdag-ndebug "$build/test_voxdag_ndebug"
run vulkan "$build/test_vk"
run gpu "$build/test_gpu_vk"
run spirv sh tests/spirv_check.sh "$build"
run cli sh tests/cli.sh "$build/vdag"
run third-party sh tests/third_party.sh "$build"
run fuzz-import "$build/fuzz_import" $sweep tests/data/fuzz/import
run fuzz-voxcolor "$build/fuzz_voxcolor" $sweep tests/data/fuzz/voxcolor
run fuzz-load "$build/fuzz_load" $sweep tests/data/fuzz/load
run fuzz-roundtrip "$build/fuzz_roundtrip" $sweep tests/data/fuzz/roundtrip
run fuzz-edit "$build/fuzz_edit" $sweep tests/data/fuzz/edit
wait $unit_job
echo "== unit: its log" >&2
cat "$build/unit.log" >&2
tally unit "$(cat "$build/unit.status")" "$(cat "$build/unit.out")" "$unit_t0"
run check-all sh tests/check_all.sh "$build"
echo "all: $(( $(date +%s) - start )) s" >&2
echo "$total_pass passed, $total_fail failed"
[ "$total_fail" = 0 ]
