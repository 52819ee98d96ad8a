/*
 * Command and telemetry interface: framing, parser, mailbox, replies (see pmstep_console.h).
 * Every loop is bounded by a frame's length; nothing waits on anything.
 */
#include "pmstep_console.h"

#include <stddef.h>
#include <string.h>

enum { RX_SYNC, RX_LEN, RX_PAYLOAD, RX_CRC0, RX_CRC1 };

#define FRAME_OVERHEAD 5u /* sync, len, crc x2 ... and the payload's own TYPE/SEQ are in LEN */

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

static bool is_finite(float x)
{
    return (x - x) == 0.0f; /* NaN and +-Inf give NaN */
}

static float get_f32(const uint8_t *p)
{
    float x;
    memcpy(&x, p, sizeof x); /* little-endian targets (Cortex-M, x86-64) */
    return x;
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* ---- transmitter ---- */

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
static void send(pmstep_console_t *c, uint8_t type, uint8_t seq, const uint8_t *data, uint32_t n)
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

/* A little-endian writer into a reply buffer. */
typedef struct {
    uint8_t b[PMSTEP_CONSOLE_MAX_PAYLOAD];
    uint32_t n;
} writer_t;

static void put_u8(writer_t *w, uint32_t v)
{
    if (w->n < sizeof w->b) {
        w->b[w->n++] = (uint8_t)v;
    }
}

static void put_u16(writer_t *w, uint32_t v)
{
    put_u8(w, v & 0xFFu);
    put_u8(w, (v >> 8) & 0xFFu);
}

static void put_u32(writer_t *w, uint32_t v)
{
    put_u16(w, v & 0xFFFFu);
    put_u16(w, v >> 16);
}

static void put_f32(writer_t *w, float x)
{
    uint32_t v;
    memcpy(&v, &x, sizeof v);
    put_u32(w, v);
}

static void put_text(writer_t *w, const char *s, uint32_t room)
{
    while (*s != '\0' && room > 0u) {
        put_u8(w, (uint8_t)*s++);
        --room;
    }
}

static void send_error(pmstep_console_t *c, uint8_t type, uint8_t seq, pmstep_console_error_t code)
{
    const uint8_t data[2] = {type, (uint8_t)code};
    c->count.rx_error_replies++;
    send(c, PMSTEP_CONSOLE_ERROR_FRAME, seq, data, 2u);
}

static void send_ack(pmstep_console_t *c, uint8_t type, uint8_t seq, int32_t status, uint32_t period)
{
    writer_t w;
    w.n = 0;
    put_u16(&w, (uint32_t)(uint16_t)(int16_t)status);
    put_u32(&w, period);
    send(c, (uint8_t)(type | 0x80u), seq, w.b, w.n);
}

/* ---- receiver ---- */

void pmstep_console_init(pmstep_console_t *c, const char *identity, bool simulation)
{
    memset(c, 0, sizeof *c);
    c->identity = identity;
    c->simulation = simulation;
}

bool pmstep_console_pending(const pmstep_console_t *c)
{
    return c->pending;
}

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
        send_error(c, type, seq, PMSTEP_CONSOLE_ERR_NO_POSITION);
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
        send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
        return false;
    }
    for (i = 0; i < 4u; ++i) {
        c->arg[i] = 4u * i < n ? get_f32(d + 4u * i) : 0.0f;
        if (!is_finite(c->arg[i])) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
            return false;
        }
    }
    return true;
}

/* A request with a good CRC: answered now (HELLO, GET_COUNTERS, errors), or put in the
 * mailbox for the next period boundary. */
