#!/bin/sh
# Build matrix, link and symbol checks, the README's code and determinism
# across compilers. Prints one line per check and a final "N passed, N failed".
# Usage: tests/check_all.sh [BUILD_DIR]   (run from the repository root)
#
#   compile   each header alone and with its implementation, under gcc and
#             clang as C99 and as C++11 (-Werror), at -O0 and -O2, with and
#             without NDEBUG, in every combination of the configuration macros;
#             32-bit x86 (i686-linux-gnu-gcc, clang --target) and MinGW-w64
#   errors    VOXDAG_MALLOC or VOXDAG_FREE alone, VOXDAG_MAX_LEVELS out of range
#   link      the implementations in one unit used from another (C and C++
#             mixed), both implementations in one unit, VOXDAG_STATIC and
#             VOXCOLOR_STATIC in two units linked together; each program runs
#             (the 32-bit one under qemu-i386)
#   mixed     a unit built with VOXDAG_MAX_LEVELS 8 and the NO_ switches linked
#             with an implementation built with 21 (and 12 against 21), under
#             ASan: build stats and info across the boundary, layouts compared;
#             a header whose public arrays follow VOXDAG_MAX_LEVELS must fail it
#   macros    every one- and two-letter upper-case name defined as a macro
#             before both implementations (C and C++, gcc and clang)
#   symbols   the library objects export only voxdag_ and voxcolor_ names
#   readme    README.md's ```c blocks compiled and run
#   matrix    the portable unit tests (tests/test_main.c with TEST_PORTABLE:
#             format, queries, codec, rays, builds) cross-built for 32-bit x86
#             with x87 maths and big-endian s390x, run under qemu-user, and
#             for Windows by MinGW-w64, run under Wine; and
#             tests/platform_answers.c on each, whose output (golden files'
#             answers, file bytes of builds, colour streams, 10k rays with t
#             bit for bit) must equal the x86-64 build's line for line
#   determinism  the same scene built by gcc- and clang-built vdag tools at
#             -O0 and -O2, 32-bit x86 with x87 maths (under qemu-i386), and
#             with FMA contraction, with 1 and 3 threads and
#             colours compressed at e_t 0.01, 0.03 and 0.1, gives
#             byte-identical .vdag files per setting (the colour encoder
#             decides in integers)
#
# No silent skips: an entry whose tools are missing (tests/deps.sh installs
# them) prints "SKIP name: why" and counts as failed, unless the environment
# variable VOXDAG_TEST_SKIP lists its group (comma- or space-separated: i386,
# s390x, mingw, wine, fma; or "all"), which makes it count as skipped.
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

skipped=0
# unavailable GROUP WHY: an entry of GROUP cannot run (see "No silent skips").
unavailable() {
    case ",$(echo "${VOXDAG_TEST_SKIP:-}" | tr ' ' ','),," in
    *",$1,"* | *",all,"*)
        echo "SKIP $1: $2 (allowed by VOXDAG_TEST_SKIP)"
        skipped=$((skipped + 1)) ;;
    *)
        echo "FAIL $1: cannot run: $2 (tests/deps.sh installs it; VOXDAG_TEST_SKIP=$1 allows the skip)" | tee /dev/stderr
        fail=$((fail + 1)) ;;
    esac
}

# The foreign targets: 32-bit x86 and big-endian s390x cross compilers whose
# static programs run under qemu-user, MinGW-w64 whose programs run under Wine.
I686=""
if have i686-linux-gnu-gcc && have qemu-i386; then I686=i686-linux-gnu-gcc
else unavailable i386 "i686-linux-gnu-gcc or qemu-i386 missing (gcc-i686-linux-gnu, qemu-user)"; fi
S390X=""
if have s390x-linux-gnu-gcc && have qemu-s390x; then S390X=s390x-linux-gnu-gcc
else unavailable s390x "s390x-linux-gnu-gcc or qemu-s390x missing (gcc-s390x-linux-gnu, qemu-user)"; fi
MINGW=""
if have x86_64-w64-mingw32-gcc; then MINGW=x86_64-w64-mingw32-gcc
else unavailable mingw "x86_64-w64-mingw32-gcc missing (gcc-mingw-w64-x86-64)"; fi
WINE=""
if [ -x /usr/lib/wine/wine64 ]; then WINE=/usr/lib/wine/wine64
elif have wine64; then WINE=wine64
elif have wine; then WINE=wine
else unavailable wine "wine64 missing (Debian wine64)"; fi

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
    for o in -O0 -O2; do
        job "alone $cc $o voxdag_gpu.h (C mode)" ok "$cc $f $CONV $o -c -o /dev/null -I. $L/header_voxdag_gpu.c"
    done
