/* Watches the output pins (see sim_outputs.h). */
#include "sim_outputs.h"

#include <string.h>

#include "avr_ioport.h"

typedef struct {
    const char *name;
    char port;
    uint8_t bit;
} output_pin;

typedef struct {
    const char *mcu;
    output_pin pins[4];
} board_outputs;

/* As firmware/avr/board.h has them. */
static const board_outputs boards[] = {
    {"atmega328p", {{"pwm", 'B', 3}, {"direction", 'B', 5}, {"flood", 'C', 3}, {"mist", 'C', 4}}},
    {"atmega2560", {{"pwm", 'B', 4}, {"direction", 'B', 7}, {"flood", 'H', 5}, {"mist", 'H', 6}}},
};

typedef struct {
    avr_t *avr;
    FILE *file;
    const char *name;
    int level;
} watch;

static watch watches[4];

static void on_pin(avr_irq_t *irq, uint32_t value, void *param)
{
    watch *w = param;
    const int level = value != 0;
    (void)irq;
    if (level == w->level) {
        return;
    }
    w->level = level;
    fprintf(w->file, "%llu,%s,%d\n", (unsigned long long)w->avr->cycle, w->name, level);
}

int sim_outputs_attach(avr_t *avr, const sim_board *board, FILE *file)
{
    if (!file) {
        return 0;
    }
    for (size_t b = 0; b < sizeof boards / sizeof boards[0]; b++) {
        if (strcmp(boards[b].mcu, board->mcu) != 0) {
            continue;
        }
        fputs("cycle,pin,level\n", file);
        for (int i = 0; i < 4; i++) {
            const output_pin *p = &boards[b].pins[i];
            avr_irq_t *irq = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(p->port), p->bit);
            if (!irq) {
                return -1;
            }
            watches[i] = (watch){avr, file, p->name, 0};
            avr_irq_register_notify(irq, on_pin, &watches[i]);
        }
        return 0;
    }
    return -1;
}
