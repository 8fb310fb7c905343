#include <avr/eeprom.h>

#include "boot_id.h"

/* Erased EEPROM reads 0xFFFF: the first boot is 0. Only changed bytes are
 * written, so a cell sees at most one write per reset. */
static uint16_t EEMEM boot_count;

uint16_t boot_id_next(void)
{
    const uint16_t id = (uint16_t)(eeprom_read_word(&boot_count) + 1u);

    eeprom_update_word(&boot_count, id);
    return id;
}
