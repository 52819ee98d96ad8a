/*
 * Command and telemetry interface: a request on arrival (see pmstep_console.h). A table gives
 * each request type its DATA length and its parser. HELLO, GET_COUNTERS, the simulation
 * requests and every error are answered at once; any other request is parsed into a request of
 * its own and, only once accepted, put whole in the mailbox for the next period boundary
 * (pmstep_console_boundary.c): a refused request, busy included, changes nothing.
 * Every loop is bounded by a frame's length or the table's; nothing waits on anything.
 */
#include "pmstep_console_internal.h"

#include <stddef.h>

/* A parser's outcome besides an error code (pmstep_console_error_t, > 0). */
#define REQUEST_QUEUE 0     /* accepted: @p req goes to the mailbox */
#define REQUEST_ANSWERED -1 /* answered at once, nothing for the mailbox */

/* Parses DATA @p d of @p n bytes (its length already within the row's) into @p req.
 * @return REQUEST_QUEUE, REQUEST_ANSWERED, or the error code to reply. */
typedef int (*request_parse_t)(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req);

/* What a request needs of the image before its length is looked at. */
#define NEEDS_NOTHING 0u
#define NEEDS_POSITION 1u   /* position control attached, else PMSTEP_CONSOLE_ERR_NO_POSITION */
#define NEEDS_SIMULATION 2u /* a simulation image, else PMSTEP_CONSOLE_ERR_NOT_SUPPORTED */
#define NEEDS_STORE 3u      /* the stored configuration attached, else PMSTEP_CONSOLE_ERR_NO_STORE */
#define NEEDS_CALIBRATION 4u /* the store and self-commissioning attached, else _NO_STORE / _NO_CALIBRATION */
#define NEEDS_SIM_STEPDIR 5u /* a simulation image's STEP/DIR input attached, else PMSTEP_CONSOLE_ERR_NOT_SUPPORTED */

typedef struct {
    uint8_t type;
    uint8_t needs;
    uint8_t min_length; /* DATA bytes */
    uint8_t max_length;
    request_parse_t parse;
} request_row_t;

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

static int parse_hello(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    writer_t w;
    (void)d;
    (void)n;
    w.n = 0;
    put_u8(&w, PMSTEP_CONSOLE_PROTOCOL_VERSION);
    put_u8(&w, PMSTEP_CONSOLE_MAX_PAYLOAD);
    put_u8(&w, c->store != NULL ? PMSTEP_STORE_FORMAT_VERSION : 0u);
    put_u8(&w, (c->store != NULL ? 1u : 0u) | (c->store == NULL || c->store->configured ? 2u : 0u));
    put_text(&w, c->identity != NULL ? c->identity : "pmstep", PMSTEP_CONSOLE_MAX_PAYLOAD - 6u);
    pmstep_console_send(c, (uint8_t)(req->cmd | 0x80u), req->seq, w.b, w.n);
    return REQUEST_ANSWERED;
}

static int parse_counters(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    const pmstep_console_counters_t *k = &c->count;
    const uint32_t values[] = {k->rx_bytes,          k->rx_frames,        k->rx_garbage_bytes, k->rx_bad_length,
                               k->rx_crc_errors,     k->rx_truncated,     k->rx_error_replies, k->commands_applied,
                               k->tx_frames,         k->tx_dropped,       k->telemetry_frames};
    writer_t w;
    uint32_t i;
    (void)d;
    (void)n;
    w.n = 0;
    for (i = 0; i < sizeof values / sizeof values[0]; ++i) {
        put_u32(&w, values[i]);
    }
    pmstep_console_send(c, (uint8_t)(req->cmd | 0x80u), req->seq, w.b, w.n);
    return REQUEST_ANSWERED;
}

static int parse_simulation(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    const int err = c->sim_request(c, req->cmd, req->seq, d, n); /* attached: checked by the row */
    return err != 0 ? err : REQUEST_ANSWERED;
}

/* A request without values (its length checked by the row). */
static int parse_plain(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    (void)c;
    (void)d;
    (void)n;
    (void)req;
    return REQUEST_QUEUE;
}

static int parse_speed_target(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    (void)c;
    (void)n;
    req->a = get_f32(d);
    req->b = get_f32(d + 4);
    return is_finite(req->a) && is_finite(req->b) ? REQUEST_QUEUE : PMSTEP_CONSOLE_ERR_BAD_VALUE;
}

