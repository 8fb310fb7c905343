/* The spindle (or laser) PWM, its direction and the coolant pins, driven
 * from the main loop once per PWM period: the core computes the level from
 * the engine's running state (qs_outputs.h), so a power that follows the
 * speed is right at every period, ramps and holds included. A RASTER
 * line's pixels are the step tick's (qs_port_laser_power). */
#include "outputs.h"

#include <avr/io.h>

#include "board.h"
#include "firmware.h"
#include "qs_port.h"

void outputs_init(void)
{
    QS_PWM_DDR |= _BV(QS_PWM_BIT); /* low while OC2A is disconnected */
    QS_SPINDLE_DIR_DDR |= _BV(QS_SPINDLE_DIR_BIT);
    QS_COOLANT_DDR |= _BV(QS_FLOOD_BIT) | _BV(QS_MIST_BIT);
    OCR2A = 0;
    TCCR2A = _BV(WGM21) | _BV(WGM20); /* fast PWM, OC2A disconnected */
    TCCR2B = _BV(CS22);               /* clock / 64 */
}

#if QS_RASTER_BYTES
void qs_port_laser_power(uint8_t power)
{
    outputs_laser_power(power);
}

/* 64 * 256 cycles: 32.8 ticks at 32 kHz, rounded up. */
uint8_t qs_port_laser_period_ticks(void)
{
    return (uint8_t)((64UL * 256UL * QS_TICK_HZ + F_CPU - 1UL) / F_CPU);
}

/* OCR2A is buffered: written now, it takes effect at the next period. A
 * line of pixels shorter than a period (qs_raster_level) has its pixel
 * looked up for the middle of that period, so each period shows the pixel
 * under the head half-way through it, not the one there a period or more
 * before. */
static uint16_t raster_ahead(void)
{
    const uint16_t cycles = (uint16_t)((256u - TCNT2) * 64u + 128u * 64u);
    return (uint16_t)(cycles / (uint16_t)(F_CPU / QS_TICK_HZ));
}
#endif

static void set_duty(uint16_t duty)
{
    if (OCR2A != (uint8_t)(duty >> 8))
        OCR2A = (uint8_t)(duty >> 8);
    if (!duty != !(TCCR2A & _BV(COM2A1)))
        TCCR2A ^= _BV(COM2A1);
}

/* A pin of a port the step interrupt never writes. */
#define SET_PIN(port, bit, on) ((on) ? ((port) |= _BV(bit)) : ((port) &= (uint8_t)~_BV(bit)))

QS_NOINLINE void outputs_update(void)
{
    qs_output_level level;
    uint8_t pins;
#if QS_RASTER_BYTES
    uint8_t saved;
#endif

    TIFR2 = _BV(TOV2);
#if QS_RASTER_BYTES
    if (qs_raster_lit(&core.raster))
        return; /* the tick's, pixel by pixel (its restarts bring TOV2 at every pixel) */
#endif
    if (qs_outputs_all_off(&core.outputs)) {
        level.pins = 0; /* no need to look at the engine */
        level.duty = 0;
    } else {
#if QS_RASTER_BYTES
        qs_core_outputs(&core, &level, raster_ahead());
#else
        qs_core_outputs(&core, &level, 0);
#endif
    }
    /* OCR2A takes effect at the next period: high for (OCR2A + 1) / 256 of
     * it; a duty of 0 disconnects the pin, which then stays low. Registers
     * are written only when they change, and not while the tick switches a
     * RASTER line's pixels (the lock keeps it from taking the line between
     * the look and the write). */
#if QS_RASTER_BYTES
    saved = qs_port_lock();
    if (!qs_raster_lit(&core.raster))
        set_duty(level.duty);
    qs_port_unlock(saved);
#else
    set_duty(level.duty);
#endif
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
