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

/* One run's state, from its preparation to its summary (the instances it drives are static in
 * sil_run_record(), as on the MCU). */
typedef struct {
    const sil_scenario_t *sc;
    sil_summary_t *s;
    pmstep_t *inst;
    pmstep_position_t *pos;         /* a position scenario's position control of inst */
    sil_stepdir_run_t *stepdir_run; /* a STEP/DIR scenario's generator and input */
    bool microstep;                 /* the open-loop baseline in place of the firmware */
    bool positional;
    bool stepdir; /* position.source = stepdir: the drive follows the generator's count */
    bool homing;  /* position.source = homing: the drive homes against the plant's stop */
    sil_position_run_t position_run;
    sil_homing_run_t homing_run;
    pmstep_position_output_t pos_out;
    sil_microstep_t drive;
    double period_s;
    long steps;
    sil_inverter_t *inverter;
    sil_metrics_t metrics;
    plant_t plant;
    pmstep_output_t out;
    record_t rec_state;
    record_t *rec; /* NULL: no record */
    int next_segment;
    int next_progress_decile;
    bool on_terminal;
    double clock_read_s; /* the cost of one clock read, taken out of each timed bracket */
    double timed_firmware_s;
    double timed_plant_s;
    long timed_periods;
} run_t;

/* The cost of one clock read. */
static double clock_read_cost(void)
{
    const double c0 = now_s();
    int n;
    for (n = 0; n < 64; ++n) {
        (void)now_s();
    }
    return (now_s() - c0) / 65.0;
}

/* The drive initialised (the firmware, or the baseline with nothing to record), the position, STEP/DIR
 * and homing runs, the metrics, the plant bound, the drive started and the record's header written.
 * @return 0, -1 (a configuration refused), -3 (the plant's). */
static int run_prepare(run_t *r, FILE *record)
{
    const sil_scenario_t *sc = r->sc;
    sil_summary_t *s = r->s;
    const pmstep_config_t *cfg = &sc->controller;
    memset(s, 0, sizeof *s);
    if (r->microstep) {
        sil_microstep_init(&r->drive, sc);
        record = NULL;
        s->init_status = PMSTEP_OK;
    } else {
        s->init_status = pmstep_init(r->inst, cfg);
    }
    if (s->init_status == PMSTEP_OK && r->positional) {
        const pmstep_position_config_t position_cfg = sil_position_config(sc);
        s->init_status = pmstep_position_init(r->pos, r->inst, &position_cfg);
        record = NULL; /* a replay of pmstep_step alone would not see the position loop's reference */
    }
    if (s->init_status != PMSTEP_OK) {
        return -1;
    }
    memset(&r->pos_out, 0, sizeof r->pos_out);
    sil_position_run_init(&r->position_run, sc);
    sil_metrics_init(&r->metrics, sc, s); /* its period counts need a configuration init accepted; clears s */
    s->init_status = r->stepdir ? sil_stepdir_run_init(r->stepdir_run, sc, !r->microstep, s) : PMSTEP_OK;
    if (r->homing) {
        sil_homing_run_init(&r->homing_run, sc, s);
    }
    if (s->init_status != PMSTEP_OK) {
        return -1;
    }
    s->stop_contact_s = -1.0;
    if (sil_bind_plant(sc, &r->plant) != 0) {
        return -3;
    }
    if (!r->microstep) {
        (void)pmstep_set_id_target(r->inst, (float)sc->id_target_A);
        (void)pmstep_start(r->inst);
    }
    if (record != NULL) {
        r->rec_state.file = record;
        r->rec = &r->rec_state;
        record_header(r->rec, cfg, (float)sc->id_target_A);
    }
    return 0;
}

/* The period's commands: the speed profile's, then the step generator's, the homing's or the moves'. */
static void run_command(run_t *r, double t_s)
{
    if (r->microstep) {
        command_microstep_speed(&r->drive, r->sc, t_s, &r->next_segment);
    } else {
        command_speed(r->inst, r->sc, t_s, &r->next_segment, r->rec);
    }
    if (r->stepdir) {
        sil_stepdir_run_command(r->stepdir_run, t_s, r->positional ? r->pos : NULL, r->microstep ? &r->drive : NULL,
                                r->s);
    } else if (r->homing) {
        sil_homing_run_command(&r->homing_run, r->pos, t_s, r->s);
    } else if (r->positional) {
        sil_position_run_command(&r->position_run, r->pos, t_s, r->s);
    }
}

