#!/bin/sh
# Build matrix, link and symbol checks, the README's code and determinism
# across compilers. Prints one line per check and a final "N passed, N failed".
# Usage: tests/check_all.sh [BUILD_DIR]   (run from the repository root)
#
#   compile   each header alone and with its implementation, under gcc and
#             clang as C99 and as C++11 (-Werror), at -O0 and -O2, with and
#             without NDEBUG, in every combination of the configuration macros;
#             -m32 when a multilib compiler works
#   errors    VOXDAG_MALLOC or VOXDAG_FREE alone, VOXDAG_MAX_LEVELS out of range
#   link      the implementations in one unit used from another (C and C++
#             mixed), both implementations in one unit, VOXDAG_STATIC and
#             VOXCOLOR_STATIC in two units linked together; each program runs
#   symbols   the library objects export only voxdag_ and voxcolor_ names
#   readme    README.md's ```c blocks compiled and run
#   determinism  the same scene built by gcc- and clang-built vdag tools at
#             -O0 and -O2, -m32 with SSE and with x87 maths, and with FMA
#             contraction, with 1 and 3 threads and colours compressed at
#             e_t 0.01, 0.03 and 0.1, gives byte-identical .vdag files per
#             setting (the colour encoder decides in integers)
set -u
build=${1:-build}
out=$build/check-all
rm -rf "$out"
mkdir -p "$out/jobs" "$out/obj" "$out/bin" "$out/det" "$out/readme"
jobs=$out/jobs
n=0
pass=0
fail=0
start=$(date +%s)

WARN="-Wall -Wextra -Wpedantic -Wshadow -Wundef -Werror"
CONV="-Wconversion -Wsign-conversion"
C99="-std=c99 $WARN"
CXX11="-x c++ -std=c++11 $WARN"
# voxdag.h is held to CONV when it has no such warnings (see "conversion").
VOXDAG_CONV_CEILING=0
L=tests/link

note() { echo "note: $*" >&2; }

# job NAME EXPECT COMMAND: queue COMMAND (a shell string) for the parallel
# phase. EXPECT is "ok" (exit 0) or a pattern that the
# output of a command that fails must contain.
job() {
    n=$((n + 1))
    jf=$jobs/$(printf '%04d' $n)
    printf '%s\n' "$1" >"$jf.name"
    printf '%s\n' "$2" >"$jf.expect"
    printf 'set -e\n%s\n' "$3" >"$jf.sh"
}

# -- Compilers

have() { command -v "$1" >/dev/null 2>&1; }
CCS=""
for c in gcc clang; do have $c && CCS="$CCS $c"; done
CXXS=""
for c in g++ clang++; do have $c && CXXS="$CXXS $c"; done
[ -n "$CCS" ] || { echo "check_all: no gcc or clang"; echo "0 passed, 1 failed"; exit 1; }

m32_works() {
    printf '#include <stdint.h>\n#include <stdio.h>\n#include <math.h>\nint main(void){return (int)sizeof(void*) - 4 + (int)fabs(0.0);}\n' >"$out/m32.c"
    gcc -m32 -o "$out/m32" "$out/m32.c" -lm >/dev/null 2>&1 && "$out/m32"
}
M32=""
if have gcc; then
    if ! m32_works && [ "$(id -u)" = 0 ] && have apt-get; then
        note "installing gcc-multilib g++-multilib for -m32"
        DEBIAN_FRONTEND=noninteractive apt-get install -y -q gcc-multilib g++-multilib >/dev/null 2>&1 ||
            { apt-get update -q >/dev/null 2>&1 &&
              DEBIAN_FRONTEND=noninteractive apt-get install -y -q gcc-multilib g++-multilib >/dev/null 2>&1; }
    fi
    if m32_works; then M32=1; else note "-m32 skipped: no working multilib compiler (gcc-multilib)"; fi
fi

# -- Compile matrix