static int parse_id_target(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    (void)c;
    (void)n;
    req->a = get_f32(d);
    return is_finite(req->a) ? REQUEST_QUEUE : PMSTEP_CONSOLE_ERR_BAD_VALUE;
}

static int parse_telemetry(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    (void)c;
    (void)n;
    req->u = get_u32(d);
    return REQUEST_QUEUE;
}

/* GET_CONFIG: id, or 0xFF and a name; SET_CONFIG: the same with a value after the id. */
static int parse_config(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    const bool set = req->cmd == PMSTEP_CONSOLE_SET_CONFIG;
    const uint32_t fixed = set ? 5u : 1u; /* id (+ value) */
    const bool by_name = d[0] == 0xFFu;
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    int32_t id;
    (void)c;
    if (by_name ? n == fixed : n != fixed) {
        return PMSTEP_CONSOLE_ERR_BAD_LENGTH;
    }
    id = by_name ? config_by_name(d + fixed, n - fixed) : (int32_t)d[0];
    if (id < 0 || (uint32_t)id >= count) {
        return PMSTEP_CONSOLE_ERR_UNKNOWN_CONFIG;
    }
    req->cfg_id = (uint8_t)id;
    if (!set) {
        return REQUEST_QUEUE;
    }
    if ((t[id].flags & PMSTEP_CONSOLE_CFG_READ_ONLY) != 0u) {
        return PMSTEP_CONSOLE_ERR_READ_ONLY;
    }
    req->a = get_f32(d + 1);
    return is_finite(req->a) ? REQUEST_QUEUE : PMSTEP_CONSOLE_ERR_BAD_VALUE;
}

/* A position request's values, whole floats only (MOVE_TO and HOME 3 or 4, HOLD 0 or 1), absent ones 0. */
static int parse_position(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    uint32_t i;
    (void)c;
    if (n % 4u != 0u) {
        return PMSTEP_CONSOLE_ERR_BAD_LENGTH;
    }
    for (i = 0; i < 4u; ++i) {
        req->arg[i] = 4u * i < n ? get_f32(d + 4u * i) : 0.0f;
        if (!is_finite(req->arg[i])) {
            return PMSTEP_CONSOLE_ERR_BAD_VALUE;
        }
    }
    return REQUEST_QUEUE;
}

/* CONFIG_READ: the offset to read from. */
static int parse_config_read(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    (void)c;
    (void)n;
    req->offset = (uint16_t)(d[0] | ((uint32_t)d[1] << 8));
    return req->offset < PMSTEP_STORE_RECORD_MAX_BYTES ? REQUEST_QUEUE : PMSTEP_CONSOLE_ERR_BAD_VALUE;
}

/* CONFIG_WRITE: bytes of a record into the staging buffer, in order; answered at once. Refused while
 * a CONFIG_APPLY waits to decode the buffer. */
static int parse_config_write(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    pmstep_console_store_t *cs = c->store;
    const uint32_t offset = (uint32_t)d[0] | ((uint32_t)d[1] << 8);
    const uint32_t count = n - 2u;
    writer_t w;
    if (c->pending && c->mail.cmd == PMSTEP_CONSOLE_CONFIG_APPLY) {
        return PMSTEP_CONSOLE_ERR_BUSY;
    }
    if ((offset != 0u && offset != cs->staged) || offset + count > sizeof cs->staging) {
        return PMSTEP_CONSOLE_ERR_BAD_VALUE;
    }
    memcpy(&cs->staging[offset], d + 2, count);
    cs->staged = offset + count;
    w.n = 0;
    put_u16(&w, cs->staged);
    pmstep_console_send(c, (uint8_t)(req->cmd | 0x80u), req->seq, w.b, w.n);
    return REQUEST_ANSWERED;
}

static int parse_config_status(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    const pmstep_console_store_t *cs = c->store;
    writer_t w;
    (void)d;
    (void)n;
    w.n = 0;
    put_u8(&w, cs->configured ? 1u : 0u);
    put_u16(&w, (uint32_t)(uint16_t)cs->boot_status);
    put_u16(&w, (uint32_t)(uint16_t)cs->boot_validation);
    put_u16(&w, (uint32_t)(uint16_t)cs->last_status);
    put_u8(&w, (uint32_t)(uint8_t)(int8_t)cs->store->slot);
    put_u32(&w, cs->store->sequence);
    put_u16(&w, pmstep_store_record_bytes());
    put_u8(&w, PMSTEP_STORE_FORMAT_VERSION);
    put_u32(&w, pmstep_store_layout_id());
    put_u32(&w, cs->store->board_id);
    pmstep_console_send(c, (uint8_t)(req->cmd | 0x80u), req->seq, w.b, w.n);
    return REQUEST_ANSWERED;
}

