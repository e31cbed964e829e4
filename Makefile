# Two commands set up and run everything on a fresh machine: `make demo` and `make test`.
# Each bootstraps what it needs (apt packages, a .venv, the project) and is idempotent.
SHELL := /bin/bash
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
APT_STAMP := $(VENV)/.apt-installed
APT_PACKAGES := libllvm19 libusb-1.0-0 libgomp1
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: setup demo test bench tables ablations clean

setup: $(STAMP)

$(APT_STAMP):
	@if dpkg -s $(APT_PACKAGES) >/dev/null 2>&1; then echo "apt packages present"; \
	else $(SUDO) apt-get update -qq && $(SUDO) DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $(APT_PACKAGES); fi
	@mkdir -p $(VENV) && touch $@

$(STAMP): pyproject.toml $(APT_STAMP)
	@[ -x $(PY) ] || python3.11 -m venv $(VENV) || python3 -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	# The pinned CPU wheel first: an unpinned torch would pull gigabytes of CUDA packages.
	$(PY) -m pip install -q torch==2.13.0
	$(PY) -m pip install -q -e '.[dev,ray]'
	@touch $@

demo: setup
	$(VENV)/bin/nbv demo --out demo_out

test: setup
	$(VENV)/bin/ruff check .
	$(PY) -m pytest -q

bench: setup
	$(VENV)/bin/nbv bench --out bench_out

tables: setup
	$(VENV)/bin/nbv tables --out paper_results

ablations: setup
	$(VENV)/bin/nbv ablate --out paper_results/ablations

clean:
	rm -rf demo_out bench_out .pytest_cache
