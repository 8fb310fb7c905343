/* What the harness knows about each board: where the motion pins are and
 * which interrupt vectors to watch (mirrors firmware/avr/board.h). */
#ifndef SIM_BOARD_H
#define SIM_BOARD_H

#include <stdint.h>

typedef struct {
    const char *mcu;
    char motion_port;    /* port letter holding step and dir pins */
    uint8_t step_shift;  /* step pin of axis i: bit step_shift + i */
    uint8_t dir_shift;   /* dir pin of axis i: bit dir_shift + i (high = negative) */
    uint8_t axes;
    uint8_t timer_vector; /* TIMER1_COMPA */
    uint8_t rest_vector;  /* TIMER1_COMPB: the tick while the engine rests */
    uint8_t rx_vector;    /* USART0 RX complete */
    uint8_t udre_vector;  /* USART0 data register empty */
    uint16_t ram_start;
    /* Inputs (firmware/avr/board.h, PROTOCOL.md 5.4): inputs 0-7 on the
     * limit port, 8-11 on the control port; bit of each, -1 if absent. */
    char limit_port;
    char control_port;
    int8_t input_bit[12];
    uint8_t shared_limits; /* one limit pin per axis for min and max */
} sim_board;

/* NULL for an MCU the harness does not know. */
const sim_board *sim_board_find(const char *mcu);

#endif
