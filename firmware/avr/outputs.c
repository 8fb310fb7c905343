/* The spindle (or laser) PWM, its direction and the coolant pins, driven
 * from the main loop once per PWM period: the core computes the level from
 * the engine's running state (qs_outputs.h), so a power that follows the
 * speed is right at every period, ramps and holds included. */
#include "outputs.h"

#include <avr/io.h>

#include "board.h"
#include "firmware.h"

void outputs_init(void)
{
    QS_PWM_DDR |= _BV(QS_PWM_BIT); /* low while OC2A is disconnected */
    QS_SPINDLE_DIR_DDR |= _BV(QS_SPINDLE_DIR_BIT);
    QS_COOLANT_DDR |= _BV(QS_FLOOD_BIT) | _BV(QS_MIST_BIT);
    OCR2A = 0;
    TCCR2A = _BV(WGM21) | _BV(WGM20); /* fast PWM, OC2A disconnected */
    TCCR2B = _BV(CS22);               /* clock / 64 */
}

/* OCR2A is buffered: written now, it takes effect at the next period. A
 * RASTER's pixel is looked up for the middle of that period, so each
 * period shows the pixel under the head half-way through it, not the one
 * there a period or more before. */
static uint16_t raster_ahead(void)
{
    const uint16_t cycles = (uint16_t)((256u - TCNT2) * 64u + 128u * 64u);
    return (uint16_t)(cycles / (uint16_t)(F_CPU / QS_TICK_HZ));
}

/* A pin of a port the step interrupt never writes. */
#define SET_PIN(port, bit, on) ((on) ? ((port) |= _BV(bit)) : ((port) &= (uint8_t)~_BV(bit)))

QS_NOINLINE void outputs_update(void)
{
    qs_output_level level;
    uint8_t pins;

    TIFR2 = _BV(TOV2);
    if (qs_outputs_all_off(&core.outputs)) {
        level.pins = 0; /* no need to look at the engine */
        level.duty = 0;
    } else {
        qs_core_outputs(&core, &level, QS_RASTER_BYTES ? raster_ahead() : 0);
    }
    /* OCR2A takes effect at the next period: high for (OCR2A + 1) / 256 of
     * it; a duty of 0 disconnects the pin, which then stays low. Registers
     * are written only when they change. */
    if (OCR2A != (uint8_t)(level.duty >> 8))
        OCR2A = (uint8_t)(level.duty >> 8);
    if (!level.duty != !(TCCR2A & _BV(COM2A1)))
        TCCR2A ^= _BV(COM2A1);
    /* Written only when they change: the ports also hold input pull-ups
     * (and simavr drives the PWM pin from its port on every write). */
    pins = (uint8_t)(level.pins & (QS_OUT_REVERSE | QS_OUT_FLOOD | QS_OUT_MIST));
    if (pins == (uint8_t)((QS_SPINDLE_DIR_PORT & _BV(QS_SPINDLE_DIR_BIT) ? QS_OUT_REVERSE : 0)
                          | (QS_COOLANT_PORT & _BV(QS_FLOOD_BIT) ? QS_OUT_FLOOD : 0)
                          | (QS_COOLANT_PORT & _BV(QS_MIST_BIT) ? QS_OUT_MIST : 0)))
        return;
    SET_PIN(QS_SPINDLE_DIR_PORT, QS_SPINDLE_DIR_BIT, pins & QS_OUT_REVERSE);
    SET_PIN(QS_COOLANT_PORT, QS_FLOOD_BIT, pins & QS_OUT_FLOOD);
    SET_PIN(QS_COOLANT_PORT, QS_MIST_BIT, pins & QS_OUT_MIST);
}
