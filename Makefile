# The two commands a new user needs: `make run` and `make test`. Both install what is missing.
PRESET ?= release
BUILD_DIR := build/$(PRESET)
SCENE ?= scenes/steam.json
OUT ?= out/steam
JOBS ?= $(shell nproc)

.PHONY: deps configure build app run test bench clean

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

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

bench: build
	@for b in $(BUILD_DIR)/bench/*_bench; do echo "== $$b"; $$b; done

clean:
	rm -rf build