# The configurations of voxdag.h: the three NO_ switches in all 8 combinations,
# each with the default and with custom MALLOC+FREE+ASSERT and MAX_LEVELS=12;
# then VOXDAG_NO_BUILD (load-and-query programs) alone and with every other
# switch, and the voxcolor bridge (VOXDAG_WITH_VOXCOLOR: voxdag_color decodes
# voxcolor sections) alone and with NO_BUILD.
VOXDAG_CONFIGS=""
for s in "" -DVOXDAG_NO_STDIO; do
    for t in "" -DVOXDAG_NO_THREADS; do
        for r in "" -DVOXDAG_NO_RAYTRACE; do
            for c in "" -DCHECK_CUSTOM; do
                VOXDAG_CONFIGS="$VOXDAG_CONFIGS $(echo "$s $t $r $c" | tr -s ' ' | sed 's/^ //; s/ $//; s/ /,/g; s/^$/default/')"
            done
        done
    done
done
VOXDAG_CONFIGS="$VOXDAG_CONFIGS -DVOXDAG_NO_BUILD -DVOXDAG_NO_BUILD,-DVOXDAG_NO_STDIO,-DVOXDAG_NO_THREADS,-DVOXDAG_NO_RAYTRACE,-DCHECK_CUSTOM"
VOXDAG_CONFIGS="$VOXDAG_CONFIGS -DVOXDAG_WITH_VOXCOLOR -DVOXDAG_WITH_VOXCOLOR,-DVOXDAG_NO_BUILD"

# voxdag.h's conversion warnings: counted against a ceiling until there are none.
conv_count=0
if have gcc; then
    gcc $C99 $CONV -Wno-error -O2 -fsyntax-only -I. -DVOXDAG_IMPLEMENTATION "$L/header_voxdag.c" \
        2>"$out/conversion.txt" >/dev/null
    conv_count=$(grep -c 'warning:' "$out/conversion.txt")
    if [ "$conv_count" -gt "$VOXDAG_CONV_CEILING" ]; then
        echo "FAIL conversion: voxdag.h has $conv_count -Wconversion/-Wsign-conversion warnings (ceiling $VOXDAG_CONV_CEILING)" | tee /dev/stderr
        grep 'warning:' "$out/conversion.txt" | sed 's/^/    /' >&2
        fail=$((fail + 1))
    else
        echo "ok   conversion: voxdag.h has $conv_count -Wconversion/-Wsign-conversion warnings (ceiling $VOXDAG_CONV_CEILING)"
        [ "$conv_count" -gt 0 ] && grep 'warning:' "$out/conversion.txt" | sed 's/^/    /' >&2
        pass=$((pass + 1))
    fi
fi
if [ "$conv_count" = 0 ]; then VOXDAG_WARN=$CONV; else VOXDAG_WARN=""; fi

lang_flags() {  # lang_flags COMPILER: the language and warning flags
    case $1 in
    *++) echo "$CXX11" ;;
    *) echo "$C99" ;;
    esac
}

# Each header alone, with both compilers and languages.
for cc in $CCS $CXXS; do
    f=$(lang_flags $cc)
    job "alone $cc voxdag.h" ok "$cc $f $VOXDAG_WARN -fsyntax-only -I. $L/header_voxdag.c"
    job "alone $cc voxcolor.h" ok "$cc $f $CONV -fsyntax-only -I. $L/header_voxcolor.c"
done

# Implementations: every compiler, -O0/-O2, with and without NDEBUG, default
# configuration; then every other voxdag configuration, compiled at -O2 by the
# C compilers (the optimizer adds warnings) and checked by the C++ front ends.
for cc in $CCS $CXXS; do
    f=$(lang_flags $cc)
    for o in -O0 -O2; do
        for d in "" -DNDEBUG; do
            job "impl $cc $o ${d:-(asserts)} voxdag.h" ok \
                "$cc $f $VOXDAG_WARN $o $d -c -o /dev/null -I. -DVOXDAG_IMPLEMENTATION $L/header_voxdag.c"
            for c in "" -DCHECK_CUSTOM -DVOXCOLOR_NO_THREADS; do
                job "impl $cc $o ${d:-(asserts)} ${c:-default} voxcolor.h" ok \
                    "$cc $f $CONV $o $d $c -c -o /dev/null -I. -DVOXCOLOR_IMPLEMENTATION $L/header_voxcolor.c"
            done
        done
    done
    case $cc in *++) how="-fsyntax-only" ;; *) how="-O2 -c -o /dev/null" ;; esac
    for cfg in $VOXDAG_CONFIGS; do
        [ "$cfg" = default ] && continue
        defs=$(echo "$cfg" | tr ',' ' ')
        job "config $cc $(echo "$how" | cut -d' ' -f1) $(echo "$cfg" | sed 's/-D//g')" ok \
            "$cc $f $VOXDAG_WARN $how $defs -I. -DVOXDAG_IMPLEMENTATION $L/header_voxdag.c"
    done
