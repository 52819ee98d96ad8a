/* Private to the console's sources (pmstep_console*.c): the wire helpers they share, not part of
 * the API (pmstep_console.h). */
#ifndef PMSTEP_CONSOLE_INTERNAL_H
#define PMSTEP_CONSOLE_INTERNAL_H

#include "pmstep_console.h"

#include <string.h>

static inline bool is_finite(float x)
{
    return (x - x) == 0.0f; /* NaN and +-Inf give NaN */
}

static inline float get_f32(const uint8_t *p)
{
    float x;
    memcpy(&x, p, sizeof x); /* little-endian targets (Cortex-M, x86-64) */
    return x;
}

static inline uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* A little-endian writer into a reply buffer. */
typedef struct {
    uint8_t b[PMSTEP_CONSOLE_MAX_PAYLOAD];
    uint32_t n;
} writer_t;

static inline void put_u8(writer_t *w, uint32_t v)
{
    if (w->n < sizeof w->b) {
        w->b[w->n++] = (uint8_t)v;
    }
}

static inline void put_u16(writer_t *w, uint32_t v)
{
    put_u8(w, v & 0xFFu);
    put_u8(w, (v >> 8) & 0xFFu);
}

static inline void put_u32(writer_t *w, uint32_t v)
{
    put_u16(w, v & 0xFFFFu);
    put_u16(w, v >> 16);
}

static inline void put_f32(writer_t *w, float x)
{
    uint32_t v;
    memcpy(&v, &x, sizeof v);
    put_u32(w, v);
}

static inline void put_text(writer_t *w, const char *s, uint32_t room)
{
    while (*s != '\0' && room > 0u) {
        put_u8(w, (uint8_t)*s++);
        --room;
    }
}

/* ---- framing (pmstep_console.c) ---- */

/* A frame with payload TYPE SEQ DATA, or nothing (counted) if it does not fit. */
void pmstep_console_send(pmstep_console_t *c, uint8_t type, uint8_t seq, const uint8_t *data, uint32_t n);

/* An error reply (TYPE 0xFF) to request @p type. */
void pmstep_console_send_error(pmstep_console_t *c, uint8_t type, uint8_t seq, pmstep_console_error_t code);

/* An ACK to request @p type: status i16, period u32. */
void pmstep_console_send_ack(pmstep_console_t *c, uint8_t type, uint8_t seq, int32_t status, uint32_t period);

/* ---- requests (pmstep_console_request.c) ---- */

/* A request with a good CRC: answered now (HELLO, GET_COUNTERS, errors), or put in the
 * mailbox for the next period boundary. */
void pmstep_console_handle_frame(pmstep_console_t *c);

/* ---- stored configuration (pmstep_console_store.c) ---- */

/* @p next in force: *cfg = *next, the core initialised on it, position gains designed anew.
 * @return pmstep_init()'s (or the position design's) status. */
int32_t pmstep_console_put_in_force(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg,
                                    const pmstep_config_t *next);

#endif /* PMSTEP_CONSOLE_INTERNAL_H */