/* The drive's step on @p meas: the baseline's, or the firmware's in the port's order (a STEP/DIR
 * image: the step, the step counter read, the position update, DIAG). */
static void run_drive_step(run_t *r, const pmstep_meas_t *meas, sil_sample_t *sample)
{
    if (r->microstep) {
        sample->angle_ref_rad = r->drive.angle_ref_rad; /* theta_e*(t_k), before the step advances it */
        sil_microstep_step(&r->drive, meas, &r->out);
        return;
    }
    sample->angle_ref_rad = 0.0;
    if (r->stepdir) {
        pmstep_step(r->inst, meas, &r->out);
        sil_stepdir_run_count(r->stepdir_run);
        pmstep_position_update(r->pos, &r->out, &r->pos_out);
        sil_stepdir_run_diag(r->stepdir_run, r->out.mode, &r->pos_out);
    } else if (r->positional) {
        pmstep_position_step(r->pos, meas, &r->out, &r->pos_out);
        if (r->homing) {
            sil_homing_run_update(&r->homing_run, r->pos, &r->out, &r->pos_out);
        }
    } else {
        pmstep_step(r->inst, meas, &r->out);
    }
}

/* One control period: pmstep_hal_control_period() spelled out to keep the measurement for the
 * record, the plant advanced over the period, every SIL_TIMING_STRIDE-th period timed. */
static void run_control_period(run_t *r, bool timed, sil_sample_t *sample)
{
    pmstep_meas_t meas;
    double t0 = 0.0;
    double t1 = 0.0;
    if (timed) {
        t0 = now_s();
    }
    pmstep_hal_read_measurements(&meas);
    run_drive_step(r, &meas, sample);
    pmstep_hal_apply_output(&r->out);
    if (timed) {
        t1 = now_s();
    }
    sil_drive_advance(&r->plant, r->inverter, r->period_s, r->sc->substeps);
    if (timed) {
        const double t2 = now_s();
        const double firmware_s = t1 - t0 - r->clock_read_s;
        const double plant_s = t2 - t1 - r->clock_read_s;
        r->timed_firmware_s += firmware_s > 0.0 ? firmware_s : 0.0;
        r->timed_plant_s += plant_s > 0.0 ? plant_s : 0.0;
        ++r->timed_periods;
    }
    if (r->rec != NULL) {
        record_period(r->rec, &meas, &r->out);
    }
}

/* The period's sample completed (the plant's state was taken before the step) and counted: the
 * position, homing and STEP/DIR runs, the metrics, the hard stop's first contact. */
static void run_observe(run_t *r, long k, double t_s, sil_sample_t *sample)
{
    sil_summary_t *s = r->s;
    sample->step = k;
    sample->t_s = t_s;
    sample->u_a_V = r->inverter->applied_a_V;
    sample->u_b_V = r->inverter->applied_b_V;
    sample->out = &r->out;
    sample->inst = r->microstep ? NULL : r->inst;
    sample->position = NULL;
    sample->position_rad = 0.0;
    sample->position_estimate_rad = 0.0;
    sample->position_reference_rad = 0.0;
    sample->position_updated = false;
    sample->stepdir = false;
    sample->step_count = 0;
    sample->step_error_full_steps = 0.0;
    sample->diag = false;
    if (r->positional) {
        sample->position = &r->pos_out;
        sil_position_run_sample(&r->position_run, r->pos, sample, s);
        if (r->homing && r->position_run.origin_set) {
            sil_homing_run_sample(&r->homing_run, sample, &r->plant.params, r->position_run.origin_rad, s);
        }
    }
    if (r->stepdir) {
        sil_stepdir_run_sample(r->stepdir_run, sample, s);
    }
    sil_metrics_add(&r->metrics, sample, s);
    if (s->stop_contact_s < 0.0 && plant_stop_torque(&r->plant.params, sample->theta_rad, 0.0) != 0.0) {
        s->stop_contact_s = t_s;
    }
}