done

# -m32: both C compilers, the default and the smallest configuration, NDEBUG.
if [ -n "$M32" ]; then
    for cc in $CCS; do
        for cfg in "" "-DVOXDAG_NO_STDIO -DVOXDAG_NO_THREADS -DVOXDAG_NO_RAYTRACE -DCHECK_CUSTOM"; do
            for d in "" -DNDEBUG; do
                job "m32 $cc -O2 ${d:-(asserts)} $(echo "${cfg:-default}" | sed 's/-D//g; s/ /,/g')" ok \
                    "$cc -m32 $C99 $VOXDAG_WARN -O2 $d $cfg -c -o /dev/null -I. -DVOXDAG_IMPLEMENTATION $L/header_voxdag.c"
            done
        done
        job "m32 $cc -O2 voxcolor.h" ok \
            "$cc -m32 $C99 $CONV -O2 -c -o /dev/null -I. -DVOXCOLOR_IMPLEMENTATION $L/header_voxcolor.c"
    done
fi

# voxcolor.h's Win32 thread pool: compiled by MinGW-w64 when it is installed.
if have x86_64-w64-mingw32-gcc; then
    for c in "" -DVOXCOLOR_NO_THREADS; do
        job "mingw x86_64-w64-mingw32-gcc -O2 ${c:-default} voxcolor.h" ok \
            "x86_64-w64-mingw32-gcc $C99 $CONV -O2 $c -c -o /dev/null -I. -DVOXCOLOR_IMPLEMENTATION $L/header_voxcolor.c"
    done
else
    note "MinGW-w64 voxcolor.h compile skipped: x86_64-w64-mingw32-gcc not installed (gcc-mingw-w64-x86-64)"
fi

# -- Configuration errors
cc1=$(echo $CCS | cut -d' ' -f1)
job "error VOXDAG_MALLOC alone" "define both VOXDAG_MALLOC and VOXDAG_FREE" \
    "$cc1 $C99 -fsyntax-only -I. -DVOXDAG_IMPLEMENTATION -DCHECK_MALLOC_ONLY $L/header_voxdag.c"
job "error VOXDAG_FREE alone" "define both VOXDAG_MALLOC and VOXDAG_FREE" \
    "$cc1 $C99 -fsyntax-only -I. -DVOXDAG_IMPLEMENTATION -DCHECK_FREE_ONLY $L/header_voxdag.c"
job "error VOXDAG_MAX_LEVELS=22" "VOXDAG_MAX_LEVELS must be between" \
    "$cc1 $C99 -fsyntax-only -I. -DVOXDAG_MAX_LEVELS=22 $L/header_voxdag.c"
job "error VOXDAG_MAX_LEVELS=1" "VOXDAG_MAX_LEVELS must be between" \
    "$cc1 $C99 -fsyntax-only -I. -DVOXDAG_MAX_LEVELS=1 $L/header_voxdag.c"

