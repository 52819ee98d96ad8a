/* The host side of the console on the behavioural model's LPUART1, for the application's tests:
 * frames sent into the model's receiver, and the drive's frames read back from what the model's
 * transmitter sent. Include after <cmocka.h> and stm32g4_model.h. */
#ifndef MODEL_CONSOLE_HOST_H
#define MODEL_CONSOLE_HOST_H

#include <stdint.h>
#include <string.h>

#include "pmstep_console.h"
#include "stm32g4_model.h"

/* One request frame (SYNC, LEN, TYPE, SEQ, data, CRC-16) into the model's LPUART1. */
static inline void model_host_send(uint8_t type, uint8_t seq, const void *data, uint32_t n)
{
    uint8_t f[80];
    uint16_t crc;
    f[0] = PMSTEP_CONSOLE_SYNC;
    f[1] = (uint8_t)(n + 2u);
    f[2] = type;
    f[3] = seq;
    if (n > 0u) {
        memcpy(&f[4], data, n);
    }
    crc = pmstep_console_crc16(0xFFFFu, &f[1], n + 3u);
    f[4 + n] = (uint8_t)(crc & 0xFFu);
    f[5 + n] = (uint8_t)(crc >> 8);
    stm32g4_model_uart_send(f, n + 6u);
}

/* The next frame the drive sent of @p type (others skipped, each frame's CRC checked), from *@p cursor
 * (the frames of stm32g4_model.uart_tx before it are read); @return its data length, or -1 when none is complete. */
static inline int model_host_receive(uint32_t *cursor, uint8_t type, uint8_t *data)
{
    while (*cursor + 4u <= stm32g4_model.uart_tx_len) {
        const uint8_t *f = &stm32g4_model.uart_tx[*cursor];
        const uint32_t len = f[1];
        assert_int_equal(f[0], PMSTEP_CONSOLE_SYNC);
        if (*cursor + len + 4u > stm32g4_model.uart_tx_len) {
            return -1; /* not all sent yet */
        }
        assert_int_equal(pmstep_console_crc16(0xFFFFu, &f[1], len + 1u), f[2 + len] | (f[3 + len] << 8));
        *cursor += len + 4u;
        if (f[2] == type) {
            memcpy(data, &f[4], len - 2u);
            return (int)len - 2;
        }
    }
    return -1;
}

#endif /* MODEL_CONSOLE_HOST_H */
