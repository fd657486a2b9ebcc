# facetfit: the two commands of the README, and the maintenance targets.
#   make demo   install what is missing, build, fit and bake the built-in material set, run the accuracy report
#   make test   install what is missing, build, run every test (and the unit and stress tests under ASan+UBSan)

BUILD      ?= build/release
BPY_VENV   ?= build/bpy-venv
MITSUBA_VENV ?= build/mitsuba-venv
PY_VENV    ?= build/py-venv
ASAN_BUILD ?= build/asan
FUZZ_BUILD ?= build/fuzz
FUZZ_SECONDS ?= 600
JOBS       ?= $(shell nproc)
CMAKE_GEN  := -G Ninja

.PHONY: all deps configure build demo test asan fuzz-build fuzz osl-host mitsuba-host python osl-docs bench accuracy clean

all: build

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) $(CMAKE_GEN) -DCMAKE_BUILD_TYPE=Release -DFACETFIT_WERROR=ON \
	  -DFACETFIT_BPY_PYTHON=$(CURDIR)/$(BPY_VENV)/bin/python -DFACETFIT_MITSUBA_PYTHON=$(CURDIR)/$(MITSUBA_VENV)/bin/python \
	  -DFACETFIT_PY_PYTHON=$(CURDIR)/$(PY_VENV)/bin/python >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# The demo builds the command alone (and its plugin), not the tests and benchmarks.
demo: configure
	@cmake --build $(BUILD) -j $(JOBS) --target facetfit_cli
	$(BUILD)/bin/facetfit fit --builtin
	$(BUILD)/bin/facetfit bake builtin: -o out/luts
	@echo "LUTs: $(CURDIR)/out/luts (index: out/luts/index.json; inspect one with: $(BUILD)/bin/facetfit info out/luts/gold-ggx-0.15.exr)"
	$(BUILD)/bin/facetfit report -o out/report
	@echo "Report: $(CURDIR)/out/report/index.html"

# The unit and stress tests under ASan + UBSan. -O1 (ASan's advice) and line tables only (-g1): the reports
# still name file and line, and the build takes half the time of -O2 -g (docs/measured-decisions.md).
asan: deps
	@cmake -S . -B $(ASAN_BUILD) $(CMAKE_GEN) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
	  -DFACETFIT_SANITIZE=ON -DFACETFIT_BUILD_TOOLS=OFF -DFACETFIT_WERROR=ON >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS) --target facetfit_unit_tests facetfit_stress_tests

# libFuzzer harnesses of every reader (fuzz/), built by clang with ASan + UBSan. Without unity files: the one
# build where each source of the library compiles alone, so that none leans on a neighbour's includes.
fuzz-build: deps
	@cmake -S . -B $(FUZZ_BUILD) $(CMAKE_GEN) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DFACETFIT_UNITY_BUILD=OFF \
	  -DFACETFIT_SANITIZE=ON -DFACETFIT_FUZZ=ON -DFACETFIT_BUILD_TOOLS=OFF -DFACETFIT_OSL_TESTS=OFF -DFACETFIT_MITSUBA_TESTS=OFF >/dev/null
	@cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_all

# Runs each fuzz target for FUZZ_SECONDS (default 600); fails on any finding (docs/reliability.md).
fuzz: fuzz-build
	fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS)

# Blender's bpy wheel (Cycles with OSL) in a venv: the host of the OSL tests (label osl).
osl-host:
	@scripts/setup-bpy.sh $(BPY_VENV) >/dev/null

# Mitsuba 3's wheel in a venv: the reference evaluation of RGL files (label mitsuba).
mitsuba-host:
	@scripts/setup-mitsuba.sh $(MITSUBA_VENV) >/dev/null

# The Python module, built and installed by `pip install .` into a venv of the build (label python).
python: deps
	@scripts/setup-python.sh $(PY_VENV) >/dev/null

test: build asan fuzz-build osl-host mitsuba-host python
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)
	fuzz/run.sh $(FUZZ_BUILD) 20
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --output-on-failure -j $(JOBS) -L 'unit|stress'

# Regenerates the pictures and figures of docs/osl.md (the OSL sphere tests, in Cycles).
osl-docs: build osl-host
	rm -f docs/images/osl/figures.md
	FACETFIT_OSL_PICTURES=$(CURDIR)/docs/images/osl $(BUILD)/tests/facetfit_osl_tests --gtest_filter='OslSphere*'

# Regenerates docs/benchmarks.md (Google Benchmark, this machine).
bench: build
	scripts/bench.sh $(BUILD)

# Regenerates docs/accuracy.md: ground-truth fits, then the real RGL materials against Mitsuba 3's renders
# (facetfit's renderer, the production OSL material in Cycles, and each material's neural BRDF, the anchor).
accuracy: build osl-host python
	$(BUILD)/bench/facetfit_accuracy docs/accuracy.md ../shared/data/rgl
	scripts/real_accuracy.sh $(BUILD)/bin/facetfit docs/accuracy.md ../shared/data

clean:
	rm -rf build