done
# The GPU header's C mode on the foreign compilers: x87 and s390x evaluate
# floats wider (FLT_EVAL_METHOD 2 and 1), where it stores every result.
for c in $MINGW $I686 $S390X; do
    job "alone $c voxdag_gpu.h (C mode)" ok "$c $C99 $CONV -O2 -c -o /dev/null -I. $L/header_voxdag_gpu.c"
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

# 32-bit x86 (x87 maths): gcc and clang, the default and the smallest
# configuration, NDEBUG.
I686_CCS=""
[ -n "$I686" ] && I686_CCS="$I686"
[ -n "$I686" ] && have clang && I686_CCS="$I686_CCS clang--target=i686-linux-gnu"
for c32 in $I686_CCS; do
    cc=$(echo "$c32" | sed 's/--/ --/')
    for cfg in "" "-DVOXDAG_NO_STDIO -DVOXDAG_NO_THREADS -DVOXDAG_NO_RAYTRACE -DCHECK_CUSTOM"; do
        for d in "" -DNDEBUG; do
            job "i386 $cc -O2 ${d:-(asserts)} $(echo "${cfg:-default}" | sed 's/-D//g; s/ /,/g')" ok \
                "$cc $C99 $VOXDAG_WARN -O2 $d $cfg -c -o /dev/null -I. -DVOXDAG_IMPLEMENTATION $L/header_voxdag.c"
        done
    done
    job "i386 $cc -O2 voxcolor.h" ok \
        "$cc $C99 $CONV -O2 -c -o /dev/null -I. -DVOXCOLOR_IMPLEMENTATION $L/header_voxcolor.c"
done

# Windows: both headers' Win32 threads (and the NO_THREADS builds), MinGW-w64.
if [ -n "$MINGW" ]; then
    for c in "" -DVOXCOLOR_NO_THREADS; do
        job "mingw $MINGW -O2 ${c:-default} voxcolor.h" ok \
            "$MINGW $C99 $CONV -O2 $c -c -o /dev/null -I. -DVOXCOLOR_IMPLEMENTATION $L/header_voxcolor.c"
    done
    for c in "" -DVOXDAG_NO_THREADS "-DVOXDAG_NO_STDIO -DVOXDAG_NO_RAYTRACE -DCHECK_CUSTOM"; do
        job "mingw $MINGW -O2 $(echo "${c:-default}" | sed 's/-D//g; s/ /,/g') voxdag.h" ok \
            "$MINGW $C99 $VOXDAG_WARN -O2 $c -c -o /dev/null -I. -DVOXDAG_IMPLEMENTATION $L/header_voxdag.c"
    done
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
if [ -n "$I686" ]; then
    job "link $I686 (qemu-i386): both implementations in one unit" ok \
        "$I686 $C99 -O2 -c -o $O/i386-impl_both.o -I. $L/impl_both.c
         $I686 $C99 -O2 -static -o $B/i386-use -I. $L/use.c $O/i386-impl_both.o $LIBS
         qemu-i386 $B/i386-use"
fi

