# Two entry points (see README): `make run` and `make test`. Both set up what is
# missing first: the system library libngspice0 (apt) and a virtualenv in .venv
# with the project installed in editable mode.
PY      ?= python3
VENV    := .venv
STAMP   := $(VENV)/.installed
OUT     ?= runs/default

.PHONY: run test setup bench accuracy clean

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
	# bytecode now: where PYTHONDONTWRITEBYTECODE is set (containers often set it) Python
	# reads caches but never writes them, and every start compiled ~100 modules (0.1 s)
	$(VENV)/bin/python -m compileall -q mech circuit coupling
	touch $(STAMP)

bench: $(STAMP)
	for b in benchmarks/bench_*.py; do $(VENV)/bin/python $$b || exit 1; done

# Regenerates docs/accuracy.md and its plots in docs/accuracy/ (parts 1-5 ~2 min on 2 cores, part 6 far longer);
# part 6 compares with Exudyn, the optional `bench` extra, installed here first (not by run or test)
accuracy: $(STAMP)
	$(VENV)/bin/python -m pip install -q -e '.[bench]'
	for p in mech modes coupling circuit matrix exudyn; do $(VENV)/bin/python benchmarks/accuracy_$$p.py || exit 1; done
	$(VENV)/bin/python benchmarks/accuracy_report.py

clean:
	rm -rf $(VENV) runs
