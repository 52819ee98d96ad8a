/* Host side of the console protocol for the tests: one request framed as pmstep_console.h says. */
#ifndef CONSOLE_TEST_FRAME_H
#define CONSOLE_TEST_FRAME_H

#include <stdint.h>

/** Frames request @p type, @p seq with @p n bytes of @p data into @p out (n + 6 bytes).
 *  @return the frame's length */
uint32_t console_test_frame(uint8_t *out, uint8_t type, uint8_t seq, const void *data, uint32_t n);

#endif /* CONSOLE_TEST_FRAME_H */
