/*
 * The console's simulation requests (pmstep_console.h, SIM_ADVANCE, SIM_FINISH and the emulated
 * STEP/DIR input's SIM_STEPS, SIM_FOLLOW_STEPS, SIM_STEPDIR): in a file of its own so that only an
 * image that calls pmstep_console_attach_simulation() (the QEMU processor-in-the-loop image, the host
 * drive of the tool's tests) links them; a hardware image refuses them as
 * PMSTEP_CONSOLE_ERR_NOT_SUPPORTED.
 */
#include "pmstep_console_internal.h"

#include <stddef.h>

/* SIM_ADVANCE: periods to run, answered once they have run (pmstep_console_advance_done());
 * SIM_FINISH: acknowledged at once, the image then writes its results and exits;
 * SIM_STEPS: the edges of the coming periods queued, acknowledged at once (its length checked by the
 * request table, 1..PMSTEP_CONSOLE_SIM_STEPS_MAX). */
static int sim_request(pmstep_console_t *c, uint8_t type, uint8_t seq, const uint8_t *d, uint32_t n)
{
    if (c->advancing) {
        return PMSTEP_CONSOLE_ERR_BUSY;
    }
    if (type == PMSTEP_CONSOLE_SIM_FINISH) {
        c->finish_requested = true;
        pmstep_console_send_ack(c, type, seq, 0, 0u);
        return 0;
    }
    if (type == PMSTEP_CONSOLE_SIM_STEPS) {
        uint32_t k;
        if (c->sim_edges_next < c->sim_edges_queued) {
            return PMSTEP_CONSOLE_ERR_BUSY; /* the last request's edges not all out yet */
        }
        for (k = 0; k < n; ++k) {
            c->sim_edges[k] = d[k];
        }
        c->sim_edges_queued = n;
        c->sim_edges_next = 0u;
        pmstep_console_send_ack(c, type, seq, 0, 0u);
        return 0;
    }
    if (get_u32(d) == 0u) {
        return PMSTEP_CONSOLE_ERR_BAD_VALUE;
    }
    c->advance_periods = get_u32(d);
    c->advance_seq = seq;
    c->advancing = true;
    return 0;
}

void pmstep_console_attach_simulation(pmstep_console_t *c)
{
    c->sim_request = sim_request;
}

/* @p sd started on the STEP/DIR settings in force for the motor of @p cfg, at the emulated counter's
 * present value: nothing counted, not followed (as a STEP/DIR image starts its input on EN). */
static pmstep_status_t sim_stepdir_start(const pmstep_console_t *c, const pmstep_config_t *cfg, pmstep_stepdir_t *sd)
{
    pmstep_stepdir_config_t sd_cfg;
    pmstep_status_t st = pmstep_console_stepdir_config(cfg, &c->stepdir, &sd_cfg);
    if (st == PMSTEP_OK) {
        st = pmstep_stepdir_init(sd, &sd_cfg, cfg->motor.pole_pairs, cfg->timing.period_s, c->sim_step_counter);
    }
    return st;
}

/* SIM_FOLLOW_STEPS and SIM_STEPDIR at the period boundary; each replies. */
static bool sim_stepdir_apply(pmstep_console_t *c, const pmstep_console_request_t *req, pmstep_t *inst,
                              pmstep_config_t *cfg, const pmstep_console_snapshot_t *snap)
{
    pmstep_stepdir_t *sd = c->sim_stepdir;
    writer_t w;
    (void)inst;
    if (req->cmd == PMSTEP_CONSOLE_SIM_FOLLOW_STEPS) {
        const pmstep_stepdir_t before = *sd;
        pmstep_status_t st = sim_stepdir_start(c, cfg, sd);
        if (st == PMSTEP_OK) {
            st = pmstep_position_follow_steps(c->position, sd);
        }
        if (st != PMSTEP_OK) {
            *sd = before; /* refused: the input as it was */
        }
        pmstep_console_send_ack(c, req->cmd, req->seq, (int32_t)st, snap->period + 1u);
        return true;
    }
    w.n = 0;
    put_u32(&w, snap->period);
    put_u32(&w, (uint32_t)sd->steps);
    put_u32(&w, c->sim_step_edges);
    put_u16(&w, c->sim_step_counter);
    put_u8(&w, (sd->following ? PMSTEP_CONSOLE_SIM_STEPDIR_FOLLOWING : 0u)
                   | (sd->moving ? PMSTEP_CONSOLE_SIM_STEPDIR_MOVING : 0u)
                   | (sd->diag ? PMSTEP_CONSOLE_SIM_STEPDIR_DIAG : 0u));
    put_f32(&w, pmstep_stepdir_commanded(sd));
    put_f32(&w, sd->following ? pmstep_stepdir_following_error(sd, c->position->out.position_rad) : 0.0f);
    pmstep_console_send(c, PMSTEP_CONSOLE_SIM_STEPDIR | 0x80u, req->seq, w.b, w.n);
    return true;
}

pmstep_status_t pmstep_console_attach_sim_stepdir(pmstep_console_t *c, pmstep_stepdir_t *sd, const pmstep_config_t *cfg)
{
    pmstep_status_t st;
    if (c == NULL || sd == NULL || cfg == NULL || c->sim_request == NULL || c->position == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    st = sim_stepdir_start(c, cfg, sd);
    if (st == PMSTEP_OK) {
        c->sim_stepdir = sd;
        c->sim_stepdir_apply = sim_stepdir_apply;
    }
    return st;
}

uint16_t pmstep_console_sim_steps_period(pmstep_console_t *c)
{
    if (c->sim_edges_next < c->sim_edges_queued) {
        const uint32_t b = c->sim_edges[c->sim_edges_next++];
        /* i8 edges: a timer's CNT counts each one up or down, modulo 2^16 (the total modulo 2^32) */
        const uint32_t step = b >= 0x80u ? b - 0x100u : b;
        c->sim_step_counter = (uint16_t)(c->sim_step_counter + step);
        c->sim_step_edges += step;
    }
    return c->sim_step_counter;
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
    pmstep_console_send(c, PMSTEP_CONSOLE_SIM_ADVANCE | 0x80u, c->advance_seq, w.b, w.n);
}

bool pmstep_console_finish_requested(const pmstep_console_t *c)
{
    return c->finish_requested;
}
