#include "qs_queue.h"

void qs_queue_init(qs_queue *q, uint8_t capacity)
{
    q->head = 0;
    q->tail = 0;
    q->retired = 0;
    q->capacity = capacity;
    q->wrap = (uint8_t)(2 * capacity);
    q->front = q->slot;
    q->last = &q->slot[capacity - 1];
}
