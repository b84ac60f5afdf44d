#!/bin/sh
# Checks every compiled shader under BUILD_DIR/shaders (the Makefile's .spv
# files): spirv-val for Vulkan 1.1 must accept it, and it may declare no
# capability but Shader, so that it runs on any Vulkan 1.1 device with no
# optional feature (Int64, Float64, Int16 and the like are optional).
# No .spv at all fails, unless VOXDAG_TEST_SKIP lists "gpu" (a build
# without the GPU path). Prints "N passed, N failed".
# Usage: tests/spirv_check.sh BUILD_DIR
set -u
build=${1:-build}
pass=0
fail=0
skip_allowed() {
    case ",$(echo "${VOXDAG_TEST_SKIP:-}" | tr ' ' ','),," in
    *,gpu,* | *,all,*) return 0 ;;
    esac
    return 1
}
if ! command -v spirv-val >/dev/null 2>&1 || ! command -v spirv-dis >/dev/null 2>&1; then
    if skip_allowed; then
        echo "SKIP gpu: no spirv-val or spirv-dis (allowed by VOXDAG_TEST_SKIP)"
        echo "0 passed, 0 failed"
        exit 0
    fi
    echo "FAIL gpu: no spirv-val or spirv-dis (tests/deps.sh installs spirv-tools; VOXDAG_TEST_SKIP=gpu allows the skip)" >&2
    echo "0 passed, 1 failed"
    exit 1
fi
found=0
for spv in "$build"/shaders/*.spv; do
    [ -f "$spv" ] || continue
    found=1
    if out=$(spirv-val --target-env vulkan1.1 "$spv" 2>&1); then
        pass=$((pass + 1))
    else
        echo "FAIL $spv: spirv-val: $out" >&2
        fail=$((fail + 1))
    fi
    caps=$(spirv-dis "$spv" 2>/dev/null | sed -n 's/^ *OpCapability  *//p' | grep -v '^Shader$' | tr '\n' ' ')
    if [ -z "$caps" ] && spirv-dis "$spv" >/dev/null 2>&1; then
        pass=$((pass + 1))
    else
        echo "FAIL $spv: capabilities other than Shader: ${caps:-(spirv-dis failed)}" >&2
        fail=$((fail + 1))
    fi
done
if [ "$found" = 0 ]; then
    if skip_allowed; then
        echo "SKIP gpu: no shaders in $build/shaders (allowed by VOXDAG_TEST_SKIP)"
    else
        echo "FAIL gpu: no .spv files in $build/shaders (built without the GPU path?)" >&2
        fail=$((fail + 1))
    fi
fi
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
