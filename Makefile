# Set-up contract: `make run` and `make test` on a fresh machine each create
# .venv, install the pinned dependency set and do their job.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
RUN_NAME ?= quick
# Test processes of `make test` (pytest-xdist, one test file per process at a time).
JOBS ?= 2

.PHONY: venv run lint test test-slow test-cluster bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev]'
	$(PY) -m pip check
	touch $(STAMP)

venv: $(STAMP)

# The learned feasibility condition: over 5 training seeds its `quick` policies climb both stairs
# and finish the circuit on 5, the cylinders' on 1, at equal coverage of their own guides
# (docs/results/2026-12-04-ablation-more-seeds); training takes about 2.5 x as long.
run: $(STAMP)
	$(VENV)/bin/leas run --preset quick --reachability learned --out runs/$(RUN_NAME)

# The linter and the formatter's check, as CI runs them (fix with `ruff check --fix . && ruff format .`).
lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

# The 30 slowest tests are listed after each run: what to move to the slow tier when the
# fast one nears its 10-minute budget on 2 cores (tests/conftest.py). The files run in
# JOBS processes; `make test JOBS=0` runs them in this one.
test: lint
	$(PY) -m pytest -q -n $(JOBS) --dist loadfile --durations=30

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

# The Ray backend of the contact-plan validation (optional extra leas-jax[cluster]).
test-cluster: $(STAMP)
	$(PY) -m pip install -q -e '.[dev,cluster]'
	$(PY) -m pip check
	$(PY) -m pytest -q -m slow tests/test_ray_backend.py

bench: $(STAMP)
	$(PY) benchmarks/env_throughput.py
	$(PY) benchmarks/train_throughput.py
	$(PY) benchmarks/contact_planner_speed.py
	$(PY) benchmarks/planner_training_throughput.py

clean:
	rm -rf $(VENV) build *.egg-info
