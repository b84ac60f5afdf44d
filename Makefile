# voxdag: examples, tests, demo and benchmarks.
#   make          build the vdag tool (build/vdag)
#   make test     install missing test packages, run every test
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
HEADERS := voxdag.h voxcolor.h

VDAG_SRC := examples/vdag.c
TEST_SRC := tests/test_main.c tests/impl.c tests/test_core.c tests/test_voxcolor.c

.PHONY: all test deps demo bench clean

all: $(BUILD)/vdag

$(BUILD):
	@mkdir -p $(BUILD)

$(BUILD)/vdag: $(VDAG_SRC) $(wildcard examples/*.h) $(HEADERS) | $(BUILD)
	$(CC) $(CSTD) $(WARN) $(OPT) -I. -o $@ $(VDAG_SRC) $(THREADS) -lm

# Tests run with AddressSanitizer and UndefinedBehaviorSanitizer.
$(BUILD)/test: $(TEST_SRC) tests/test.h $(HEADERS) | $(BUILD)
	$(CC) $(CSTD) $(WARN) -O1 -g $(SAN) -I. -o $@ $(TEST_SRC) $(THREADS) -lm

deps:
	@sh tests/deps.sh

test: deps $(BUILD)/test $(BUILD)/vdag
	@sh tests/run.sh $(BUILD)

clean:
	rm -rf $(BUILD)
