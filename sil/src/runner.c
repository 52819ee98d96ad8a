/* Closed loop: plant -> host HAL -> pmstep_step -> host HAL -> plant. */
#define _POSIX_C_SOURCE 200112L
#include "sil/runner.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "pmstep_hal_host.h"
#include "sil/microstep.h"
#include "sil/homing_run.h"
#include "sil/position_run.h"
#include "sil/stepdir_run.h"

/* The firmware and plant shares are timed on every SIL_TIMING_STRIDE-th period only (three
 * clock reads there, none elsewhere) and scaled to the run: a clock read costs about as
 * much as a tenth of a period's work. */
#define SIL_TIMING_STRIDE 16

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double cpu_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The record of sil/record.h; a write error is kept and reported at the end. */
typedef struct {
    FILE *file;
    bool failed;
} record_t;

static void record_words(record_t *rec, const uint32_t *words, size_t n)
{
    if (rec != NULL && !rec->failed && sil_record_write_words(rec->file, words, n) != 0) {
        rec->failed = true;
    }
}

static void record_header(record_t *rec, const pmstep_config_t *c, float id_target_A)
{
    uint32_t head[SIL_RECORD_HEADER_WORDS] = {SIL_RECORD_MAGIC, SIL_RECORD_VERSION, SIL_RECORD_CONFIG_WORDS,
                                              (uint32_t)SIL_RECORD_IN_WORDS, (uint32_t)SIL_RECORD_OUT_WORDS};
    sil_record_config_to_words(c, &head[5]);
    head[5u + SIL_RECORD_CONFIG_WORDS] = sil_record_bits(id_target_A);
    record_words(rec, head, SIL_RECORD_HEADER_WORDS);
}

static void record_speed_target(record_t *rec, float target_rad_s, float ramp_rate_rad_s2)
{
    const uint32_t words[] = {SIL_RECORD_TAG_SPEED_TARGET, sil_record_bits(target_rad_s),
                              sil_record_bits(ramp_rate_rad_s2)};
    record_words(rec, words, sizeof words / sizeof words[0]);
}

static void record_period(record_t *rec, const pmstep_meas_t *in, const pmstep_output_t *o)
{
    uint32_t w[1u + SIL_RECORD_PERIOD_WORDS];
    w[0] = SIL_RECORD_TAG_PERIOD;
    sil_record_meas_to_words(in, &w[1]);
    sil_record_output_to_words(o, &w[1u + SIL_RECORD_IN_WORDS]);
    record_words(rec, w, sizeof w / sizeof w[0]);
}

/* Issues (and records) the speed commands of the set-point profile due at t_s. */
static void command_speed(pmstep_t *inst, const sil_scenario_t *sc, double t_s, int *next_segment, record_t *rec)
{
    float target_rad_s;
    float ramp_rate_rad_s2;
    while (sil_scenario_speed_command(sc, t_s, next_segment, &target_rad_s, &ramp_rate_rad_s2)) {
        (void)pmstep_set_speed_target(inst, target_rad_s, ramp_rate_rad_s2);
        record_speed_target(rec, target_rad_s, ramp_rate_rad_s2);
    }
}

/* The same speed commands for the microstep drive (a plain ramp, no record). */
static void command_microstep_speed(sil_microstep_t *drive, const sil_scenario_t *sc, double t_s, int *next_segment)
{
    float target_rad_s;
    float ramp_rate_rad_s2;
    while (sil_scenario_speed_command(sc, t_s, next_segment, &target_rad_s, &ramp_rate_rad_s2)) {
        sil_microstep_set_speed_target(drive, (double)target_rad_s, (double)ramp_rate_rad_s2);
    }
}

int sil_bind_plant(const sil_scenario_t *sc, plant_t *plant)
{
    pmstep_hal_host_setup_t hardware;
    memset(plant, 0, sizeof *plant);
    plant->params = sc->motor;
    plant->load = sc->load;
    plant->x.theta_rad = sc->theta0_rad;
    plant->x.omega_rad_s = sc->omega0_rad_s;
    plant->x.i_a_A = sc->i_a0_A;
    plant->x.i_b_A = sc->i_b0_A;
    plant->integrator = sc->integrator;
    hardware.bus_voltage_V = sc->bus_voltage_V;
    hardware.delay_periods = sc->controller.timing.computational_delay_periods;
    hardware.inverter = sc->inverter;
    hardware.bus = sc->bus;
    hardware.sensors = sc->sensors;
    hardware.faults = sc->faults;
    hardware.seed = sc->seed;
    if (pmstep_hal_host_bind(plant, &hardware) != 0) {
        pmstep_hal_host_release();
        return -3;
    }
    return 0;
}

int sil_run(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress, sil_summary_t *s)
{
    return sil_run_record(sc, on_sample, user, progress, s, NULL);
}

