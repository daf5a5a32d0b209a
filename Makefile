# Two entry points for a fresh machine: `make demo` and `make test` (see README.md).
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: setup llvm open3d-deps bench-deps demo test bench clean

# Dr.Jit's LLVM back end needs libLLVM >= 16 (Debian's 15 aborts the process; see
# docs/conventions.md). Debian and Ubuntu name libLLVM N's package libllvmN: any of these that is
# installed will do, else the first apt can install (19 first: the one measured here). Never an
# error: without one the renderer falls back to the slow scalar_rgb with a warning.
LLVM_PACKAGES ?= libllvm19 libllvm20 libllvm21 libllvm18 libllvm17 libllvm16
llvm:
	@for p in $(LLVM_PACKAGES); do \
	  if command -v dpkg >/dev/null 2>&1 && dpkg -s $$p >/dev/null 2>&1; then exit 0; fi; \
	done; \
	if ! command -v apt-get >/dev/null 2>&1; then \
	  echo "warning: no apt-get: install libLLVM >= 16 yourself (or set DRJIT_LIBLLVM_PATH), else the renderer falls back to the slow scalar_rgb" >&2; \
	  exit 0; \
	fi; \
	for update in no yes; do \
	  [ $$update = yes ] && { $(SUDO) apt-get update -qq >/dev/null 2>&1 || true; }; \
	  for p in $(LLVM_PACKAGES); do \
	    if $(SUDO) apt-get install -y -qq $$p >/dev/null 2>&1; then \
	      echo "installed $$p for Dr.Jit's LLVM back end"; exit 0; \
	    fi; \
	  done; \
	done; \
	echo "warning: apt-get could install none of $(LLVM_PACKAGES): install libLLVM >= 16 yourself (or set DRJIT_LIBLLVM_PATH), else the renderer falls back to the slow scalar_rgb" >&2

$(VENV)/.installed: pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[dev,runners]'
	touch $@

setup: llvm open3d-deps $(VENV)/.installed

demo: setup
	$(BIN)/scenegen render scenes/demo.yaml -o out/demo
	$(BIN)/scenegen info out/demo

test: setup
	$(BIN)/python -m pytest -q

# Open3D (the runners' extra, installed by setup: the object and TSDF-fusion runners and the F-score
# benchmark's reference) loads Debian's libusb-1.0-0, which a fresh Debian machine lacks.
open3d-deps:
	@if command -v dpkg >/dev/null && dpkg -s libusb-1.0-0 >/dev/null 2>&1; then :; \
	elif command -v apt-get >/dev/null; then \
	  echo "installing libusb-1.0-0 (Debian) for Open3D"; \
	  $(SUDO) apt-get install -y -qq libusb-1.0-0 >/dev/null 2>&1 || \
	  { $(SUDO) apt-get update -qq >/dev/null && $(SUDO) apt-get install -y -qq libusb-1.0-0 >/dev/null; }; \
	else echo "warning: no apt-get: install libusb-1.0 yourself, else Open3D (runners, benchmarks) cannot be imported" >&2; fi

bench-deps: open3d-deps

bench: setup bench-deps
	$(BIN)/python benchmarks/run.py

clean:
	rm -rf $(VENV) out *.egg-info
