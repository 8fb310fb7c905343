#include "toml_lite.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int fail(char *err, size_t errlen, const char *path, int line, const char *why)
{
    snprintf(err, errlen, "%s:%d: %s", path, line, why);
    return 0;
}

static char *trim(char *s)
{
    char *end;
    while (isspace((unsigned char)*s))
        s++;
    end = s + strlen(s);
    while (end > s && isspace((unsigned char)end[-1]))
        *--end = '\0';
    return s;
}

/* Cut a comment off, outside strings. */
static void strip_comment(char *s)
{
    int in_string = 0;
    for (; *s; s++) {
        if (*s == '"' && (s[-1] != '\\'))
            in_string = !in_string;
        else if (*s == '#' && !in_string) {
            *s = '\0';
            return;
        }
    }
}

static int valid_name(const char *s)
{
    if (!*s)
        return 0;
    for (; *s; s++)
        if (!isalnum((unsigned char)*s) && *s != '_' && *s != '-' && *s != '.')
            return 0;
    return 1;
}

static int array_index(const toml_doc *doc, const char *name)
{
    int i;
    for (i = 0; i < doc->array_count; i++)
        if (strcmp(doc->arrays[i], name) == 0)
            return i;
    return -1;
}

/* A dotted header name with each component that names an array of tables
 * replaced by its last element: axis.limit_min -> axis[2].limit_min. */
static int resolve(const toml_doc *doc, const char *name, char *out, size_t cap)
{
    char plain[TOML_MAX_PATH] = "", resolved[TOML_MAX_PATH] = "";
    const char *p = name;

    while (*p) {
        const char *dot = strchr(p, '.');
        size_t len = dot ? (size_t)(dot - p) : strlen(p);
        int a;
        if (strlen(plain) + len + 2 >= sizeof plain)
            return 0;
        if (*plain) {
            strcat(plain, ".");
            strcat(resolved, ".");
        }
        strncat(plain, p, len);
        strncat(resolved, p, len);
        a = array_index(doc, plain);
        if (a >= 0) {
            char idx[16];
            snprintf(idx, sizeof idx, "[%d]", doc->array_len[a] - 1);
            if (strlen(resolved) + strlen(idx) >= sizeof resolved)
                return 0;
            strcat(resolved, idx);
        }
        p = dot ? dot + 1 : p + len;
    }
    if (strlen(resolved) >= cap)
        return 0;
    strcpy(out, resolved);
    return 1;
}

static int parse_value(toml_entry *e, char *v)
{
    char *end;
    size_t len = strlen(v);

    if (len >= 2 && v[0] == '"' && v[len - 1] == '"') {
        if (len - 2 >= sizeof e->text)
            return 0;
        memcpy(e->text, v + 1, len - 2);
        e->text[len - 2] = '\0';
        e->kind = TOML_STRING;
        return 1;
    }
    if (strcmp(v, "true") == 0 || strcmp(v, "false") == 0) {
        e->kind = TOML_BOOL;
        e->number = v[0] == 't';
        return 1;
    }
    {
        char digits[64];
        size_t i, n = 0;
        for (i = 0; i < len && n + 1 < sizeof digits; i++)
            if (v[i] != '_')
                digits[n++] = v[i];
        digits[n] = '\0';
        if (n == 0)
            return 0;
        errno = 0;
        e->number = strtod(digits, &end);
        if (*end != '\0' || errno != 0)
            return 0;
        e->is_integer = strpbrk(digits, ".eE") == NULL;
        e->kind = TOML_NUMBER;
        return 1;
    }
}

int toml_read(toml_doc *doc, const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "r");
    char line[512], prefix[TOML_MAX_PATH] = "";
    int number = 0;

    memset(doc, 0, sizeof *doc);
    if (!f) {
        snprintf(err, errlen, "%s: cannot read: %s", path, strerror(errno));
        return 0;
    }
    while (fgets(line, sizeof line, f)) {
        char *s, *eq;
        number++;
        if (!strchr(line, '\n') && !feof(f)) {
            fclose(f);
            return fail(err, errlen, path, number, "line longer than 510 characters");
        }
        strip_comment(line);
        s = trim(line);
        if (!*s)
            continue;
        if (s[0] == '[') {
            int array = s[1] == '[';
            size_t len = strlen(s);
            char name[TOML_MAX_PATH];
            if ((array && (len < 4 || strcmp(s + len - 2, "]]") != 0)) || (!array && s[len - 1] != ']')) {
                fclose(f);
                return fail(err, errlen, path, number, "a table header must end with ] (or ]] for [[...]])");
            }
            s[len - (array ? 2 : 1)] = '\0';
            snprintf(name, sizeof name, "%s", trim(s + (array ? 2 : 1)));
            if (!valid_name(name)) {
                fclose(f);
                return fail(err, errlen, path, number, "a table name is letters, digits, _ and dots");
            }
            if (array) {
                int a = array_index(doc, name);
                if (a < 0) {
                    if (doc->array_count == 16) {
                        fclose(f);
                        return fail(err, errlen, path, number, "more than 16 kinds of [[array]]");
                    }
                    a = doc->array_count++;
                    strcpy(doc->arrays[a], name);
                }
                doc->array_len[a]++;
            }
            if (!resolve(doc, name, prefix, sizeof prefix)) {
                fclose(f);
                return fail(err, errlen, path, number, "table name too long");
            }
            continue;
        }
        eq = strchr(s, '=');
        if (!eq) {
            fclose(f);
            return fail(err, errlen, path, number, "expected `key = value` or a [table] header");
        }
        *eq = '\0';
        {
            char *key = trim(s), *value = trim(eq + 1);
            toml_entry *e;
            if (!valid_name(key) || strchr(key, '.')) {
                fclose(f);
                return fail(err, errlen, path, number, "a key is letters, digits and _");
            }
            if (doc->count == TOML_MAX_ENTRIES) {
                fclose(f);
                return fail(err, errlen, path, number, "too many keys");
            }
            e = &doc->entry[doc->count];
            memset(e, 0, sizeof *e);
            if ((size_t)snprintf(e->path, sizeof e->path, "%s%s%s", prefix, *prefix ? "." : "", key)
                >= sizeof e->path) {
                fclose(f);
                return fail(err, errlen, path, number, "key path too long");
            }
            if (toml_get(doc, e->path)) {
                char why[160];
                snprintf(why, sizeof why, "%s given twice", e->path);
                fclose(f);
                return fail(err, errlen, path, number, why);
            }
            doc->entry[doc->count].used = 0;
            e->line = number;
            if (!parse_value(e, value)) {
                char why[200];
                snprintf(why, sizeof why, "%s = %s: not a number, true/false or a \"string\"", e->path, value);
                fclose(f);
                return fail(err, errlen, path, number, why);
            }
            doc->count++;
        }
    }
    fclose(f);
    return 1;
}

toml_entry *toml_get(toml_doc *doc, const char *path)
{
    int i;
    for (i = 0; i < doc->count; i++)
        if (strcmp(doc->entry[i].path, path) == 0) {
            doc->entry[i].used = 1;
            return &doc->entry[i];
        }
    return NULL;
}

int toml_array_length(const toml_doc *doc, const char *path)
{
    int a = array_index(doc, path);
    return a < 0 ? 0 : doc->array_len[a];
}

const toml_entry *toml_unused(const toml_doc *doc)
{
    int i;
    for (i = 0; i < doc->count; i++)
        if (!doc->entry[i].used)
            return &doc->entry[i];
    return NULL;
}
