/* Board pin setup: motion outputs, driver enable, reserved inputs. */
#include "pins.h"

#include "board.h"

void pins_init(void)
{
    /* Step and direction pins start low, then become outputs. */
    QS_MOTION_PORT &= (uint8_t)~(QS_STEP_PINS | QS_DIR_PINS);
    QS_MOTION_DDR |= QS_STEP_PINS | QS_DIR_PINS;

    /* Drivers enabled (active low) from power-up: steps are only ever made
     * by segments the host sent, and an enabled driver holds position. */
    QS_ENABLE_PORT &= (uint8_t)~_BV(QS_ENABLE_BIT);
    QS_ENABLE_DDR |= _BV(QS_ENABLE_BIT);

    /* Limit and probe switches close to ground: inputs with pull-ups. They
     * are wired and readable but not acted on by this firmware version. */
    QS_LIMIT_DDR &= (uint8_t)~QS_LIMIT_MASK;
    QS_LIMIT_PORT |= QS_LIMIT_MASK;
    QS_PROBE_DDR &= (uint8_t)~_BV(QS_PROBE_BIT);
    QS_PROBE_PORT |= _BV(QS_PROBE_BIT);
}
