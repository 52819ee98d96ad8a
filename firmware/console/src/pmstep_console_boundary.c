/*
 * Command and telemetry interface: at a period boundary (see pmstep_console.h): the mailbox's
 * request applied to the core and answered, and the telemetry frames.
 */
#include "pmstep_console_internal.h"

#include <stddef.h>

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
    pmstep_console_send(c, PMSTEP_CONSOLE_GET_STATUS | 0x80u, seq, w.b, w.n);
}

static void send_config(pmstep_console_t *c, uint8_t seq, const pmstep_config_t *cfg, uint32_t id)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    writer_t w;
    float value = 0.0f;
    (void)pmstep_console_config_get(cfg, &c->stepdir, id, &value);
    w.n = 0;
    put_u8(&w, id);
    put_u8(&w, t[id].type);
    put_u8(&w, t[id].flags);
    put_f32(&w, value);
    put_text(&w, t[id].name, PMSTEP_CONSOLE_MAX_PAYLOAD - 2u - 7u);
    pmstep_console_send(c, PMSTEP_CONSOLE_GET_CONFIG | 0x80u, seq, w.b, w.n);
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
    pmstep_console_send(c, PMSTEP_CONSOLE_GET_POSITION | 0x80u, seq, w.b, w.n);
}

static void send_home_status(pmstep_console_t *c, uint8_t seq, int32_t status, const pmstep_console_snapshot_t *s,
                             const pmstep_console_position_reading_t *r)
{
    writer_t w;
    w.n = 0;
    put_u16(&w, (uint32_t)(uint16_t)(int16_t)status);
    put_u32(&w, s->period);
    put_u8(&w, r->homing_state);
    put_u8(&w, r->homing_by_current);
    put_f32(&w, r->homing_stop_rad);
    put_f32(&w, r->position_rad);
    pmstep_console_send(c, PMSTEP_CONSOLE_HOME_STATUS | 0x80u, seq, w.b, w.n);
}

/* What a request may do while a calibration runs: read, or STOP it (the calibration's); the rest would
 * reach a core the calibration drives. */
static bool allowed_while_calibrating(uint8_t cmd)
{
    return cmd == PMSTEP_CONSOLE_GET_STATUS || cmd == PMSTEP_CONSOLE_GET_CONFIG
           || cmd == PMSTEP_CONSOLE_GET_COMMISSIONING || cmd == PMSTEP_CONSOLE_TELEMETRY
           || cmd == PMSTEP_CONSOLE_GET_POSITION || cmd == PMSTEP_CONSOLE_CONFIG_READ
           || cmd == PMSTEP_CONSOLE_SIM_STEPDIR;
}

/* How a request applied at the boundary ended: acknowledged by the boundary with its status, answered
 * by its handler, or refused by its handler (which replied, or whose attachment did) and not counted
 * as applied. */
typedef enum { APPLY_ACK, APPLY_REPLIED, APPLY_REFUSED } apply_end_t;

/* What a handler works on at the boundary. */
typedef struct {
    pmstep_t *inst;
    pmstep_config_t *cfg;
    const pmstep_console_snapshot_t *snap;
} boundary_t;

/* A request's handler; @p status is the acknowledgement's with APPLY_ACK. */
typedef apply_end_t (*apply_t)(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                               int32_t *status);

