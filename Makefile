# specref: the two set-up commands (README) and the developer targets.
# Every target creates .venv and installs the package on first use, so a fresh clone needs nothing else.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed-stamp
# One BLAS/OpenMP thread per process: these machines are shared 2-core boxes, and multithreaded BLAS
# collapses there (see docs/dependencies.md). Code that wants more threads asks threadpoolctl itself.
export OMP_NUM_THREADS ?= 1
export OPENBLAS_NUM_THREADS ?= 1
export MKL_NUM_THREADS ?= 1
export MPLBACKEND ?= Agg
# Python writes its bytecode (__pycache__, ignored by git) even where the environment turns that off:
# the suite and the report start many Python processes (commands, Dask workers, test workers), and
# without bytecode each compiles specref's modules again (imports 3.8 s instead of 2.1 s here; the
# suite's collection 15 s instead of 7 s).
unexport PYTHONDONTWRITEBYTECODE

.PHONY: install demo test test-wheel bench bench-json results equations coverage lint clean

$(STAMP): setup.cfg pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

install: $(STAMP)

## make demo: install, then run the main job (specref report) on built-in defaults into ./report
demo: $(STAMP)
	$(VENV)/bin/specref report --out report

## make test: install, then run the whole suite (doctests and docs examples included, benchmarks off)
## on two worker processes (pytest-xdist; a module's tests stay together, so module fixtures run once)
test: $(STAMP)
	$(PY) -m pytest -q -n 2 --dist loadscope --durations=15

## make test-wheel: build the wheel, install it in a fresh venv outside the repository, use it there
test-wheel: $(STAMP)
	$(PY) -m pytest -q -m wheel tests/test_wheel.py

## make bench-json: run the pytest-benchmark suite and save bench.json
bench-json: $(STAMP)
	SPECREF_BENCH=1 $(PY) -m pytest -q tests/benchmarks --benchmark-enable \
		--benchmark-json=bench.json --benchmark-min-rounds=3

## make bench: the benchmarks, then the report with their charts and speed checks in ./report
bench: bench-json
	$(VENV)/bin/specref report --out report --bench bench.json

## make results: benchmarks, then the full report; regenerates docs/results.md and docs/results/
results: bench-json
	$(VENV)/bin/specref report --full --out docs/results --bench bench.json \
		--markdown docs/results.md --markdown-image-prefix results/

## make equations: regenerate docs/equations.md, the equation index (tests/validation/test_equations.py)
equations: $(STAMP)
	$(VENV)/bin/specref equations -o docs/equations.md

## make coverage: the suite once with the JIT off, so kernel bodies count as Python
coverage: $(STAMP)
	$(PY) -m pip install --quiet coverage
	NUMBA_DISABLE_JIT=1 $(PY) -m coverage run -m pytest -q -m "not slow and not xslow"
	$(PY) -m coverage report

lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

clean:
	rm -rf $(VENV) report bench.json .benchmarks *.egg-info