static void handle_frame(pmstep_console_t *c)
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
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        w.n = 0;
        put_u8(&w, PMSTEP_CONSOLE_PROTOCOL_VERSION);
        put_u8(&w, PMSTEP_CONSOLE_MAX_PAYLOAD);
        put_text(&w, c->identity != NULL ? c->identity : "pmstep", PMSTEP_CONSOLE_MAX_PAYLOAD - 4u);
        send(c, (uint8_t)(type | 0x80u), seq, w.b, w.n);
        return;
    }
    case PMSTEP_CONSOLE_GET_COUNTERS: {
        writer_t w;
        if (n != 0u) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
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
        send(c, (uint8_t)(type | 0x80u), seq, w.b, w.n);
        return;
    }
    case PMSTEP_CONSOLE_SIM_ADVANCE:
        if (!c->simulation) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_NOT_SUPPORTED);
        } else if (n != 4u) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
        } else if (c->advancing) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BUSY);
        } else if (get_u32(d) == 0u) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
        } else {
            c->advance_periods = get_u32(d);
            c->advance_seq = seq;
            c->advancing = true;
        }
        return;
    case PMSTEP_CONSOLE_SIM_FINISH:
        if (!c->simulation) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_NOT_SUPPORTED);
        } else if (n != 0u) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
        } else if (c->advancing) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BUSY);
        } else {
            c->finish_requested = true;
            send_ack(c, type, seq, 0, 0u);
        }
        return;
    case PMSTEP_CONSOLE_START:
    case PMSTEP_CONSOLE_STOP:
    case PMSTEP_CONSOLE_CLEAR_FAULT:
    case PMSTEP_CONSOLE_GET_STATUS:
    case PMSTEP_CONSOLE_GET_COMMISSIONING:
        if (n != 0u) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        break;
    case PMSTEP_CONSOLE_SPEED_TARGET:
        if (n != 8u) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        c->a = get_f32(d);
        c->b = get_f32(d + 4);
        if (!is_finite(c->a) || !is_finite(c->b)) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
            return;
        }
        break;
    case PMSTEP_CONSOLE_ID_TARGET:
        if (n != 4u) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        c->a = get_f32(d);
        if (!is_finite(c->a)) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
            return;
        }
        break;
    case PMSTEP_CONSOLE_TELEMETRY:
        if (n != 4u) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
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
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
            return;
        }
        id = d[0] == 0xFFu ? config_by_name(d + fixed, n - fixed) : (int32_t)d[0];
        if (id < 0 || (uint32_t)id >= count) {
            send_error(c, type, seq, PMSTEP_CONSOLE_ERR_UNKNOWN_CONFIG);
            return;
        }
        c->cfg_id = (uint8_t)id;
        if (type == PMSTEP_CONSOLE_SET_CONFIG) {
            c->a = get_f32(d + 1);
            if ((t[id].flags & PMSTEP_CONSOLE_CFG_READ_ONLY) != 0u) {
                send_error(c, type, seq, PMSTEP_CONSOLE_ERR_READ_ONLY);
                return;
            }
            if (!is_finite(c->a)) {
                send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BAD_VALUE);
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
        send_error(c, type, seq, PMSTEP_CONSOLE_ERR_UNKNOWN_COMMAND);
        return;
    }
    if (c->pending) {
        send_error(c, type, seq, PMSTEP_CONSOLE_ERR_BUSY);
        return;
    }
    c->cmd = type;
    c->seq = seq;
    c->pending = true;
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
                handle_frame(c);
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

/* ---- at a period boundary ---- */

static void send_status(pmstep_console_t *c, uint8_t seq, const pmstep_console_snapshot_t *s)
{
    writer_t w;
    w.n = 0;
    put_u32(&w, s->period);
    put_u8(&w, (uint32_t)s->out.mode);
    put_u8(&w, (uint32_t)s->out.fault);
    put_u8(&w, s->port_fault);
    put_u8(&w, (s->out.bridge_enable ? 1u : 0u) | (s->out.voltage_limited ? 2u : 0u));
    put_u32(&w, s->out.fault_step);
    put_f32(&w, s->out.speed_ref_rad_s);
    put_f32(&w, s->out.speed_hat_rad_s);
    put_f32(&w, s->out.load_hat_Nm);
    put_f32(&w, s->out.cos_hat);
    put_f32(&w, s->out.sin_hat);
    put_f32(&w, s->meas.i_a_A);
    put_f32(&w, s->meas.i_b_A);
    put_f32(&w, s->meas.bus_voltage_V);
    put_f32(&w, s->out.u_a_V);
    put_f32(&w, s->out.u_b_V);
    put_f32(&w, s->out.i_d_A);
    put_f32(&w, s->out.i_q_A);
    send(c, PMSTEP_CONSOLE_GET_STATUS | 0x80u, seq, w.b, w.n);
}

