/* A minimal flow-controlled host for benchmarks (see sim_feed.h). */
#include "sim_feed.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "qs_frame.h"
#include "qs_messages.h"
#include "qs_protocol.h"

#define MAX_IN_FLIGHT 127

typedef struct {
    size_t offset; /* into bytes */
    uint8_t len;   /* wire bytes, delimiter included */
    uint8_t seq;
    uint8_t slots; /* queue slots it takes: its records in SEGMENTS and CUBIC_SEGMENTS, else 1 */
} feed_frame;

struct sim_feed {
    avr_t *avr;
    sim_wire *wire;
    uint8_t *bytes;
    feed_frame *frames;
    size_t count;
    size_t next_to_send;
    size_t first_unacked; /* frames from here to next_to_send are in flight */
    int session;      /* IDENTIFY_REPLY seen */
    uint8_t next_seq; /* from the latest reply */
    uint8_t free;
    qs_frame_rx rx;
    sim_feed_stats stats;
};

static int load_frames(sim_feed *f, const char *path)
{
    FILE *in = fopen(path, "rb");
    if (!in) {
        perror(path);
        return -1;
    }
    size_t cap = 1 << 16, len = 0;
    f->bytes = malloc(cap);
    size_t got;
    while (f->bytes && (got = fread(f->bytes + len, 1, cap - len, in)) > 0) {
        len += got;
        if (len == cap) {
            cap *= 2;
            f->bytes = realloc(f->bytes, cap);
        }
    }
    fclose(in);
    if (!f->bytes) {
        return -1;
    }
    f->frames = calloc(len + 1, sizeof *f->frames);
    qs_frame_rx rx;
    qs_frame_rx_init(&rx);
    size_t start = 0;
    for (size_t i = 0; i < len; i++) {
        const uint8_t r = qs_frame_rx_byte(&rx, f->bytes[i]);
        if (f->bytes[i] != 0) {
            continue;
        }
        if (r == QS_FRAME_NOTHING && i == start) { /* empty frame: a flush delimiter */
            start = i + 1;
            continue;
        }
        const uint8_t *body = qs_frame_body(&rx);
        if (r != QS_FRAME_READY || body[0] < 0x10 || body[0] > 0x3F) {
            fprintf(stderr, "%s: byte %zu: not a well-formed sequenced frame\n", path, start);
            return -1;
        }
        qs_segments_msg run = {0};
        const uint8_t plen = (uint8_t)(qs_frame_body_len(&rx) - 2);
        if (body[0] == QS_TYPE_SEGMENTS)
            qs_msg_parse_segments(body + 2, plen, &run);
        else if (body[0] == QS_TYPE_CUBIC_SEGMENTS)
            qs_msg_parse_cubic_segments(body + 2, plen, &run);
        f->frames[f->count++] = (feed_frame){start, (uint8_t)(i + 1 - start), body[1], run.count ? run.count : 1};
        start = i + 1;
    }
    if (start != len || f->count == 0) {
        fprintf(stderr, "%s: no frames, or a frame without its 0x00 delimiter\n", path);
        return -1;
    }
    f->stats.frames = f->count;
    return 0;
}

sim_feed *sim_feed_open(avr_t *avr, sim_wire *wire, const char *path)
{
    sim_feed *f = calloc(1, sizeof *f);
    if (!f) {
        return NULL;
    }
    f->avr = avr;
    f->wire = wire;
    qs_frame_rx_init(&f->rx);
    if (load_frames(f, path) != 0) {
        free(f->bytes);
        free(f->frames);
        free(f);
        return NULL;
    }
    return f;
}

void sim_feed_start(sim_feed *f)
{
    uint8_t body[QS_MAX_BODY + 2] = {QS_TYPE_IDENTIFY, 0};
    uint8_t wire[QS_MAX_WIRE + 1] = {0}; /* a leading delimiter flushes the line */
    const uint8_t len = qs_frame_encode(body, 2, wire + 1);
    sim_wire_send(f->wire, wire, (size_t)len + 1);
}

/* Send every frame the window allows: from next_seq on, frames whose slots
 * together fit in free. */
static void pump(sim_feed *f)
{
    while (f->session && f->next_to_send < f->count) {
        const feed_frame *fr = &f->frames[f->next_to_send];
        const uint8_t ahead = (uint8_t)(fr->seq - f->next_seq);
        unsigned slots = fr->slots;
        for (size_t i = f->first_unacked; i < f->next_to_send; i++)
            slots += f->frames[i].slots;
        if (slots > f->free || ahead >= MAX_IN_FLIGHT) {
            return;
        }
        sim_wire_send(f->wire, f->bytes + fr->offset, fr->len);
        f->next_to_send++;
        f->stats.sent++;
    }
}

static void on_ack(sim_feed *f, const uint8_t *p)
{
    f->next_seq = p[0];
    f->free = p[1];
    /* frames before next_seq are taken (seqs compared mod 256, in order) */
    while (f->first_unacked < f->next_to_send
           && (uint8_t)(f->next_seq - f->frames[f->first_unacked].seq - 1) < MAX_IN_FLIGHT)
        f->first_unacked++;
    switch (p[2]) {
    case QS_ACK_ACCEPTED:
        if (f->stats.accepted++ == 0) {
            f->stats.first_accept_cycle = f->avr->cycle;
        }
        f->stats.last_accept_cycle = f->avr->cycle;
        break;
    case QS_ACK_GAP:
        f->stats.gap++;
        break;
    case QS_ACK_DUPLICATE:
        f->stats.duplicate++;
        break;
    case QS_ACK_QUEUE_FULL:
        f->stats.queue_full++;
        break;
    case QS_ACK_REJECTED:
        f->stats.rejected++;
        break;
    case QS_ACK_SPACE:
        f->stats.space++;
        break;
    default:
        f->stats.bad_replies++;
    }
}

void sim_feed_board_byte(sim_feed *f, uint8_t byte)
{
    const uint8_t r = qs_frame_rx_byte(&f->rx, byte);
    if (r == QS_FRAME_NOTHING) {
        return;
    }
    if (r != QS_FRAME_READY) {
        f->stats.bad_replies++;
        return;
    }
    const uint8_t *body = qs_frame_body(&f->rx);
    const uint8_t len = qs_frame_body_len(&f->rx);
    const uint8_t *p = body + 2;
    if (body[0] == QS_TYPE_IDENTIFY_REPLY && len == 2 + QS_LEN_IDENTIFY_REPLY) {
        f->session = 1;
        f->next_seq = p[16];
        f->free = p[6]; /* the queue is empty at the start */
    } else if (body[0] == QS_TYPE_ACK && len == 2 + QS_LEN_ACK) {
        on_ack(f, p);
    } else if (body[0] == QS_TYPE_ALARM) {
        if (f->stats.alarms++ == 0) {
            f->stats.first_alarm_cycle = f->avr->cycle;
            f->stats.first_alarm_code = p[0];
        }
    } else if (body[0] == QS_TYPE_EVENT && len > 2 && p[0] == QS_EVENT_HOLD_DONE) {
        f->stats.holds++;
    } else if (body[0] == QS_TYPE_ERROR) {
        f->stats.errors++;
    } else {
        f->stats.bad_replies++;
    }
    pump(f);
}

int sim_feed_finished(const sim_feed *f)
{
    return f->stats.alarms > 0 || f->stats.accepted + f->stats.rejected >= f->count;
}

sim_feed_stats sim_feed_get_stats(const sim_feed *f)
{
    return f->stats;
}
