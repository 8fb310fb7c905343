/* What the harness knows about each board (mirrors firmware/avr/board.h). */
#include "sim_board.h"

#include <string.h>

static const sim_board boards[] = {
    /* Uno: step PD2..PD4, dir PD5..PD7; vectors per the ATmega328P datasheet. */
    /* Inputs: limits X/Y/Z on PB1/PB2/PB4; probe PC5, abort PC0, feed hold PC1, cycle start PC2. */
    {"atmega328p", 'D', 2, 5, 3, 11, 12, 18, 19, 0x100, 'B', 'C', {1, 2, 4, -1, -1, -1, -1, -1, 5, 0, 1, 2}, 1},
    /* Mega: step PA0..PA3, dir PA4..PA7; vectors per the ATmega2560 datasheet.
     * Inputs: min limits PK0..PK3, max PK4..PK7; probe PB5, abort PB0, feed hold PB1, cycle start PB2. */
    {"atmega2560", 'A', 0, 4, 4, 17, 18, 25, 26, 0x200, 'K', 'B', {0, 1, 2, 3, 4, 5, 6, 7, 5, 0, 1, 2}, 0},
};

const sim_board *sim_board_find(const char *mcu)
{
    for (size_t i = 0; i < sizeof boards / sizeof boards[0]; i++) {
        if (strcmp(boards[i].mcu, mcu) == 0) {
            return &boards[i];
        }
    }
    return NULL;
}
