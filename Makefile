# The two commands a newcomer needs: `make run` and `make test`.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin

.PHONY: run test test-all sanitize lint bench serve constraints clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

# Stamp files: reinstall when pyproject.toml, setup.py or the C search core change (the
# install compiles the extensions in avs_planner/cp in place).
NATIVE := setup.py avs_planner/cp/_native.c avs_planner/cp/_native_axioms.h avs_planner/cp/_fixpoint.c \
	avs_planner/cp/_ground.c

# The project's own modules as bytecode, compiled ahead: where the environment forbids writing
# it (PYTHONDONTWRITEBYTECODE=1, common in containers) Python would otherwise compile every
# module from source at each start: `avs plan` on corridor.pddl took 0.316 s against 0.238 s
# with bytecode (median of 7, docs/planner.md). Up-to-date files are skipped, so this is cheap.
BYTECODE := $(BIN)/python -m compileall -q -j 0 avs_planner conceptual_map sim api

# constraints.txt: the tested set of versions (`make constraints` refreshes it)
$(VENV)/.installed: pyproject.toml constraints.txt $(NATIVE) | $(BIN)/python
	$(BIN)/python -m pip install -q -c constraints.txt -e .
	touch $@

$(VENV)/.installed-dev: pyproject.toml constraints.txt $(NATIVE) | $(BIN)/python
	$(BIN)/python -m pip install -q -c constraints.txt -e '.[dev]'
	touch $@

$(VENV)/.installed-bench: pyproject.toml constraints.txt $(NATIVE) | $(BIN)/python
	$(BIN)/python -m pip install -q -c constraints.txt -e '.[dev,bench]'
	touch $@

## run: set up .venv and run the main job: one object-search episode in the built-in office
## world (Göbelbecker et al., Fig. 3a: start in the corridor, find the cereal box), outputs in runs/
## (with the viewer extra installed also a Rerun recording: `avs view runs/office-cerealbox`)
run: $(VENV)/.installed
	$(BYTECODE)
	$(BIN)/avs simulate --scenario a --seed 1 --out runs/office-cerealbox \
		$$($(BIN)/python -c 'import rerun' 2>/dev/null && echo --record)

## test: set up .venv with test extras and run the fast test suite
test: $(VENV)/.installed-dev
	$(BYTECODE)
	$(BIN)/python -m pytest -q

## test-all: the whole suite, slow tests included
test-all: $(VENV)/.installed-dev
	$(BYTECODE)
	$(BIN)/python -m pytest -q -m ''

## sanitize: build the three C extensions with AddressSanitizer + UBSan out of tree (build/sanitize/;
## the in-place .so files are not touched) and run the differential tests against them (needs gcc)
sanitize: $(VENV)/.installed-dev
	$(BIN)/python tools/sanitize.py

## lint: ruff, and the dependency rules of docs/architecture.md (import-linter contracts in pyproject.toml)
lint: $(VENV)/.installed-dev
	$(BIN)/ruff check .
	$(BIN)/lint-imports

bench: $(VENV)/.installed-bench
	$(BYTECODE)
	$(BIN)/python -m bench

## serve: the HTTP service on 127.0.0.1:8000 (see api/README.md)
serve: $(VENV)/.installed
	$(BYTECODE)
	$(BIN)/avs serve

## constraints: refresh constraints.txt from a fresh venv with the newest versions pyproject.toml
## allows (then run `make test`: the file is the set the tests passed with)
constraints:
	rm -rf .venv-constraints
	$(PYTHON) -m venv .venv-constraints
	.venv-constraints/bin/python -m pip install -q --upgrade pip
	.venv-constraints/bin/python -m pip install -q -e '.[dev]'
	{ sed -n '/^#/p' constraints.txt; \
	  .venv-constraints/bin/python -m pip freeze --exclude-editable; } > constraints.txt.new
	mv constraints.txt.new constraints.txt
	rm -rf .venv-constraints

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
