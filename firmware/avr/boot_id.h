/* The boot id IDENTIFY_REPLY reports: new at each reset, so that a host
 * can tell a board that was reset (its positions lost) from one it talked
 * to before. */
#ifndef QS_BOOT_ID_H
#define QS_BOOT_ID_H

#include <stdint.h>

/* The count of resets kept in EEPROM, moved on by one and stored: once per
 * reset, before interrupts are enabled (a write waits a few ms). */
uint16_t boot_id_next(void);

#endif
