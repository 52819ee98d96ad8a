/*
 * Command and telemetry interface: a request on arrival (see pmstep_console.h). HELLO,
 * GET_COUNTERS and every error are answered at once; any other request is checked and put in
 * the mailbox for the next period boundary (pmstep_console_boundary.c).
 * Every loop is bounded by a frame's length; nothing waits on anything.
 */
#include "pmstep_console_internal.h"

#include <stddef.h>

/* The id of the configuration value named by @p n bytes at @p name, or -1. */
static int32_t config_by_name(const uint8_t *name, uint32_t n)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    uint32_t id;
    for (id = 0; id < count; ++id) {
        const char *s = t[id].name;
        uint32_t k = 0;
        while (k < n && s[k] != '\0' && (uint8_t)s[k] == name[k]) {
            ++k;
        }
        if (k == n && s[k] == '\0') {
            return (int32_t)id;
        }
    }
    return -1;
}

/* A position request's DATA into c->arg (absent values 0): false after an error reply. */
static bool parse_position(pmstep_console_t *c, uint8_t type, uint8_t seq, const uint8_t *d, uint32_t n)
{
    uint32_t i;
    bool length_ok;
    if (c->position == NULL || c->position_apply == NULL) {
        pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_NO_POSITION);
        return false;
    }
    if (type == PMSTEP_CONSOLE_MOVE_TO) {
        length_ok = n == 12u || n == 16u;
    } else if (type == PMSTEP_CONSOLE_HOLD) {
        length_ok = n == 0u || n == 4u;
    } else {
        length_ok = n == 0u;
    }
    if (!length_ok) {
        pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
        return false;
    }
    for (i = 0; i < 4u; ++i) {
        c->arg[i] = 4u * i < n ? get_f32(d + 4u * i) : 0.0f;
        if (!is_finite(c->arg[i])) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
            return false;
        }
    }
    return true;
}

/* A request with a good CRC: answered now (HELLO, GET_COUNTERS, errors), or put in the
 * mailbox for the next period boundary. */
void pmstep_console_handle_frame(pmstep_console_t *c)
{
    const uint8_t type = c->buf[0];
    const uint8_t seq = c->buf[1];
    const uint8_t *d = &c->buf[2];
    const uint32_t n = (uint32_t)c->len - 2u;
    uint32_t count;
    c->count.rx_frames++;
    switch (type) {
    case PMSTEP_CONSOLE_HELLO: {
        writer_t w;
        if (n != 0u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        w.n = 0;
        put_u8(&w, PMSTEP_CONSOLE_PROTOCOL_VERSION);
        put_u8(&w, PMSTEP_CONSOLE_MAX_PAYLOAD);
        put_text(&w, c->identity != NULL ? c->identity : "pmstep", PMSTEP_CONSOLE_MAX_PAYLOAD - 4u);
        pmstep_console_send(c, (uint8_t)(type | 0x80u), seq, w.b, w.n);
        return;
    }
    case PMSTEP_CONSOLE_GET_COUNTERS: {
        writer_t w;
        if (n != 0u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        w.n = 0;
        put_u32(&w, c->count.rx_bytes);
        put_u32(&w, c->count.rx_frames);
        put_u32(&w, c->count.rx_garbage_bytes);
        put_u32(&w, c->count.rx_bad_length);
        put_u32(&w, c->count.rx_crc_errors);
        put_u32(&w, c->count.rx_truncated);
        put_u32(&w, c->count.rx_error_replies);
        put_u32(&w, c->count.commands_applied);
        put_u32(&w, c->count.tx_frames);
        put_u32(&w, c->count.tx_dropped);
        put_u32(&w, c->count.telemetry_frames);
        pmstep_console_send(c, (uint8_t)(type | 0x80u), seq, w.b, w.n);
        return;
    }
    case PMSTEP_CONSOLE_SIM_ADVANCE:
        if (!c->simulation) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_NOT_SUPPORTED);
        } else if (n != 4u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
        } else if (c->advancing) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BUSY);
        } else if (get_u32(d) == 0u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
        } else {
            c->advance_periods = get_u32(d);
            c->advance_seq = seq;
            c->advancing = true;
        }
        return;
    case PMSTEP_CONSOLE_SIM_FINISH:
        if (!c->simulation) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_NOT_SUPPORTED);
        } else if (n != 0u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
        } else if (c->advancing) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BUSY);
        } else {
            c->finish_requested = true;
            pmstep_console_send_ack(c, type, seq, 0, 0u);
        }
        return;
    case PMSTEP_CONSOLE_START:
    case PMSTEP_CONSOLE_STOP:
    case PMSTEP_CONSOLE_CLEAR_FAULT:
    case PMSTEP_CONSOLE_GET_STATUS:
    case PMSTEP_CONSOLE_GET_COMMISSIONING:
        if (n != 0u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        break;
    case PMSTEP_CONSOLE_SPEED_TARGET:
        if (n != 8u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        c->a = get_f32(d);
        c->b = get_f32(d + 4);
        if (!is_finite(c->a) || !is_finite(c->b)) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
            return;
        }
        break;
    case PMSTEP_CONSOLE_ID_TARGET:
        if (n != 4u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        c->a = get_f32(d);
        if (!is_finite(c->a)) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
            return;
        }
        break;
    case PMSTEP_CONSOLE_TELEMETRY:
        if (n != 4u) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        c->u = get_u32(d);
        break;
    case PMSTEP_CONSOLE_GET_CONFIG:
    case PMSTEP_CONSOLE_SET_CONFIG: {
        const uint32_t fixed = type == PMSTEP_CONSOLE_SET_CONFIG ? 5u : 1u; /* id (+ value) */
        const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
        int32_t id;
        if (n < fixed || (d[0] != 0xFFu && n != fixed) || (d[0] == 0xFFu && n == fixed)) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        id = d[0] == 0xFFu ? config_by_name(d + fixed, n - fixed) : (int32_t)d[0];
        if (id < 0 || (uint32_t)id >= count) {
            pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_UNKNOWN_CONFIG);
            return;
        }
        c->cfg_id = (uint8_t)id;
        if (type == PMSTEP_CONSOLE_SET_CONFIG) {
            c->a = get_f32(d + 1);
            if ((t[id].flags & PMSTEP_CONSOLE_CFG_READ_ONLY) != 0u) {
                pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_READ_ONLY);
                return;
            }
            if (!is_finite(c->a)) {
                pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
                return;
            }
        }
        break;
    }
    case PMSTEP_CONSOLE_MOVE_TO:
    case PMSTEP_CONSOLE_HOLD:
    case PMSTEP_CONSOLE_GET_POSITION:
    case PMSTEP_CONSOLE_SET_POSITION_ZERO:
        if (!parse_position(c, type, seq, d, n)) {
            return;
        }
        break;
    default:
        pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_UNKNOWN_COMMAND);
        return;
    }
    if (c->pending) {
        pmstep_console_send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BUSY);
        return;
    }
    c->cmd = type;
    c->seq = seq;
    c->pending = true;
}