int sil_run_record(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress, sil_summary_t *s,
                   FILE *record)
{
    static pmstep_t inst; /* as on the MCU: one static instance */
    static pmstep_position_t pos; /* a position scenario's position control of inst */
    static sil_stepdir_run_t stepdir_run; /* a STEP/DIR scenario's generator and input (large: static) */
    const bool microstep = sc->drive == SIL_DRIVE_MICROSTEP;
    const bool positional = !microstep && sc->position_moves > 0;
    /* position.source = stepdir: the drive (either) follows the step generator's count */
    const bool stepdir = sc->position_moves > 0 && sc->position_source == SIL_SOURCE_STEPDIR;
    /* position.source = homing: the drive homes against the plant's stop */
    const bool homing = positional && sc->position_source == SIL_SOURCE_HOMING;
    sil_position_run_t position_run;
    sil_homing_run_t homing_run;
    pmstep_position_output_t pos_out;
    sil_microstep_t drive;
    const pmstep_config_t *cfg = &sc->controller;
    const double period_s = (double)cfg->timing.period_s;
    const long steps = sil_periods_in(sc->duration_s, period_s);
    const bool on_terminal = isatty(fileno(stderr)) != 0;
    sil_inverter_t *inverter = pmstep_hal_host_inverter();
    sil_metrics_t metrics;
    plant_t plant;
    pmstep_output_t out;
    record_t rec_state = {NULL, false};
    record_t *rec = NULL;
    int next_segment = 0;
    int next_progress_decile = 1;
    double wall_start, cpu_start;
    double timed_firmware_s = 0.0, timed_plant_s = 0.0, clock_read_s;
    long timed_periods = 0;
    long k;

    memset(s, 0, sizeof *s);
    if (microstep) {
        /* The baseline: no firmware at all, and nothing to record for a replay. */
        sil_microstep_init(&drive, sc);
        record = NULL;
        s->init_status = PMSTEP_OK;
    } else {
        s->init_status = pmstep_init(&inst, cfg);
    }
    if (s->init_status == PMSTEP_OK && positional) {
        const pmstep_position_config_t position_cfg = sil_position_config(sc);
        s->init_status = pmstep_position_init(&pos, &inst, &position_cfg);
        record = NULL; /* a replay of pmstep_step alone would not see the position loop's reference */
    }
    if (s->init_status != PMSTEP_OK) {
        return -1;
    }
    memset(&pos_out, 0, sizeof pos_out);
    sil_position_run_init(&position_run, sc);
    sil_metrics_init(&metrics, sc, s); /* its period counts need a configuration init accepted; clears s */
    s->init_status = stepdir ? sil_stepdir_run_init(&stepdir_run, sc, !microstep, s) : PMSTEP_OK;
    if (homing) {
        sil_homing_run_init(&homing_run, sc, s);
    }
    if (s->init_status != PMSTEP_OK) {
        return -1;
    }
    s->stop_contact_s = -1.0;
    if (sil_bind_plant(sc, &plant) != 0) {
        return -3;
    }
    if (!microstep) {
        (void)pmstep_set_id_target(&inst, (float)sc->id_target_A);
        (void)pmstep_start(&inst);
    }
    if (record != NULL) {
        rec_state.file = record;
        rec = &rec_state;
        record_header(rec, cfg, (float)sc->id_target_A);
    }

    {
        /* The cost of one clock read, taken out of each timed bracket below. */
        const double c0 = now_s();
        int n;
        for (n = 0; n < 64; ++n) {
            (void)now_s();
        }
        clock_read_s = (now_s() - c0) / 65.0;
    }
    cpu_start = cpu_now_s();
    wall_start = now_s();
    for (k = 0; k < steps; ++k) {
        const double t_s = (double)k * period_s;
        const bool timed = k % SIL_TIMING_STRIDE == 0;
        pmstep_meas_t meas;
        sil_sample_t sample;
        double t0 = 0.0, t1 = 0.0;

        plant.time_s = t_s;
        if (microstep) {
            command_microstep_speed(&drive, sc, t_s, &next_segment);
        } else {
            command_speed(&inst, sc, t_s, &next_segment, rec);
        }
        if (stepdir) {
            sil_stepdir_run_command(&stepdir_run, t_s, positional ? &pos : NULL, microstep ? &drive : NULL, s);
        } else if (homing) {
            sil_homing_run_command(&homing_run, &pos, t_s, s);
        } else if (positional) {
            sil_position_run_command(&position_run, &pos, t_s, s);
        }
        sample.theta_rad = plant.x.theta_rad;
        sample.omega_rad_s = plant.x.omega_rad_s;
        sample.i_a_A = plant.x.i_a_A;
        sample.i_b_A = plant.x.i_b_A;
        sample.load_Nm = plant_load_torque(&plant.load, t_s, plant.x.omega_rad_s);
        plant_sin_cos(&plant, &sample.sin_ptheta, &sample.cos_ptheta); /* the step's first stage reuses them */

        /* pmstep_hal_control_period(), spelled out to keep the measurement for the record. */
        if (timed) {
            t0 = now_s();
        }
        pmstep_hal_read_measurements(&meas);
        if (microstep) {
            sample.angle_ref_rad = drive.angle_ref_rad; /* theta_e*(t_k), before the step advances it */
            sil_microstep_step(&drive, &meas, &out);
        } else {
            sample.angle_ref_rad = 0.0;
            if (stepdir) {
                /* the port's order: the step, the step counter read, the position update, DIAG */
                pmstep_step(&inst, &meas, &out);
                sil_stepdir_run_count(&stepdir_run);
                pmstep_position_update(&pos, &out, &pos_out);
                sil_stepdir_run_diag(&stepdir_run, out.mode, &pos_out);
            } else if (positional) {
                pmstep_position_step(&pos, &meas, &out, &pos_out);
                if (homing) {
                    sil_homing_run_update(&homing_run, &pos, &out, &pos_out);
                }
            } else {
                pmstep_step(&inst, &meas, &out);
            }
        }
        pmstep_hal_apply_output(&out);
        if (timed) {
            t1 = now_s();
        }
        sil_drive_advance(&plant, inverter, period_s, sc->substeps);
        if (timed) {
            const double t2 = now_s();
            const double firmware_s = t1 - t0 - clock_read_s;
            const double plant_s = t2 - t1 - clock_read_s;
            timed_firmware_s += firmware_s > 0.0 ? firmware_s : 0.0;
            timed_plant_s += plant_s > 0.0 ? plant_s : 0.0;
            ++timed_periods;
        }
        if (rec != NULL) {
            record_period(rec, &meas, &out);
        }

        sample.step = k;
        sample.t_s = t_s;
        sample.u_a_V = inverter->applied_a_V;
        sample.u_b_V = inverter->applied_b_V;
        sample.out = &out;
        sample.inst = microstep ? NULL : &inst;
        sample.position = NULL;
        sample.position_rad = 0.0;
        sample.position_estimate_rad = 0.0;
        sample.position_reference_rad = 0.0;
        sample.position_updated = false;
        sample.stepdir = false;
        sample.step_count = 0;
        sample.step_error_full_steps = 0.0;
        sample.diag = false;
        if (positional) {
            sample.position = &pos_out;
            sil_position_run_sample(&position_run, &pos, &sample, s);
            if (homing && position_run.origin_set) {
                sil_homing_run_sample(&homing_run, &sample, &plant.params, position_run.origin_rad, s);
            }
        }
        if (stepdir) {
            sil_stepdir_run_sample(&stepdir_run, &sample, s);
        }
        sil_metrics_add(&metrics, &sample, s);
        if (s->stop_contact_s < 0.0 && plant_stop_torque(&plant.params, sample.theta_rad, 0.0) != 0.0) {
            s->stop_contact_s = t_s;
        }

        if (progress && k + 1 >= steps * next_progress_decile / 10) {
            /* A line that rewrites itself on a terminal, one line per 10 % in a log. */
            fprintf(stderr, "%s  simulated %6.3f of %.3f s (%3d%%)%s", on_terminal ? "\r" : "", t_s + period_s,
                    sc->duration_s, next_progress_decile * 10,
                    (!on_terminal || next_progress_decile == 10) ? "\n" : "");
            fflush(stderr);
            ++next_progress_decile;
        }
        if (on_sample != NULL && !on_sample(&sample, user)) {
            break;
        }
    }
    s->wall_time_s = now_s() - wall_start;
    s->cpu_time_s = cpu_now_s() - cpu_start;
    if (timed_periods > 0) {
        s->firmware_time_s = timed_firmware_s * (double)s->steps / (double)timed_periods;
        s->plant_time_s = timed_plant_s * (double)s->steps / (double)timed_periods;
    }
    s->sim_time_s = (double)s->steps * period_s;
    s->real_time_factor = s->wall_time_s > 0.0 ? s->sim_time_s / s->wall_time_s : 0.0;
    sil_metrics_finish(&metrics, s);
    if (positional) {
        sil_position_run_finish(&position_run, s);
    }
    if (stepdir) {
        sil_stepdir_run_finish(&stepdir_run, s);
    }
    s->inverter_limited_periods = (long)inverter->limited_periods;
    pmstep_hal_host_release();
    if (rec != NULL) {
        const uint32_t end[] = {SIL_RECORD_TAG_END, (uint32_t)s->steps};
        record_words(rec, end, sizeof end / sizeof end[0]);
        return rec->failed ? -2 : 0;
    }
    return 0;
}