static void send_config(pmstep_console_t *c, uint8_t seq, const pmstep_config_t *cfg, uint32_t id)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    writer_t w;
    float value = 0.0f;
    (void)pmstep_console_config_get(cfg, id, &value);
    w.n = 0;
    put_u8(&w, id);
    put_u8(&w, t[id].type);
    put_u8(&w, t[id].flags);
    put_f32(&w, value);
    put_text(&w, t[id].name, PMSTEP_CONSOLE_MAX_PAYLOAD - 2u - 7u);
    send(c, PMSTEP_CONSOLE_GET_CONFIG | 0x80u, seq, w.b, w.n);
}

static void send_position(pmstep_console_t *c, uint8_t seq, int32_t status, const pmstep_console_snapshot_t *s,
                          const pmstep_console_position_reading_t *r)
{
    writer_t w;
    w.n = 0;
    put_u16(&w, (uint32_t)(uint16_t)(int16_t)status);
    put_u32(&w, s->period);
    put_f32(&w, r->position_rad);
    put_f32(&w, r->position_ref_rad);
    put_f32(&w, r->position_error_rad);
    put_u8(&w, r->flags);
    send(c, PMSTEP_CONSOLE_GET_POSITION | 0x80u, seq, w.b, w.n);
}

void pmstep_console_boundary(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg,
                             const pmstep_console_snapshot_t *snap)
{
    const uint8_t seq = c->seq;
    int32_t st = 0;
    if (!c->pending) {
        return;
    }
    c->pending = false;
    c->count.commands_applied++;
    switch (c->cmd) {
    case PMSTEP_CONSOLE_START:
        st = (int32_t)pmstep_start(inst);
        break;
    case PMSTEP_CONSOLE_STOP:
        st = (int32_t)pmstep_stop(inst);
        break;
    case PMSTEP_CONSOLE_CLEAR_FAULT:
        st = (int32_t)pmstep_clear_fault(inst);
        break;
    case PMSTEP_CONSOLE_SPEED_TARGET:
        st = (int32_t)pmstep_set_speed_target(inst, c->a, c->b);
        break;
    case PMSTEP_CONSOLE_ID_TARGET:
        st = (int32_t)pmstep_set_id_target(inst, c->a);
        break;
    case PMSTEP_CONSOLE_TELEMETRY:
        /* Frames for the periods that are multiples of the decimation, from the next one on. */
        c->decimation = c->u;
        c->next_telemetry = c->u == 0u ? 0u : (snap->period + 1u) - (snap->period + 1u) % c->u + c->u;
        break;
    case PMSTEP_CONSOLE_MOVE_TO:
    case PMSTEP_CONSOLE_HOLD:
    case PMSTEP_CONSOLE_SET_POSITION_ZERO:
        st = c->position_apply(c->position, c->cmd, c->arg, NULL); /* attached: checked at parsing */
        break;
    case PMSTEP_CONSOLE_GET_POSITION: {
        pmstep_console_position_reading_t r;
        st = c->position_apply(c->position, c->cmd, c->arg, &r);
        send_position(c, seq, st, snap, &r);
        return;
    }
    case PMSTEP_CONSOLE_GET_STATUS:
        send_status(c, seq, snap);
        return;
    case PMSTEP_CONSOLE_GET_CONFIG:
        send_config(c, seq, cfg, c->cfg_id);
        return;
    case PMSTEP_CONSOLE_GET_COMMISSIONING: {
        pmstep_commissioning_t cm;
        writer_t w;
        pmstep_get_commissioning(inst, &cm);
        w.n = 0;
        put_u8(&w, cm.measured ? 1u : 0u);
        put_u32(&w, cm.offset_samples);
        put_u32(&w, cm.realignments);
        put_f32(&w, cm.offset_a_A);
        put_f32(&w, cm.offset_b_A);
        put_f32(&w, cm.resistance_Ohm);
        put_f32(&w, cm.phase_a_current_scale);
        put_f32(&w, cm.inductance_H);
        put_f32(&w, cm.torque_constant_Nm_A);
        put_f32(&w, cm.voltage_bias_a_V);
        put_f32(&w, cm.voltage_bias_b_V);
        send(c, PMSTEP_CONSOLE_GET_COMMISSIONING | 0x80u, seq, w.b, w.n);
        return;
    }
    case PMSTEP_CONSOLE_SET_CONFIG: {
        pmstep_config_t trial;
        int err;
        /* A configuration change re-initialises the core: only with the motor stopped. */
        if (snap->out.mode != PMSTEP_MODE_IDLE) {
            c->count.commands_applied--;
            send_error(c, PMSTEP_CONSOLE_SET_CONFIG, seq, PMSTEP_CONSOLE_ERR_NOT_STOPPED);
            return;
        }
        trial = *cfg;
        err = pmstep_console_config_set(&trial, c->cfg_id, c->a);
        if (err != 0) {
            c->count.commands_applied--;
            send_error(c, PMSTEP_CONSOLE_SET_CONFIG, seq, (pmstep_console_error_t)err);
            return;
        }
        st = (int32_t)pmstep_validate_config(&trial);
        if (st == (int32_t)PMSTEP_OK) {
            *cfg = trial;
            st = (int32_t)pmstep_init(inst, cfg);
        }
        break;
    }
    default:
        break;
    }
    send_ack(c, c->cmd, seq, st, snap->period + 1u);
}

