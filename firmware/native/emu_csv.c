#include "emu_csv.h"

#include <errno.h>
#include <string.h>

int emu_csv_open(FILE **file, const char *path, const char *what, const char *header, size_t buffer)
{
    *file = NULL;
    if (!path)
        return 1;
    *file = fopen(path, "w");
    if (!*file) {
        fprintf(stderr, "quadstep-emu: cannot write %s '%s': %s\n", what, path, strerror(errno));
        return 0;
    }
    if (buffer)
        setvbuf(*file, NULL, _IOFBF, buffer);
    fputs(header, *file);
    fputc('\n', *file);
    fflush(*file); /* a reader finds the header at once */
    return 1;
}

void emu_csv_close(FILE **file)
{
    if (*file)
        fclose(*file);
    *file = NULL;
}
