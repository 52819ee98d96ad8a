/* A position scenario in the runner: moves at their times, metrics on the true position. */
#include "sil/position_run.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

pmstep_position_config_t sil_position_config(const sil_scenario_t *sc)
{
    pmstep_position_config_t cfg = sc->position;
    pmstep_position_config_t designed;
    (void)pmstep_position_design(&sc->controller, &designed);
    if (cfg.gain_per_s == 0.0f) {
        cfg.gain_per_s = designed.gain_per_s;
        cfg.integral_gain_per_s2 = designed.integral_gain_per_s2;
    }
    if (cfg.hold_current_A < 0.0f) {
        cfg.hold_current_A = designed.hold_current_A;
    }
    return cfg;
}

void sil_position_run_init(sil_position_run_t *run, const sil_scenario_t *sc)
{
    memset(run, 0, sizeof *run);
    run->sc = sc;
    run->pole_pairs = (double)sc->motor.pole_pairs;
}

/* The present move's figures into the summary (at the next move or the end of the run). */
static void close_move(sil_position_run_t *run, sil_summary_t *s)
{
    sil_position_summary_t *p = &s->position;
    const double travel = fabs(run->move_target_rad - run->move_start_rad);
    const double final_rad = run->last_error_rad * run->pole_pairs;
    if (!run->in_move) {
        return;
    }
    if (final_rad > p->max_final_error_rad) {
        p->max_final_error_rad = final_rad;
        p->worst_move = p->moves;
    }
    run->final_error_sum += final_rad;
    if (travel > 0.0 && run->move_overshoot_rad / travel > p->max_overshoot_fraction) {
        p->max_overshoot_fraction = run->move_overshoot_rad / travel;
    }
    if (run->last_moving) {
        p->unfinished_moves++;
    }
    run->in_move = false;
}

void sil_position_run_command(sil_position_run_t *run, pmstep_position_t *pos, double t_s, sil_summary_t *s)
{
    const sil_scenario_t *sc = run->sc;
    while (run->next_move < sc->position_moves && t_s >= sc->move_time_s[run->next_move] && pos->out.tracked
           && run->origin_set) {
        const int n = run->next_move++;
        const pmstep_status_t status =
            pmstep_position_move_to(pos, (float)sc->move_target_rad[n], (float)sc->move_speed_rad_s,
                                    (float)sc->move_accel_rad_s2, (float)sc->move_jerk_rad_s3);
        close_move(run, s);
        if (status != PMSTEP_OK) {
            s->position.rejected_moves++;
            continue;
        }
        s->position.moves++;
        run->in_move = true;
        run->move_target_rad = sc->move_target_rad[n];
        run->move_start_rad = run->last_theta_rad;
        run->move_overshoot_rad = 0.0;
        run->last_moving = true;
    }
}

void sil_position_run_sample(sil_position_run_t *run, const pmstep_position_t *pos, sil_sample_t *sample,
                             sil_summary_t *s)
{
    sil_position_summary_t *p = &s->position;
    const pmstep_position_output_t *out = sample->position;
    const double p_pairs = run->pole_pairs;
    double theta;
    double estimate;
    double reference;
    float value;
    if (!out->tracked) {
        sample->position_rad = 0.0;
        return;
    }
    sample->position_updated = pos->loop_countdown == PMSTEP_POSITION_DECIMATION;
    (void)pmstep_get_position(pos, &value);
    estimate = (double)value;
    (void)pmstep_position_reference(pos, &value);
    reference = (double)value;
    sample->position_estimate_rad = estimate;
    sample->position_reference_rad = reference;
    if (!run->origin_set) {
        /* RUN's first period: the rotor sits at (near) an equilibrium of the c-alignment, theta = 0 mod 2 pi/p. */
        run->origin_rad = floor(sample->theta_rad * p_pairs / (2.0 * PI) + 0.5) * 2.0 * PI / p_pairs;
        run->origin_set = true;
    }
    theta = sample->theta_rad - run->origin_rad;
    sample->position_rad = theta;
    run->last_theta_rad = theta;
    if (fabs(estimate - theta) * p_pairs > p->max_estimate_error_rad) {
        p->max_estimate_error_rad = fabs(estimate - theta) * p_pairs;
    }
    if (out->position_mode && fabs(reference - theta) * p_pairs > p->max_tracking_error_rad) {
        p->max_tracking_error_rad = fabs(reference - theta) * p_pairs;
    }
    if (run->in_move) {
        const double direction = run->move_target_rad >= run->move_start_rad ? 1.0 : -1.0;
        run->move_overshoot_rad = fmax(run->move_overshoot_rad, direction * (theta - run->move_target_rad));
        run->last_error_rad = fabs(theta - run->move_target_rad);
        run->last_moving = out->moving;
    } else {
        run->last_error_rad = 0.0;
    }
    if (run->sc->hold_start_s > 0.0 && sample->t_s >= run->sc->hold_start_s) {
        close_move(run, s); /* the last move ends where the hold begins (its figures are the hold's) */
        const double t = sample->t_s - run->sc->hold_start_s;
        const double e = (theta - reference) * p_pairs;
        p->hold_max_error_rad = fmax(p->hold_max_error_rad, fabs(e));
        p->hold_max_estimate_error_rad = fmax(p->hold_max_estimate_error_rad, fabs(estimate - theta) * p_pairs);
        run->hold_n++;
        run->hold_st += t;
        run->hold_sy += e;
        run->hold_stt += t * t;
        run->hold_sty += t * e;
        p->hold_duration_s = t;
    }
}

void sil_position_run_finish(sil_position_run_t *run, sil_summary_t *s)
{
    sil_position_summary_t *p = &s->position;
    close_move(run, s);
    if (p->moves > 0) {
        p->mean_final_error_rad = run->final_error_sum / (double)p->moves;
    }
    if (run->hold_n > 1) {
        const double n = (double)run->hold_n;
        const double denominator = n * run->hold_stt - run->hold_st * run->hold_st;
        if (denominator > 0.0) {
            p->hold_drift_rad_s = (n * run->hold_sty - run->hold_st * run->hold_sy) / denominator;
        }
    }
}
