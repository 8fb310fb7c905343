/* The simulated machine around the motors, in motor steps: per axis a
 * carriage that follows the motor with backlash, hard stops where steps
 * are lost, limit switches with hysteresis, bounce, jitter and glitches;
 * a probe that touches plates, blocks and bores; scripted presses of any
 * input. The emulator (firmware/native) and the simavr harness
 * (tests/simavr) both move it, from the step pulses, and read the input
 * pins from it, so the two see the same machine. machine.md in this
 * directory describes the file (machine_load) and the model. */
#ifndef MACHINE_H
#define MACHINE_H

#include <stdint.h>
#include <stdio.h>

#define MACHINE_AXES 4
#define MACHINE_INPUTS 12 /* numbered as the firmware's (qs_inputs.h) */
#define MACHINE_TARGETS 8
#define MACHINE_SCRIPTS 16
#define MACHINE_EVENTS 4096 /* kept for the summary; later ones are counted */

typedef struct {
    int present;
    double at;          /* carriage position where it closes */
    double hysteresis;  /* it opens again this far back */
    int normally_closed;
    int bounce;         /* extra contacts after each edge */
    int bounce_ticks;   /* ... within this many ticks */
    double jitter;      /* the closing point moves by up to +-jitter each time */
    double glitch;      /* chance per step pulse of a false pulse */
    int glitch_ticks;
    /* state */
    int closed;         /* mechanically */
    double point;       /* this actuation's closing point (at + jitter) */
} machine_switch;

typedef struct {
    double backlash;     /* dead band, steps */
    long start;          /* motor position at power-up */
    double carriage0;    /* carriage at power-up */
    int has_hard_min, has_hard_max;
    double hard_min, hard_max;
    machine_switch min, max;
    /* state */
    long motor;          /* where the rotor is (lost steps do not move it) */
    double carriage;
    uint64_t pulses;     /* step pulses, either direction */
    int64_t steps;       /* pulses counted with their direction */
    uint64_t lost;       /* pulses the hard stops swallowed */
} machine_axis;

typedef enum { TARGET_PLATE, TARGET_BLOCK, TARGET_BORE } machine_target_kind;

typedef struct {
    machine_target_kind kind;
    double z;                                /* top surface, z steps */
    double x_min, x_max, y_min, y_max;       /* plate (optional) and block extent */
    int bounded;                             /* a plate with an extent */
    double x, y, radius_x, radius_y;         /* bore */
} machine_target;

typedef struct {
    int input;
    uint32_t at_tick; /* motion tick */
    uint32_t ticks;   /* held for this many sample ticks */
    int state;        /* 0 waiting, 1 pressed, 2 done */
    uint64_t pressed_at;
} machine_script;

typedef struct {
    uint64_t sample;     /* sample tick */
    uint32_t tick;       /* motion tick */
    uint8_t input;
    uint8_t level;       /* pin level after the change */
    uint8_t active;      /* mechanically actuated (or pressed) */
    char cause;          /* 's' switch or probe, 'b' bounce, 'g' glitch, 'p' scripted press */
    double carriage[MACHINE_AXES];
} machine_event;

typedef struct {
    uint8_t level;        /* pin level now */
    int actuated;         /* what the mechanics (or a script) say */
    int normally_closed;
    int bounce_left;      /* toggles still to come */
    uint64_t next_toggle; /* sample tick of the next */
    uint64_t glitch_until;
} machine_pin;

typedef struct {
    char path[256];
    int axes;
    int shared_limits;    /* one pin per axis for min and max (the Uno) */
    uint64_t seed, rng;
    machine_axis axis[MACHINE_AXES];
    /* probe */
    int probe_present;
    machine_switch probe; /* at unused; hysteresis in steps of penetration */
    int probe_axis[3];    /* x, y, z axes */
    machine_target target[MACHINE_TARGETS];
    int targets;
    machine_script script[MACHINE_SCRIPTS];
    int scripts;
    /* state */
    machine_pin pin[MACHINE_INPUTS];
    uint64_t sample;      /* sample ticks so far */
    uint32_t motion_tick;
    machine_event event[MACHINE_EVENTS];
    uint32_t events;
    uint32_t events_dropped;
} machine;

/* Read a machine file for `axes` axes; on failure write why into err
 * (the file, line and key) and return 0. */
int machine_load(machine *m, const char *path, int axes, int shared_limits, char *err, size_t errlen);

/* The power-up state from the settings (machine_load calls it). */
void machine_start(machine *m);

/* A step pulse on axis, direction +1 or -1. */
void machine_step(machine *m, int axis, int direction);

/* A sample tick begins, at this motion tick: time-driven changes
 * (bounce, glitches ending, scripted presses) happen now. */
void machine_tick(machine *m, uint32_t motion_tick);

/* Pin levels, bit i for input i (1 high); bits of inputs the machine does
 * not wire read high (pulled up, open). */
uint16_t machine_levels(const machine *m);

/* Pending time-driven changes: the emulator keeps sampling while idle. */
int machine_busy(const machine *m);

/* The summary's "machine" object, JSON. */
void machine_write_json(const machine *m, FILE *f);

#endif
