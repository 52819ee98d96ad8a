/*
 * Command and telemetry interface: the receiver (see pmstep_console.h), a state machine that
 * takes bytes into frames. The requests a frame carries are pmstep_console_request.c, what is
 * done at a period boundary pmstep_console_boundary.c, the transmit side pmstep_console_tx.c.
 * Every loop is bounded by a frame's length; nothing waits on anything.
 */
#include "pmstep_console_internal.h"

#include <stddef.h>
#include <string.h>

enum { RX_SYNC, RX_LEN, RX_PAYLOAD, RX_CRC0, RX_CRC1 };

/* ---- receiver ---- */

void pmstep_console_init(pmstep_console_t *c, const char *identity)
{
    memset(c, 0, sizeof *c);
    c->stepdir = pmstep_console_stepdir_defaults();
    c->identity = identity;
}

bool pmstep_console_pending(const pmstep_console_t *c)
{
    return c->pending || c->calibrating;
}

void pmstep_console_receive(pmstep_console_t *c, const uint8_t *data, uint32_t n, uint32_t now_ms)
{
    uint32_t i;
    pmstep_console_poll(c, now_ms);
    for (i = 0; i < n; ++i) {
        const uint8_t b = data[i];
        c->count.rx_bytes++;
        c->last_byte_ms = now_ms;
        switch (c->state) {
        case RX_SYNC:
            if (b == PMSTEP_CONSOLE_SYNC) {
                c->state = RX_LEN;
            } else {
                c->count.rx_garbage_bytes++;
            }
            break;
        case RX_LEN:
            if (b < 2u || b > PMSTEP_CONSOLE_MAX_PAYLOAD) {
                c->count.rx_bad_length++;
                c->state = b == PMSTEP_CONSOLE_SYNC ? RX_LEN : RX_SYNC; /* a sync byte may start the next frame */
            } else {
                c->len = b;
                c->pos = 0;
                c->state = RX_PAYLOAD;
            }
            break;
        case RX_PAYLOAD:
            c->buf[c->pos++] = b;
            if (c->pos == c->len) {
                c->state = RX_CRC0;
            }
            break;
        case RX_CRC0:
            c->buf[c->len] = b;
            c->state = RX_CRC1;
            break;
        default: { /* RX_CRC1 */
            uint16_t crc = pmstep_console_crc16(0xFFFFu, &c->len, 1u);
            crc = pmstep_console_crc16(crc, c->buf, c->len);
            c->state = RX_SYNC;
            if (crc == (uint16_t)(c->buf[c->len] | ((uint16_t)b << 8))) {
                pmstep_console_handle_frame(c);
            } else {
                c->count.rx_crc_errors++;
            }
            break;
        }
        }
    }
}

void pmstep_console_poll(pmstep_console_t *c, uint32_t now_ms)
{
    if (c->state != RX_SYNC && now_ms - c->last_byte_ms > PMSTEP_CONSOLE_TRUNCATION_MS) {
        c->count.rx_truncated++;
        c->state = RX_SYNC;
    }
}