# -- Mixed configurations: public layouts do not depend on configuration
# macros, so units built with different ones link and agree (under ASan: a
# write past a caller's struct fails). The control: the same test with a
# header whose public arrays are sized by VOXDAG_MAX_LEVELS must fail.
SANF="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
SMALL="-DVOXDAG_MAX_LEVELS=8 -DVOXDAG_NO_STDIO -DVOXDAG_NO_RAYTRACE -DVOXDAG_NO_THREADS"
mkdir -p "$out/badabi"
sed 's/^#define VOXDAG_LEVEL_CAPACITY 21$/#define VOXDAG_LEVEL_CAPACITY VOXDAG_MAX_LEVELS/' voxdag.h >"$out/badabi/voxdag.h"
mixed() {  # mixed INCLUDES TAG: the two pairings
    echo "$cc1 $C99 -O1 -g $SANF $1 -c -o $O/mixed-$2-impl21.o $L/mixed_impl.c
          $cc1 $C99 -O1 -g $SANF $1 $SMALL -o $B/mixed-$2-use8 $L/mixed_use.c $O/mixed-$2-impl21.o $LIBS
          $B/mixed-$2-use8
          $cc1 $C99 -O1 -g $SANF $1 -DVOXDAG_MAX_LEVELS=12 -DVOXDAG_NO_THREADS -DVOXDAG_NO_STDIO -c -o $O/mixed-$2-impl12.o $L/mixed_impl.c
          $cc1 $C99 -O1 -g $SANF $1 -o $B/mixed-$2-use21 $L/mixed_use.c $O/mixed-$2-impl12.o $LIBS
          $B/mixed-$2-use21"
}
job "mixed: MAX_LEVELS 8 + NO_ switches with 21, 21 with 12, under ASan: stats, info, layouts agree" ok "$(mixed -I. ok)"
job "mixed: the control (public arrays sized by VOXDAG_MAX_LEVELS) fails" "AddressSanitizer: stack-buffer-overflow" \
    "grep -q 'CAPACITY VOXDAG_MAX_LEVELS' $out/badabi/voxdag.h
     $(mixed "-I$out/badabi -I." bad)"

# -- Macro names: a user's short macros (every upper-case name of one or two
# characters, N L B M S T and the like, defined as an invalid token) before
# both implementations in one unit; the control shows such a name breaks code.
awk 'BEGIN { u = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"; v = u "0123456789_"
    for (i = 1; i <= 26; i++) { a = substr(u, i, 1); print "#define " a " @"
        for (j = 1; j <= 37; j++) print "#define " a substr(v, j, 1) " @" } }' >"$out/macros.h"
for cc in $CCS $CXXS; do
    job "macros $cc: one- and two-letter user macros before both implementations" ok \
        "$cc $(lang_flags $cc) -O0 -include $out/macros.h -c -o $O/$cc-macros.o -I. $L/impl_both.c"
done
job "macros: the control (a variable named N under those macros) fails" "error" \
    "printf 'int f(void) { int N = 1; return N; }\\n' >$out/macros_control.c
     $cc1 $C99 -include $out/macros.h -c -o $O/macros_control.o $out/macros_control.c"

# -- README: every ```c block, preprocessor lines first, the rest in main(),
# run where build/demo.vdag is a scene built as `make demo` does (colours in a
# voxcolor stream, vdag build --color-error): its colour lookup must print.
# The same text is compiled as C99 and as C++11 (-Wall -Wextra -Werror: a
# `= {0}` initialiser fails there) and both programs must print the same.
VDAG_SRC="$(sed -n 's/^VDAG_SRC *:= *//p' Makefile | sed 's|examples/image_stb.c|examples/image_none.c|')" # no texture read
cxx1=$(echo $CXXS | cut -d' ' -f1)
[ -n "$cxx1" ] || { echo "FAIL readme: no g++ or clang++ for the README's code as C++" | tee /dev/stderr; fail=$((fail + 1)); }
job "readme: README.md's C code compiled as C99 and as C++11 ($cxx1), run on a voxcolor-coloured file" ok \
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
     grep -q '^hit voxel .* colour [0-9]* [0-9]* [0-9]*\$' $out/readme/out.txt
     grep -qx 'lit\|in shadow' $out/readme/out.txt
     $cxx1 $CXX11 -Wno-unused -O1 -o $out/readme/readme_cxx -I. $out/readme/readme.c $LIBS
     (cd $out/readme && ./readme_cxx) >$out/readme/out_cxx.txt
     cmp $out/readme/out.txt $out/readme/out_cxx.txt"

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
[ -n "$I686" ] && DET_BUILDS="$DET_BUILDS $I686:-O2,-static" # x87 maths (SSE2 maths is x86-64's)
if have clang && grep -q -w fma /proc/cpuinfo 2>/dev/null; then
    DET_BUILDS="$DET_BUILDS clang:-O2,-mfma,-ffp-contract=on"