# -- Link tests: objects kept in $out/obj for the symbol check.
O=$out/obj
B=$out/bin
LIBS="-pthread -lm"
for cc in $CCS; do
    f=$(lang_flags $cc)
    job "link $cc: implementations in their own units, used from a third" ok \
        "$cc $f -O2 -c -o $O/$cc-impl_voxdag.o -I. $L/impl_voxdag.c
         $cc $f -O2 -c -o $O/$cc-impl_voxcolor.o -I. $L/impl_voxcolor.c
         $cc $f -O2 -o $B/$cc-use -I. $L/use.c $O/$cc-impl_voxdag.o $O/$cc-impl_voxcolor.o $LIBS
         $B/$cc-use"
    job "link $cc: voxcolor built with VOXCOLOR_NO_THREADS, used from a default unit" ok \
        "$cc $f -O2 -DVOXCOLOR_NO_THREADS -c -o $O/$cc-impl_voxcolor_nothreads.o -I. $L/impl_voxcolor.c
         $cc $f -O2 -c -o $O/$cc-impl_voxdag_for_nothreads.o -I. $L/impl_voxdag.c
         $cc $f -O2 -o $B/$cc-use-nothreads -I. $L/use.c $O/$cc-impl_voxdag_for_nothreads.o $O/$cc-impl_voxcolor_nothreads.o $LIBS
         $B/$cc-use-nothreads"
    job "link $cc -O0: both implementations in one unit" ok \
        "$cc $f -O0 -c -o $O/$cc-impl_both.o -I. $L/impl_both.c
         $cc $f -O0 -o $B/$cc-use-both -I. $L/use.c $O/$cc-impl_both.o $LIBS
         $B/$cc-use-both"
    job "link $cc: a load-and-query program built with VOXDAG_NO_BUILD, run on a golden file" ok \
        "$cc $f -O2 -o $B/$cc-load_query -I. $L/load_query.c $LIBS
         $B/$cc-load_query tests/data/golden/mirrored_blob_l5.vdag"
    job "link $cc: VOXDAG_STATIC and VOXCOLOR_STATIC in two units" ok \
        "$cc $f -O2 -c -o $O/$cc-static_a.o -I. -DSTATIC_UNIT=static_unit_a $L/static_unit.c
         $cc $f -O2 -c -o $O/$cc-static_b.o -I. -DSTATIC_UNIT=static_unit_b $L/static_unit.c
         $cc $f -O2 -o $B/$cc-static -I. $L/static_main.c $O/$cc-static_a.o $O/$cc-static_b.o $LIBS
         $B/$cc-static"
done
for cxx in $CXXS; do
    f=$(lang_flags $cxx)
    cc=$(echo $CCS | cut -d' ' -f1)
    job "link $cxx: implementations compiled as C++, used from C" ok \
        "$cxx $f -O2 -c -o $O/$cxx-impl_both.o -I. $L/impl_both.c
         $cc $C99 -O2 -c -o $O/$cxx-use.o -I. $L/use.c
         $cxx -o $B/$cxx-use $O/$cxx-use.o $O/$cxx-impl_both.o $LIBS
         $B/$cxx-use"
    job "link $cxx: C implementations used from C++" ok \
        "$cc $C99 -O2 -c -o $O/$cxx-c-impl_both.o -I. $L/impl_both.c
         $cxx $f -O2 -o $B/$cxx-use-c -I. $L/use.c -x none $O/$cxx-c-impl_both.o $LIBS
         $B/$cxx-use-c"
    job "link $cxx: VOXDAG_STATIC and VOXCOLOR_STATIC in two units" ok \
        "$cxx $f -O2 -c -o $O/$cxx-static_a.o -I. -DSTATIC_UNIT=static_unit_a $L/static_unit.c
         $cxx $f -O2 -c -o $O/$cxx-static_b.o -I. -DSTATIC_UNIT=static_unit_b $L/static_unit.c
         $cxx $f -O2 -o $B/$cxx-static -I. $L/static_main.c -x none $O/$cxx-static_a.o $O/$cxx-static_b.o $LIBS
         $B/$cxx-static"
done
if [ -n "$M32" ]; then
    job "link gcc -m32: both implementations in one unit" ok \
        "gcc -m32 $C99 -O2 -c -o $O/m32-impl_both.o -I. $L/impl_both.c
         gcc -m32 $C99 -O2 -o $B/m32-use -I. $L/use.c $O/m32-impl_both.o $LIBS
         $B/m32-use"
fi

