# qs-simavr: the harness that runs the real AVR firmware ELF in simavr
# (Debian's libsimavr). It decodes the board's replies with the core's own
# frame code, compiled natively, and moves the emulator's simulated machine
# (firmware/native/machine.c) from the step pins.

SIMAVR_OUT := $(BUILD)/simavr
SIMAVR_SOURCES := $(sort $(wildcard tests/simavr/*.c)) \
	firmware/core/qs_frame.c firmware/core/qs_cobs.c firmware/core/qs_crc16.c \
	firmware/native/machine.c firmware/native/machine_file.c firmware/native/toml_lite.c
SIMAVR_CFLAGS := -std=gnu11 -O2 -g -Wall -Wextra -Werror \
	$(shell pkg-config --cflags simavr 2>/dev/null || echo -I/usr/include/simavr) \
	-Ifirmware/core -Ifirmware/native -Itests/simavr
SIMAVR_LIBS := $(shell pkg-config --libs simavr 2>/dev/null || echo -lsimavr) -lelf -lm

.PHONY: harness

harness: $(SIMAVR_OUT)/qs-simavr

$(SIMAVR_OUT)/%.o: %.c
	@mkdir -p $(@D)
	$(CC) $(SIMAVR_CFLAGS) -MMD -MP -c $< -o $@

$(SIMAVR_OUT)/qs-simavr: $(patsubst %.c,$(SIMAVR_OUT)/%.o,$(SIMAVR_SOURCES))
	$(CC) $^ -o $@ $(SIMAVR_LIBS)

-include $(patsubst %.c,$(SIMAVR_OUT)/%.d,$(SIMAVR_SOURCES))
