# Two entry points (see README): `make run` and `make test`. Both set up what is
# missing first: the system library libngspice0 (apt) and a virtualenv in .venv
# with the project installed in editable mode.
PY      ?= python3
VENV    := .venv
STAMP   := $(VENV)/.installed
OUT     ?= runs/default

.PHONY: run test setup bench clean

run: $(STAMP)
	$(VENV)/bin/switchsim run --out $(OUT)

test: $(STAMP)
	$(VENV)/bin/python -m pytest -q

setup: $(STAMP)

$(STAMP): pyproject.toml scripts/install-system-deps
	sh scripts/install-system-deps
	$(PY) -m venv $(VENV)
	$(VENV)/bin/python -m pip install -q --upgrade pip
	$(VENV)/bin/python -m pip install -q -e '.[test]'
	touch $(STAMP)

bench: $(STAMP)
	for b in benchmarks/bench_*.py; do $(VENV)/bin/python $$b || exit 1; done

clean:
	rm -rf $(VENV) runs
