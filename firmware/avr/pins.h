/* Board pin setup: motion outputs, driver enable, reserved inputs. */
#ifndef QS_PINS_H
#define QS_PINS_H

void pins_init(void);

#endif
