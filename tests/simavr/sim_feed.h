/* A minimal host for benchmarks: sends a file of ready-made sequenced
 * frames as fast as the protocol's flow control allows (PROTOCOL.md
 * section 4), learning next_seq and free from IDENTIFY_REPLY and every
 * ACK, and records when each frame is accepted. It never retransmits: a
 * lost frame, GAP, QUEUE_FULL or ALARM is counted and reported, so a run
 * that needed one is visibly not a clean measurement. Replies are decoded
 * with the firmware core's own frame decoder, compiled natively. */
#ifndef SIM_FEED_H
#define SIM_FEED_H

#include <stdint.h>

#include "sim_avr.h"
#include "sim_wire.h"

typedef struct {
    uint64_t frames;
    uint64_t sent;
    uint64_t accepted;
    uint64_t rejected;
    uint64_t gap;
    uint64_t duplicate;
    uint64_t queue_full;
    uint64_t space;
    uint64_t alarms;
    uint64_t holds;       /* EVENT HOLD_DONE: a stop the board made itself (the queue ran dry: STARVED) */
    uint64_t errors;
    uint64_t bad_replies;
    uint64_t first_accept_cycle;
    uint64_t last_accept_cycle;
    uint64_t first_alarm_cycle;
    uint8_t first_alarm_code;
} sim_feed_stats;

typedef struct sim_feed sim_feed;

/* NULL (and a message on stderr) if the file cannot be read or holds a
 * frame that is not a well-formed sequenced frame. */
sim_feed *sim_feed_open(avr_t *avr, sim_wire *wire, const char *path);

/* Starts the session (IDENTIFY). */
void sim_feed_start(sim_feed *f);

/* A byte the board sent. */
void sim_feed_board_byte(sim_feed *f, uint8_t byte);

/* Every frame answered, or an alarm stopped the run. */
int sim_feed_finished(const sim_feed *f);

sim_feed_stats sim_feed_get_stats(const sim_feed *f);

#endif
