/* Watches the spindle (or laser) PWM, direction and coolant pins
 * (firmware/avr/board.h) and writes every edge as CSV "cycle,pin,level",
 * pin one of pwm, direction, flood, mist. */
#ifndef SIM_OUTPUTS_H
#define SIM_OUTPUTS_H

#include <stdio.h>

#include "sim_avr.h"
#include "sim_board.h"

/* 0 on success; file may be NULL (nothing recorded). */
int sim_outputs_attach(avr_t *avr, const sim_board *board, FILE *file);

#endif
