# lutbake — the two commands of the README, and a few more.
#   make luts      create the venv if missing, install, bake every config in configs/ and every engine
#                  preset (PRESETS) into outputs/
#   make test      create the venv if missing, install, run ruff (check + format --check), then the test suite
#   make demo      bake the presets the engine pages load (threejs, babylon, ltc-threejs, ltc-babylon; filament and
#                  filament-corrected at Filament's web 64² into outputs/filament-web/) into outputs/ (if not up to
#                  date) and serve the pages (web/) on 127.0.0.1:8049: each engine's shipped table beside lutbake's,
#                  and their difference
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= outputs
CONFIGS := $(wildcard configs/*.toml)
PRESETS ?= filament filament-corrected gltf gltf-charlie gltf-sheen-e blender-eevee unreal blender-eevee-btdf blender-eevee-bsdf \
           openpbr turquin ltc-ggx ltc-threejs ltc-eevee ltc-hdrp \
           unity-hdrp unity-hdrp-charlie godot bevy threejs babylon babylon-openpbr babylon-fuzz
WORKERS ?=
FORCE   ?=
TEST_WORKERS ?= 2  # pytest-xdist processes for make test; a module's tests stay on one (its fixtures are built once)

.PHONY: lint luts test validate bench clean venv help figures demo bench-diffuse bench-ltc bench-cluster bench-luts

help:
	@echo "make luts | test | demo | validate | figures | bench | clean"

venv: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test,plot]'
	touch $(STAMP)

# `make luts` always asks lutbake, which rebakes exactly the tables whose output is missing or whose content
# hash (config, lutbake version, kernel sources) differs from the file's -- also a table another command
# overwrote with other settings -- and prints "skipped ... (up to date)" for the others (about a second).
# `make luts FORCE=1` rebakes every table. Tables that hold the same values (one LTC fit for three engines) are
# computed once; $(OUT)/.cache keeps each computation's values, so a deleted output or a layout-only change
# (format, dtype of an ltc or dielectric table) is written again without computing.
luts: $(STAMP)
	$(BIN)/lutbake bake $(CONFIGS) $(foreach p,$(PRESETS),--preset $(p)) --out-dir $(OUT) --report $(OUT)/report.json \
		--cache $(OUT)/.cache \
		$(if $(WORKERS),--workers $(WORKERS)) $(if $(FORCE),--force)

# every figure lutbake draws, under $(OUT)/figures (the PNGs tracked in docs/figures are not rewritten)
figures: $(STAMP)
	$(BIN)/lutbake plot --out-dir $(OUT)/figures
	$(BIN)/python docs/plot_fresnel.py $(OUT)/figures

lint: $(STAMP)
	$(BIN)/ruff check lutbake tests benchmarks
	$(BIN)/ruff format --check lutbake tests benchmarks

test: $(STAMP) lint
	@$(BIN)/python -c "import moderngl; moderngl.create_standalone_context(backend='egl').release()" 2>/dev/null \
		|| echo "note: no EGL OpenGL here; the GL consumer test will skip (Debian: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri)"
	@command -v chromium >/dev/null && test -d web/node_modules \
		|| echo "note: no chromium or web/node_modules; the in-engine tests will skip (apt-get install chromium; npm ci --prefix web)"
	$(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadscope --no-loadscope-reorder

# the engines' npm packages (web/package-lock.json) on first use; then tests/web_harness.py serves the pages
demo: $(STAMP)
	test -d web/node_modules || npm ci --prefix web
	$(BIN)/lutbake bake --preset threejs --preset babylon --preset ltc-threejs --preset ltc-babylon --out-dir $(OUT)
	$(BIN)/lutbake bake --preset filament --preset filament-corrected --set 'size=[64,64]' --set row_order=lo_first \
		--out-dir $(OUT)/filament-web
	$(BIN)/python tests/web_harness.py --luts $(OUT)

# diffuse kinds against converged references (accuracy and wall time): outputs/bench/diffuse.json
bench-diffuse: $(STAMP)
	$(BIN)/python benchmarks/bench_diffuse.py

validate: $(STAMP)
	$(BIN)/lutbake validate

clean:
	rm -rf $(OUT) .pytest_cache

# every kind against converged references, C and numpy baselines: outputs/bench/report.json + accuracy_vs_time.png;
# then the Dask executor (local:2) against the thread executor on the make-luts batch, and a scaling projection:
# outputs/bench/cluster.json (docs/cluster.md); first, `make luts` into an empty folder timed (wall, CPU, top ten
# tables): outputs/bench/luts.json; every table that interpolates between texels against itself integrated (CPU ratio,
# honesty): outputs/bench/interpolation.json; the prefiltered environment (a 2048 x 1024 CC0 map to a 256^2 cube and
# its SH) against the importance-sampled prefilter: outputs/bench/environment.json (needs Debian's blender-data); sums of
# anisotropic GGX LTCs per texel (docs/ltc_aniso.md): outputs/bench/ltc_aniso_lobes.json
bench: $(STAMP)
	$(BIN)/python benchmarks/bench_luts.py
	$(BIN)/python benchmarks/bench.py
	$(BIN)/python benchmarks/bench_interpolation.py
	$(BIN)/python benchmarks/bench_dielectric.py
	$(BIN)/python benchmarks/bench_ltc.py
	$(BIN)/python benchmarks/bench_ltc.py --lobes eon,gotanda
	$(BIN)/python benchmarks/bench_ltc_aniso.py
	$(BIN)/python benchmarks/ltc_aniso_lobes.py
	$(BIN)/python benchmarks/bench_cluster.py
	$(BIN)/python benchmarks/bench_environment.py
	$(BIN)/python benchmarks/write_benchmarks_md.py

# LTC fits (kind ltc): fit time per lobe at 64^2, the straight-port baseline, area-light errors (L3 and shaded fits):
# outputs/bench/ltc.json (ggx, beckmann, charlie, lambert) and ltc_eon_gotanda.json
bench-ltc: $(STAMP)
	$(BIN)/python benchmarks/bench_ltc.py
	$(BIN)/python benchmarks/bench_ltc.py --lobes eon,gotanda

bench-luts: $(STAMP)
	$(BIN)/python benchmarks/bench_luts.py

bench-cluster: $(STAMP)
	$(BIN)/python benchmarks/bench_cluster.py