/* A line that rewrites itself on a terminal, one line per 10 % in a log. */
static void run_progress(run_t *r, long k, double t_s)
{
    if (k + 1 >= r->steps * r->next_progress_decile / 10) {
        fprintf(stderr, "%s  simulated %6.3f of %.3f s (%3d%%)%s", r->on_terminal ? "\r" : "", t_s + r->period_s,
                r->sc->duration_s, r->next_progress_decile * 10,
                (!r->on_terminal || r->next_progress_decile == 10) ? "\n" : "");
        fflush(stderr);
        ++r->next_progress_decile;
    }
}

/* The summary's times and the runs' results; the record's end. @return 0, or -2 on a write error. */
static int run_finish(run_t *r, double wall_start, double cpu_start)
{
    sil_summary_t *s = r->s;
    s->wall_time_s = now_s() - wall_start;
    s->cpu_time_s = cpu_now_s() - cpu_start;
    if (r->timed_periods > 0) {
        s->firmware_time_s = r->timed_firmware_s * (double)s->steps / (double)r->timed_periods;
        s->plant_time_s = r->timed_plant_s * (double)s->steps / (double)r->timed_periods;
    }
    s->sim_time_s = (double)s->steps * r->period_s;
    s->real_time_factor = s->wall_time_s > 0.0 ? s->sim_time_s / s->wall_time_s : 0.0;
    sil_metrics_finish(&r->metrics, s);
    if (r->positional) {
        sil_position_run_finish(&r->position_run, s);
    }
    if (r->stepdir) {
        sil_stepdir_run_finish(r->stepdir_run, s);
    }
    s->inverter_limited_periods = (long)r->inverter->limited_periods;
    pmstep_hal_host_release();
    if (r->rec != NULL) {
        const uint32_t end[] = {SIL_RECORD_TAG_END, (uint32_t)s->steps};
        record_words(r->rec, end, sizeof end / sizeof end[0]);
        return r->rec->failed ? -2 : 0;
    }
    return 0;
}

int sil_run_record(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress, sil_summary_t *s,
                   FILE *record)
{
    static pmstep_t inst; /* as on the MCU: one static instance */
    static pmstep_position_t pos;
    static sil_stepdir_run_t stepdir_run; /* large: static */
    run_t r;
    double wall_start;
    double cpu_start;
    long k;
    int status;
    memset(&r, 0, sizeof r);
    r.sc = sc;
    r.s = s;
    r.inst = &inst;
    r.pos = &pos;
    r.stepdir_run = &stepdir_run;
    r.microstep = sc->drive == SIL_DRIVE_MICROSTEP;
    r.positional = !r.microstep && sc->position_moves > 0;
    r.stepdir = sc->position_moves > 0 && sc->position_source == SIL_SOURCE_STEPDIR;
    r.homing = r.positional && sc->position_source == SIL_SOURCE_HOMING;
    r.period_s = (double)sc->controller.timing.period_s;
    r.steps = sil_periods_in(sc->duration_s, r.period_s);
    r.on_terminal = isatty(fileno(stderr)) != 0;
    r.inverter = pmstep_hal_host_inverter();
    r.next_progress_decile = 1;
    status = run_prepare(&r, record);
    if (status != 0) {
        return status;
    }
    r.clock_read_s = clock_read_cost();
    cpu_start = cpu_now_s();
    wall_start = now_s();
    for (k = 0; k < r.steps; ++k) {
        const double t_s = (double)k * r.period_s;
        sil_sample_t sample;
        r.plant.time_s = t_s;
        run_command(&r, t_s);
        sample.theta_rad = r.plant.x.theta_rad;
        sample.omega_rad_s = r.plant.x.omega_rad_s;
        sample.i_a_A = r.plant.x.i_a_A;
        sample.i_b_A = r.plant.x.i_b_A;
        sample.load_Nm = plant_load_torque(&r.plant.load, t_s, r.plant.x.omega_rad_s);
        plant_sin_cos(&r.plant, &sample.sin_ptheta, &sample.cos_ptheta); /* the step's first stage reuses them */
        run_control_period(&r, k % SIL_TIMING_STRIDE == 0, &sample);
        run_observe(&r, k, t_s, &sample);
        if (progress) {
            run_progress(&r, k, t_s);
        }
        if (on_sample != NULL && !on_sample(&sample, user)) {
            break;
        }
    }
    return run_finish(&r, wall_start, cpu_start);
}
