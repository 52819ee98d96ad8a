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

/* What a request may do while a calibration runs: read, or STOP it (the calibration's); the rest would
 * reach a core the calibration drives. */
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

static bool allowed_while_calibrating(uint8_t cmd)
{
    return cmd == PMSTEP_CONSOLE_GET_STATUS || cmd == PMSTEP_CONSOLE_GET_CONFIG || cmd == PMSTEP_CONSOLE_GET_COMMISSIONING
           || cmd == PMSTEP_CONSOLE_TELEMETRY || cmd == PMSTEP_CONSOLE_GET_POSITION || cmd == PMSTEP_CONSOLE_CONFIG_READ
           || cmd == PMSTEP_CONSOLE_SIM_STEPDIR;
}

void pmstep_console_boundary(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg,
                             const pmstep_console_snapshot_t *snap)
{
    const pmstep_console_request_t *req = &c->mail;
    const uint8_t seq = req->seq;
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
                pmstep_console_send_error(c, req->cmd, seq, PMSTEP_CONSOLE_ERR_BUSY);
            }
        }
        return;
    }
    switch (req->cmd) {
    case PMSTEP_CONSOLE_START:
        if (c->store != NULL && !c->store->configured) {
            /* No motor's configuration in force: the board's defaults are no motor's to drive. */
            c->count.commands_applied--;
            pmstep_console_send_error(c, PMSTEP_CONSOLE_START, seq, PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
            return;
        }
        st = (int32_t)pmstep_start(inst);
        break;
    case PMSTEP_CONSOLE_CALIBRATE:
        if (!c->calibration_apply(c, req, inst, cfg, snap)) { /* attached: checked at parsing; it replies */
            c->count.commands_applied--;
        }
        return;
    case PMSTEP_CONSOLE_CONFIG_READ:
    case PMSTEP_CONSOLE_CONFIG_APPLY:
    case PMSTEP_CONSOLE_CONFIG_SAVE:
    case PMSTEP_CONSOLE_CONFIG_ERASE:
    case PMSTEP_CONSOLE_CONFIG_DEFAULTS:
        if (!c->store_apply(c, req, inst, cfg, snap)) { /* attached: checked at parsing; it replies */
            c->count.commands_applied--;
        }
        return;
    case PMSTEP_CONSOLE_SIM_FOLLOW_STEPS:
    case PMSTEP_CONSOLE_SIM_STEPDIR:
        (void)c->sim_stepdir_apply(c, req, inst, cfg, snap); /* attached: checked at parsing; it replies */
        return;
    case PMSTEP_CONSOLE_STOP:
        st = (int32_t)pmstep_stop(inst);
        break;
    case PMSTEP_CONSOLE_CLEAR_FAULT:
        st = (int32_t)pmstep_clear_fault(inst);
        break;
    case PMSTEP_CONSOLE_SPEED_TARGET:
        st = (int32_t)pmstep_set_speed_target(inst, req->a, req->b);
        break;
    case PMSTEP_CONSOLE_ID_TARGET:
        st = (int32_t)pmstep_set_id_target(inst, req->a);
        break;
    case PMSTEP_CONSOLE_TELEMETRY:
        /* Frames for the periods that are multiples of the decimation, from the next one on. */
        c->decimation = req->u;
        c->next_telemetry = req->u == 0u ? 0u : (snap->period + 1u) - (snap->period + 1u) % req->u + req->u;
        break;
    case PMSTEP_CONSOLE_MOVE_TO:
    case PMSTEP_CONSOLE_HOLD:
    case PMSTEP_CONSOLE_SET_POSITION_ZERO:
    case PMSTEP_CONSOLE_HOME:
        st = c->position_apply(c, req->cmd, req->arg, NULL); /* attached: checked at parsing */
        break;
    case PMSTEP_CONSOLE_GET_POSITION: {
        pmstep_console_position_reading_t r;
        st = c->position_apply(c, req->cmd, req->arg, &r);
        send_position(c, seq, st, snap, &r);
        return;
    }
    case PMSTEP_CONSOLE_HOME_STATUS: {
        pmstep_console_position_reading_t r;
        st = c->position_apply(c, req->cmd, req->arg, &r);
        send_home_status(c, seq, st, snap, &r);
        return;
    }
    case PMSTEP_CONSOLE_GET_STATUS:
        send_status(c, seq, snap);
        return;
    case PMSTEP_CONSOLE_GET_CONFIG:
        send_config(c, seq, cfg, req->cfg_id);
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
        pmstep_console_send(c, PMSTEP_CONSOLE_GET_COMMISSIONING | 0x80u, seq, w.b, w.n);
        return;
    }
    case PMSTEP_CONSOLE_SET_CONFIG: {
        pmstep_config_t trial;
        pmstep_stepdir_settings_t stepdir = c->stepdir;
        int err;
        /* A configuration change re-initialises the core: only with the motor stopped, as the core
         * is now (a START applied at an earlier boundary may not have reached a step yet, so the
         * snapshot's mode cannot tell), and never out of FAULT (only CLEAR_FAULT leaves it). */
        if (pmstep_get_mode(inst) != PMSTEP_MODE_IDLE) {
            c->count.commands_applied--;
            pmstep_console_send_error(c, PMSTEP_CONSOLE_SET_CONFIG, seq, PMSTEP_CONSOLE_ERR_NOT_STOPPED);
            return;
        }
        trial = *cfg;
        err = pmstep_console_config_set(&trial, &stepdir, req->cfg_id, req->a);
        if (err != 0) {
            c->count.commands_applied--;
            pmstep_console_send_error(c, PMSTEP_CONSOLE_SET_CONFIG, seq, (pmstep_console_error_t)err);
            return;
        }
        if (pmstep_console_config_is_stepdir(req->cfg_id)) {
            /* The STEP/DIR input's: checked whole, in force when accepted; the core is not touched (the
             * image applies them when it next starts following). */
            pmstep_stepdir_config_t in_force;
            st = (int32_t)pmstep_console_stepdir_config(cfg, &stepdir, &in_force); /* the stall current by the trip */
            if (st == (int32_t)PMSTEP_OK) {
                c->stepdir = stepdir;
            }
            break;
        }
        st = (int32_t)pmstep_validate_config(&trial);
        if (st == (int32_t)PMSTEP_OK && !(c->stepdir.stall_current_A < trial.limits.max_phase_current_A)) {
            st = (int32_t)PMSTEP_ERR_STEPDIR_STALL_CURRENT; /* the trip lowered to or below the STEP/DIR stall current */
        }
        if (st == (int32_t)PMSTEP_OK) {
            *cfg = trial;
            st = (int32_t)pmstep_init(inst, cfg);
        }
        if (st == (int32_t)PMSTEP_OK && c->position_apply != NULL) {
            st = c->position_apply(c, PMSTEP_CONSOLE_SET_CONFIG, req->arg, NULL); /* gains anew */
        }
        break;
    }
    default:
        break;
    }
    pmstep_console_send_ack(c, req->cmd, seq, st, snap->period + 1u);
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