void pmstep_console_telemetry(pmstep_console_t *c, const pmstep_console_snapshot_t *snap)
{
    writer_t w;
    if (c->decimation == 0u || (int32_t)(snap->period - c->next_telemetry) < 0) {
        return;
    }
    c->next_telemetry = snap->period - snap->period % c->decimation + c->decimation;
    w.n = 0;
    put_u32(&w, snap->period);
    put_u8(&w, (uint32_t)snap->out.mode);
    put_u8(&w, (uint32_t)snap->out.fault);
    put_f32(&w, snap->out.speed_ref_rad_s);
    put_f32(&w, snap->out.speed_hat_rad_s);
    put_f32(&w, snap->out.load_hat_Nm);
    put_f32(&w, snap->out.cos_hat);
    put_f32(&w, snap->out.sin_hat);
    put_f32(&w, snap->meas.i_a_A);
    put_f32(&w, snap->meas.i_b_A);
    put_f32(&w, snap->meas.bus_voltage_V);
    put_f32(&w, snap->out.u_a_V);
    put_f32(&w, snap->out.u_b_V);
    put_f32(&w, snap->out.i_q_A);
    c->count.telemetry_frames++;
    send(c, PMSTEP_CONSOLE_TELEMETRY_FRAME, 0u, w.b, w.n);
}

uint32_t pmstep_console_advance_request(pmstep_console_t *c)
{
    return c->advancing ? c->advance_periods : 0u;
}

void pmstep_console_advance_done(pmstep_console_t *c, uint32_t period)
{
    writer_t w;
    if (!c->advancing) {
        return;
    }
    c->advancing = false;
    w.n = 0;
    put_u16(&w, 0u);
    put_u32(&w, period);
    send(c, PMSTEP_CONSOLE_SIM_ADVANCE | 0x80u, c->advance_seq, w.b, w.n);
}

bool pmstep_console_finish_requested(const pmstep_console_t *c)
{
    return c->finish_requested;
}

uint8_t pmstep_console_pending_command(const pmstep_console_t *c)
{
    return c->pending ? c->cmd : 0u;
}
