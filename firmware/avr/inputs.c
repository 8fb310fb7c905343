/* The rare path of the tick's input sample (inputs_tick.h): a pin has
 * changed, or a debounce window is open. */
#include "inputs_tick.h"

#include "firmware.h"

static uint16_t read_inputs(void)
{
    const uint8_t limits = QS_LIMIT_PIN & QS_LIMIT_MASK; /* each port read once */
    const uint8_t control = QS_CONTROL_PIN & QS_CONTROL_MASK;

    return (uint16_t)(QS_LIMIT_INPUTS(limits) | QS_CONTROL_INPUTS(control));
}

/* From the step interrupt's asm (which saved the registers), and once
 * from main before interrupts are on: the power-up state. */
__attribute__((used, externally_visible)) void inputs_changed(void)
{
    uint16_t raw = read_inputs();

    for (;;) {
        uint16_t again;
        if (qs_inputs_update(&core.inputs, &core.engine, raw))
            return; /* the window stays open: the flags stay set, the next tick looks again */
        PCIFR = QS_INPUT_FLAGS; /* cleared by writing ones */
        /* A change between the read and the clear left no flag: look. */
        again = read_inputs();
        if (again == raw)
            return;
        raw = again;
    }
}