# -- README: every ```c block, preprocessor lines first, the rest in main(),
# run where build/demo.vdag is a scene built as `make demo` does (colours in a
# voxcolor stream, vdag build --color-error): its colour lookup must print.
VDAG_SRC="$(sed -n 's/^VDAG_SRC *:= *//p' Makefile | sed 's|examples/image_stb.c|examples/image_none.c|')" # no texture read
job "readme: README.md's C code compiled and run on a voxcolor-coloured file" ok \
    "mkdir -p $out/readme/build
     $cc1 -std=c99 -O2 -pthread -I. -o $out/readme/vdag $VDAG_SRC -lm
     $out/readme/vdag gen demo $out/readme/build/demo.xyz --levels 7 >/dev/null
     $out/readme/vdag build $out/readme/build/demo.xyz $out/readme/build/demo.vdag --color-error 0.02 --quiet
     $out/readme/vdag info $out/readme/build/demo.vdag --json | grep -q voxcolor
     awk '/^\`\`\`c\$/ { c = 1; next } /^\`\`\`/ { c = 0 } c' README.md >$out/readme/blocks.txt
     test -s $out/readme/blocks.txt
     { echo '#include <stdio.h>'; echo '#include <stdlib.h>'; echo '#include <string.h>'
       grep '^#' $out/readme/blocks.txt
       echo 'int main(void) {'
       grep -v '^#' $out/readme/blocks.txt
       echo 'return 0;'; echo '}'; } >$out/readme/readme.c
     $cc1 $C99 -Wno-unused -O1 -o $out/readme/readme -I. $out/readme/readme.c $LIBS
     (cd $out/readme && ./readme) >$out/readme/out.txt
     cat $out/readme/out.txt
     grep -q '^hit voxel .* colour [0-9]* [0-9]* [0-9]*\$' $out/readme/out.txt"

# -- Determinism: vdag built by each C compiler at -O0 and -O2 and in other
# floating-point models, one scene built with 1 and 3 threads (colour error
# 0.03) and with colour errors 0.01 and 0.1; each setting's .vdag files must
# be byte-identical.
DET_RUNS="1 3 e0.01 e0.1"
D=$out/det
DET_BUILDS=""
for cc in $CCS; do
    for o in -O0 -O2; do DET_BUILDS="$DET_BUILDS $cc:$o"; done
done
[ -n "$M32" ] && DET_BUILDS="$DET_BUILDS gcc:-O2,-m32,-msse2,-mfpmath=sse gcc:-O2,-m32,-mfpmath=387"
have clang && grep -q -w fma /proc/cpuinfo 2>/dev/null &&
    DET_BUILDS="$DET_BUILDS clang:-O2,-mfma,-ffp-contract=on"
for spec in $DET_BUILDS; do
    cc=${spec%%:*}
    flags=$(echo "$spec" | cut -d: -f2 | tr ',' ' ')
    t=$(echo "$spec" | tr ':,=' '___')
    job "determinism: vdag built by $cc $flags" ok \
        "$cc -std=c99 $flags -pthread -I. -o $D/vdag-$t $VDAG_SRC -lm
         $D/vdag-$t gen demo $D/scene-$t.xyz --levels 7 >/dev/null
         $D/vdag-$t build $D/scene-$t.xyz $D/scene-$t-1.vdag --threads 1 --color-error 0.03 >/dev/null
         $D/vdag-$t build $D/scene-$t.xyz $D/scene-$t-3.vdag --threads 3 --color-error 0.03 >/dev/null
         $D/vdag-$t build $D/scene-$t.xyz $D/scene-$t-e0.01.vdag --threads 1 --color-error 0.01 >/dev/null
         $D/vdag-$t build $D/scene-$t.xyz $D/scene-$t-e0.1.vdag --threads 1 --color-error 0.1 >/dev/null"
done

# -- Parallel phase
cat >"$out/run_job.sh" <<'EOF'
#!/bin/sh
# run_job.sh JOBFILE.sh: runs it, writes JOBFILE.result (pass/fail) and .log
j=${1%.sh}
expect=$(cat "$j.expect")
t0=$(date +%s)
sh "$1" >"$j.log" 2>&1
status=$?
echo $(($(date +%s) - t0)) >"$j.time"
if [ "$expect" = ok ]; then
    [ $status = 0 ] && r=pass || r=fail
else
    if [ $status != 0 ] && grep -q -- "$expect" "$j.log"; then r=pass; else r=fail; fi
