# quadstep build: the emulator and firmware tests (gcc), the AVR firmware
# (avr-gcc) and the simavr harness. `make demo` and `make test` are the two
# commands in the README; both set up everything they need first.

BUILD ?= build
PYTHON ?= python3
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
APT_PACKAGES := gcc make pkg-config gcc-avr avr-libc binutils-avr simavr libsimavr-dev libelf-dev \
	clang libclang-rt-14-dev avrdude

.PHONY: all setup setup-apt setup-python demo test test-firmware test-python bench clean

all: emulator firmware

include firmware/native/native.mk
include firmware/avr/avr.mk
include tests/firmware/firmware-tests.mk
include tests/simavr/simavr.mk
include tests/fuzz/fuzz.mk

setup: setup-apt setup-python

# Debian packages, installed only when a tool is missing.
setup-apt:
	@if ! command -v avr-gcc >/dev/null || ! command -v gcc >/dev/null || ! command -v clang >/dev/null \
	    || ! command -v avrdude >/dev/null \
	    || ! pkg-config --exists simavr 2>/dev/null || [ ! -e /usr/include/libelf.h ]; then \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $(APT_PACKAGES); \
	fi

setup-python:
	$(PYTHON) -m pip install -q -e '.[test]'

demo: setup emulator
	$(PYTHON) -m quadstep.cli run examples/demo.gcode --config examples/router-uno.toml --emulator

test: setup all harness test-firmware fuzz-short test-python

test-python:
	$(PYTHON) -m pytest -q

bench: setup all harness
	$(PYTHON) tests/bench/run_all.py

clean:
	rm -rf $(BUILD)
