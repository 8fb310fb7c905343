/* Stack high-water mark: RAM above the firmware's static data is painted
 * before reset; the lowest byte that no longer holds the paint is as deep
 * as the stack reached (a pushed byte equal to the paint can hide one). */
#ifndef SIM_STACK_H
#define SIM_STACK_H

#include <stdint.h>

#include "sim_avr.h"

#define SIM_STACK_PAINT 0xA5

typedef struct {
    uint16_t static_end; /* first address above .data/.bss (__bss_end) */
    uint16_t ram_end;
    uint16_t deepest;    /* lowest address the stack wrote */
    uint16_t max_bytes;  /* ram_end - deepest + 1 */
} sim_stack_stats;

void sim_stack_paint(avr_t *avr, uint16_t static_end);

sim_stack_stats sim_stack_measure(const avr_t *avr, uint16_t static_end);

#endif
