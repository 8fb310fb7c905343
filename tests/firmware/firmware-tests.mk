# Firmware unit tests, written against Unity's API (so `pio test -e native`
# runs them with the real Unity), built here with gcc. Each test_*/ folder is
# one test program; the .c files beside them are linked into every one.
#
# Unity: a real Unity is used when found, first in $(UNITY_DIR) or
# $(UNITY_DIR)/src (a Unity checkout: unity.c, unity.h), then as a system
# library (unity.h in /usr/local/include, /usr/include or /usr/include/unity,
# linked with -lunity). Otherwise tests/firmware/unity_compat, a small
# stand-in for the part of the API the tests use.

FWT_DIR := tests/firmware
FWT_OUT := $(BUILD)/firmware-tests
FWT_SUITES := $(sort $(notdir $(patsubst %/,%,$(wildcard $(FWT_DIR)/test_*/))))
FWT_BINS := $(addprefix $(FWT_OUT)/,$(FWT_SUITES))
FWT_SHARED := $(sort $(wildcard $(FWT_DIR)/*.c))
FWT_CORE := $(sort $(wildcard firmware/core/*.c))
FWT_DEPS := $(wildcard firmware/core/*.h $(FWT_DIR)/*.h $(FWT_DIR)/unity_compat/*)
FWT_PYTHON := $(or $(PYTHON),python3)
QS_VECTORS ?= protocol/vectors.json
FWT_VECTORS_H := $(FWT_OUT)/generated/qs_vectors.h

FWT_UNITY_SRC_DIR := $(firstword $(foreach d,$(UNITY_DIR) $(UNITY_DIR)/src,$(if $(wildcard $(d)/unity.c),$(d))))
FWT_UNITY_SYSTEM := $(firstword $(wildcard /usr/local/include/unity.h /usr/include/unity.h /usr/include/unity/unity.h))
ifneq ($(FWT_UNITY_SRC_DIR),)
  FWT_UNITY_FLAGS := -I$(FWT_UNITY_SRC_DIR)
  FWT_UNITY_SRC := $(FWT_UNITY_SRC_DIR)/unity.c
  FWT_UNITY_LIBS :=
  FWT_UNITY_NOTE := Unity from $(FWT_UNITY_SRC_DIR)
else ifneq ($(FWT_UNITY_SYSTEM),)
  FWT_UNITY_FLAGS := -I$(dir $(FWT_UNITY_SYSTEM))
  FWT_UNITY_SRC :=
  FWT_UNITY_LIBS := -lunity
  FWT_UNITY_NOTE := Unity from $(FWT_UNITY_SYSTEM) (-lunity)
else
  FWT_UNITY_FLAGS := -I$(FWT_DIR)/unity_compat
  FWT_UNITY_SRC := $(FWT_DIR)/unity_compat/unity.c
  FWT_UNITY_LIBS :=
  FWT_UNITY_NOTE := no Unity in UNITY_DIR='$(UNITY_DIR)', /usr/local/include, /usr/include or /usr/include/unity: using $(FWT_DIR)/unity_compat
endif

# The core is compiled as the emulator compiles it (NATIVE_DEFINES, native.mk).
FWT_CFLAGS = -std=c99 -O2 -g -Wall -Wextra -Werror $(NATIVE_DEFINES) -DUNITY_SUPPORT_64 \
	-Ifirmware/core -I$(FWT_DIR) -I$(FWT_OUT)/generated $(FWT_UNITY_FLAGS)

.PHONY: test-firmware firmware-tests

firmware-tests: $(FWT_BINS)

# Each program is a job of its own, so that `make -j` runs them side by side.
FWT_RUNS := $(addprefix run-,$(FWT_SUITES))
.PHONY: $(FWT_RUNS)

test-firmware: $(FWT_RUNS)
	@echo "firmware tests: $(words $(FWT_RUNS)) programs passed ($(FWT_UNITY_NOTE))"

$(FWT_RUNS): run-%: $(FWT_OUT)/%
	$<

$(FWT_VECTORS_H): $(QS_VECTORS) $(FWT_DIR)/gen_vectors.py
	@mkdir -p $(@D)
	$(FWT_PYTHON) $(FWT_DIR)/gen_vectors.py $(QS_VECTORS) $@

# The core, the shared support and Unity are compiled once, for every program to link.
FWT_COMMON_OBJS := $(patsubst %.c,$(FWT_OUT)/obj/%.o,$(FWT_SHARED) $(FWT_CORE) $(FWT_UNITY_SRC))

$(FWT_OUT)/obj/%.o: %.c $(FWT_DEPS) $(FWT_VECTORS_H)
	@mkdir -p $(@D)
	$(CC) $(FWT_CFLAGS) -c $< -o $@

$(FWT_OUT)/test_%: $(FWT_DIR)/test_%/*.c $(FWT_COMMON_OBJS) $(FWT_DEPS) $(FWT_VECTORS_H)
	@mkdir -p $(@D)
	$(CC) $(FWT_CFLAGS) $(wildcard $(FWT_DIR)/test_$*/*.c) $(FWT_COMMON_OBJS) -o $@ $(FWT_UNITY_LIBS)
