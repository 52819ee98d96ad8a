/* Host side of the console protocol for the tests (console_test_frame.h). */
#include "console_test_frame.h"

#include <string.h>

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
