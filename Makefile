# coapt — the two commands of the README, and the rest of the workflow.
#   make demo     install what is missing, build (Release), run the demo case
#   make test     install what is missing, build, run the whole test suite (CTest)
#   make verify   long verification runs; writes docs/verification.md and its plots
#   make bench    the benchmarks recorded in bench/RESULTS.md
#   make sanitize build with AddressSanitizer + UBSan and run the unit tests
#   make format   clang-format every source file (format-check: verify only)

BUILD ?= build
JOBS ?= $(shell nproc)
# -Werror in CI (CI=true), warnings stay warnings for local builds unless WERROR=ON.
WERROR ?= $(if $(CI),ON,OFF)
PYTHON := /usr/bin/python3
MPIRUN := mpirun --oversubscribe --bind-to none
DEMO_CASE ?= cases/dfg/2d1.yaml
DEMO_SET ?= mesh.level=1
DEMO_RANKS ?= 2

export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMP_NUM_THREADS := 1

SOURCES := $(shell find src apps bench tests -name '*.cpp' -o -name '*.hpp' 2>/dev/null)

.PHONY: deps configure build demo test verify bench sanitize format format-check clean

deps:
	@bash scripts/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DCOAPT_WERROR=$(WERROR)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	$(MPIRUN) -np $(DEMO_RANKS) $(BUILD)/coapt run $(DEMO_CASE) --output out/demo --set $(DEMO_SET)
	@echo "demo: flow around a cylinder (Schafer-Turek 2D-1) in out/demo; open out/demo/solution.pvd in ParaView"

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 1500

verify: build
	$(PYTHON) tools/verify_fem.py --coapt $(BUILD)/coapt --levels 5 --report docs/verification.md

bench: build
	$(PYTHON) tools/run_benchmarks.py --bench $(BUILD)/coapt-bench

sanitize: deps
	cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=Debug -DCOAPT_SANITIZE=ON -DCOAPT_BUILD_BENCH=OFF
	cmake --build build-sanitize -j $(JOBS)
	cd build-sanitize && ASAN_OPTIONS=detect_leaks=0 ctest --output-on-failure -L unit

format:
	clang-format -i $(SOURCES)

format-check:
	clang-format --dry-run -Werror $(SOURCES)

clean:
	rm -rf $(BUILD) build-sanitize out
