# quadstep build: the emulator and firmware tests (gcc), the AVR firmware
# (avr-gcc) and the simavr harness. `make demo` and `make test` are the two
# commands in the README; both set up everything they need first. The Python
# side runs in a virtual environment of its own, $(VENV), made from $(PYTHON)
# (Debian's own python by default, which pip may not install into: PEP 668).

BUILD ?= build
PYTHON ?= $(if $(wildcard /usr/bin/python3),/usr/bin/python3,python3)
VENV := $(BUILD)/venv
VENV_PYTHON := $(VENV)/bin/python
VENV_INSTALLED := $(VENV)/.installed
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
APT_PACKAGES := gcc make pkg-config gcc-avr avr-libc binutils-avr simavr libsimavr-dev libelf-dev \
	clang libclang-rt-14-dev avrdude python3-venv python3-tk
CNCJS_VERSION := 1.11.5
CNCJS_INSTALLED := $(BUILD)/cncjs/.installed-$(CNCJS_VERSION)

.PHONY: all setup setup-apt setup-python setup-senders demo lint test test-ready test-fast test-firmware test-python bench clean

all: emulator firmware

include firmware/native/native.mk
include firmware/avr/avr.mk
include tests/firmware/firmware-tests.mk
include tests/simavr/simavr.mk
include tests/fuzz/fuzz.mk

setup: setup-apt setup-python

# Debian packages, installed only when a tool is missing. Debian's python
# makes a virtual environment only with python3-venv (ensurepip and the pip wheel).
setup-apt:
	@if ! command -v avr-gcc >/dev/null || ! command -v gcc >/dev/null || ! command -v clang >/dev/null \
	    || ! command -v avrdude >/dev/null \
	    || ! $(PYTHON) -c 'import ensurepip, venv; ensurepip.version()' >/dev/null 2>&1 \
	    || ! $(PYTHON) -c 'import tkinter' >/dev/null 2>&1 \
	    || ! pkg-config --exists simavr 2>/dev/null || [ ! -e /usr/include/libelf.h ]; then \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $(APT_PACKAGES); \
	fi
	@if ! command -v npm >/dev/null || ! command -v node >/dev/null; then \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq nodejs npm; \
	fi

setup-python: $(VENV_INSTALLED)

# A half-made environment is removed, so that the next run makes it again.
$(VENV_PYTHON): | setup-apt
	$(PYTHON) -m venv $(VENV) || { rm -rf $(VENV); exit 1; }

# The package (editable) and its test tools; again only when pyproject.toml changes.
$(VENV_INSTALLED): pyproject.toml | $(VENV_PYTHON)
	$(VENV_PYTHON) -m pip install -q --disable-pip-version-check -e '.[test]'
	@touch $@

# A real sender for the tests (tests/grbl/test_grbl_cncjs.py): CNCjs from the npm registry, its server
# and Grbl controller, in $(BUILD)/cncjs.
setup-senders: $(CNCJS_INSTALLED)

$(CNCJS_INSTALLED): | setup-apt
	rm -rf $(BUILD)/cncjs && mkdir -p $(BUILD)/cncjs && echo '{"private": true}' > $(BUILD)/cncjs/package.json
	npm install --prefix $(abspath $(BUILD))/cncjs --no-audit --no-fund --loglevel=error \
	  cncjs@$(CNCJS_VERSION) >/dev/null
	@touch $@

demo: setup emulator
	$(VENV_PYTHON) -m quadstep.cli run examples/demo.gcode --config examples/router-uno.toml --emulator

# Once the Debian packages are in, everything the Python tests need is made and checked side by side
# (downloads, compiles and the firmware's own tests overlap; each job's output is kept together),
# then the Python tests run. They run ruff and mypy too (tests/test_host_structure.py, as `make lint`
# does), beside the other tests rather than before them all. The AVR forms check is built here, not
# by the two tests that run it side by side.
TEST_JOBS ?= 4

test: setup-apt
	$(MAKE) -j$(TEST_JOBS) --output-sync=target test-ready
	$(MAKE) test-python

test-ready: setup-python setup-senders all harness avr-forms-check test-firmware fuzz-short

# The host package's style and types (pyproject.toml: [tool.ruff], [tool.mypy]); `ruff format
# host/quadstep` fixes the first.
lint: setup-python
	$(VENV_PYTHON) -m ruff format --check host/quadstep
	$(VENV_PYTHON) -m ruff check host/quadstep
	$(VENV_PYTHON) -m mypy host/quadstep

# Five at a time, on any number of cores: most tests wait on an emulator paced in real time
# rather than compute (on 2 cores three at a time keep 1.3 of them busy, five 1.8). Then, two at a
# time and after all the others, those whose host must keep a board running in real time from
# running dry while it plans or resends (marked realtime): two side by side on two cores kept every
# board fed in most runs, in about 115 s against 196 one at a time (docs/HOST.md). A realtime test
# that fails runs once more: a shared machine can hold the host back past what the board has
# queued, which is no fault of the code; a test that fails twice fails. The slowest tests are
# listed, to see where the suite's time goes.
test-python: setup-python
	$(VENV_PYTHON) -m pytest -q -n 5 --dist worksteal -m 'not realtime' --durations=15
	$(VENV_PYTHON) -m pytest -q -n 2 --dist worksteal -m realtime --reruns 1 --durations=5

# The Python tests that start no emulator and no simavr (tests/conftest.py marks the others), on
# every core.
test-fast: setup-python
	$(VENV_PYTHON) -m pytest -q -n auto -m 'not emulator and not slow'

bench: setup all harness
	$(VENV_PYTHON) tests/bench/run_all.py

clean:
	rm -rf $(BUILD)
