/* Command line of the emulator. */
#ifndef EMU_OPTIONS_H
#define EMU_OPTIONS_H

#include <stdint.h>

#define EMU_MAX_FAULTS 64

typedef struct {
    uint32_t at[EMU_MAX_FAULTS]; /* 1-based frame numbers */
    uint32_t count;
} emu_fault_list;

typedef struct {
    int tcp;              /* serve TCP instead of a pseudo-terminal */
    uint16_t tcp_port;    /* 0: pick a free one */
    int free_running;     /* run ticks as fast as possible, not in real time */
    uint32_t tick_hz;
    uint8_t axes;
    uint8_t queue;
    const char *trace_path; /* NULL: no trace */
    const char *events_path; /* NULL: no events log */
    const char *outputs_path; /* NULL: no output trace */
    const char *machine_path; /* NULL: a perfect machine with nothing wired to the inputs */
    uint8_t limit_pins;   /* per axis: 2 (a min and a max input) or 1 (shared, as the Uno) */
    int boot_id_set;      /* --boot-id given; else the boot id is random */
    uint16_t boot_id;
    /* --hold-at: inject a HOLD when this motion tick is reached (tests). */
    int hold_at_set;
    uint32_t hold_at_tick;
    uint16_t hold_at_decel[4]; /* per axis; 0 for axes beyond --axes */
    emu_fault_list drop_rx;
    emu_fault_list corrupt_rx;
    emu_fault_list drop_tx;
} emu_options;

/* Parse argv; on a bad option print why (naming it and its limits) and
 * return 0. */
int emu_options_parse(emu_options *o, int argc, char **argv);

#endif
