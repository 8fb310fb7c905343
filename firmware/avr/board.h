/* Pin map and per-chip names for the two boards (docs/AVR.md has the tables).
 *
 * Step and direction pins of all axes share one 8-bit port, step pins in one
 * run of bits and direction pins in another, so that the step interrupt sets
 * every pin of a tick with a single `out` instruction and needs no per-axis
 * bit juggling: pins = (dir_bits << QS_DIR_SHIFT) | (steps << QS_STEP_SHIFT). */
#ifndef QS_BOARD_H
#define QS_BOARD_H

#include <avr/io.h>

#if QS_BOARD == 1
/* Arduino Uno (ATmega328P) with the common GRBL CNC shield:
 * step X/Y/Z = D2/D3/D4 = PD2..PD4, dir X/Y/Z = D5/D6/D7 = PD5..PD7.
 * PD0/PD1 are the UART; the UART overrides them, so writing 0 there is harmless. */
#if !defined(__AVR_ATmega328P__)
#error "QS_BOARD=1 is the ATmega328P (-mmcu=atmega328p)"
#endif
#define QS_MAX_AXES 3
#define QS_MOTION_PORT PORTD
#define QS_MOTION_DDR DDRD
#define QS_STEP_SHIFT 2
#define QS_DIR_SHIFT 5
/* Stepper driver enable: D8 = PB0, active low. */
#define QS_ENABLE_PORT PORTB
#define QS_ENABLE_DDR DDRB
#define QS_ENABLE_BIT PB0
/* Inputs, all with pull-ups (a switch to ground closes them), on two
 * ports whose pin-change flags the tick looks at (inputs_tick.h). Limits
 * X/Y/Z: D9/D10/D12 = PB1/PB2/PB4, one pin per axis as on the shield (an
 * axis's min and max switches share it). Control: abort A0 = PC0, feed
 * hold A1 = PC1, cycle start A2 = PC2, probe A5 = PC5. */
#define QS_LIMIT_PORT PORTB
#define QS_LIMIT_DDR DDRB
#define QS_LIMIT_PIN PINB
#define QS_LIMIT_MASK (_BV(PB1) | _BV(PB2) | _BV(PB4))
#define QS_LIMIT_PCMSK PCMSK0
#define QS_LIMIT_PCIF PCIF0
/* Limit pins to input numbers (qs_inputs.h): PB1, PB2, PB4 -> 0, 1, 2. */
#define QS_LIMIT_INPUTS(b) ((uint16_t)((((b) >> 1) & 3u) | (((b) >> 2) & 4u)))
#define QS_CONTROL_PORT PORTC
#define QS_CONTROL_DDR DDRC
#define QS_CONTROL_PIN PINC
#define QS_CONTROL_PCMSK PCMSK1
#define QS_CONTROL_PCIF PCIF1
#define QS_INPUTS_PRESENT 0x0F07u /* limits 0-2, probe, abort, feed hold, cycle start */
/* Outputs (outputs.c), as on GRBL's shield: spindle or laser PWM on D11 =
 * PB3 (Timer2's OC2A), spindle direction D13 = PB5, coolant flood A3 = PC3,
 * mist A4 = PC4. */
#define QS_PWM_DDR DDRB
#define QS_PWM_PORT PORTB
#define QS_PWM_BIT PB3
#define QS_SPINDLE_DIR_PORT PORTB
#define QS_SPINDLE_DIR_DDR DDRB
#define QS_SPINDLE_DIR_BIT PB5
#define QS_COOLANT_PORT PORTC
#define QS_COOLANT_DDR DDRC
#define QS_FLOOD_BIT PC3
#define QS_MIST_BIT PC4

#elif QS_BOARD == 2
/* Arduino Mega 2560: all motion pins on PORTA (the double header's D22..D29):
 * step X/Y/Z/A = D22/D23/D24/D25 = PA0..PA3, dir X/Y/Z/A = D26..D29 = PA4..PA7. */
