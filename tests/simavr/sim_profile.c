/* Where the CPU's cycles go (see sim_profile.h). */
#include "sim_profile.h"

#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *name;
    uint32_t start; /* byte address in flash */
    uint64_t cycles;
} profile_entry;

struct sim_profile {
    profile_entry *entry; /* sorted by start */
    uint32_t count;
    int32_t *by_word;     /* flash word -> entry index, -1 before the first symbol */
    uint64_t *word_cycles; /* flash word -> cycles of the instruction there */
    uint32_t words;
};

static int by_start(const void *a, const void *b)
{
    const profile_entry *x = a, *y = b;
    return (x->start > y->start) - (x->start < y->start);
}

sim_profile *sim_profile_new(const elf_firmware_t *fw, const avr_t *avr)
{
    sim_profile *p = calloc(1, sizeof *p);
    if (!p) {
        return NULL;
    }
    p->entry = calloc(fw->symbolcount + 1, sizeof *p->entry);
    for (uint32_t i = 0; i < fw->symbolcount; i++) {
        const avr_symbol_t *s = fw->symbol[i];
        /* Code addresses only; the linker's region sizes are not places. */
        if (s->addr < 0x800000 && s->symbol[0] != '.' && !strstr(s->symbol, "_REGION_")) {
            p->entry[p->count++] = (profile_entry){s->symbol, s->addr, 0};
        }
    }
    qsort(p->entry, p->count, sizeof *p->entry, by_start);
    p->words = (avr->flashend + 1) / 2;
    p->by_word = malloc(p->words * sizeof *p->by_word);
    p->word_cycles = calloc(p->words, sizeof *p->word_cycles);
    int32_t current = -1;
    uint32_t next = 0;
    for (uint32_t w = 0; w < p->words; w++) {
        while (next < p->count && p->entry[next].start <= w * 2) {
            current = (int32_t)next++;
        }
        p->by_word[w] = current;
    }
    return p;
}

void sim_profile_add(sim_profile *p, uint32_t pc, uint64_t cycles)
{
    const uint32_t w = pc / 2;
    if (w < p->words) {
        p->word_cycles[w] += cycles;
        if (p->by_word[w] >= 0) {
            p->entry[p->by_word[w]].cycles += cycles;
        }
    }
}

const char *sim_profile_name(const sim_profile *p, uint32_t pc)
{
    const uint32_t w = pc / 2;
    return w < p->words && p->by_word[w] >= 0 ? p->entry[p->by_word[w]].name : "?";
}

static int by_cycles(const void *a, const void *b)
{
    const profile_entry *x = a, *y = b;
    return (x->cycles < y->cycles) - (x->cycles > y->cycles);
}

void sim_profile_write(const sim_profile *p, FILE *out)
{
    profile_entry *sorted = malloc(p->count * sizeof *sorted);
    memcpy(sorted, p->entry, p->count * sizeof *sorted);
    qsort(sorted, p->count, sizeof *sorted, by_cycles);
    fprintf(out, "function,cycles\n");
    for (uint32_t i = 0; i < p->count && sorted[i].cycles; i++) {
        fprintf(out, "%s,%llu\n", sorted[i].name, (unsigned long long)sorted[i].cycles);
    }
    free(sorted);
}

void sim_profile_write_pc(const sim_profile *p, FILE *out)
{
    fprintf(out, "address,function,cycles\n");
    for (uint32_t w = 0; w < p->words; w++) {
        if (p->word_cycles[w]) {
            fprintf(out, "0x%x,%s,%llu\n", w * 2, sim_profile_name(p, w * 2),
                    (unsigned long long)p->word_cycles[w]);
        }
    }
}
