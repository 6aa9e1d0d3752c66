# Two-command set-up: `make all` (environment + every figure), `make test` (environment + test suite).
# The environment is .venv, built from the committed lock file requirements.lock with uv (itself
# pinned and installed from PyPI into the venv, so a machine needs only python3 with venv and pip).

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
UV_VERSION := 0.13.8
STAMP := $(VENV)/.installed
CORES ?= 2
# One numba cache for the project, cleared by `make clean` and CI (never trust it across kernel edits).
export NUMBA_CACHE_DIR := $(CURDIR)/.cache/numba
export MPLBACKEND := Agg
# Byte-compiled installs: without .pyc every snakemake start recompiles the stack (15 s vs 2 s).
export UV_COMPILE_BYTECODE := 1
unexport PYTHONDONTWRITEBYTECODE

.PHONY: all test env lock report notebooks benchmarks bench-report bench-smoke lint clean distclean help
.PHONY: cluster-env cluster-lock slurm-test

help:
	@echo "make all        build .venv from requirements.lock, then snakemake -c$(CORES) all"
	@echo "make test       build .venv, then run the whole test suite"
	@echo "make lock       re-resolve requirements.lock from pyproject.toml"
	@echo "make report     build report.html: figures, tables, captions (runs 'all' first)"
	@echo "make notebooks  execute notebooks/*.py into notebooks/executed/ (after 'make all')"
	@echo "make benchmarks work-precision study (results/ and figures/benchmarks/, < 10 min)"
	@echo "make bench-report  results/benchmarks/report.html after 'make benchmarks'"
	@echo "make bench-smoke reduced benchmarks into \$$BENCH_SMOKE_DIR (default results/bench-smoke)"
	@echo "make lint       ruff, snakefmt --check, snakemake --lint"
	@echo "make clean      remove results, logs, figures' build caches and the numba cache"
	@echo "make cluster-env    build .venv-cluster (.venv + SLURM executor plugin) from its lock"
	@echo "make cluster-lock   re-resolve requirements-cluster.lock (pins of requirements.lock kept)"
	@echo "make slurm-test     start a one-node SLURM here (root), run a small workflow through it"

all: env
	$(BIN)/snakemake -c$(CORES) all

test: env
	$(BIN)/python -m pytest -n $(CORES) --dist loadgroup

env: $(STAMP)

# Rebuilt when the lock or the package metadata changes (stale environment).
$(STAMP): requirements.lock pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check uv==$(UV_VERSION)
	$(BIN)/uv pip sync --python $(BIN)/python requirements.lock
	# uv pip sync removes anything not in the lock, the project included: reinstall it.
	$(BIN)/uv pip install --python $(BIN)/python --no-deps -e .
	touch $(STAMP)

lock:
	$(BIN)/uv pip compile pyproject.toml --extra test --python-version 3.11.7 -o requirements.lock \
		|| uv pip compile pyproject.toml --extra test --python-version 3.11.7 -o requirements.lock

# Cluster environment: .venv plus the SLURM executor plugin, in its own venv so that local runs
# never load the plugin (with `sinfo` on PATH it queries the controller on every snakemake call).
# Its lock is constrained by requirements.lock, so every package the two share has the same pin.
CLUSTER_VENV := .venv-cluster
CLUSTER_STAMP := $(CLUSTER_VENV)/.installed

cluster-env: $(CLUSTER_STAMP)

$(CLUSTER_STAMP): requirements-cluster.lock pyproject.toml | $(STAMP)
	test -x $(CLUSTER_VENV)/bin/python || $(PYTHON) -m venv $(CLUSTER_VENV)
	$(BIN)/uv pip sync --python $(CLUSTER_VENV)/bin/python requirements-cluster.lock
	$(BIN)/uv pip install --python $(CLUSTER_VENV)/bin/python --no-deps -e .
	touch $(CLUSTER_STAMP)

cluster-lock: env
	$(BIN)/uv pip compile pyproject.toml --extra test --extra cluster --constraint requirements.lock \
		--python-version 3.11.7 -o requirements-cluster.lock

slurm-test: env cluster-env
	.ci/slurm_test.sh

# --report never runs a job and fails on a missing output, so the targets are brought up to date
# first (nothing runs after `make all`). REPORT_TARGETS="all benchmarks" adds the work-precision
# study. Open report.html in a browser (self-contained; JavaScript on).
REPORT_TARGETS ?= all
report: env
	$(BIN)/snakemake -c$(CORES) $(REPORT_TARGETS)
	$(BIN)/snakemake $(REPORT_TARGETS) --report report.html

# Each notebooks/*.py (jupytext percent format) is converted and executed into notebooks/executed/
# (git-ignored), reading results/ (first brought up to date: the notebook loads the Fig. 2(a) sweep);
# MPLBACKEND is unset so that the kernel draws inline (Agg, exported above, would draw nothing).
NOTEBOOKS := $(wildcard notebooks/*.py)
notebooks: env
	$(BIN)/snakemake -c$(CORES) results/fig2a/sweep.parquet
	mkdir -p notebooks/executed
	for nb in $(NOTEBOOKS); do \
		out=notebooks/executed/$$(basename $$nb .py).ipynb; \
		$(BIN)/jupytext --quiet --to ipynb --output $$out $$nb || exit 1; \
		RESTITUTION_RESULTS=$${RESTITUTION_RESULTS:-$(CURDIR)/results} env -u MPLBACKEND \
			$(BIN)/jupyter-execute --inplace --timeout=1800 --kernel_name=python3 $$out || exit 1; \
		echo "executed: $$out"; \
	done

benchmarks: env
	$(BIN)/snakemake -c$(CORES) benchmarks

# The benchmarks' own report (the main report covers target `all` only).
bench-report: env
	$(BIN)/snakemake -c$(CORES) benchmarks --report results/benchmarks/report.html

# The reduced benchmarks (config/benchmarks-smoke.yaml, ~1-2 min) in a scratch folder, for CI:
# proves every rule of the target runs; its timings are not meant to be read.
BENCH_SMOKE_DIR ?= results/bench-smoke
bench-smoke: env
	mkdir -p $(BENCH_SMOKE_DIR)
	$(BIN)/snakemake -c$(CORES) benchmarks --configfile $(CURDIR)/config/benchmarks-smoke.yaml \
		--directory $(BENCH_SMOKE_DIR)

lint: env
	$(BIN)/ruff check src tests workflow/scripts benchmarks notebooks .ci
	$(BIN)/ruff format --check src tests workflow/scripts benchmarks notebooks .ci
	$(BIN)/snakefmt --check Snakefile workflow/rules
	$(BIN)/snakemake --lint

clean:
	rm -rf results logs .cache .snakemake/incomplete .pytest_cache report.html notebooks/executed

distclean: clean
	rm -rf $(VENV) $(CLUSTER_VENV) .snakemake
