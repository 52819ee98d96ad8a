/* A homing scenario in the runner (homing_run.h). */
#include "sil/homing_run.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

pmstep_homing_config_t sil_homing_config(const sil_scenario_t *sc)
{
    pmstep_homing_config_t cfg;
    (void)pmstep_homing_design(&sc->controller, &cfg);
    if (sc->homing_speed_rad_s > 0.0) {
        cfg.speed_rad_s = (float)sc->homing_speed_rad_s;
    }
    if (sc->homing_stall_current_A > 0.0) {
        cfg.stall_current_A = (float)sc->homing_stall_current_A;
    }
    if (sc->homing_back_off_rad >= 0.0) {
        cfg.back_off_rad = (float)sc->homing_back_off_rad;
    }
    if (sc->position_moves > 0) {
        cfg.max_travel_rad = (float)fabs(sc->move_target_rad[0]);
    }
    return cfg;
}

void sil_homing_run_init(sil_homing_run_t *run, const sil_scenario_t *sc, sil_summary_t *s)
{
    sil_homing_summary_t *h = &s->homing;
    memset(run, 0, sizeof *run);
    run->sc = sc;
    run->full_step_rad = 0.5 * PI / (double)sc->motor.pole_pairs;
    run->last_state = PMSTEP_HOMING_IDLE;
    h->config = sil_homing_config(sc);
    h->start_status = PMSTEP_OK;
    h->found_s = -1.0;
    h->done_s = -1.0;
    h->contact_s = -1.0;
}

void sil_homing_run_command(sil_homing_run_t *run, pmstep_position_t *pos, double t_s, sil_summary_t *s)
{
    const sil_scenario_t *sc = run->sc;
    if (!run->started && sc->position_moves > 0 && t_s >= sc->move_time_s[0] && pos->out.tracked) {
        const int32_t direction = sc->move_target_rad[0] >= 0.0 ? 1 : -1;
        run->started = true;
        s->homing.start_s = t_s;
        s->homing.start_status = pmstep_homing_start(&run->homing, pos, &s->homing.config, direction);
    }
}

void sil_homing_run_update(sil_homing_run_t *run, pmstep_position_t *pos, const pmstep_output_t *out,
                           const pmstep_position_output_t *pos_out)
{
    if (run->started) {
        (void)pmstep_homing_update(&run->homing, pos, out, pos_out);
    }
}

void sil_homing_run_sample(sil_homing_run_t *run, const sil_sample_t *sample, const plant_params_t *plant,
                           double origin_rad, sil_summary_t *s)
{
    sil_homing_summary_t *h = &s->homing;
    const pmstep_homing_state_t state = run->homing.state;
    const double fs = run->full_step_rad;
    const double contact_rad = plant->stop_position_rad - origin_rad; /* in the drive's frame at RUN */
    if (!run->started) {
        return;
    }
    if (state == PMSTEP_HOMING_SEEKING) {
        if (h->contact_s >= 0.0) {
            h->contact_peak_current_A = fmax(h->contact_peak_current_A, fmax(fabs(sample->i_a_A), fabs(sample->i_b_A)));
        }
        h->seek_peak_stop_torque_Nm =
            fmax(h->seek_peak_stop_torque_Nm, fabs(plant_stop_torque(plant, sample->theta_rad, sample->omega_rad_s)));
        if (plant->stop_side != 0 && h->contact_s < 0.0
            && (double)plant->stop_side * (sample->theta_rad - plant->stop_position_rad) > 0.0) {
            h->contact_s = sample->t_s;
        }
    }
    if (run->last_state == PMSTEP_HOMING_SEEKING && state != PMSTEP_HOMING_SEEKING) {
        h->found_s = sample->t_s;
        h->by_current = run->homing.stalled_by_current;
        /* the zero the drive set (its stop, in the frame before the zero) against the contact */
        h->stop_error_full_steps = ((double)run->homing.stop_rad - contact_rad) / fs;
        h->zero_rad = (double)run->homing.stop_rad;
    }
    if (state == PMSTEP_HOMING_DONE && h->done_s < 0.0) {
        h->done_s = sample->t_s;
    }
    if (state == PMSTEP_HOMING_DONE || state == PMSTEP_HOMING_BACKING_OFF) {
        /* where the rotor is from the true stop, against where the drive says it is from its zero */
        const double from_stop_rad = sample->position_rad - contact_rad;
        const double said_rad = sample->position_estimate_rad;
        h->final_position_error_full_steps = (said_rad - from_stop_rad) / fs;
        h->final_from_stop_full_steps = from_stop_rad / fs;
    }
    h->state = state;
    run->last_state = state;
}