fi
echo $r >"$j.result"
EOF
ls "$jobs"/*.sh | xargs -P "${CHECK_JOBS:-2}" -n 1 sh "$out/run_job.sh"

for s in "$jobs"/*.sh; do
    j=${s%.sh}
    name=$(cat "$j.name")
    if [ "$(cat "$j.result" 2>/dev/null)" = pass ]; then
        echo "ok   $name"
        pass=$((pass + 1))
    else
        echo "FAIL $name"
        { echo "FAIL $name"; cut -c 1-300 "$j.log" | head -n 30 | sed 's/^/    /'; } >&2
        fail=$((fail + 1))
    fi
done

# -- Symbols: the library objects export only prefixed names.
check_symbols() {  # check_symbols NAME OBJECT ALLOWED_PATTERN
    if [ ! -f "$2" ]; then
        echo "FAIL symbols $1: no object (its link test failed)" | tee /dev/stderr
        fail=$((fail + 1))
        return
    fi
    bad=$(nm -g --defined-only "$2" | awk '{ print $NF }' | grep -v -E "$3" || true)
    if [ -n "$bad" ]; then
        echo "FAIL symbols $1: unexpected exports:" | tee /dev/stderr
        echo "$bad" | sed 's/^/    /' | head -n 20 >&2
        fail=$((fail + 1))
    else
        echo "ok   symbols $1: $(nm -g --defined-only "$2" | wc -l) exports, all prefixed"
        pass=$((pass + 1))
    fi
}
if have nm; then
    for cc in $CCS; do
        check_symbols "$cc voxdag" "$O/$cc-impl_voxdag.o" '^voxdag_[a-z0-9_]*$'
        check_symbols "$cc voxcolor" "$O/$cc-impl_voxcolor.o" '^voxcolor_[a-z0-9_]*$'
        check_symbols "$cc -O0 both" "$O/$cc-impl_both.o" '^(voxdag|voxcolor)_[a-z0-9_]*$'
        check_symbols "$cc VOXDAG_STATIC" "$O/$cc-static_a.o" '^static_unit_a$'
    done
    for cxx in $CXXS; do
        check_symbols "$cxx both" "$O/$cxx-impl_both.o" '^(voxdag|voxcolor)_[a-z0-9_]*$'
        check_symbols "$cxx VOXDAG_STATIC" "$O/$cxx-static_a.o" '^_Z[0-9]*static_unit_av$'
    done
    # (-m32 code gets the compiler's hidden __x86.get_pc_thunk helpers)
    [ -n "$M32" ] && check_symbols "gcc -m32 both" "$O/m32-impl_both.o" \
        '^((voxdag|voxcolor)_[a-z0-9_]*|__x86\.get_pc_thunk\.[a-z]+)$'
else
    note "symbol checks skipped: no nm"
fi

# -- Determinism: compare every .vdag with the first build's of the same
# setting (threads 3 with threads 1).
det_bad=""
det_count=0
first1=""
for run in $DET_RUNS; do
    first=""
    for spec in $DET_BUILDS; do
        t=$(echo "$spec" | tr ':,=' '___')
        v=$D/scene-$t-$run.vdag
        det_count=$((det_count + 1))
        if [ ! -f "$v" ]; then det_bad="$det_bad $t/$run(missing)"; continue; fi
        [ "$run" = 3 ] && [ -z "$first" ] && first=$first1
        if [ -z "$first" ]; then first=$v
        elif ! cmp -s "$first" "$v"; then det_bad="$det_bad $t/$run($(cmp -l "$first" "$v" | wc -l) bytes)"; fi
    done
    [ "$run" = 1 ] && first1=$first
done
if [ -z "$det_bad" ] && [ -n "$first1" ]; then
    echo "ok   determinism: $det_count .vdag files byte-identical per setting ($(wc -c <"$first1") bytes at e_t 0.03)"
    pass=$((pass + 1))
else
    echo "FAIL determinism: differ from the first build of their setting:$det_bad" | tee /dev/stderr
    fail=$((fail + 1))
fi

echo "check-all took $(($(date +%s) - start)) s" >&2
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
