# Two entry points for a fresh machine: `make demo` and `make test` (see README.md).
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: setup llvm bench-deps demo test bench clean

# Dr.Jit's LLVM back end needs libLLVM >= 16 (Debian's 15 aborts the process; see
# docs/conventions.md). Without apt the renderer falls back to scalar_rgb with a warning.
llvm:
	@if command -v dpkg >/dev/null && dpkg -s libllvm19 >/dev/null 2>&1; then :; \
	elif command -v apt-get >/dev/null; then \
	  echo "installing libllvm19 (Debian) for Dr.Jit's LLVM back end"; \
	  $(SUDO) apt-get install -y -qq libllvm19 >/dev/null 2>&1 || \
	  { $(SUDO) apt-get update -qq >/dev/null && $(SUDO) apt-get install -y -qq libllvm19 >/dev/null; }; \
	else echo "no apt-get: install libLLVM >= 16 yourself or expect the slow scalar_rgb fallback"; fi

$(VENV)/.installed: pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[dev]'
	touch $@

setup: llvm $(VENV)/.installed

demo: setup
	$(BIN)/scenegen render scenes/demo.yaml -o out/demo
	$(BIN)/scenegen info out/demo

test: setup
	$(BIN)/python -m pytest -q

# Open3D (the F-score benchmark's reference, in its own venv) needs Debian's libusb-1.0-0.
bench-deps:
	@if command -v dpkg >/dev/null && dpkg -s libusb-1.0-0 >/dev/null 2>&1; then :; \
	elif command -v apt-get >/dev/null; then \
	  echo "installing libusb-1.0-0 (Debian) for Open3D in benchmarks/bench_fscore.py"; \
	  $(SUDO) apt-get install -y -qq libusb-1.0-0 >/dev/null 2>&1 || \
	  { $(SUDO) apt-get update -qq >/dev/null && $(SUDO) apt-get install -y -qq libusb-1.0-0 >/dev/null; }; \
	else echo "no apt-get: install libusb-1.0 yourself or bench_fscore.py cannot import Open3D"; fi

bench: setup bench-deps
	$(BIN)/python benchmarks/run.py

clean:
	rm -rf $(VENV) out *.egg-info
