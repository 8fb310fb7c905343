# The native build of the firmware core: the loopback emulator
# ($(BUILD)/native/quadstep-emu) and the engine benchmark. The emulator
# serves up to 4 axes and 127 queue slots; --axes and --queue narrow what it
# reports at run time.

NATIVE_OUT := $(BUILD)/native
NATIVE_CORE_SOURCES := $(sort $(wildcard firmware/core/*.c))
NATIVE_EMU_SOURCES := $(sort $(wildcard firmware/native/*.c))
NATIVE_DEFINES := -DQS_BOARD=0 -DQS_AXIS_COUNT=4 -DQS_QUEUE_CAPACITY=127 -DQS_TICK_HZ=50000UL
NATIVE_CFLAGS := -std=c99 -O2 -g -Wall -Wextra -Werror $(NATIVE_DEFINES) -Ifirmware/core
# The emulator's own files use POSIX (pseudo-terminals, sockets, clocks).
NATIVE_EMU_CFLAGS := $(NATIVE_CFLAGS) -D_DEFAULT_SOURCE -D_XOPEN_SOURCE=700

.PHONY: emulator bench-engine

emulator: $(NATIVE_OUT)/quadstep-emu

$(NATIVE_OUT)/core/%.o: firmware/core/%.c
	@mkdir -p $(@D)
	$(CC) $(NATIVE_CFLAGS) -MMD -MP -c $< -o $@

$(NATIVE_OUT)/emu/%.o: firmware/native/%.c
	@mkdir -p $(@D)
	$(CC) $(NATIVE_EMU_CFLAGS) -MMD -MP -c $< -o $@

NATIVE_CORE_OBJS := $(patsubst firmware/core/%.c,$(NATIVE_OUT)/core/%.o,$(NATIVE_CORE_SOURCES))
NATIVE_EMU_OBJS := $(patsubst firmware/native/%.c,$(NATIVE_OUT)/emu/%.o,$(NATIVE_EMU_SOURCES))

$(NATIVE_OUT)/quadstep-emu: $(NATIVE_CORE_OBJS) $(NATIVE_EMU_OBJS)
	$(CC) $^ -o $@ -lm

# Engine speed, free-running on this machine: prints axis-ticks per second.
bench-engine: $(NATIVE_OUT)/bench_engine
	$(NATIVE_OUT)/bench_engine

$(NATIVE_OUT)/bench_engine: tests/bench/bench_engine.c $(NATIVE_CORE_OBJS)
	@mkdir -p $(@D)
	$(CC) $(NATIVE_CFLAGS) -D_POSIX_C_SOURCE=200809L $^ -o $@

-include $(NATIVE_CORE_OBJS:.o=.d) $(NATIVE_EMU_OBJS:.o=.d)

# The emulator with AddressSanitizer and UndefinedBehaviorSanitizer, any
# finding fatal; `make test-sanitize` runs the whole Python suite on it.
SAN_OUT := $(BUILD)/native-san
SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

.PHONY: emulator-sanitize test-sanitize

emulator-sanitize: $(SAN_OUT)/quadstep-emu

$(SAN_OUT)/quadstep-emu: $(NATIVE_CORE_SOURCES) $(NATIVE_EMU_SOURCES) $(wildcard firmware/core/*.h firmware/native/*.h)
	@mkdir -p $(@D)
	$(CC) $(NATIVE_EMU_CFLAGS) $(SAN_FLAGS) $(NATIVE_CORE_SOURCES) $(NATIVE_EMU_SOURCES) -o $@ -lm

test-sanitize: setup all harness $(SAN_OUT)/quadstep-emu
	QUADSTEP_EMULATOR=$(abspath $(SAN_OUT)/quadstep-emu) ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 $(VENV_PYTHON) -m pytest -q
