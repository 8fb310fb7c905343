/* Bounded single-producer, single-consumer ring of ready segments. The main
 * loop fills and publishes slots (head), the step tick runs the oldest in
 * place and releases it (tail), and the main loop later retires released
 * slots (retired), folding their step counts into the positions, before it
 * may fill them again. Indices count modulo 2*capacity, so a full ring and
 * an empty one differ without a spare slot; each index is one byte written
 * by one side only, so neither side needs a lock to read the other's. */
#ifndef QS_QUEUE_H
#define QS_QUEUE_H

#include <stdint.h>
#include "qs_config.h"
#include "qs_segment.h"

typedef struct {
    qs_segment slot[QS_QUEUE_CAPACITY];
    volatile uint8_t head; /* next slot to publish; main loop */
    volatile uint8_t tail; /* slot running or next to run; tick */
    uint8_t retired;       /* oldest slot not yet retired; main loop */
    uint8_t capacity;      /* slots in use, 1 .. QS_QUEUE_CAPACITY */
    uint8_t wrap;          /* 2 * capacity, where indices wrap */
    qs_segment *front;     /* the slot at tail, kept with it (the tick
                            * finds it without a multiply) */
    qs_segment *last;      /* the last slot in use */
} qs_queue;

/* 1 <= capacity <= QS_QUEUE_CAPACITY. */
void qs_queue_init(qs_queue *q, uint8_t capacity);

static inline uint8_t qs_queue_next(const qs_queue *q, uint8_t i)
{
    i++;
    return (uint8_t)(i == q->wrap ? 0 : i);
}

static inline qs_segment *qs_queue_at(qs_queue *q, uint8_t i)
{
    return &q->slot[(uint8_t)(i >= q->capacity ? i - q->capacity : i)];
}

static inline uint8_t qs_queue_distance(const qs_queue *q, uint8_t from, uint8_t to)
{
    return (uint8_t)(to >= from ? to - from : to + q->wrap - from);
}

/* Segments published and not yet finished (the running one included). */
static inline uint8_t qs_queue_count(const qs_queue *q)
{
    return qs_queue_distance(q, q->tail, q->head);
}

/* Slots the producer may fill now. */
static inline uint8_t qs_queue_free(const qs_queue *q)
{
    return (uint8_t)(q->capacity - qs_queue_distance(q, q->retired, q->head));
}

static inline uint8_t qs_queue_empty(const qs_queue *q)
{
    return q->head == q->tail;
}

/* Main loop: the slot to fill (only when qs_queue_free > 0), then publish. */
static inline qs_segment *qs_queue_back(qs_queue *q)
{
    return qs_queue_at(q, q->head);
}

static inline void qs_queue_publish(qs_queue *q)
{
    QS_COMPILER_BARRIER(); /* the slot's contents before the new head */
    q->head = qs_queue_next(q, q->head);
}

/* Main loop: publish every slot filled up to index head at once. */
static inline void qs_queue_publish_to(qs_queue *q, uint8_t head)
{
    QS_COMPILER_BARRIER(); /* the slots' contents before the new head */
    q->head = head;
}

/* Tick: the oldest published slot (only when not empty), then release it. */
static inline qs_segment *qs_queue_front(qs_queue *q)
{
    return q->front;
}

static QS_ALWAYS_INLINE void qs_queue_release(qs_queue *q)
{
    qs_segment *s = q->front;
    q->front = s == q->last ? q->slot : s + 1;
    q->tail = qs_queue_next(q, q->tail);
}

/* Main loop, with the tick locked out: drop every published slot. */
static inline void qs_queue_drop(qs_queue *q)
{
    q->tail = q->head;
    q->retired = q->head;
    q->front = qs_queue_at(q, q->head);
}

#endif
