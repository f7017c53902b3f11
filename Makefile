# rigidfold: the two commands of the quick start are `make demo` and `make test`.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test browser bench broad-set lint format clean same-path

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip

$(STAMP): $(PY) pyproject.toml
	$(PY) -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/rigidfold generate --surface bezier --seed 1 --pattern 1 --criterion shat --out out/demo --overwrite
	@echo "open the report: out/demo/report.html"

# the suite on every core (pytest-xdist); the tests run with the pinned numerics
# (rigidfold.runtime.numerics: pytest restarts itself with them)
test: $(STAMP) browser
	$(PY) -m pytest -q -n $(shell nproc 2>/dev/null || echo 2)

# the demo case under several OpenBLAS kernels: the same counters and F to every digit
same-path: $(STAMP)
	$(PY) .ci/same_path.py

# headless Chromium for the browser test of the report; where it cannot be installed (no
# apt-get, not root) that test skips and says why
browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || \
	  (command -v apt-get >/dev/null 2>&1 && apt-get update -qq && \
	   DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium) || \
	  echo "note: Chromium is not installed and could not be; the browser test of the report will skip"

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
	$(PY) benchmarks/bench_report.py
	$(PY) benchmarks/mesh_surface.py
	$(PY) benchmarks/own_design.py
	$(PY) benchmarks/bench_solve_scale.py
	$(PY) benchmarks/bench_scale.py
	$(PY) benchmarks/bench_generate_scale.py
	$(PY) benchmarks/bench_numerics.py
	$(PY) benchmarks/bench_path.py
	$(PY) benchmarks/deploy_share.py
	$(PY) benchmarks/bench_structure.py
	$(PY) benchmarks/panel_pin_trend.py
	$(PY) benchmarks/bench_fabricate.py
	$(PY) benchmarks/bench_drive.py

# the broad set of issue 49 (a sample of about 60 cases, 3 min each: about two hours on 2
# cores; docs/broad_set.md), not part of bench
broad-set: $(STAMP)
	$(PY) benchmarks/broad_set.py --sample 50 --variants today,batch-off --jobs 2 --out out/broad_set.jsonl --resume

lint: $(STAMP)
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/ruff format --check src tests benchmarks
	$(VENV)/bin/mypy

format: $(STAMP)
	$(VENV)/bin/ruff format src tests benchmarks
	$(VENV)/bin/ruff check --fix src tests benchmarks

clean:
	rm -rf $(VENV) out build *.egg-info src/*.egg-info
