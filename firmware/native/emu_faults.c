#include "emu_faults.h"

void emu_faults_init(emu_faults *f, const emu_options *opts)
{
    f->opts = opts;
    f->rx_len = 0;
    f->rx_passing = 0;
    f->rx_frames = 0;
    f->rx_dropped = 0;
    f->rx_corrupted = 0;
    f->tx_frames = 0;
    f->tx_in_frame = 0;
    f->tx_dropped = 0;
}

static int listed(const emu_fault_list *list, uint32_t frame)
{
    uint32_t i;
    for (i = 0; i < list->count; i++)
        if (list->at[i] == frame)
            return 1;
    return 0;
}

/* Flip one bit of a data byte (not a COBS code byte), keeping it non-zero,
 * so the frame still decodes and fails only its CRC, as a bit error on a
 * real wire most often does. Frames with no data byte get a code byte
 * flipped instead. */
static void corrupt(uint8_t *frame, size_t len)
{
    size_t code_at = 0;
    size_t i;

    for (i = 0; i < len; i++) {
        if (i == code_at) {
            code_at = i + frame[i];
            continue;
        }
        frame[i] ^= frame[i] == 0x01 ? 0x02 : 0x01;
        return;
    }
    if (len > 0)
        frame[0] ^= frame[0] == 0x01 ? 0x02 : 0x01;
}

void emu_faults_rx(emu_faults *f, uint8_t byte, emu_byte_sink *sink, void *ctx)
{
    size_t i;

    if (byte != 0) {
        if (f->rx_passing) {
            sink(ctx, byte);
        } else if (f->rx_len == EMU_RX_FRAME_MAX) {
            for (i = 0; i < f->rx_len; i++)
                sink(ctx, f->rx_buf[i]);
            sink(ctx, byte);
            f->rx_passing = 1;
        } else {
            f->rx_buf[f->rx_len++] = byte;
        }
        return;
    }
    if (f->rx_len == 0 && !f->rx_passing) {
        sink(ctx, 0); /* an empty frame: not counted, never faulted */
        return;
    }
    f->rx_frames++;
    if (!f->rx_passing && listed(&f->opts->drop_rx, f->rx_frames)) {
        f->rx_dropped++;
    } else {
        if (!f->rx_passing && listed(&f->opts->corrupt_rx, f->rx_frames)) {
            corrupt(f->rx_buf, f->rx_len);
            f->rx_corrupted++;
        }
        if (!f->rx_passing)
            for (i = 0; i < f->rx_len; i++)
                sink(ctx, f->rx_buf[i]);
        sink(ctx, 0);
    }
    f->rx_len = 0;
    f->rx_passing = 0;
}

void emu_faults_tx(emu_faults *f, const uint8_t *bytes, size_t len, emu_byte_sink *sink,
                   void *ctx)
{
    size_t i;

    for (i = 0; i < len; i++) {
        uint8_t byte = bytes[i];
        int dropping;
        if (byte == 0 && !f->tx_in_frame) {
            sink(ctx, 0);
            continue;
        }
        f->tx_in_frame = 1;
        dropping = listed(&f->opts->drop_tx, f->tx_frames + 1);
        if (!dropping)
            sink(ctx, byte);
        if (byte == 0) {
            f->tx_frames++;
            f->tx_in_frame = 0;
            if (dropping)
                f->tx_dropped++;
        }
    }
}
