/* Host side of the console protocol for the tests: requests framed and replies decoded as
 * pmstep_console.h says. */
#ifndef CONSOLE_TEST_FRAME_H
#define CONSOLE_TEST_FRAME_H

#include <stdint.h>

/** A reply frame as the host reads it. */
typedef struct {
    uint8_t type;
    uint8_t seq;
    uint8_t data[64];
    uint32_t n; /**< bytes of data */
} console_test_reply_t;

/** Frames request @p type, @p seq with @p n bytes of @p data into @p out (n + 6 bytes).
 *  @return the frame's length */
uint32_t console_test_frame(uint8_t *out, uint8_t type, uint8_t seq, const void *data, uint32_t n);

/** Decodes the frames in @p tx[0..n) into @p r (at most @p max kept), checking each frame's sync
 *  byte, length and CRC (a cmocka failure otherwise). @return how many frames there were */
unsigned console_test_replies(const uint8_t *tx, uint32_t n, console_test_reply_t *r, unsigned max);

struct pmstep_console;

/** Frames request @p type, @p seq with @p n bytes of @p data and feeds it to @p con (at time 0). */
void console_test_send(struct pmstep_console *con, uint8_t type, uint8_t seq, const void *data, uint32_t n);

/** Takes what @p con has to transmit and decodes it into @p r (at most @p max kept), as
 *  console_test_replies(). @return how many frames there were */
unsigned console_test_take_replies(struct pmstep_console *con, console_test_reply_t *r, unsigned max);

/** Little-endian float32, u32 and i16 at @p p. */
float console_test_f32(const uint8_t *p);
uint32_t console_test_u32(const uint8_t *p);
int16_t console_test_i16(const uint8_t *p);

#endif /* CONSOLE_TEST_FRAME_H */