#if !defined(__AVR_ATmega2560__)
#error "QS_BOARD=2 is the ATmega2560 (-mmcu=atmega2560)"
#endif
#define QS_MAX_AXES 4
#define QS_MOTION_PORT PORTA
#define QS_MOTION_DDR DDRA
#define QS_STEP_SHIFT 0
#define QS_DIR_SHIFT 4
/* Stepper driver enable: D30 = PC7, active low. */
#define QS_ENABLE_PORT PORTC
#define QS_ENABLE_DDR DDRC
#define QS_ENABLE_BIT PC7
/* Inputs, all with pull-ups (a switch to ground closes them), on two
 * ports with pin-change flags. Limits on PORTK, a min and a max switch per
 * axis: min X/Y/Z/A = A8/A9/A10/A11 (PK0..PK3), max X/Y/Z/A =
 * A12/A13/A14/A15 (PK4..PK7). Control on PORTB, in the Uno's PORTC bits:
 * abort D53 = PB0, feed hold D52 = PB1, cycle start D51 = PB2, probe
 * D11 = PB5 (SPI is unused). */
#define QS_LIMIT_PORT PORTK
#define QS_LIMIT_DDR DDRK
#define QS_LIMIT_PIN PINK
#define QS_LIMIT_MASK 0xFF
#define QS_LIMIT_PCMSK PCMSK2
#define QS_LIMIT_PCIF PCIF2
#define QS_LIMIT_INPUTS(b) ((uint16_t)(b))
#define QS_CONTROL_PORT PORTB
#define QS_CONTROL_DDR DDRB
#define QS_CONTROL_PIN PINB
#define QS_CONTROL_PCMSK PCMSK0
#define QS_CONTROL_PCIF PCIF0
#define QS_INPUTS_PRESENT 0x0FFFu
/* Outputs (outputs.c): spindle or laser PWM on D10 = PB4 (Timer2's OC2A),
 * spindle direction D13 = PB7, coolant flood D8 = PH5, mist D9 = PH6. */
#define QS_PWM_DDR DDRB
#define QS_PWM_PORT PORTB
#define QS_PWM_BIT PB4
#define QS_SPINDLE_DIR_PORT PORTB
#define QS_SPINDLE_DIR_DDR DDRB
#define QS_SPINDLE_DIR_BIT PB7
#define QS_COOLANT_PORT PORTH
#define QS_COOLANT_DDR DDRH
#define QS_FLOOD_BIT PH5
#define QS_MIST_BIT PH6

#else
#error "QS_BOARD must be 1 (ATmega328P) or 2 (ATmega2560) for the AVR build"
#endif

/* Control pins on both boards: abort, feed hold, cycle start on bits 0-2,
 * the probe on bit 5; to input numbers 9, 10, 11 and 8. */
#define QS_CONTROL_MASK 0x27u
#define QS_CONTROL_INPUTS(c) ((uint16_t)((uint16_t)(uint8_t)((((c) & 7u) << 1) | (((uint8_t)(c) >> 5) & 1u)) << 8))
/* The pin-change flags of both ports (set by any change of a masked pin;
 * the pin-change interrupts themselves stay off). */
#define QS_INPUT_FLAGS ((uint8_t)(_BV(QS_LIMIT_PCIF) | _BV(QS_CONTROL_PCIF)))

#if QS_AXIS_COUNT > QS_MAX_AXES
#error "QS_AXIS_COUNT exceeds the step/dir pins this board maps"
#endif

#define QS_AXIS_MASK ((uint8_t)((1u << QS_AXIS_COUNT) - 1u))
#define QS_STEP_PINS ((uint8_t)(QS_AXIS_MASK << QS_STEP_SHIFT))
#define QS_DIR_PINS ((uint8_t)(QS_AXIS_MASK << QS_DIR_SHIFT))

#endif
