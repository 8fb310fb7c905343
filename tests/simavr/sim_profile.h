/* Where the CPU's cycles go: cycles counted per function of the firmware
 * (by the ELF's symbols), sleep counted apart. */
#ifndef SIM_PROFILE_H
#define SIM_PROFILE_H

#include <stdint.h>
#include <stdio.h>

#include "sim_avr.h"
#include "sim_elf.h"

typedef struct sim_profile sim_profile;

sim_profile *sim_profile_new(const elf_firmware_t *fw, const avr_t *avr);

/* The instruction at byte address pc took `cycles`. */
void sim_profile_add(sim_profile *p, uint32_t pc, uint64_t cycles);

/* The function holding byte address pc ("?" if none). */
const char *sim_profile_name(const sim_profile *p, uint32_t pc);

/* CSV `function,cycles`, most cycles first. */
void sim_profile_write(const sim_profile *p, FILE *out);

/* CSV `address,function,cycles`: every instruction that ran, by flash byte
 * address, to read beside the disassembly (`make avr-disasm`). */
void sim_profile_write_pc(const sim_profile *p, FILE *out);

#endif
