/* Host side of the console protocol for the tests (console_test_frame.h). */
#include "console_test_frame.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "pmstep_console.h"

uint32_t console_test_frame(uint8_t *out, uint8_t type, uint8_t seq, const void *data, uint32_t n)
{
    uint16_t crc;
    out[0] = PMSTEP_CONSOLE_SYNC;
    out[1] = (uint8_t)(n + 2u);
    out[2] = type;
    out[3] = seq;
    if (n > 0u) {
        memcpy(out + 4, data, n);
    }
    crc = pmstep_console_crc16(0xFFFFu, out + 1, n + 3u);
    out[4 + n] = (uint8_t)(crc & 0xFFu);
    out[5 + n] = (uint8_t)(crc >> 8);
    return n + 6u;
}

void console_test_send(struct pmstep_console *con, uint8_t type, uint8_t seq, const void *data, uint32_t n)
{
    uint8_t buf[PMSTEP_CONSOLE_MAX_PAYLOAD + 6u];
    const uint32_t len = console_test_frame(buf, type, seq, data, n);
    pmstep_console_receive(con, buf, len, 0u);
}

unsigned console_test_take_replies(struct pmstep_console *con, console_test_reply_t *r, unsigned max)
{
    uint8_t tx[PMSTEP_CONSOLE_TX_BYTES];
    const uint32_t n = pmstep_console_transmit(con, tx, sizeof tx);
    return console_test_replies(tx, n, r, max);
}

unsigned console_test_replies(const uint8_t *tx, uint32_t n, console_test_reply_t *r, unsigned max)
{
    uint32_t i = 0;
    unsigned count = 0;
    while (i < n) {
        uint8_t len;
        uint16_t crc;
        assert_int_equal(tx[i], PMSTEP_CONSOLE_SYNC);
        len = tx[i + 1u];
        assert_true(i + 4u + len <= n);
        crc = pmstep_console_crc16(0xFFFFu, &tx[i + 1u], 1u + (uint32_t)len);
        assert_int_equal(crc, tx[i + 2u + len] | (tx[i + 3u + len] << 8));
        if (count < max) {
            r[count].type = tx[i + 2u];
            r[count].seq = tx[i + 3u];
            r[count].n = (uint32_t)len - 2u;
            memcpy(r[count].data, &tx[i + 4u], r[count].n);
        }
        ++count;
        i += 4u + len;
    }
    return count;
}

float console_test_f32(const uint8_t *p)
{
    float x;
    memcpy(&x, p, sizeof x);
    return x;
}

uint32_t console_test_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

int16_t console_test_i16(const uint8_t *p) { return (int16_t)(uint16_t)(p[0] | (p[1] << 8)); }
