# voxdag: examples, tests, demo and benchmarks.
#   make          build the vdag tool (build/vdag; installs libstb-dev when missing)
#   make test     install missing test packages, run every test
#   make test-full the same with exhaustive mutation sweeps (long)
#   make check-all build matrix, link/symbol checks, determinism (in make test)
#   make test-real the importers' fixes on real third-party files (fetched; not in make test)
#   make demo     build, colour-compress, save and render the default scene
#   make bench    regenerate BENCHMARKS.md

CC      ?= cc
CXX     ?= c++
BUILD   := build
WARN    := -Wall -Wextra -Wpedantic -Wshadow -Wundef
CSTD    := -std=c99
OPT     ?= -O2
THREADS := -pthread
SAN     := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
HEADERS := voxdag.h voxcolor.h voxdag_gpu.h

VDAG_SRC := examples/vdag.c examples/import.c examples/render.c examples/image_stb.c examples/check_colors.c examples/gpu_vulkan.c examples/gpu.c
TEST_SRC := tests/test_main.c tests/impl.c tests/test_core.c tests/test_voxcolor.c tests/test_import.c tests/test_voxelize.c tests/test_raytrace.c tests/test_gpu.c tests/test_format.c tests/test_import_scene.c tests/test_image.c tests/test_api.c tests/test_no_voxcolor.c tests/test_lod_colors.c tests/test_edit.c tests/test_check_colors.c examples/import.c examples/image_stb.c examples/check_colors.c

# Texture decoding (examples/image_stb.c) uses stb_image.h from Debian's
# libstb-dev, a header compiled into the tool: nothing at run time. `make`
# installs the package when the header is missing (examples/deps.sh).
STB_IMAGE := /usr/include/stb/stb_image.h
# The tests keep OpenImageIO as the reference decoder (tests/oiio_ref.cpp,
# compiled with $(CXX); the test program links with the C++ driver).
OIIO_CFLAGS = $(shell pkg-config --cflags OpenImageIO)
OIIO_LIBS   = $(shell pkg-config --libs OpenImageIO)

# The GPU path (examples/gpu_vulkan.c) runs compute shaders on Vulkan. It is
# built when the Vulkan headers and glslangValidator are here: the loader is
# opened at run time, so the tool still needs nothing installed to run. The
# first `make` in a build directory installs libvulkan-dev and glslang-tools
# when missing (examples/deps.sh; a failure leaves the GPU path out) and
# records what it found in $(BUILD)/vulkan.mk (delete it to look again).
# VULKAN=1 or VULKAN= on the command line forces the choice.
VULKAN_H := /usr/include/vulkan/vulkan.h
ifeq ($(origin VULKAN),undefined)
ifneq ($(MAKECMDGOALS),clean)
-include $(BUILD)/vulkan.mk
endif
VULKAN = $(VULKAN_FOUND)
endif
$(BUILD)/vulkan.mk:
	@mkdir -p $(@D)
	@sh examples/deps.sh || :
	@if test -f $(VULKAN_H) && command -v glslangValidator >/dev/null; then \
	    echo 'VULKAN_FOUND := 1' >$@; else echo 'VULKAN_FOUND :=' >$@; fi
# Rewritten only when the choice changes, so that objects built with the
# other choice are rebuilt.
$(BUILD)/vulkan.flag: FORCE
	@mkdir -p $(@D)
	@echo '$(VULKAN)' | cmp -s - $@ || echo '$(VULKAN)' >$@
.PHONY: FORCE
VULKAN_CFLAGS = $(if $(VULKAN),-DVDAG_HAVE_VULKAN)
VULKAN_LIBS   = $(if $(VULKAN),-ldl)