static apply_end_t apply_start(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                               int32_t *status)
{
    if (c->store != NULL && !c->store->configured) {
        /* No motor's configuration in force: the board's defaults are no motor's to drive. */
        pmstep_console_send_error(c, PMSTEP_CONSOLE_START, req->seq, PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
        return APPLY_REFUSED;
    }
    *status = (int32_t)pmstep_start(b->inst);
    return APPLY_ACK;
}

static apply_end_t apply_stop(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                              int32_t *status)
{
    (void)c;
    (void)req;
    *status = (int32_t)pmstep_stop(b->inst);
    return APPLY_ACK;
}

static apply_end_t apply_clear_fault(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                     int32_t *status)
{
    (void)c;
    (void)req;
    *status = (int32_t)pmstep_clear_fault(b->inst);
    return APPLY_ACK;
}

static apply_end_t apply_speed_target(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                      int32_t *status)
{
    (void)c;
    *status = (int32_t)pmstep_set_speed_target(b->inst, req->a, req->b);
    return APPLY_ACK;
}

static apply_end_t apply_id_target(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                   int32_t *status)
{
    (void)c;
    *status = (int32_t)pmstep_set_id_target(b->inst, req->a);
    return APPLY_ACK;
}

/* Frames for the periods that are multiples of the decimation, from the next one on. */
static apply_end_t apply_telemetry(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                   int32_t *status)
{
    const uint32_t next_period = b->snap->period + 1u;
    c->decimation = req->u;
    c->next_telemetry = req->u == 0u ? 0u : next_period - next_period % req->u + req->u;
    *status = 0;
    return APPLY_ACK;
}

/* CALIBRATE: its attachment (checked at parsing) replies. */
static apply_end_t apply_calibrate(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                   int32_t *status)
{
    (void)status;
    return c->calibration_apply(c, req, b->inst, b->cfg, b->snap) ? APPLY_REPLIED : APPLY_REFUSED;
}

/* CONFIG_READ, _APPLY, _SAVE, _ERASE, _DEFAULTS: the store's attachment (checked at parsing) replies. */
static apply_end_t apply_store(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                               int32_t *status)
{
    (void)status;
    return c->store_apply(c, req, b->inst, b->cfg, b->snap) ? APPLY_REPLIED : APPLY_REFUSED;
}

/* SIM_FOLLOW_STEPS, SIM_STEPDIR: a simulation image's attachment (checked at parsing) replies. */
static apply_end_t apply_sim_stepdir(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                     int32_t *status)
{
    (void)status;
    (void)c->sim_stepdir_apply(c, req, b->inst, b->cfg, b->snap);
    return APPLY_REPLIED;
}

/* MOVE_TO, HOLD, SET_POSITION_ZERO, HOME: the position attachment (checked at parsing). */
static apply_end_t apply_position_command(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                          int32_t *status)
{
    (void)b;
    *status = c->position_apply(c, req->cmd, req->arg, NULL);
    return APPLY_ACK;
}

static apply_end_t apply_get_position(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                      int32_t *status)
{
    pmstep_console_position_reading_t r;
    *status = c->position_apply(c, req->cmd, req->arg, &r);
    send_position(c, req->seq, *status, b->snap, &r);
    return APPLY_REPLIED;
}

static apply_end_t apply_home_status(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                     int32_t *status)
{
    pmstep_console_position_reading_t r;
    *status = c->position_apply(c, req->cmd, req->arg, &r);
    send_home_status(c, req->seq, *status, b->snap, &r);
    return APPLY_REPLIED;
}

static apply_end_t apply_get_status(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                    int32_t *status)
{
    (void)status;
    send_status(c, req->seq, b->snap);
    return APPLY_REPLIED;
}

static apply_end_t apply_get_config(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                    int32_t *status)
{
    (void)status;
    send_config(c, req->seq, b->cfg, req->cfg_id);
    return APPLY_REPLIED;
}

static apply_end_t apply_get_commissioning(pmstep_console_t *c, const pmstep_console_request_t *req,
                                           const boundary_t *b, int32_t *status)
{
    pmstep_commissioning_t cm;
    writer_t w;
    (void)status;
    pmstep_get_commissioning(b->inst, &cm);
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
    pmstep_console_send(c, PMSTEP_CONSOLE_GET_COMMISSIONING | 0x80u, req->seq, w.b, w.n);
    return APPLY_REPLIED;
}

/* The core's part of SET_CONFIG: the trial configuration validated, the STEP/DIR stall current kept
 * below its trip, then in force and the core initialised with it (the position loop's gains anew). */
static int32_t put_core_config_in_force(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                        const pmstep_config_t *trial)
{
    int32_t st = (int32_t)pmstep_validate_config(trial);
    if (st == (int32_t)PMSTEP_OK && !(c->stepdir.stall_current_A < trial->limits.max_phase_current_A)) {
        st = (int32_t)PMSTEP_ERR_STEPDIR_STALL_CURRENT; /* the trip lowered to or below the STEP/DIR stall current */
    }
    if (st == (int32_t)PMSTEP_OK) {
        *b->cfg = *trial;
        st = (int32_t)pmstep_init(b->inst, b->cfg);
    }
    if (st == (int32_t)PMSTEP_OK && c->position_apply != NULL) {
        st = c->position_apply(c, PMSTEP_CONSOLE_SET_CONFIG, req->arg, NULL); /* gains anew */
    }
    return st;
}

/* A configuration change re-initialises the core: only with the motor stopped, as the core is now (a
 * START applied at an earlier boundary may not have reached a step yet, so the snapshot's mode cannot
 * tell), and never out of FAULT (only CLEAR_FAULT leaves it). */
static apply_end_t apply_set_config(pmstep_console_t *c, const pmstep_console_request_t *req, const boundary_t *b,
                                    int32_t *status)
{
    pmstep_config_t trial;
    pmstep_stepdir_settings_t stepdir = c->stepdir;
    int err;
    if (pmstep_get_mode(b->inst) != PMSTEP_MODE_IDLE) {
        pmstep_console_send_error(c, PMSTEP_CONSOLE_SET_CONFIG, req->seq, PMSTEP_CONSOLE_ERR_NOT_STOPPED);
        return APPLY_REFUSED;
    }
    trial = *b->cfg;
    err = pmstep_console_config_set(&trial, &stepdir, req->cfg_id, req->a);
    if (err != 0) {
        pmstep_console_send_error(c, PMSTEP_CONSOLE_SET_CONFIG, req->seq, (pmstep_console_error_t)err);
        return APPLY_REFUSED;
    }
    if (pmstep_console_config_is_stepdir(req->cfg_id)) {
        /* The STEP/DIR input's: checked whole, in force when accepted; the core is not touched (the
         * image applies them when it next starts following). */
        pmstep_stepdir_config_t in_force;
        *status =
            (int32_t)pmstep_console_stepdir_config(b->cfg, &stepdir, &in_force); /* the stall current by the trip */
        if (*status == (int32_t)PMSTEP_OK) {
            c->stepdir = stepdir;
        }
    } else {
        *status = put_core_config_in_force(c, req, b, &trial);
    }
    return APPLY_ACK;
}

/* Each request the boundary applies, with its handler. HELLO and GET_COUNTERS are answered at
 * parsing and never reach it; a request without a row is acknowledged with status 0. */
typedef struct {
    uint8_t cmd;
    apply_t apply;
} apply_row_t;

static const apply_row_t apply_rows[] = {
    {PMSTEP_CONSOLE_START, apply_start},
    {PMSTEP_CONSOLE_STOP, apply_stop},
    {PMSTEP_CONSOLE_CLEAR_FAULT, apply_clear_fault},
    {PMSTEP_CONSOLE_SPEED_TARGET, apply_speed_target},
    {PMSTEP_CONSOLE_ID_TARGET, apply_id_target},
    {PMSTEP_CONSOLE_TELEMETRY, apply_telemetry},
    {PMSTEP_CONSOLE_CALIBRATE, apply_calibrate},
    {PMSTEP_CONSOLE_CONFIG_READ, apply_store},
    {PMSTEP_CONSOLE_CONFIG_APPLY, apply_store},
    {PMSTEP_CONSOLE_CONFIG_SAVE, apply_store},
    {PMSTEP_CONSOLE_CONFIG_ERASE, apply_store},
    {PMSTEP_CONSOLE_CONFIG_DEFAULTS, apply_store},
    {PMSTEP_CONSOLE_SIM_FOLLOW_STEPS, apply_sim_stepdir},
    {PMSTEP_CONSOLE_SIM_STEPDIR, apply_sim_stepdir},
    {PMSTEP_CONSOLE_MOVE_TO, apply_position_command},
    {PMSTEP_CONSOLE_HOLD, apply_position_command},
    {PMSTEP_CONSOLE_SET_POSITION_ZERO, apply_position_command},
    {PMSTEP_CONSOLE_HOME, apply_position_command},
    {PMSTEP_CONSOLE_GET_POSITION, apply_get_position},
    {PMSTEP_CONSOLE_HOME_STATUS, apply_home_status},
    {PMSTEP_CONSOLE_GET_STATUS, apply_get_status},
    {PMSTEP_CONSOLE_GET_CONFIG, apply_get_config},
    {PMSTEP_CONSOLE_GET_COMMISSIONING, apply_get_commissioning},
    {PMSTEP_CONSOLE_SET_CONFIG, apply_set_config},
};

static apply_t handler_of(uint8_t cmd)
{
    apply_t found = NULL;
    size_t k;
    for (k = 0u; k < sizeof apply_rows / sizeof apply_rows[0]; ++k) {
        if (apply_rows[k].cmd == cmd) {
            found = apply_rows[k].apply;
        }
    }
    return found;
}

void pmstep_console_boundary(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg,
                             const pmstep_console_snapshot_t *snap)
{
    const pmstep_console_request_t *req = &c->mail;
    const boundary_t b = {inst, cfg, snap};
    apply_t apply;
    apply_end_t end = APPLY_ACK;
    int32_t st = 0;
    if (c->calibrating) {
        (void)c->calibration_apply(c, NULL, inst, cfg, snap); /* its runs advance at every boundary */
    }
    if (!c->pending) {
        return;
    }
    c->pending = false;
    c->count.commands_applied++;
    if (c->calibrating && !allowed_while_calibrating(req->cmd)) {
        if (req->cmd != PMSTEP_CONSOLE_STOP || !c->calibration_apply(c, req, inst, cfg, snap)) {
            c->count.commands_applied--;
            if (req->cmd != PMSTEP_CONSOLE_STOP) {
                pmstep_console_send_error(c, req->cmd, req->seq, PMSTEP_CONSOLE_ERR_BUSY);
            }
        }
        return;
    }
    apply = handler_of(req->cmd);
    if (apply != NULL) {
        end = apply(c, req, &b, &st);
    }
    if (end == APPLY_REFUSED) {
        c->count.commands_applied--;
    } else if (end == APPLY_ACK) {
        pmstep_console_send_ack(c, req->cmd, req->seq, st, snap->period + 1u);
    } else {
        /* the handler replied */
    }
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
    pmstep_console_send(c, PMSTEP_CONSOLE_TELEMETRY_FRAME, 0u, w.b, w.n);
}

uint8_t pmstep_console_pending_command(const pmstep_console_t *c)
{
    return c->pending ? c->mail.cmd : 0u;
}
