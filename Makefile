# specc — `make demo` and `make test` set everything up from a fresh clone (Python 3.11 + pip).
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
EXAMPLES := examples/hilare examples/generic examples/atrv examples/tug

.PHONY: demo tour test test-slow goldens bench style install clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/specc check $(EXAMPLES)
	$(BIN)/specc compile examples/hilare -o generated
	$(BIN)/specc run examples/hilare --seed 0
	$(BIN)/specc run examples/atrv --mission M1 --world W2 --config Robot1/2
	$(BIN)/specc run examples/tug --mission shuttle --world crowded

# The rest of the tour: each level on its own, the formal checks, the planner, the simulator.
tour: $(STAMP)
	$(BIN)/python examples/hilare/run_modules.py
	$(BIN)/python examples/hilare/run_executive.py
	$(BIN)/python examples/hilare/run_supervisor.py
	$(BIN)/specc verify examples/hilare --requests 1
	$(BIN)/specc verify examples/hilare --goal '!(COLLECT-OBJECTS 1)' --fail ARM-OBJ --steps 4 \
	    --reach 'Explore:254; TakeObject:236 ?(& (OBJ-FOUND @I) (> @I (+ @TAKEN 1)))'
	$(BIN)/specc plan examples/atrv --problem M4 --domain model1 -o build/m4-plan.png
	$(BIN)/python examples/atrv/run_ftplan.py --config Robot1/2c --mission M3
	$(BIN)/python examples/hilare/run_sim.py --goal 9,7 --goal 2,7 -o build/hilare-run.png
	$(BIN)/python examples/atrv/run_sim.py --world W3 --goal 2,1 --goal -1,2 --goal -2,-2 --goal 1,-3 \
	    --goal 0,0 --photos -o build/atrv-w3.png
	$(BIN)/specc table examples/atrv --mission M1 --mission M2 --world W1 --world W2 --world W3 \
	    --config Robot1 --config Robot1/2

test: $(STAMP)
	$(BIN)/ruff check specc tests
	$(BIN)/mypy
	$(BIN)/lint-imports
	$(BIN)/python -m pytest

test-slow: $(STAMP)
	$(BIN)/python -m pytest -m slow

goldens: $(STAMP)
	$(BIN)/specc compile examples/hilare -o generated
	$(BIN)/specc compile examples/generic -o generated
	$(BIN)/specc compile examples/atrv -o generated
	$(BIN)/specc compile examples/tug -o generated

BENCH_STAMP := $(VENV)/.bench-stamp

$(BENCH_STAMP): $(STAMP) pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[dev,bench]'
	touch $(BENCH_STAMP)

bench: $(BENCH_STAMP)
	$(BIN)/python -m pytest -m bench --benchmark-enable -s

style: $(STAMP)
	$(BIN)/ruff check specc tests
	$(BIN)/ruff format --check specc tests || true
	$(BIN)/mypy

clean:
	rm -rf $(VENV) build dist *.egg-info .pytest_cache .mypy_cache .ruff_cache .import_linter_cache