/* CALIBRATE: rated current f32, pole pairs u16 [, flags u8 [, detent fraction f32]]. */
static int parse_calibrate(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    (void)c;
    if (n != 6u && n != 7u && n != 11u) {
        return PMSTEP_CONSOLE_ERR_BAD_LENGTH;
    }
    req->a = get_f32(d);
    req->u = (uint32_t)d[4] | ((uint32_t)d[5] << 8);
    req->arg[0] = n >= 7u ? (float)d[6] : 0.0f;
    req->b = n == 11u ? get_f32(d + 7) : PMSTEP_CALIBRATE_DETENT_PER_HOLDING;
    return is_finite(req->a) && is_finite(req->b) ? REQUEST_QUEUE : PMSTEP_CONSOLE_ERR_BAD_VALUE;
}

static int parse_calibrate_status(pmstep_console_t *c, const uint8_t *d, uint32_t n, pmstep_console_request_t *req)
{
    const pmstep_calibrate_t *cal = c->calibration;
    writer_t w;
    (void)d;
    (void)n;
    w.n = 0;
    put_u8(&w, (uint32_t)cal->stage);
    put_u16(&w, (uint32_t)(uint16_t)(int16_t)cal->status);
    put_u8(&w, (uint32_t)cal->fault);
    put_u8(&w, cal->runs < 255u ? cal->runs : 255u);
    put_u8(&w, (uint32_t)cal->identification);
    put_u16(&w, (uint32_t)(uint16_t)c->calibration_save_status);
    put_f32(&w, cal->resistance_Ohm);
    put_f32(&w, cal->inductance_H);
    put_f32(&w, cal->torque_constant_Nm_A);
    put_f32(&w, cal->inertia_kgm2);
    put_f32(&w, cal->friction_Nms_rad);
    pmstep_console_send(c, (uint8_t)(req->cmd | 0x80u), req->seq, w.b, w.n);
    return REQUEST_ANSWERED;
}

#define NAME_ROOM (PMSTEP_CONSOLE_MAX_PAYLOAD - 2u) /* DATA bytes a frame can carry */

static const request_row_t requests[] = {
    {PMSTEP_CONSOLE_HELLO, NEEDS_NOTHING, 0u, 0u, parse_hello},
    {PMSTEP_CONSOLE_START, NEEDS_NOTHING, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_STOP, NEEDS_NOTHING, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_CLEAR_FAULT, NEEDS_NOTHING, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_SPEED_TARGET, NEEDS_NOTHING, 8u, 8u, parse_speed_target},
    {PMSTEP_CONSOLE_ID_TARGET, NEEDS_NOTHING, 4u, 4u, parse_id_target},
    {PMSTEP_CONSOLE_GET_STATUS, NEEDS_NOTHING, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_GET_CONFIG, NEEDS_NOTHING, 1u, NAME_ROOM, parse_config},
    {PMSTEP_CONSOLE_SET_CONFIG, NEEDS_NOTHING, 5u, NAME_ROOM, parse_config},
    {PMSTEP_CONSOLE_GET_COMMISSIONING, NEEDS_NOTHING, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_TELEMETRY, NEEDS_NOTHING, 4u, 4u, parse_telemetry},
    {PMSTEP_CONSOLE_GET_COUNTERS, NEEDS_NOTHING, 0u, 0u, parse_counters},
    {PMSTEP_CONSOLE_MOVE_TO, NEEDS_POSITION, 12u, 16u, parse_position},
    {PMSTEP_CONSOLE_HOLD, NEEDS_POSITION, 0u, 4u, parse_position},
    {PMSTEP_CONSOLE_GET_POSITION, NEEDS_POSITION, 0u, 0u, parse_position},
    {PMSTEP_CONSOLE_SET_POSITION_ZERO, NEEDS_POSITION, 0u, 0u, parse_position},
    {PMSTEP_CONSOLE_HOME, NEEDS_POSITION, 12u, 16u, parse_position},
    {PMSTEP_CONSOLE_HOME_STATUS, NEEDS_POSITION, 0u, 0u, parse_position},
    {PMSTEP_CONSOLE_CONFIG_READ, NEEDS_STORE, 2u, 2u, parse_config_read},
    {PMSTEP_CONSOLE_CONFIG_WRITE, NEEDS_STORE, 3u, NAME_ROOM, parse_config_write},
    {PMSTEP_CONSOLE_CONFIG_APPLY, NEEDS_STORE, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_CONFIG_SAVE, NEEDS_STORE, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_CONFIG_ERASE, NEEDS_STORE, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_CONFIG_DEFAULTS, NEEDS_STORE, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_CONFIG_STATUS, NEEDS_STORE, 0u, 0u, parse_config_status},
    {PMSTEP_CONSOLE_CALIBRATE, NEEDS_CALIBRATION, 6u, 11u, parse_calibrate},
    {PMSTEP_CONSOLE_CALIBRATE_STATUS, NEEDS_CALIBRATION, 0u, 0u, parse_calibrate_status},
    {PMSTEP_CONSOLE_SIM_ADVANCE, NEEDS_SIMULATION, 4u, 4u, parse_simulation},
    {PMSTEP_CONSOLE_SIM_FINISH, NEEDS_SIMULATION, 0u, 0u, parse_simulation},
    {PMSTEP_CONSOLE_SIM_STEPS, NEEDS_SIM_STEPDIR, 1u, PMSTEP_CONSOLE_SIM_STEPS_MAX, parse_simulation},
    {PMSTEP_CONSOLE_SIM_FOLLOW_STEPS, NEEDS_SIM_STEPDIR, 0u, 0u, parse_plain},
    {PMSTEP_CONSOLE_SIM_STEPDIR, NEEDS_SIM_STEPDIR, 0u, 0u, parse_plain},
};

