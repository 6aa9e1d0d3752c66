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
.PHONY: cluster-env cluster-lock slurm-test notebooks-env notebooks-lock lab lab-check docs
.PHONY: report-shots wheel-check cff-check

help:
	@echo "make all        build .venv from requirements.lock, then snakemake -c$(CORES) all"
	@echo "make test       build .venv, then run the whole test suite"
	@echo "make lock       re-resolve requirements.lock, then the cluster and notebooks locks"
	@echo "make docs       build the documentation (MkDocs, warnings are errors) into site/"
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
	@echo "make lab            JupyterLab (.venv-notebooks) on notebooks/; LAB_ARGS=--no-browser etc."
	@echo "make lab-check      start JupyterLab headless, probe it over HTTP, stop it"
	@echo "make report-shots   report.html in headless Chromium: PNGs under results/report-shots/"
	@echo "make wheel-check    build the wheel, install it in a fresh venv without snakemake, run it"

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
	# Every kernel compiled once into the one numba cache (seconds per kind of scene printed):
	# the test workers and the workflow's jobs then load it instead of each compiling it.
	$(BIN)/restitution warmup
	touch $(STAMP)

# .venv holds the package with the extras `make all`, `make test`, `make lint` and `make docs`
# need; the cluster and notebooks locks are constrained by it, so every shared package has one pin.
LOCK_EXTRAS := --extra workflow --extra test --extra docs
lock:
	$(BIN)/uv pip compile pyproject.toml $(LOCK_EXTRAS) --python-version 3.11.7 -o requirements.lock \
		|| uv pip compile pyproject.toml $(LOCK_EXTRAS) --python-version 3.11.7 -o requirements.lock
	$(MAKE) cluster-lock notebooks-lock

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
	$(BIN)/uv pip compile pyproject.toml $(LOCK_EXTRAS) --extra cluster \
		--constraint requirements.lock --python-version 3.11.7 -o requirements-cluster.lock

# Notebooks environment: the package plus JupyterLab, jupytext and ipympl, in its own venv (the
# Jupyter server's dependencies slow every snakemake configuration check in .venv ~10 times).
NB_VENV := .venv-notebooks
NB_STAMP := $(NB_VENV)/.installed

notebooks-env: $(NB_STAMP)

$(NB_STAMP): requirements-notebooks.lock pyproject.toml | $(STAMP)
	test -x $(NB_VENV)/bin/python || $(PYTHON) -m venv $(NB_VENV)
	$(BIN)/uv pip sync --python $(NB_VENV)/bin/python requirements-notebooks.lock
	$(BIN)/uv pip install --python $(NB_VENV)/bin/python --no-deps -e .
	touch $(NB_STAMP)

notebooks-lock: env
	$(BIN)/uv pip compile pyproject.toml --extra notebooks --constraint requirements.lock \
		--python-version 3.11.7 -o requirements-notebooks.lock

# JupyterLab on notebooks/ (jupytext opens the .py notebooks as notebooks). MPLBACKEND is unset
# so that figures draw inline. LAB_ARGS adds options, e.g. LAB_ARGS="--no-browser --port 8899".
# As root (containers, CI) Jupyter refuses to start without --allow-root.
LAB_ARGS ?=
LAB_ROOT := $(if $(filter 0,$(shell id -u)),--allow-root)
lab: notebooks-env
	env -u MPLBACKEND RESTITUTION_RESULTS=$${RESTITUTION_RESULTS:-$(CURDIR)/results} \
		$(NB_VENV)/bin/jupyter lab --notebook-dir=notebooks $(LAB_ROOT) $(LAB_ARGS)

# Headless check of `make lab`: starts it with --no-browser on a free local port, waits for the
# server, fetches the notebook's page and the contents API over HTTP, and stops the server.
lab-check: notebooks-env
	$(NB_VENV)/bin/python .ci/lab_check.py --make "$(MAKE)"

slurm-test: env cluster-env
	.ci/slurm_test.sh

# --report never runs a job and fails on a missing output, so the targets are brought up to date
# first (nothing runs after `make all`). REPORT_TARGETS="all benchmarks" adds the work-precision
# study. Open report.html in a browser (self-contained; JavaScript on).
# workflow/report/style.css fixes the report template's vertical centring (a long page could not
# be scrolled to its top).
REPORT_TARGETS ?= all
REPORT_STYLE := workflow/report/style.css
report: env
	$(BIN)/snakemake -c$(CORES) $(REPORT_TARGETS)
	$(BIN)/snakemake $(REPORT_TARGETS) --report report.html --report-stylesheet $(REPORT_STYLE)

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
	$(BIN)/snakemake -c$(CORES) benchmarks --report results/benchmarks/report.html \
		--report-stylesheet $(REPORT_STYLE)

# The reduced benchmarks (config/benchmarks-smoke.yaml, ~1-2 min) in a scratch folder, for CI:
# proves every rule of the target runs; its timings are not meant to be read.
BENCH_SMOKE_DIR ?= results/bench-smoke
bench-smoke: env
	mkdir -p $(BENCH_SMOKE_DIR)
	$(BIN)/snakemake -c$(CORES) benchmarks --configfile $(CURDIR)/config/benchmarks-smoke.yaml \
		--directory $(BENCH_SMOKE_DIR)

# The documentation: docs/*.md (readable as sources), API reference generated from the
# docstrings by mkdocstrings; --strict turns every warning (broken link, unknown object) into an error.
# NO_MKDOCS_2_WARNING silences mkdocs-material's banner about its successor (not a build warning).
docs: env
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir site

# The wheel as a user gets it: built from the sources, installed (not editable) into a fresh venv
# without the extras, then the CLI, solve_many and the plotting style are run from there.
wheel-check: env
	$(BIN)/python .ci/wheel_check.py

# CITATION.cff against the Citation File Format schema (cffconvert, run by uv in a throw-away
# environment: its pins of jsonschema clash with snakemake's).
CFFCONVERT_VERSION := 2.0.0
cff-check: env
	$(BIN)/uv tool run --python $(BIN)/python --from cffconvert==$(CFFCONVERT_VERSION) \
		cffconvert --validate --infile CITATION.cff

# Screenshots of report.html in Debian's headless Chromium (driven by selenium through Debian's
# chromium-driver; both installed with apt-get when missing, as root): the front page and two
# figure pages, under results/report-shots/. Needs report.html (`make report`).
report-shots: env
	test -s report.html || $(MAKE) report
	$(BIN)/python .ci/report_shots.py report.html results/report-shots

lint: env
	$(BIN)/ruff check src tests workflow/scripts benchmarks notebooks examples .ci docs/hooks.py
	$(BIN)/ruff format --check src tests workflow/scripts benchmarks notebooks examples .ci docs/hooks.py
	$(BIN)/snakefmt --check Snakefile workflow/rules
	$(BIN)/snakemake --lint

clean:
	rm -rf results logs .cache .snakemake/incomplete .pytest_cache report.html notebooks/executed \
		site dist

distclean: clean
	rm -rf $(VENV) $(CLUSTER_VENV) $(NB_VENV) .snakemake
