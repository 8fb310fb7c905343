# AVR board firmware: the portable core plus firmware/avr, built with avr-gcc
# for the Uno (ATmega328P, 3 axes) and the Mega (ATmega2560, 4 axes).
# platformio.ini builds the same sources with the same flags and defines;
# tests/simavr/test_platformio_sync.py holds the two in step (it reads them
# with `make -s print-avr-vars`).
#
# Build settings can be overridden on the command line, e.g.
#   make firmware AVR_TICK_HZ=50000 AVR_BAUD=1000000 BUILD=build/t50k
# (AVR_TICK_HZ sets both boards; AVR_UNO_TICK_HZ or AVR_MEGA_TICK_HZ one).

AVR_CC ?= avr-gcc
AVR_SIZE ?= avr-size
AVR_OBJDUMP ?= avr-objdump
AVR_OBJCOPY ?= avr-objcopy
AVR_OUT := $(BUILD)/avr

AVR_SOURCES := $(sort $(wildcard firmware/core/*.c)) $(sort $(wildcard firmware/avr/*.c))
AVR_INCLUDES := -Ifirmware/core -Ifirmware/avr

# Settings a user may change (each is a -D define the sources read). The
# tick rate is the board's: the highest at which the step interrupt leaves
# room for the rest (docs/AVR.md, "Figures"); the Mega's fourth axis costs
# it the Uno's.
AVR_F_CPU ?= 16000000L
AVR_UNO_TICK_HZ ?= 32000
AVR_MEGA_TICK_HZ ?= 25000
ifdef AVR_TICK_HZ
AVR_UNO_TICK_HZ := $(AVR_TICK_HZ)
AVR_MEGA_TICK_HZ := $(AVR_TICK_HZ)
endif
AVR_BAUD ?= 500000
AVR_STEP_PULSE_US ?= 2

AVR_DEFINES := -DF_CPU=$(AVR_F_CPU) -DQS_BAUD=$(AVR_BAUD) -DQS_STEP_PULSE_US=$(AVR_STEP_PULSE_US)
AVR_UNO_MCU := atmega328p
AVR_UNO_DEFINES := -DQS_BOARD=1 -DQS_AXIS_COUNT=3 -DQS_QUEUE_CAPACITY=14 -DQS_LATCH_RING=1 -DQS_QUADRATIC_RUNS=0 -DQS_TICK_HZ=$(AVR_UNO_TICK_HZ)
# The Uno for a laser: RASTER (a ring of 128 powers) in the room of the
# cubic segments (jerk-limited motion, which rasters do not use) and two
# queue slots (docs/AVR.md, "The Uno's laser build").
AVR_UNO_LASER_MCU := atmega328p
AVR_UNO_LASER_DEFINES := -DQS_BOARD=1 -DQS_AXIS_COUNT=3 -DQS_QUEUE_CAPACITY=12 -DQS_LATCH_RING=1 -DQS_QUADRATIC_RUNS=0 -DQS_CUBIC=0 -DQS_RASTER_BYTES=128 -DQS_TICK_HZ=$(AVR_UNO_TICK_HZ)
AVR_MEGA_MCU := atmega2560
AVR_MEGA_DEFINES := -DQS_BOARD=2 -DQS_AXIS_COUNT=4 -DQS_QUEUE_CAPACITY=32 -DQS_TICK_HZ=$(AVR_MEGA_TICK_HZ)

# The flags PlatformIO's bare atmelavr build uses, plus strict warnings.
AVR_CFLAGS := -std=gnu11 -Os -Wall -Wextra -Werror -ffunction-sections -fdata-sections \
	-flto -fno-fat-lto-objects -g
AVR_LDFLAGS := -Os -Wl,--gc-sections -Wl,--relax -flto -fuse-linker-plugin -Wl,--undefined=qs_debug_probe

.PHONY: firmware print-avr-vars avr-disasm avr-flags-changed

# Objects depend on this file, rewritten only when a setting or flag changes,
# so `make firmware AVR_TICK_HZ=...` into the same BUILD rebuilds everything.
AVR_FLAGS_STAMP := $(AVR_OUT)/flags
AVR_FLAGS_TEXT := $(AVR_CFLAGS) $(AVR_LDFLAGS) $(AVR_DEFINES) $(AVR_UNO_DEFINES) $(AVR_UNO_LASER_DEFINES) \
	$(AVR_MEGA_DEFINES)
$(AVR_FLAGS_STAMP): avr-flags-changed
	@mkdir -p $(@D)
	@echo '$(AVR_FLAGS_TEXT)' | cmp -s - $@ || echo '$(AVR_FLAGS_TEXT)' > $@

AVR_BOARDS := uno uno-laser mega
firmware: $(foreach b,$(AVR_BOARDS),$(AVR_OUT)/$(b).elf $(AVR_OUT)/$(b).hex)
	@for b in uno:$(AVR_UNO_MCU) uno-laser:$(AVR_UNO_LASER_MCU) mega:$(AVR_MEGA_MCU); do \
	  elf=$(AVR_OUT)/$${b%%:*}.elf; \
	  $(AVR_SIZE) -A $$elf | awk -v name=$${b%%:*} -v mcu=$${b#*:} \
	    '$$1==".text"{t=$$2} $$1==".data"{d=$$2} $$1==".bss"{b=$$2} $$1==".noinit"{n=$$2} \
	     END{printf "%-9s %-10s flash %6d bytes   RAM %5d bytes (data %d + bss %d + noinit %d)\n", \
	         name, mcu, t+d, d+b+n, d, b, n}'; \
	done

# $(1): board name, $(2): MCU, $(3): board defines
define AVR_BOARD_RULES
$(AVR_OUT)/$(1)/%.o: %.c $$(AVR_FLAGS_STAMP)
	@mkdir -p $$(@D)
	$$(AVR_CC) -mmcu=$(2) $$(AVR_CFLAGS) $$(AVR_DEFINES) $(3) $$(AVR_INCLUDES) -MMD -MP -c $$< -o $$@

$(AVR_OUT)/$(1).elf: $$(patsubst %.c,$(AVR_OUT)/$(1)/%.o,$$(AVR_SOURCES)) $$(AVR_FLAGS_STAMP)
	$$(AVR_CC) -mmcu=$(2) $$(AVR_CFLAGS) $$(AVR_LDFLAGS) $$(filter %.o,$$^) -o $$@

-include $$(patsubst %.c,$(AVR_OUT)/$(1)/%.d,$$(AVR_SOURCES))
endef

# What avrdude writes (quadstep flash): the flash image as Intel HEX.
$(AVR_OUT)/%.hex: $(AVR_OUT)/%.elf
	$(AVR_OBJCOPY) -O ihex -R .eeprom -R .noinit $< $@

$(eval $(call AVR_BOARD_RULES,uno,$(AVR_UNO_MCU),$(AVR_UNO_DEFINES)))
$(eval $(call AVR_BOARD_RULES,uno-laser,$(AVR_UNO_LASER_MCU),$(AVR_UNO_LASER_DEFINES)))
$(eval $(call AVR_BOARD_RULES,mega,$(AVR_MEGA_MCU),$(AVR_MEGA_DEFINES)))

# Annotated disassembly, for reading where the step interrupt's cycles go.
avr-disasm: $(AVR_OUT)/uno.elf
	$(AVR_OBJDUMP) -d -S $< > $(AVR_OUT)/uno.lst
	@echo "wrote $(AVR_OUT)/uno.lst"

print-avr-vars:
	@echo 'AVR_SOURCES=$(AVR_SOURCES)'
	@echo 'AVR_INCLUDES=$(AVR_INCLUDES)'
	@echo 'AVR_DEFINES=$(AVR_DEFINES)'
	@echo 'AVR_UNO_MCU=$(AVR_UNO_MCU)'
	@echo 'AVR_UNO_DEFINES=$(AVR_UNO_DEFINES)'
	@echo 'AVR_UNO_LASER_MCU=$(AVR_UNO_LASER_MCU)'
	@echo 'AVR_UNO_LASER_DEFINES=$(AVR_UNO_LASER_DEFINES)'
	@echo 'AVR_MEGA_MCU=$(AVR_MEGA_MCU)'
	@echo 'AVR_MEGA_DEFINES=$(AVR_MEGA_DEFINES)'
	@echo 'AVR_CFLAGS=$(AVR_CFLAGS)'
	@echo 'AVR_LDFLAGS=$(AVR_LDFLAGS)'
