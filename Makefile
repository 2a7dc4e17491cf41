# The two commands a new user needs: `make run` and `make test`. Both install what is missing.
PRESET ?= release
BUILD_DIR := build/$(PRESET)
SCENE ?= scenes/steam.json
OUT ?= out/steam
JOBS ?= $(shell nproc)

.PHONY: deps configure build app run run-mpi test sanitize bench clean

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The program alone: a first run should not wait for the test suite and benchmarks to compile.
app: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target msim_app

run: app
	$(BUILD_DIR)/bin/msim run $(SCENE) --out $(OUT)

# A 3D smoke scene split among NP processes (docs/parallel.md). OpenMPI refuses root without the
# two variables (containers); --oversubscribe lets NP exceed the cores.
NP ?= 2
MPI_SCENE ?= scenes/plume_3d.json
MPI_OUT ?= out/plume_3d_mpi
run-mpi: app
	OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -np $(NP) --oversubscribe --bind-to none \
		$(BUILD_DIR)/bin/msim run $(MPI_SCENE) --out $(MPI_OUT)

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

# The whole suite under AddressSanitizer (leak detection on) and UBSan, in the asan preset's
# instrumented -O1 build; long tests run at a smaller size of the same check there. Any sanitizer
# report fails its test.
SANITIZER_ENV := ASAN_OPTIONS=detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1:check_initialization_order=1 \
	UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
sanitize: deps
	@cmake --preset asan >/dev/null
	@cmake --build build/asan -j $(JOBS)
	cd build/asan && $(SANITIZER_ENV) ctest --output-on-failure -j $(JOBS)

bench: build
	@for b in $(BUILD_DIR)/bench/*_bench; do echo "== $$b"; $$b; done

clean:
	rm -rf build
