# lutbake — the two commands of the README, and a few more.
#   make luts      create the venv if missing, install, bake every config in configs/ and every engine
#                  preset (PRESETS) into outputs/
#   make test      create the venv if missing, install, run the test suite
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= outputs
CONFIGS := $(wildcard configs/*.toml)
PRESETS ?= filament filament-corrected gltf blender-eevee unreal
SOURCES := $(shell find lutbake -name '*.py' -o -name '*.toml' 2>/dev/null)
WORKERS ?=

.PHONY: luts test validate bench clean venv help

help:
	@echo "make luts | test | validate | clean"

venv: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[test,plot]'
	touch $(STAMP)

luts: $(STAMP)
	$(BIN)/lutbake bake $(CONFIGS) $(foreach p,$(PRESETS),--preset $(p)) --out-dir $(OUT) $(if $(WORKERS),--workers $(WORKERS))

test: $(STAMP)
	@$(BIN)/python -c "import moderngl; moderngl.create_standalone_context(backend='egl').release()" 2>/dev/null \
		|| echo "note: no EGL OpenGL here; the GL consumer test will skip (Debian: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri)"
	$(BIN)/python -m pytest -q

validate: $(STAMP)
	$(BIN)/lutbake validate

clean:
	rm -rf $(OUT) .pytest_cache
