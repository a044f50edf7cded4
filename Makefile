# planbench: `make demo` runs every scenario with videos, `make test` runs the lint, format and
# type checks and then the test suite. Both create .venv and install the project into it when
# needed (pyproject.toml changed), with the optional Ray extra, so that the tests cover both
# campaign engines.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp

# The modules that define planbench's public API (planbench.__all__), type-checked by mypy.
PUBLIC_API := __init__.py api.py task.py checks.py runner.py params.py envs.py campaign/__init__.py \
	planners/trajectory.py planners/errors.py planners/loader/__init__.py planners/hexapod/__init__.py \
	planners/fast/plan.py planners/antenna/__init__.py
# mypy reads files, not the installed package's folder mapping (sims/ is planbench/): it checks
# them through a tree of links laid out as the import names.
TYPED := build/typecheck

.PHONY: demo test lint typecheck bench clean

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[test,ray]'
	@touch $(STAMP)

demo: $(STAMP)
	$(BIN)/planbench demo --out results

# worksteal: a worker that runs out of tests takes some of the other's (the suite's long
# subprocess tests otherwise leave one core idle at the end).
test: lint typecheck
	$(BIN)/python -m pytest -q -n auto --dist worksteal

lint: $(STAMP)
	$(BIN)/ruff check --quiet .
	$(BIN)/ruff format --check --quiet .

typecheck: $(STAMP)
	@rm -rf $(TYPED) && mkdir -p $(TYPED)/planbench
	@ln -s $(CURDIR)/sims/* $(TYPED)/planbench/ && ln -s $(CURDIR)/planners $(CURDIR)/models $(TYPED)/planbench/
	cd $(TYPED) && $(CURDIR)/$(BIN)/mypy --config-file $(CURDIR)/pyproject.toml --cache-dir $(CURDIR)/.mypy_cache $(addprefix planbench/,$(PUBLIC_API))

bench: $(STAMP)
	$(BIN)/planbench bench

clean:
	rm -rf results .pytest_cache .hypothesis .mypy_cache .ruff_cache $(TYPED)
