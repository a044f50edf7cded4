# planbench: `make demo` runs every scenario with videos, `make test` runs the test suite.
# Both create .venv and install the project into it when needed (pyproject.toml changed),
# with the optional Ray extra, so that the tests cover both campaign engines.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp

.PHONY: demo test bench clean

$(STAMP): pyproject.toml
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -e '.[test,ray]'
	@touch $(STAMP)

demo: $(STAMP)
	$(BIN)/planbench demo --out results

test: $(STAMP)
	$(BIN)/python -m pytest -q -n auto

bench: $(STAMP)
	$(BIN)/planbench bench

clean:
	rm -rf results .pytest_cache .hypothesis
