/*
 * Command and telemetry interface: the transmit side (see pmstep_console.h): the CRC, the
 * transmit ring, and the frames every other part of the console sends through it.
 * Every loop is bounded by a frame's length; nothing waits on anything.
 */
#include "pmstep_console_internal.h"

uint16_t pmstep_console_crc16(uint16_t crc, const uint8_t *data, uint32_t n)
{
    uint32_t r = crc;
    uint32_t i;
    for (i = 0; i < n; ++i) {
        unsigned bit;
        r ^= (uint32_t)data[i] << 8;
        for (bit = 0; bit < 8u; ++bit) {
            r = (r & 0x8000u) != 0u ? ((r << 1) ^ 0x1021u) : (r << 1);
        }
        r &= 0xFFFFu;
    }
    return (uint16_t)r;
}

static uint32_t tx_free(const pmstep_console_t *c)
{
    return PMSTEP_CONSOLE_TX_BYTES - 1u - ((c->tx_head - c->tx_tail) % PMSTEP_CONSOLE_TX_BYTES);
}

static void tx_byte(pmstep_console_t *c, uint8_t b)
{
    c->tx[c->tx_head] = b;
    c->tx_head = (c->tx_head + 1u) % PMSTEP_CONSOLE_TX_BYTES;
}

/* A frame with payload TYPE SEQ DATA, or nothing (counted) if it does not fit. */
void pmstep_console_send(pmstep_console_t *c, uint8_t type, uint8_t seq, const uint8_t *data, uint32_t n)
{
    uint8_t head[3];
    uint16_t crc;
    uint32_t i;
    if (n + 2u > PMSTEP_CONSOLE_MAX_PAYLOAD || tx_free(c) < n + 2u + 4u) {
        c->count.tx_dropped++;
        return;
    }
    head[0] = (uint8_t)(n + 2u);
    head[1] = type;
    head[2] = seq;
    crc = pmstep_console_crc16(0xFFFFu, head, 3u);
    crc = pmstep_console_crc16(crc, data, n);
    tx_byte(c, PMSTEP_CONSOLE_SYNC);
    for (i = 0; i < 3u; ++i) {
        tx_byte(c, head[i]);
    }
    for (i = 0; i < n; ++i) {
        tx_byte(c, data[i]);
    }
    tx_byte(c, (uint8_t)(crc & 0xFFu));
    tx_byte(c, (uint8_t)(crc >> 8));
    c->count.tx_frames++;
}

uint32_t pmstep_console_transmit(pmstep_console_t *c, uint8_t *out, uint32_t max)
{
    uint32_t n = 0;
    while (n < max && c->tx_tail != c->tx_head) {
        out[n++] = c->tx[c->tx_tail];
        c->tx_tail = (c->tx_tail + 1u) % PMSTEP_CONSOLE_TX_BYTES;
    }
    return n;
}

void pmstep_console_send_error(pmstep_console_t *c, uint8_t type, uint8_t seq, pmstep_console_error_t code)
{
    const uint8_t data[2] = {type, (uint8_t)code};
    c->count.rx_error_replies++;
    pmstep_console_send(c, PMSTEP_CONSOLE_ERROR_FRAME, seq, data, 2u);
}

void pmstep_console_send_ack(pmstep_console_t *c, uint8_t type, uint8_t seq, int32_t status, uint32_t period)
{
    writer_t w;
    w.n = 0;
    put_u16(&w, (uint32_t)(uint16_t)(int16_t)status);
    put_u32(&w, period);
    pmstep_console_send(c, (uint8_t)(type | 0x80u), seq, w.b, w.n);
}