else
    unavailable fma "clang or a processor with FMA missing: no FMA-contraction build"
fi
for spec in $DET_BUILDS; do
    cc=${spec%%:*}
    flags=$(echo "$spec" | cut -d: -f2 | tr ',' ' ')
    t=$(echo "$spec" | tr ':,=' '___')
    run=""
    [ "$cc" = "$I686" ] && run="qemu-i386 "
    job "determinism: vdag built by $cc $flags" ok \
        "$cc -std=c99 $flags -pthread -I. -o $D/vdag-$t $VDAG_SRC -lm
         $run$D/vdag-$t gen demo $D/scene-$t.xyz --levels 7 >/dev/null
         $run$D/vdag-$t build $D/scene-$t.xyz $D/scene-$t-1.vdag --threads 1 --color-error 0.03 >/dev/null
         $run$D/vdag-$t build $D/scene-$t.xyz $D/scene-$t-3.vdag --threads 3 --color-error 0.03 >/dev/null
         $run$D/vdag-$t build $D/scene-$t.xyz $D/scene-$t-e0.01.vdag --threads 1 --color-error 0.01 >/dev/null
         $run$D/vdag-$t build $D/scene-$t.xyz $D/scene-$t-e0.1.vdag --threads 1 --color-error 0.1 >/dev/null"
done

# The GPU traversal's C build under FMA contraction (clang and gcc, -mfma
# -ffp-contract=fast): the same float bits as the plain build.
if grep -q -w fma /proc/cpuinfo 2>/dev/null; then
    for cc in $CCS; do
        job "gpu header: $cc -O2 -mfma -ffp-contract=fast answers equal the plain build's" ok \
            "$cc -std=gnu99 -O2 -I. -o $D/answers-plain-$cc tests/platform_answers.c -pthread -lm
             $cc -std=gnu99 -O2 -mfma -ffp-contract=fast -I. -o $D/answers-fma-$cc tests/platform_answers.c -pthread -lm
             $D/answers-plain-$cc | grep 'gpu ray' >$D/answers-plain-$cc.txt
             $D/answers-fma-$cc | grep 'gpu ray' >$D/answers-fma-$cc.txt
             test \$(wc -l <$D/answers-plain-$cc.txt) -gt 10000
             cmp $D/answers-plain-$cc.txt $D/answers-fma-$cc.txt"
    done
fi

# -- Portability matrix: the portable unit tests and the platform answers on
# each foreign target. On Wine every portable test but the two slowest; under
# qemu (20-30 times slower) the format, query, codec and ray conventions
# tests, and on big-endian s390x the loader's mutation sweep too. The rays,
# queries and builds themselves are compared bit for bit through
# tests/platform_answers.c.
M=$out/matrix
mkdir -p "$M"
PORTABLE_SRC="tests/test_main.c tests/impl.c tests/test_core.c tests/test_voxcolor.c tests/test_format.c tests/test_raytrace.c tests/test_gpu.c tests/test_voxelize.c tests/test_no_voxcolor.c tests/test_lod_colors.c tests/test_edit.c"
PORTABLE="$C99 -O2 -DTEST_PORTABLE -I. -o"
SEL_QEMU="format/golden format/offsets format/header format/limits format/hostile format/version3 format/save
          format/build_allocation voxcolor/golden voxcolor/lossless voxcolor/handmade voxcolor/rejects
          voxcolor/wide voxcolor/empty voxcolor/morton2d voxcolor/error_offsets voxcolor/deterministic
          voxcolor/invalid voxcolor/cielab raytrace_conventions core/streaming core/color_sink
          core/bad_arguments core/build_limits voxelize/face_plane voxelize/bad_meshes gpu/transforms gpu/golden
          gpu/domain"
SEL_WINE="format/ voxcolor/ raytrace gpu/ voxelize/ core/mirrored core/determinism core/thread_pool core/streaming
          core/color_sink core/load_roundtrip core/bad_arguments core/allocation core/build_limits"
