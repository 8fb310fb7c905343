/* Board pin setup: motion outputs, driver enable, inputs. */
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

    /* Switches and buttons close to ground: inputs with pull-ups. */
    QS_LIMIT_DDR &= (uint8_t)~QS_LIMIT_MASK;
    QS_LIMIT_PORT |= QS_LIMIT_MASK;
    QS_CONTROL_DDR &= (uint8_t)~QS_CONTROL_MASK;
    QS_CONTROL_PORT |= QS_CONTROL_MASK;
    /* Their changes raise the pin-change flags the tick looks at; no
     * interrupt (PCICR stays 0). */
    QS_LIMIT_PCMSK = QS_LIMIT_MASK;
    QS_CONTROL_PCMSK = QS_CONTROL_MASK;
}
