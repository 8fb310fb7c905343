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
/* Limit inputs X/Y/Z: D9/D10/D12 = PB1/PB2/PB4 (pull-ups; reserved). */
#define QS_LIMIT_PORT PORTB
#define QS_LIMIT_DDR DDRB
#define QS_LIMIT_MASK (_BV(PB1) | _BV(PB2) | _BV(PB4))
/* Probe input: A5 = PC5 (pull-up; reserved). */
#define QS_PROBE_PORT PORTC
#define QS_PROBE_DDR DDRC
#define QS_PROBE_BIT PC5

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
/* Limit inputs X/Y/Z/A: D31/D32/D33/D34 = PC6/PC5/PC4/PC3 (pull-ups; reserved). */
#define QS_LIMIT_PORT PORTC
#define QS_LIMIT_DDR DDRC
#define QS_LIMIT_MASK (_BV(PC6) | _BV(PC5) | _BV(PC4) | _BV(PC3))
/* Probe input: D35 = PC2 (pull-up; reserved). */
#define QS_PROBE_PORT PORTC
#define QS_PROBE_DDR DDRC
#define QS_PROBE_BIT PC2

#else
#error "QS_BOARD must be 1 (ATmega328P) or 2 (ATmega2560) for the AVR build"
#endif

#if QS_AXIS_COUNT > QS_MAX_AXES
#error "QS_AXIS_COUNT exceeds the step/dir pins this board maps"
#endif

#define QS_AXIS_MASK ((uint8_t)((1u << QS_AXIS_COUNT) - 1u))
#define QS_STEP_PINS ((uint8_t)(QS_AXIS_MASK << QS_STEP_SHIFT))
#define QS_DIR_PINS ((uint8_t)(QS_AXIS_MASK << QS_DIR_SHIFT))

#endif