SEL_QEMU=$(echo $SEL_QEMU) # one line each in the job scripts
SEL_WINE=$(echo $SEL_WINE)
# The reference answers: x86-64, built here before the parallel phase.
if $cc1 $C99 -O2 -pthread -I. -o "$M/answers-native" tests/platform_answers.c -lm >"$M/native.log" 2>&1 &&
    "$M/answers-native" >"$M/answers-native.txt" 2>>"$M/native.log"; then
    :
else
    echo "FAIL matrix: the x86-64 reference answers (tests/platform_answers.c)" | tee /dev/stderr
    sed 's/^/    /' "$M/native.log" | head -n 20 >&2
    fail=$((fail + 1))
fi
# answers NAME RUN: compare a target's answers with the reference.
answers() {
    printf '%s\n' "$2 >$M/answers-$1.txt
          tr -d '\\r' <$M/answers-$1.txt >$M/answers-$1.lf
          test \$(wc -l <$M/answers-$1.lf) -gt 10000
          if ! cmp -s $M/answers-native.txt $M/answers-$1.lf; then
              echo \"\$(diff $M/answers-native.txt $M/answers-$1.lf | grep -c '^<') of \$(wc -l <$M/answers-native.txt) lines differ from x86-64's:\"
              diff $M/answers-native.txt $M/answers-$1.lf | head -n 20
              exit 1
          fi"
}
if [ -n "$I686" ]; then
    job "matrix i386 (x87 maths, qemu-i386): portable unit tests" ok \
        "$I686 -static $PORTABLE $M/test-i386 $PORTABLE_SRC -pthread -lm
         qemu-i386 $M/test-i386 $SEL_QEMU"
    job "matrix i386 (x87 maths, gnu99 excess precision, qemu-i386): answers equal x86-64's" ok \
        "$I686 -static -std=gnu99 $WARN -O2 -I. -o $M/answers-i386 tests/platform_answers.c -pthread -lm
         $(answers i386 "qemu-i386 $M/answers-i386")"
fi
if [ -n "$S390X" ]; then
    job "matrix s390x (big-endian, qemu-s390x): portable unit tests" ok \
        "$S390X -static $PORTABLE $M/test-s390x $PORTABLE_SRC -pthread -lm
         qemu-s390x $M/test-s390x $SEL_QEMU format/mutations"
    job "matrix s390x (big-endian, qemu-s390x): answers equal x86-64's" ok \
        "$S390X -static $C99 -O2 -I. -o $M/answers-s390x tests/platform_answers.c -pthread -lm
         $(answers s390x "qemu-s390x $M/answers-s390x")"
fi
if [ -n "$MINGW" ] && [ -n "$WINE" ]; then
    # One job: the first Wine program makes the prefix (kept in BUILD_DIR).
    job "matrix windows (MinGW-w64, Wine): portable unit tests, answers equal x86-64's" ok \
        "$MINGW $PORTABLE $M/test.exe $PORTABLE_SRC
         $MINGW $C99 -O2 -I. -o $M/answers.exe tests/platform_answers.c
         export WINEPREFIX=\$(cd $build && pwd)/wine-prefix WINEDEBUG=-all
         $WINE $M/test.exe $SEL_WINE
         $(answers windows "$WINE $M/answers.exe")"
elif [ -n "$MINGW" ]; then
    : # "wine" was reported unavailable above
fi

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
    # (32-bit x86 code gets the compiler's hidden __x86.get_pc_thunk helpers)
    [ -n "$I686" ] && check_symbols "$I686 both" "$O/i386-impl_both.o" \
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

echo "check-all took $(($(date +%s) - start)) s; the slowest jobs:" >&2
for s in "$jobs"/*.sh; do echo "$(cat "${s%.sh}.time" 2>/dev/null || echo 0) s $(cat "${s%.sh}.name")"; done |
    sort -rn | head -n 8 | sed 's/^/    /' >&2
if [ "$skipped" -gt 0 ]; then echo "$pass passed, $fail failed, $skipped skipped"
else echo "$pass passed, $fail failed"; fi
[ "$fail" = 0 ]
