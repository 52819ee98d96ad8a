/* A STEP/DIR scenario in the runner (stepdir_run.h): the count, the drive following it, the
 * following error on the plant's position. */
#include "sil/stepdir_run.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

pmstep_status_t sil_stepdir_run_init(sil_stepdir_run_t *run, const sil_scenario_t *sc, bool firmware, sil_summary_t *s)
{
    sil_stepdir_summary_t *d = &s->stepdir;
    int n;
    memset(run, 0, sizeof *run);
    run->sc = sc;
    run->firmware = firmware;
    run->pole_pairs = (double)sc->motor.pole_pairs;
    run->full_step_rad = 0.5 * PI / run->pole_pairs;
    sil_step_generator_plan(&run->gen, sc);
    d->microsteps = sc->stepdir_microsteps;
    d->moves = run->gen.moves;
    d->first_move_s = sil_step_generator_first_start_s(&run->gen);
    d->last_move_end_s = sil_step_generator_last_end_s(&run->gen);
    for (n = 0; n < run->gen.moves; ++n) {
        d->peak_speed_rad_s = fmax(d->peak_speed_rad_s, run->gen.move[n].peak_speed_rad_s);
    }
    d->following_start_s = -1.0;
    d->following_end_s = -1.0;
    d->error_beyond_full_step_s = -1.0;
    d->diag_first_s = -1.0;
    if (firmware) {
        pmstep_stepdir_config_t cfg;
        pmstep_status_t status = pmstep_stepdir_design(&sc->controller, sc->stepdir_microsteps, &cfg);
        if (status != PMSTEP_OK) {
            return status;
        }
        cfg.diag_mode = sc->stepdir_diag_mode;
        cfg.stall_current_A = sc->stepdir_stall_current_A;
        if (sc->stepdir_tracking_bandwidth_rad_s > 0.0f) {
            /* the designer's stop time is a fixed number of tracker time constants: it scales with 1 / w_t */
            cfg.stop_time_s *= cfg.tracking_bandwidth_rad_s / sc->stepdir_tracking_bandwidth_rad_s;
            cfg.tracking_bandwidth_rad_s = sc->stepdir_tracking_bandwidth_rad_s;
        }
        status = pmstep_stepdir_init(&run->input, &cfg, sc->controller.motor.pole_pairs, sc->controller.timing.period_s,
                                     (uint16_t)SIL_STEPDIR_COUNTER_START);
        if (status != PMSTEP_OK) {
            return status;
        }
    }
    return PMSTEP_OK;
}

void sil_stepdir_run_command(sil_stepdir_run_t *run, double t_s, pmstep_position_t *pos, sil_microstep_t *drive,
                             sil_summary_t *s)
{
    const bool due = t_s >= s->stepdir.first_move_s;
    run->command = sil_step_generator_sample(&run->gen, t_s);
    run->count = sil_step_generator_count(&run->gen, run->command.position_rad);
    if (pos != NULL) {
        /* Once: count 0 is put where the reference is now, before this period's count is read (the
         * first step of the first move is counted after it). A drive that leaves RUN loses the
         * position and is not told to follow again: the steps it missed stay missed. */
        if (!run->following && due && pos->out.tracked && pmstep_position_follow_steps(pos, &run->input) == PMSTEP_OK) {
            run->following = true;
            s->stepdir.following_start_s = t_s;
        }
    } else if (drive != NULL && due) {
        /* one microstep is pi / (2 m) electrical: p n q */
        sil_microstep_set_angle(drive, (double)run->count * 0.5 * PI / (double)run->sc->stepdir_microsteps);
        if (!run->following) {
            run->following = true;
            s->stepdir.following_start_s = t_s;
        }
    }
}

void sil_stepdir_run_count(sil_stepdir_run_t *run)
{
    /* the port's counter: counted from its start value, up or down by DIR; its low 16 bits are read */
    pmstep_stepdir_count(&run->input, (uint32_t)SIL_STEPDIR_COUNTER_START + (uint32_t)run->count);
}

void sil_stepdir_run_diag(sil_stepdir_run_t *run, pmstep_mode_t mode, const pmstep_position_output_t *pos_out)
{
    run->diag = pmstep_stepdir_diag(&run->input, mode, pos_out->position_rad, pos_out->tracked);
}

void sil_stepdir_run_sample(sil_stepdir_run_t *run, sil_sample_t *sample, sil_summary_t *s)
{
    sil_stepdir_summary_t *d = &s->stepdir;
    const double p = run->pole_pairs;
    sample->stepdir = true;
    sample->step_count = run->count;
    sample->step_error_full_steps = 0.0;
    sample->diag = run->firmware && run->diag;
    if (sample->diag) {
        d->diag_periods++;
        if (d->diag_first_s < 0.0) {
            d->diag_first_s = sample->t_s;
        }
    }
    if (run->firmware && run->following && !run->input.following && d->following_end_s < 0.0) {
        d->following_end_s = sample->t_s; /* left RUN (a fault, a re-alignment): the position is lost */
    }
    if (!run->origin_set
        && (run->firmware ? (sample->position != NULL && sample->position->tracked) : run->following)) {
        /* the equilibrium p theta = 0 mod 2 pi nearest the rotor: the c-alignment's, or the baseline's hold */
        run->origin_rad = floor(sample->theta_rad * p / (2.0 * PI) + 0.5) * 2.0 * PI / p;
        run->origin_set = true;
    }
    if (run->following && run->origin_set) {
        const double commanded_rad = (double)run->count * run->gen.rad_per_microstep;
        const double error = (commanded_rad - (sample->theta_rad - run->origin_rad)) / run->full_step_rad;
        const double magnitude = fabs(error);
        sample->step_error_full_steps = error;
        d->max_error_full_steps = fmax(d->max_error_full_steps, magnitude);
        run->sum_sq_all += error * error;
        run->n_all++;
        if (run->command.moving) {
            d->max_error_moving_full_steps = fmax(d->max_error_moving_full_steps, magnitude);
            run->sum_sq_moving += error * error;
            run->n_moving++;
        }
        if (magnitude > 1.0 && d->error_beyond_full_step_s < 0.0) {
            d->error_beyond_full_step_s = sample->t_s;
        }
        d->final_error_full_steps = error;
    }
}

void sil_stepdir_run_finish(const sil_stepdir_run_t *run, sil_summary_t *s)
{
    sil_stepdir_summary_t *d = &s->stepdir;
    d->rms_error_full_steps = run->n_all > 0 ? sqrt(run->sum_sq_all / (double)run->n_all) : 0.0;
    d->rms_error_moving_full_steps = run->n_moving > 0 ? sqrt(run->sum_sq_moving / (double)run->n_moving) : 0.0;
    d->lost_full_steps = (int32_t)lround(d->final_error_full_steps);
    d->generator_steps = run->count;
    d->drive_steps = run->firmware ? run->input.steps : run->count;
}