static const request_row_t *request_row(uint8_t type)
{
    uint32_t i;
    for (i = 0; i < sizeof requests / sizeof requests[0]; ++i) {
        if (requests[i].type == type) {
            return &requests[i];
        }
    }
    return NULL;
}

/* Whether the image has what @p row needs; the error reply otherwise. */
static int row_available(const pmstep_console_t *c, const request_row_t *row)
{
    if (row->needs == NEEDS_POSITION && (c->position == NULL || c->position_apply == NULL)) {
        return PMSTEP_CONSOLE_ERR_NO_POSITION;
    }
    if ((row->needs == NEEDS_SIMULATION || row->needs == NEEDS_SIM_STEPDIR) && c->sim_request == NULL) {
        return PMSTEP_CONSOLE_ERR_NOT_SUPPORTED;
    }
    if (row->needs == NEEDS_SIM_STEPDIR && (c->sim_stepdir == NULL || c->sim_stepdir_apply == NULL)) {
        return PMSTEP_CONSOLE_ERR_NOT_SUPPORTED;
    }
    if ((row->needs == NEEDS_STORE || row->needs == NEEDS_CALIBRATION) && (c->store == NULL || c->store_apply == NULL)) {
        return PMSTEP_CONSOLE_ERR_NO_STORE;
    }
    if (row->needs == NEEDS_CALIBRATION && (c->calibration == NULL || c->calibration_apply == NULL)) {
        return PMSTEP_CONSOLE_ERR_NO_CALIBRATION;
    }
    return REQUEST_QUEUE;
}

/* A request with a good CRC: answered now (HELLO, GET_COUNTERS, the simulation's, errors), or
 * put in the mailbox for the next period boundary. */
void pmstep_console_handle_frame(pmstep_console_t *c)
{
    const uint8_t *d = &c->buf[2];
    const uint32_t n = (uint32_t)c->len - 2u;
    const request_row_t *row = request_row(c->buf[0]);
    pmstep_console_request_t req = {0};
    int outcome;
    req.cmd = c->buf[0];
    req.seq = c->buf[1];
    c->count.rx_frames++;
    if (row == NULL) {
        outcome = PMSTEP_CONSOLE_ERR_UNKNOWN_COMMAND;
    } else {
        outcome = row_available(c, row);
        if (outcome == REQUEST_QUEUE && (n < row->min_length || n > row->max_length)) {
            outcome = PMSTEP_CONSOLE_ERR_BAD_LENGTH;
        }
        if (outcome == REQUEST_QUEUE) {
            outcome = row->parse(c, d, n, &req);
        }
    }
    if (outcome == REQUEST_QUEUE && c->pending) {
        outcome = PMSTEP_CONSOLE_ERR_BUSY;
    }
    if (outcome == REQUEST_QUEUE) {
        c->mail = req;
        c->pending = true;
    } else if (outcome != REQUEST_ANSWERED) {
        pmstep_console_send_error(c, req.cmd, req.seq, (pmstep_console_error_t)outcome);
    }
}
