/* Where the step engine's tick-visible state lives in data memory, for a
 * debugger or a simulator watching the board run. tests/simavr's harness
 * reads `left` and the queue's `tail` before and after each tick interrupt
 * to number motion ticks exactly as the core counts them, and the latch
 * ring's write index to time the latches. Ten bytes of
 * flash; the firmware never reads them, so avr.mk and platformio.ini keep
 * them with -Wl,--undefined. */
#include <avr/pgmspace.h>

#include "firmware.h"

const volatile void *const qs_debug_probe[] PROGMEM = {
    (const volatile void *)5,  /* layout version */
    &core.engine.left,         /* uint16_t: ticks left in the running segment */
    &core.engine.queue.tail,   /* uint8_t: released with each finished segment */
    &core.engine.state,        /* uint8_t: QS_STATE_* */
    &core.engine.latches.taken, /* uint8_t: moves on with each latch the tick takes */
    &core.engine.hold.tick_byte, /* uint8_t: moves on with each tick of a hold */
    &core.engine.resequence,   /* uint8_t: set by a trigger's hold, in the tick */
    &core.engine.hold.moving,  /* uint8_t: axes a hold still decelerates */
};
