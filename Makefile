# rigidfold: the two commands of the quick start are `make demo` and `make test`.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test bench lint format clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

$(STAMP): $(PY) pyproject.toml
	$(PY) -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/rigidfold generate --surface bezier --seed 1 --pattern 1 --criterion shat --out out/demo --overwrite

test: $(STAMP)
	$(PY) -m pytest -q

bench: $(STAMP)
	$(PY) benchmarks/bench_optimize.py
	$(PY) benchmarks/hessian_size.py
	$(PY) benchmarks/bench_generate.py
	$(PY) benchmarks/blas_threads.py
	$(PY) benchmarks/bench_develop.py
	$(PY) benchmarks/bench_deform.py
	$(PY) benchmarks/bench_study.py
	$(PY) benchmarks/bench_cpu_scaling.py
	$(PY) benchmarks/bench_lookahead.py

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/ruff format --check src tests benchmarks
	$(VENV)/bin/mypy

format: $(STAMP)
	$(VENV)/bin/ruff format src tests benchmarks
	$(VENV)/bin/ruff check --fix src tests benchmarks

clean:
	rm -rf $(VENV) out build *.egg-info src/*.egg-info
