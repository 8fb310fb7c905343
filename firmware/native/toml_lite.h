/* A reader for the small part of TOML the simulated machine's file uses:
 * `key = value` (integers, floats, booleans, "strings"), [table] and
 * [table.sub] headers, [[array]] of tables (a later [array.sub] belongs to
 * its last element), and # comments. Each value is kept under its full
 * path, e.g. `axis[0].limit_min.at`, with its line, so that the reader of
 * the file can refuse what it does not know by name and line. */
#ifndef TOML_LITE_H
#define TOML_LITE_H

#include <stddef.h>

#define TOML_MAX_ENTRIES 512
#define TOML_MAX_PATH 96
#define TOML_MAX_TEXT 64

typedef enum { TOML_NUMBER, TOML_BOOL, TOML_STRING } toml_kind;

typedef struct {
    char path[TOML_MAX_PATH];
    toml_kind kind;
    double number;
    int is_integer;
    char text[TOML_MAX_TEXT];
    int line;
    int used; /* set by the file's reader as it takes each key */
} toml_entry;

typedef struct {
    toml_entry entry[TOML_MAX_ENTRIES];
    int count;
    char arrays[16][TOML_MAX_PATH]; /* names of [[arrays]] and their lengths */
    int array_len[16];
    int array_count;
} toml_doc;

/* Read path; on failure write "path:line: why" into err and return 0. */
int toml_read(toml_doc *doc, const char *path, char *err, size_t errlen);

/* The entry at path, marked used, or NULL. */
toml_entry *toml_get(toml_doc *doc, const char *path);

/* Elements of the [[array]] at path (0 if none). */
int toml_array_length(const toml_doc *doc, const char *path);

/* The first entry not taken by toml_get, or NULL. */
const toml_entry *toml_unused(const toml_doc *doc);

#endif
