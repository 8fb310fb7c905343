/* The rare path of the tick's input sample (inputs_tick.h): the pins have
 * changed, or a debounce window is open. */
#include "inputs_tick.h"

#include "firmware.h"

volatile uint8_t inputs_seen_limits;
volatile uint8_t inputs_seen_control = 0xFF; /* no sample yet: the first tick looks */

/* Called from the step interrupt's asm, which saved the registers. */
__attribute__((used, externally_visible)) void inputs_changed(void)
{
    const uint8_t limits = QS_LIMIT_PIN & QS_LIMIT_MASK;
    const uint8_t control = QS_CONTROL_PIN & QS_CONTROL_MASK;
    const uint16_t raw = (uint16_t)(QS_LIMIT_INPUTS(limits) | QS_CONTROL_INPUTS(control));

    inputs_seen_limits = limits;
    inputs_seen_control = qs_inputs_update(&core.inputs, &core.engine, raw) ? 0xFF : control;
}
