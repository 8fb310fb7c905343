/* What the harness knows about each board (mirrors firmware/avr/board.h). */
#include "sim_board.h"

#include <string.h>

static const sim_board boards[] = {
    /* Uno: step PD2..PD4, dir PD5..PD7; vectors per the ATmega328P datasheet. */
    {"atmega328p", 'D', 2, 5, 3, 11, 18, 19, 0x100},
    /* Mega: step PA0..PA3, dir PA4..PA7; vectors per the ATmega2560 datasheet. */
    {"atmega2560", 'A', 0, 4, 4, 17, 25, 26, 0x200},
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
