#include "qs_retransmit.h"
#include "qs_dispatch.h"
#include "qs_reports.h"

#define PARK_MAX 32 /* frames ahead that can wait (the bits of parked) */

_Static_assert(sizeof(qs_host_msg) <= sizeof(qs_segment), "a parked frame waits in a queue slot");

/* Bring the parked frames' bookkeeping to next_seq and the queue's head:
 * every frame consumed since must have taken a slot (else the slots they
 * wait in are not theirs any more: all go, the host sends them again). */
static void rebase_parked(qs_core *c)
{
    const uint8_t frames = (uint8_t)(c->next_seq - c->parked_seq);
    const uint8_t slots = qs_queue_distance(&c->engine.queue, c->parked_head, c->engine.queue.head);

    if (frames != slots || frames >= PARK_MAX)
        c->parked = 0;
    else
        c->parked >>= frames;
    c->parked_seq = c->next_seq;
    c->parked_head = c->engine.queue.head;
}

static qs_segment *slot_ahead(qs_queue *q, uint8_t d)
{
    uint8_t i = q->head;

    while (d--)
        i = qs_queue_next(q, i);
    return qs_queue_at(q, i);
}

/* A segment d frames ahead of next_seq: kept in the slot it will take, if
 * there is room, and while segments may run. Returns whether it was. */
static uint8_t park(qs_core *c, const qs_host_msg *m, uint8_t d)
{
    const uint8_t state = c->engine.state;
    const uint8_t *from = (const uint8_t *)m;
    uint8_t *to;
    uint8_t i;

    if ((m->type != QS_TYPE_SEGMENT && m->type != QS_TYPE_CUBIC_SEGMENT) || d >= PARK_MAX
        || (state != QS_STATE_IDLE && state != QS_STATE_RUNNING))
        return 0;
    rebase_parked(c);
    if (d >= qs_queue_free(&c->engine.queue))
        return 0;
    to = (uint8_t *)slot_ahead(&c->engine.queue, d);
    for (i = 0; i < sizeof *m; i++)
        to[i] = from[i];
    c->parked |= (uint32_t)1 << d;
    return 1;
}

QS_NOINLINE void qs_run_parked(qs_core *c)
{
    qs_host_msg m;

    for (;;) {
        const uint8_t *from;
        uint8_t *to = (uint8_t *)&m;
        uint8_t i;

        rebase_parked(c);
        if (!(c->parked & 1u))
            return;
        c->parked &= ~(uint32_t)1;
        from = (const uint8_t *)qs_queue_back(&c->engine.queue);
        for (i = 0; i < sizeof m; i++)
            to[i] = from[i];
        if (m.type == QS_TYPE_SEGMENT)
            qs_on_segment(c, &m);
        else
            qs_on_cubic_segment(c, &m);
    }
}

uint8_t qs_in_sequence(qs_core *c, const qs_host_msg *m)
{
    uint8_t delta = (uint8_t)(m->seq - c->next_seq);

    if (delta == 0)
        return 1;
    if (delta <= 127) {
        qs_count(&c->counters.seq_gap);
        qs_report_ack(c, m->seq, park(c, m, delta) ? QS_ACK_PARKED : QS_ACK_GAP);
    } else {
        qs_count(&c->counters.seq_dup);
        qs_report_ack(c, m->seq, QS_ACK_DUPLICATE);
    }
    return 0;
}

void qs_end_stream(qs_core *c)
{
    c->engine.resequence = 0;
    c->parked = 0;
    c->next_seq = (uint8_t)(c->next_seq + 128);
}
