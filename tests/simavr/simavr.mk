# qs-simavr: the harness that runs the real AVR firmware ELF in simavr
# (Debian's libsimavr). It decodes the board's replies with the core's own
# frame code, compiled natively, and moves the emulator's simulated machine
# (firmware/native/machine.c) from the step pins.

SIMAVR_OUT := $(BUILD)/simavr
SIMAVR_SOURCES := $(sort $(wildcard tests/simavr/*.c)) \
	firmware/core/qs_frame.c firmware/core/qs_cobs.c firmware/core/qs_crc16.c firmware/core/qs_messages.c firmware/core/qs_varint.c \
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

# The AVR's written-out forms of core functions (the cubic sums, the receive
# copy) against their C forms, for each board's layout: a small AVR program
# run in simavr (test_avr_forms.py). The cubic sums' C forms are built for
# the AVR under other names (ref_*).
CUBIC_CHECK_REF := -DQS_CUBIC_SUMS_IN_C -Dqs_cubic_load=ref_load -Dqs_cubic_check=ref_check \
	-Dqs_cubic_last=ref_last -Dqs_cubic_finish=ref_finish

.PHONY: avr-forms-check
avr-forms-check: $(SIMAVR_OUT)/forms-uno.elf $(SIMAVR_OUT)/forms-mega.elf

# $(1): board name, $(2): MCU, $(3): board defines
define CUBIC_CHECK_RULES
$(SIMAVR_OUT)/forms-$(1).elf: tests/simavr/avr/forms_check.c firmware/core/qs_cubic_sums.c \
		firmware/avr/cubic_sums.c firmware/avr/frame_rx.h $(wildcard firmware/core/*.h) $$(AVR_FLAGS_STAMP)
	@mkdir -p $$(@D)
	$$(AVR_CC) -mmcu=$(2) -std=gnu11 -Os -Wall -Wextra -Werror $$(AVR_DEFINES) $(3) $$(AVR_INCLUDES) \
		$$(CUBIC_CHECK_REF) -c firmware/core/qs_cubic_sums.c -o $$(@:.elf=-ref.o)
	$$(AVR_CC) -mmcu=$(2) -std=gnu11 -Os -Wall -Wextra -Werror $$(AVR_DEFINES) $(3) $$(AVR_INCLUDES) \
		tests/simavr/avr/forms_check.c firmware/avr/cubic_sums.c $$(@:.elf=-ref.o) -o $$@
endef

$(eval $(call CUBIC_CHECK_RULES,uno,$(AVR_UNO_MCU),$(AVR_UNO_DEFINES)))
$(eval $(call CUBIC_CHECK_RULES,mega,$(AVR_MEGA_MCU),$(AVR_MEGA_DEFINES)))
