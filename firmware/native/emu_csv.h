/* The emulator's CSV outputs (step trace, events log): each is optional,
 * a NULL path meaning no file. */
#ifndef EMU_CSV_H
#define EMU_CSV_H

#include <stddef.h>
#include <stdio.h>

/* Create `path` and write its header line; NULL path: *file = NULL and
 * success. `buffer` bytes of full buffering, 0 for stdio's default. Returns
 * 0 (after saying why on stderr) if the file cannot be written. */
int emu_csv_open(FILE **file, const char *path, const char *what, const char *header, size_t buffer);
void emu_csv_close(FILE **file);

#endif