# Compute shaders become SPIR-V for Vulkan 1.1, embedded as C arrays:
# NAME.comp (GLSL) gives $(BUILD)/shaders/NAME_glsl.h with the array NAME_glsl,
# NAME.hlsl (HLSL, entry point main) gives NAME_hlsl.h with NAME_hlsl; the
# .spv beside each is what tests/spirv_check.sh validates. Shaders live in
# examples/shaders (the tool's) and tests/shaders (the tests'); a program
# that includes NAME_glsl.h lists it as a prerequisite and adds
# -I$(BUILD)/shaders.
GLSLANG       := glslangValidator -V --target-env vulkan1.1 -I.
SHADER_DEPS   := voxdag_gpu.h $(wildcard examples/shaders/*.h examples/shaders/*.glsl examples/shaders/*.hlsli)
define shader_rules
$$(BUILD)/shaders/%_glsl.h $$(BUILD)/shaders/%_glsl.spv: $(1)/%.comp $$(SHADER_DEPS)
	@mkdir -p $$(@D)
	$$(GLSLANG) --vn $$*_glsl -o $$(BUILD)/shaders/$$*_glsl.h $$<
	$$(GLSLANG) -o $$(BUILD)/shaders/$$*_glsl.spv $$< >/dev/null
$$(BUILD)/shaders/%_hlsl.h $$(BUILD)/shaders/%_hlsl.spv: $(1)/%.hlsl $$(SHADER_DEPS)
	@mkdir -p $$(@D)
	$$(GLSLANG) -D -e main -S comp --vn $$*_hlsl -o $$(BUILD)/shaders/$$*_hlsl.h $$<
	$$(GLSLANG) -D -e main -S comp -o $$(BUILD)/shaders/$$*_hlsl.spv $$< >/dev/null
endef
# README.md's shader code (the ```glsl and ```hlsl blocks of "Rendering on
# the GPU") compiled as fragment shaders, checked by tests/spirv_check.sh.
$(BUILD)/shaders/readme_glsl_frag.spv: README.md voxdag_gpu.h
	@mkdir -p $(@D)
	@awk '/^```glsl$$/ { c = 1; next } /^```/ { c = 0 } c' README.md >$(BUILD)/shaders/readme.frag
	@test -s $(BUILD)/shaders/readme.frag
	@printf '%s\n' 'layout(location = 0) out vec4 colour;' \
	    'void main() { colour = vec4(shade(vec3(gl_FragCoord.xy, -9.0), vec3(0.1, 0.2, 1.0)), 1.0); }' >>$(BUILD)/shaders/readme.frag
	$(GLSLANG) -S frag -o $@ $(BUILD)/shaders/readme.frag >/dev/null
$(BUILD)/shaders/readme_hlsl_frag.spv: README.md voxdag_gpu.h
	@mkdir -p $(@D)
	@awk '/^```hlsl$$/ { c = 1; next } /^```/ { c = 0 } c' README.md >$(BUILD)/shaders/readme_frag.hlsl
	@test -s $(BUILD)/shaders/readme_frag.hlsl
	@printf '%s\n' 'float4 main(float4 pos : SV_Position) : SV_Target {' \
	    '    voxdag_gpu_file f = voxdag_gpu_open(0u, 0u);' \
	    '    voxdag_gpu_ray r; r.ox = pos.x; r.oy = pos.y; r.oz = -9.0; r.dx = 0.1; r.dy = 0.2; r.dz = 1.0;' \
	    '    r.t_min = 0.0; r.t_max = 0.0; r.lod = 0.0; r.flags = VOXDAG_GPU_WANT_INDEX;' \
	    '    voxdag_gpu_hit h = voxdag_gpu_raycast(0u, f, r);' \
	    '    uint rgb = h.hit != 0u ? voxdag_gpu_color(0u, f, h.index_lo, h.index_hi) : 0u;' \
	    '    return float4(rgb & 255u, rgb >> 8 & 255u, rgb >> 16 & 255u, 255.0) / 255.0;' '}' >>$(BUILD)/shaders/readme_frag.hlsl
	$(GLSLANG) -D -e main -S frag -o $@ $(BUILD)/shaders/readme_frag.hlsl >/dev/null
README_SHADERS := $(BUILD)/shaders/readme_glsl_frag.spv $(BUILD)/shaders/readme_hlsl_frag.spv
$(eval $(call shader_rules,examples/shaders))
$(eval $(call shader_rules,tests/shaders))

.PHONY: all test deps demo bench clean

all: $(BUILD)/vdag

$(BUILD):
	@mkdir -p $(BUILD)

$(STB_IMAGE):
	@sh examples/deps.sh

# Objects: $(BUILD)/opt for the tool, $(BUILD)/san (sanitizers) for tests.
$(BUILD)/opt/%.o: %.c $(wildcard examples/*.h) $(HEADERS)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) $(OPT) $(THREADS) -I. -c -o $@ $<
$(BUILD)/san/%.o: %.c tests/test.h tests/edit_model.h tests/rscene.h tests/gpu_oracle.h tests/count_alloc.h tests/import_test.h tests/oiio_ref.h $(wildcard examples/*.h examples/shaders/*.h) $(HEADERS)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) -O2 -g $(SAN) $(THREADS) -I. -c -o $@ $<
$(BUILD)/opt/examples/image_stb.o $(BUILD)/san/examples/image_stb.o: $(STB_IMAGE)
$(BUILD)/san/oiio_ref.o: tests/oiio_ref.cpp tests/oiio_ref.h
	@mkdir -p $(@D)
	$(CXX) -std=c++14 $(OIIO_CFLAGS) $(WARN) -O1 -g $(SAN) -c -o $@ tests/oiio_ref.cpp

# gpu_vulkan.c with or without the GPU path (see VULKAN above).
$(BUILD)/opt/examples/gpu_vulkan.o: examples/gpu_vulkan.c examples/gpu_vulkan.h $(BUILD)/vulkan.flag
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) $(OPT) $(VULKAN_CFLAGS) -I. -c -o $@ $<

# gpu.c embeds the kernel's SPIR-V, compiled from examples/shaders.
VDAG_KERNEL := $(BUILD)/shaders/vdag_kernel_glsl.h $(BUILD)/shaders/vdag_kernel_hlsl.h
$(BUILD)/opt/examples/gpu.o: examples/gpu.c examples/gpu.h examples/gpu_vulkan.h examples/shaders/vdag_kernel.h \
                             $(HEADERS) $(BUILD)/vulkan.flag $(if $(VULKAN),$(VDAG_KERNEL))
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) $(OPT) $(THREADS) $(VULKAN_CFLAGS) -I. -I$(BUILD)/shaders -c -o $@ $<

# import.c includes import_scene.c (.spm and .ac share its helpers).
$(BUILD)/opt/examples/import.o $(BUILD)/san/examples/import.o: examples/import_scene.c

$(BUILD)/vdag: $(VDAG_SRC:%.c=$(BUILD)/opt/%.o)
	$(CC) $(OPT) -o $@ $^ $(THREADS) -lm $(VULKAN_LIBS)

# Tests run with AddressSanitizer and UndefinedBehaviorSanitizer.
$(BUILD)/test: $(TEST_SRC:%.c=$(BUILD)/san/%.o) $(BUILD)/san/oiio_ref.o
	$(CXX) $(SAN) -o $@ $^ $(OIIO_LIBS) $(THREADS) -lm

# voxcolor's option and argument checks in a release build (-DNDEBUG),
# sanitized: they must not be asserts.
$(BUILD)/test_voxcolor_ndebug: tests/test_voxcolor_ndebug.c tests/tally.h voxcolor.h | $(BUILD)
	$(CC) $(CSTD) $(WARN) -O1 -g -DNDEBUG $(SAN) $(THREADS) -I. -o $@ $< -lm
# The same for voxdag.h: its options and NULL arguments in a release build.
$(BUILD)/test_voxdag_ndebug: tests/test_voxdag_ndebug.c tests/tally.h voxdag.h | $(BUILD)
	$(CC) $(CSTD) $(WARN) -O1 -g -DNDEBUG $(SAN) $(THREADS) -I. -o $@ $< -lm

# The Vulkan runner on the machine's device (lavapipe without a GPU),
# sanitized, with the smoke shaders in GLSL and HLSL (tests/shaders).
VK_SMOKE := $(BUILD)/shaders/vk_smoke_glsl.h $(BUILD)/shaders/vk_smoke_hlsl.h
$(BUILD)/test_vk: tests/test_vk.c tests/tally.h examples/gpu_vulkan.c examples/gpu_vulkan.h $(BUILD)/vulkan.flag \
                  $(if $(VULKAN),$(VK_SMOKE)) | $(BUILD)
	$(CC) $(CSTD) $(WARN) -O1 -g $(SAN) $(VULKAN_CFLAGS) -I. -I$(BUILD)/shaders -o $@ tests/test_vk.c \
	    examples/gpu_vulkan.c $(VULKAN_LIBS)

# The GPU kernel on Vulkan (GLSL and HLSL builds) against its C build and
# the library, sanitized.
$(BUILD)/test_gpu_vk: tests/test_gpu_vk.c tests/gpu_oracle.h tests/rscene.h tests/golden.h tests/impl.c examples/gpu.c \
                      examples/gpu.h examples/gpu_vulkan.c examples/gpu_vulkan.h examples/shaders/vdag_kernel.h $(HEADERS) \
                      $(BUILD)/vulkan.flag $(if $(VULKAN),$(VDAG_KERNEL)) | $(BUILD)
	$(CC) $(CSTD) $(WARN) -O2 -g $(SAN) $(THREADS) $(VULKAN_CFLAGS) -I. -Itests -I$(BUILD)/shaders -o $@ tests/test_gpu_vk.c \
	    tests/impl.c examples/gpu.c examples/gpu_vulkan.c -lm $(VULKAN_LIBS)

# Fuzz targets, one per entry point that takes bytes (tests/fuzz_NAME.c):
#   import     the scene importers (the first byte picks the format)
#   voxcolor   colour streams decoded, and colours encoded and decoded
#   load       .vdag files loaded, and queries on what loaded
#   roundtrip  scenes built, saved and loaded, every query against an oracle
#   edit       random edits on random scenes against a brute-force model
# `make fuzz-NAME` builds one with libFuzzer, ASan and UBSan (clang; any
# finding stops the run and is saved in $(BUILD)) and fuzzes it for
# FUZZ_SECONDS from the committed corpus tests/data/fuzz/NAME, with
# tests/data/fuzz/NAME.dict when there is one. Built without libFuzzer,
# $(BUILD)/fuzz_NAME replays files with the same entry point
# (tests/fuzz_replay.h); `make test` replays and sweeps every corpus.
FUZZ_NAMES   := import voxcolor load roundtrip edit
FUZZ_SECONDS ?= 120
FUZZ_DEPS    := tests/fuzz_replay.h tests/fuzz_require.h tests/count_alloc.h tests/golden.h tests/edit_model.h $(HEADERS) \
                examples/import.c examples/import_scene.c examples/import.h examples/image.h
FUZZ_EXTRA_import := examples/import.c examples/image_none.c -DVDAG_IMPORT_REALLOC=fuzz_import_realloc
FUZZ_FLAGS   = $(CSTD) $(WARN) -g $(THREADS) -I. tests/fuzz_$*.c $(FUZZ_EXTRA_$*) -lm

$(BUILD)/fuzz_%: tests/fuzz_%.c $(FUZZ_DEPS) | $(BUILD)
	$(CC) -O2 $(SAN) -o $@ $(FUZZ_FLAGS)

.PHONY: $(FUZZ_NAMES:%=fuzz-%)
$(FUZZ_NAMES:%=fuzz-%): fuzz-%: | $(BUILD)
	clang -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -DFUZZ_LIBFUZZER \
	    -o $(BUILD)/fuzz_$*_libfuzzer $(FUZZ_FLAGS)
	@mkdir -p $(BUILD)/fuzz_$*_corpus
	$(BUILD)/fuzz_$*_libfuzzer -max_total_time=$(FUZZ_SECONDS) \
	    $(if $(wildcard tests/data/fuzz/$*.dict),-dict=tests/data/fuzz/$*.dict) \
	    -artifact_prefix=$(BUILD)/ $(BUILD)/fuzz_$*_corpus tests/data/fuzz/$*

# The main job on the built-in scene: generate, build, compress the colours,
# save, validate, render.
demo: $(BUILD)/vdag
	$(BUILD)/vdag gen demo $(BUILD)/demo.xyz --levels 8
	$(BUILD)/vdag build $(BUILD)/demo.xyz $(BUILD)/demo.vdag --color-error 0.02
	$(BUILD)/vdag validate $(BUILD)/demo.vdag
	$(BUILD)/vdag info $(BUILD)/demo.vdag
	$(BUILD)/vdag render $(BUILD)/demo.vdag $(BUILD)/demo.png --size 800x500 \
	    --eye 420 -160 300 --target 128 128 60 --fov 40 --shadows
	@echo "demo: the picture is $(BUILD)/demo.png"

deps:
	@sh tests/deps.sh

# Build matrix (gcc/clang, C99/C++11, -O0/-O2, NDEBUG, configuration macros,
# -m32), link and exported-symbol checks, the README's code and determinism
# across compilers; `make test` runs it through tests/run.sh.
.PHONY: check-all
check-all:
	@sh tests/check_all.sh $(BUILD)

# The importers' triangles, printed for tests/third_party.sh (sanitized).
# The editing example (README, Editing), run by tests/cli.sh.
$(BUILD)/edit_demo: examples/edit_demo.c $(HEADERS) | $(BUILD)
	$(CC) $(CSTD) $(WARN) -O2 -I. -o $@ examples/edit_demo.c $(THREADS) -lm

$(BUILD)/import_dump: tests/import_dump.c examples/import.c examples/import_scene.c examples/image_none.c examples/import.h examples/image.h | $(BUILD)
	$(CC) $(CSTD) $(WARN) -O1 -g $(SAN) -I. -o $@ tests/import_dump.c examples/import.c examples/image_none.c -lm

# Each fix of the importers and the tool checked on the real third-party
# files it was found on (tests/real.sh): Debian and npm packages fetched once
# into $(BUILD)/cache (about 1 GB with SuperTuxKart's data; packages that
# bench/fetch.sh unpacked into bench/data/x are used from there). Not part
# of `make test`.
.PHONY: test-real
test-real: $(BUILD)/vdag $(BUILD)/import_dump
	@sh tests/real.sh $(BUILD)

TEST_PROGRAMS := $(BUILD)/test $(BUILD)/test_voxcolor_ndebug $(BUILD)/test_voxdag_ndebug $(BUILD)/vdag $(BUILD)/fuzz_import $(BUILD)/fuzz_voxcolor $(BUILD)/fuzz_load $(BUILD)/fuzz_roundtrip $(BUILD)/fuzz_edit $(BUILD)/import_dump $(BUILD)/edit_demo $(BUILD)/test_vk $(BUILD)/test_gpu_vk \
                 $(if $(VULKAN),$(VK_SMOKE:.h=.spv) $(VDAG_KERNEL:.h=.spv) $(README_SHADERS))
# The test programs build on every CPU (a sub-make with -j), after deps.
JOBS := $(shell nproc 2>/dev/null || echo 2)
.PHONY: test-programs
test-programs: deps
	@$(MAKE) --no-print-directory -j$(JOBS) $(TEST_PROGRAMS)

test: test-programs
	@sh tests/run.sh $(BUILD)

# The same with exhaustive sweeps: every byte of every golden file, colour
# stream, importer sample and fuzz seed patched to each of its 255 other
# values (about an hour of CPU).
.PHONY: test-full
test-full: test-programs
	@sh tests/run.sh $(BUILD) --full

clean:
	rm -rf $(BUILD)

# Benchmarks: `make bench` installs what it lacks (bench/deps.sh), fetches the
# scenes (bench/fetch.sh) and regenerates BENCHMARKS.md, its CSV files, plots
# and pictures (docs/bench/) with the full set (long); `make bench-quick` runs a
# smaller set (under 5 minutes). bench-build / bench-geometry print one table
# set each.
BENCH_CFLAGS := $(CSTD) $(WARN) -O2 -g $(THREADS) -I.
BENCH_SUBMAKE := $(MAKE)
BENCH_DEPS   := bench/scenes.h $(HEADERS) examples/import.c examples/import.h examples/image_none.c
.PHONY: bench-quick bench-build bench-geometry bench-data

$(BUILD)/bench/bench_build: bench/bench_build.c $(BUILD)/bench/v2.o $(BENCH_DEPS)
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -o $@ $< $(BUILD)/bench/v2.o examples/import.c examples/image_none.c -lm
# Format version 2 side by side: its voxdag.h from the last version-2 commit
# (git history; without it the size column reads 0 and the speed tables are left out).
VOXDAG_V2_COMMIT := 3013133
$(BUILD)/bench/v2/voxdag.h:
	@mkdir -p $(@D)
	@git show $(VOXDAG_V2_COMMIT):voxdag.h > $@ 2>/dev/null || rm -f $@
# bench/v2.c links it next to the current one (sizes, ray, lookup and build speeds).
$(BUILD)/bench/v2.o: bench/v2.c bench/v2.h $(BUILD)/bench/v2/voxdag.h
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) $(if $(wildcard $(BUILD)/bench/v2/voxdag.h),-I$(BUILD)/bench,-DBENCH_NO_V2) -c -o $@ bench/v2.c
$(BUILD)/bench/bench_geometry: bench/bench_geometry.c $(BUILD)/bench/v2.o $(BENCH_DEPS)
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -o $@ $< $(BUILD)/bench/v2.o examples/import.c examples/image_none.c -lm

bench-data:
	@sh bench/deps.sh
	@sh bench/fetch.sh bench/data >/dev/null

bench-build: bench-data $(BUILD)/bench/bench_build
	$(BUILD)/bench/bench_build bench/data $(BENCH_FLAGS)
bench-geometry: bench-data $(BUILD)/bench/bench_geometry
	$(BUILD)/bench/bench_geometry bench/data $(BENCH_FLAGS)

# bench-rays: primary-ray throughput next to NanoVDB (libnanovdb-dev headers,
# when installed: the peer is compiled with $(CXX), else voxdag alone) and
# Embree on the source triangles (libembree-dev, when installed).
NANOVDB = $(shell test -f /usr/include/nanovdb/NanoVDB.h && echo 1)
EMBREE  = $(shell test -f /usr/include/embree3/rtcore.h && echo 1)
$(BUILD)/bench/bench_rays: bench/bench_rays.c bench/bench_rays_nanovdb.cpp bench/bench_rays_peer.h $(BUILD)/bench/v2.o $(BENCH_DEPS)
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -c -o $(BUILD)/bench/import.o examples/import.c
	$(CC) $(BENCH_CFLAGS) -c -o $(BUILD)/bench/image_none.o examples/image_none.c
	$(CC) $(BENCH_CFLAGS) $(if $(NANOVDB),-DBENCH_NANOVDB) $(if $(EMBREE),-DBENCH_EMBREE) -c -o $(BUILD)/bench/bench_rays.o bench/bench_rays.c
	$(if $(NANOVDB),$(CXX) -std=c++17 -O2 -c -o $(BUILD)/bench/bench_rays_nanovdb.o bench/bench_rays_nanovdb.cpp)
	$(if $(NANOVDB),$(CXX),$(CC)) -o $@ $(BUILD)/bench/bench_rays.o $(if $(NANOVDB),$(BUILD)/bench/bench_rays_nanovdb.o) \
	    $(BUILD)/bench/v2.o $(BUILD)/bench/import.o $(BUILD)/bench/image_none.o $(if $(EMBREE),-lembree3) $(THREADS) -lm
.PHONY: bench-rays
bench-rays: bench-data $(BUILD)/bench/bench_rays
	$(BUILD)/bench/bench_rays bench/data $(BENCH_FLAGS)

$(BUILD)/bench/bench_edit: bench/bench_edit.c $(BENCH_DEPS)
	@mkdir -p $(@D)
	$(CC) $(BENCH_CFLAGS) -o $@ $< examples/import.c examples/image_none.c -lm

$(BUILD)/bench/ssim: bench/ssim.c
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) -O2 -o $@ $< -lm

BENCH_PROGRAMS := $(BUILD)/bench/bench_build $(BUILD)/bench/bench_geometry $(BUILD)/bench/bench_edit $(BUILD)/bench/ssim $(BUILD)/vdag
bench: bench-data $(BENCH_PROGRAMS)
	@MAKE="$(BENCH_SUBMAKE)" CC="$(CC)" sh bench/report.sh full $(BUILD)
bench-quick: bench-data $(BENCH_PROGRAMS)
	@MAKE="$(BENCH_SUBMAKE)" CC="$(CC)" sh bench/report.sh quick $(BUILD)

# bench-color: the colour codec against the reimplemented baselines on real
# textures and a photograph (bench/color_fetch.sh); prints markdown tables.
# BENCH_COLOR_FLAGS=--quick skips the slowest baseline setting. External image
# codecs (JPEG, PNG, pngquant, ASTC, BC1, BC7) run through bench/color_peers.sh.
.PHONY: bench-color
# The previous encoder (before the parallel one), from the history, for the
# size column of the threads-and-effort table (bench/color_previous.c).
VOXCOLOR_PREV := 301313399728d545c08461c409f6bab15fa4aa2c
$(BUILD)/bench/voxcolor_prev.h:
	@mkdir -p $(@D)
	@git show $(VOXCOLOR_PREV):voxcolor.h >$@ 2>/dev/null || : >$@
COLOR_PREV_FLAGS = $(if $(shell test -s $(BUILD)/bench/voxcolor_prev.h && echo 1),-I$(BUILD)/bench,-DBENCH_NO_PREVIOUS)
$(BUILD)/bench/bench_color: bench/bench_color.c bench/color_baselines.c bench/color_baselines.h \
                            bench/color_previous.c bench/color_previous.h voxcolor.h $(BUILD)/bench/voxcolor_prev.h
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(WARN) -O2 $(THREADS) -c -o $(BUILD)/bench/color_previous.o $(COLOR_PREV_FLAGS) bench/color_previous.c
	$(CC) $(CSTD) $(WARN) -O2 $(THREADS) -o $@ bench/bench_color.c bench/color_baselines.c $(BUILD)/bench/color_previous.o -lm
bench-color: $(BUILD)/bench/bench_color
	$(BUILD)/bench/bench_color $(BENCH_COLOR_FLAGS) --peers bench/color_peers.sh $$(sh bench/color_fetch.sh bench/data/color)
