/* Stack high-water mark (see sim_stack.h). */
#include "sim_stack.h"

void sim_stack_paint(avr_t *avr, uint16_t static_end)
{
    for (uint32_t a = static_end; a <= avr->ramend; a++) {
        avr->data[a] = SIM_STACK_PAINT;
    }
}

sim_stack_stats sim_stack_measure(const avr_t *avr, uint16_t static_end)
{
    sim_stack_stats s = {static_end, (uint16_t)avr->ramend, (uint16_t)avr->ramend, 0};
    uint32_t a = static_end;
    while (a <= avr->ramend && avr->data[a] == SIM_STACK_PAINT) {
        a++;
    }
    if (a <= avr->ramend) {
        s.deepest = (uint16_t)a;
        s.max_bytes = (uint16_t)(avr->ramend - a + 1);
    }
    return s;
}
