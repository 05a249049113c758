# The two commands of the README: `make demo` and `make test` (`make check`: the fast tier).
# They set everything up first.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
EXTRAS ?= all
MINIMAL_VENV ?= .venv-minimal

.PHONY: demo test check setup lint minimal bench clean web
WEB := facelib/export/web

demo: $(VENV)/.installed
	$(BIN)/facelib render examples/hello/hello.fdl -o out/hello.mp4 --fap out/hello.fap

test: lint minimal $(WEB)/dist/player.js
	$(BIN)/python -m pytest

# The fast tier, for every edit: no rendering, speech recognition, browser, cluster or
# slow test (markers in pyproject.toml); under a minute on an idle 2-core machine.
# `make test` (CI) runs everything.
FAST := not slow and not render and not speech and not browser and not cluster
check: $(VENV)/.installed
	$(BIN)/python -m pytest -q -m "$(FAST)"

setup: $(VENV)/.installed $(WEB)/dist/player.js

# The web player: npm packages from the lockfile (three.js, esbuild, puppeteer-core and
# gltf-validator for the tests), then three.js and the player bundled into one file.
web: $(WEB)/dist/player.js

$(WEB)/node_modules/.installed: $(WEB)/package.json $(WEB)/package-lock.json
	cd $(WEB) && npm ci --no-audit --no-fund
	touch $@

$(WEB)/dist/player.js: $(WEB)/node_modules/.installed $(wildcard $(WEB)/src/*.js)
	cd $(WEB) && npm run --silent build

# Debian packages first (tools/debian-deps installs them as root, otherwise prints the
# apt-get command), then a virtualenv with the package and its extras.
$(VENV)/.installed: pyproject.toml tools/debian-packages.txt tools/debian-deps
	tools/debian-deps
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[$(EXTRAS)]"
	touch $@

# ruff (style, complexity) and mypy (types; settings in pyproject.toml's [tool.mypy]).
lint: $(VENV)/.installed
	$(BIN)/ruff check .
	$(BIN)/mypy

# The core pipeline (storyboard -> .fap) in a virtualenv with none of the extras. The
# venv is kept (rebuilt when pyproject.toml changes; facelib is installed editable), so a
# rerun costs seconds.
minimal: $(MINIMAL_VENV)/.installed
	$(MINIMAL_VENV)/bin/python tools/minimal_install_check.py

$(MINIMAL_VENV)/.installed: pyproject.toml
	rm -rf $(MINIMAL_VENV)
	$(PYTHON) -m venv $(MINIMAL_VENV)
	$(MINIMAL_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(MINIMAL_VENV)/bin/python -m pip install --quiet -e .
	touch $@

# Figures, not pass/fail: each benchmark prints what it measured.
bench: $(VENV)/.installed
	for b in engine_deform engine_deformers engine_setup render_speed gaze_simulate fdl_sandbox \
		visemes_align_accuracy export_speed speech_long cli_timings dataset_throughput tracking \
		import_time curves_linear; do \
		PYTHONPATH=. $(BIN)/python benchmarks/$$b.py || exit 1; done

clean:
	rm -rf $(VENV) $(MINIMAL_VENV) build *.egg-info .pytest_cache .ruff_cache .mypy_cache \
		$(WEB)/node_modules $(WEB)/dist
