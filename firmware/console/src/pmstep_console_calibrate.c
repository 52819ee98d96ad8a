/*
 * Command and telemetry interface: self-commissioning (CALIBRATE; see pmstep_console.h and
 * pmstep_calibrate.h). Linked only by an image that calls pmstep_console_attach_calibration(): its
 * runs advance at every period boundary while it lasts; its design, once done, is put in force, the
 * drive configured, and the record saved once the bridge is off.
 */
#include "pmstep_console_internal.h"

#include <stddef.h>

#define CALIBRATE_FLAG_PAPER_MODE 1u

/* The end of a calibration that did not finish: the board's defaults in force, no motor configured. */
static void back_to_defaults(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg)
{
    (void)pmstep_console_put_in_force(c, inst, cfg, &c->store->defaults);
    c->store->configured = false;
    memset(&c->store->measured, 0, sizeof c->store->measured);
    c->store->image_bytes = 0u;
    c->calibrating = false;
}

/* DONE: the design is in force (pmstep_calibrate's last init); the drive configured with what was
 * measured, and saved when the last step had the bridge off (the identification run's stop may
 * have been at this very boundary: then at the next). */
static void adopt_design(pmstep_console_t *c, pmstep_t *inst, pmstep_config_t *cfg,
                         const pmstep_console_snapshot_t *snap)
{
    pmstep_console_store_t *cs = c->store;
    const pmstep_calibrate_t *cal = c->calibration;
    pmstep_store_record_t rec;
    if (!cs->configured) {
        (void)pmstep_console_put_in_force(c, inst, cfg, cfg); /* position gains for it too */
        memset(&cs->measured, 0, sizeof cs->measured);
        cs->measured.flags = PMSTEP_STORE_MEASURED_RESISTANCE | PMSTEP_STORE_MEASURED_INDUCTANCE
                             | PMSTEP_STORE_MEASURED_TORQUE_CONSTANT | PMSTEP_STORE_MEASURED_MECHANICS;
        cs->measured.resistance_Ohm = cal->resistance_Ohm;
        cs->measured.inductance_H = cal->inductance_H;
        cs->measured.torque_constant_Nm_A = cal->torque_constant_Nm_A;
        cs->measured.inertia_kgm2 = cal->inertia_kgm2;
        cs->measured.friction_Nms_rad = cal->friction_Nms_rad;
        cs->configured = true;
        cs->image_bytes = 0u;
    }
    if (snap->out.bridge_enable || pmstep_get_mode(inst) != PMSTEP_MODE_IDLE) {
        return; /* saved at a boundary after a step with the bridge off */
    }
    rec.config = *cfg;
    rec.measured = cs->measured;
    rec.stepdir = c->stepdir;
    c->calibration_save_status = (int16_t)pmstep_store_save(cs->store, &rec, true);
    cs->last_status = c->calibration_save_status;
    c->calibrating = false;
}

static bool calibration_apply(pmstep_console_t *c, const pmstep_console_request_t *req, pmstep_t *inst,
                              pmstep_config_t *cfg, const pmstep_console_snapshot_t *snap)
{
    pmstep_calibrate_t *cal = c->calibration;
    if (req == NULL) { /* a boundary while it runs: the next step is the one after snap's */
        const pmstep_calibrate_stage_t stage = pmstep_calibrate_boundary(cal, inst, cfg, snap->period + 1u);
        if (stage == PMSTEP_CALIBRATE_DONE) {
            adopt_design(c, inst, cfg, snap);
        } else if (stage == PMSTEP_CALIBRATE_FAILED) {
            back_to_defaults(c, inst, cfg);
        }
        return true;
    }
    if (req->cmd == PMSTEP_CONSOLE_STOP) {
        pmstep_calibrate_cancel(cal, inst);
        if (cal->stage == PMSTEP_CALIBRATE_DONE) {
            adopt_design(c, inst, cfg, snap); /* done already, only the save left: it stays */
        } else {
            back_to_defaults(c, inst, cfg);
        }
        pmstep_console_send_ack(c, req->cmd, req->seq, 0, snap->period + 1u);
        return true;
    }
    /* CALIBRATE */
    if (pmstep_get_mode(inst) != PMSTEP_MODE_IDLE) {
        pmstep_console_send_error(c, req->cmd, req->seq, PMSTEP_CONSOLE_ERR_NOT_STOPPED);
        return false;
    }
    {
        pmstep_calibrate_request_t r;
        int32_t st;
        r.rated_current_A = req->a;
        r.pole_pairs = (int32_t)req->u;
        r.robust = (((uint32_t)req->arg[0]) & CALIBRATE_FLAG_PAPER_MODE) == 0u;
        r.detent_per_holding = req->b;
        st = (int32_t)pmstep_calibrate_start(cal, &r, &c->store->defaults, snap->meas.bus_voltage_V);
        if (st == (int32_t)PMSTEP_OK) {
            c->calibrating = true;
            c->calibration_save_status = 0;
            c->store->configured = false; /* each run's configuration is the calibration's, not a motor's */
        } else {
            st = cal->status != 0 ? cal->status : st;
        }
        pmstep_console_send_ack(c, req->cmd, req->seq, st, snap->period + 1u);
    }
    return true;
}

void pmstep_console_attach_calibration(pmstep_console_t *c, pmstep_calibrate_t *cal)
{
    c->calibration = cal;
    c->calibration_apply = calibration_apply;
    cal->stage = PMSTEP_CALIBRATE_IDLE;
}
