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

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static long periods_in(double duration_s, double period_s)
{
    return (long)floor(duration_s / period_s + 0.5);
}

/* The record of runner.h: little-endian 32-bit words, whatever the host's byte order. */
typedef struct {
    FILE *file;
    bool failed;
} record_t;

static uint32_t float_bits(float x)
{
    uint32_t w;
    memcpy(&w, &x, sizeof w);
    return w;
}

static void record_words(record_t *rec, const uint32_t *words, size_t n)
{
    unsigned char bytes[4 * (1 + SIL_RECORD_IN_WORDS + SIL_RECORD_OUT_WORDS)];
    size_t k;
    if (rec == NULL || rec->failed || n > sizeof bytes / 4) {
        return;
    }
    for (k = 0; k < n; ++k) {
        bytes[4 * k] = (unsigned char)(words[k] & 0xFFu);
        bytes[4 * k + 1] = (unsigned char)((words[k] >> 8) & 0xFFu);
        bytes[4 * k + 2] = (unsigned char)((words[k] >> 16) & 0xFFu);
        bytes[4 * k + 3] = (unsigned char)((words[k] >> 24) & 0xFFu);
    }
    if (fwrite(bytes, 4, n, rec->file) != n) {
        rec->failed = true;
    }
}

static void record_header(record_t *rec, const pmstep_config_t *c, float id_target_a)
{
    const uint32_t head[] = {SIL_RECORD_MAGIC, SIL_RECORD_VERSION, SIL_RECORD_CONFIG_WORDS,
                             (uint32_t)SIL_RECORD_IN_WORDS, (uint32_t)SIL_RECORD_OUT_WORDS};
    const uint32_t config[SIL_RECORD_CONFIG_WORDS] = {
        float_bits(c->resistance_ohm), float_bits(c->inductance_h), float_bits(c->inertia_kg_m2),
        float_bits(c->friction_nm_s_per_rad), float_bits(c->torque_constant_nm_per_a), (uint32_t)c->pole_pairs,
        float_bits(c->period_s), c->computational_delay_periods, float_bits(c->s_align_time_s),
        float_bits(c->c_align_time_s), float_bits(c->s_align_voltage_v), float_bits(c->c_align_voltage_v),
        float_bits(c->speed_gain_per_s), float_bits(c->observer_gain_per_s), float_bits(c->current_gain_per_s),
        float_bits(c->adapt_gamma), float_bits(c->adapt_lambda), float_bits(c->adapt_r),
        float_bits(c->sat_kappa_rad_per_s), float_bits(c->reference_bandwidth_rad_per_s),
        c->known_load_mode ? 1u : 0u, float_bits(c->max_phase_current_a), float_bits(c->min_bus_voltage_v),
        float_bits(c->max_bus_voltage_v)};
    const uint32_t id_target = float_bits(id_target_a);
    record_words(rec, head, sizeof head / sizeof head[0]);
    record_words(rec, config, SIL_RECORD_CONFIG_WORDS);
    record_words(rec, &id_target, 1);
}

static void record_speed_target(record_t *rec, float target_rad_s, float ramp_rate_rad_s2)
{
    const uint32_t words[] = {SIL_RECORD_TAG_SPEED_TARGET, float_bits(target_rad_s), float_bits(ramp_rate_rad_s2)};
    record_words(rec, words, sizeof words / sizeof words[0]);
}

static void record_period(record_t *rec, const pmstep_meas_t *in, const pmstep_output_t *o)
{
    uint32_t w[1 + SIL_RECORD_IN_WORDS + SIL_RECORD_OUT_WORDS];
    uint32_t *out = &w[1 + SIL_RECORD_IN_WORDS];
    w[0] = SIL_RECORD_TAG_PERIOD;
    w[1 + SIL_RECORD_IN_I_A] = float_bits(in->i_a_a);
    w[1 + SIL_RECORD_IN_I_B] = float_bits(in->i_b_a);
    w[1 + SIL_RECORD_IN_BUS] = float_bits(in->bus_voltage_v);
    w[1 + SIL_RECORD_IN_LOAD] = float_bits(in->load_torque_nm);
    out[SIL_RECORD_OUT_U_A] = float_bits(o->u_a_v);
    out[SIL_RECORD_OUT_U_B] = float_bits(o->u_b_v);
    out[SIL_RECORD_OUT_BRIDGE_ENABLE] = o->bridge_enable ? 1u : 0u;
    out[SIL_RECORD_OUT_VOLTAGE_LIMITED] = o->voltage_limited ? 1u : 0u;
    out[SIL_RECORD_OUT_MODE] = (uint32_t)o->mode;
    out[SIL_RECORD_OUT_FAULT] = (uint32_t)o->fault;
    out[SIL_RECORD_OUT_FAULT_STEP] = o->fault_step;
    out[SIL_RECORD_OUT_COS_HAT] = float_bits(o->cos_hat);
    out[SIL_RECORD_OUT_SIN_HAT] = float_bits(o->sin_hat);
    out[SIL_RECORD_OUT_SPEED_HAT] = float_bits(o->speed_hat_rad_s);
    out[SIL_RECORD_OUT_LOAD_HAT] = float_bits(o->load_hat_nm);
    out[SIL_RECORD_OUT_I_A_HAT] = float_bits(o->i_a_hat_a);
    out[SIL_RECORD_OUT_I_B_HAT] = float_bits(o->i_b_hat_a);
    out[SIL_RECORD_OUT_SPEED_REF] = float_bits(o->speed_ref_rad_s);
    out[SIL_RECORD_OUT_SPEED_REF_DOT] = float_bits(o->speed_ref_dot_rad_s2);
    out[SIL_RECORD_OUT_I_D] = float_bits(o->i_d_a);
    out[SIL_RECORD_OUT_I_Q] = float_bits(o->i_q_a);
    out[SIL_RECORD_OUT_I_D_REF] = float_bits(o->i_d_ref_a);
    out[SIL_RECORD_OUT_I_Q_REF] = float_bits(o->i_q_ref_a);
    record_words(rec, w, sizeof w / sizeof w[0]);
}

/* Issues the speed commands of the piecewise-linear profile: at the start of each
 * segment, ramp to its end value at its slope. */
static void command_speed(pmstep_t *inst, const sil_scenario_t *sc, double t_s, int *next_segment, record_t *rec)
{
    while (*next_segment + 1 < sc->speed_points && t_s >= sc->speed_time_s[*next_segment]) {
        const int k = *next_segment;
        const double dv = sc->speed_value_rad_s[k + 1] - sc->speed_value_rad_s[k];
        const double dt = sc->speed_time_s[k + 1] - sc->speed_time_s[k];
        if (dv != 0.0) {
            const float target_rad_s = (float)sc->speed_value_rad_s[k + 1];
            const float ramp_rate_rad_s2 = (float)(fabs(dv) / dt);
            (void)pmstep_set_speed_target(inst, target_rad_s, ramp_rate_rad_s2);
            record_speed_target(rec, target_rad_s, ramp_rate_rad_s2);
        }
        ++*next_segment;
    }
}

int sil_run(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress, sil_summary_t *s)
{
    return sil_run_record(sc, on_sample, user, progress, s, NULL);
}

int sil_run_record(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress, sil_summary_t *s,
                   FILE *record)
{
    static pmstep_t inst; /* as on the MCU: one static instance */
    const pmstep_config_t *cfg = &sc->controller;
    const double period_s = (double)cfg->period_s;
    const long steps = periods_in(sc->duration_s, period_s);
    const long ts_step = periods_in((double)cfg->s_align_time_s, period_s);
    const long tc_step = periods_in((double)cfg->c_align_time_s, period_s);
    const long transient_end_step = tc_step + periods_in(sc->transient_window_s, period_s);
    const double p = (double)sc->motor.pole_pairs;
    plant_t plant;
    pmstep_output_t out;
    double transient_sq = 0.0, tracking_sq = 0.0;
    long transient_n = 0, tracking_n = 0;
    int next_segment = 0;
    int next_progress_decile = 1;
    double wall_start;
    const bool on_terminal = isatty(fileno(stderr)) != 0;
    record_t rec_state = {NULL, false};
    record_t *rec = NULL;
    long k;

    memset(s, 0, sizeof *s);
    s->fault_step = -1;
    s->fault_time_s = -1.0;
    s->init_status = pmstep_init(&inst, cfg);
    if (s->init_status != PMSTEP_OK) {
        return -1;
    }
    memset(&plant, 0, sizeof plant);
    plant.params = sc->motor;
    plant.load = sc->load;
    plant.x.theta_rad = sc->theta0_rad;
    plant.x.omega_rad_s = sc->omega0_rad_s;
    plant.x.i_a_a = sc->i_a0_a;
    plant.x.i_b_a = sc->i_b0_a;
    pmstep_hal_host_bind(&plant, sc->bus_voltage_v, cfg->computational_delay_periods);
    (void)pmstep_set_id_target(&inst, (float)sc->id_target_a);
    (void)pmstep_start(&inst);
    if (record != NULL) {
        rec_state.file = record;
        rec = &rec_state;
        record_header(rec, cfg, (float)sc->id_target_a);
    }

    wall_start = now_s();
    for (k = 0; k < steps; ++k) {
        const double t_s = (double)k * period_s;
        const pmstep_hal_host_t *port;
        pmstep_meas_t meas;
        sil_sample_t sample;
        double t0, t1, t2;

        plant.time_s = t_s;
        command_speed(&inst, sc, t_s, &next_segment, rec);
        sample.theta_rad = plant.x.theta_rad;
        sample.omega_rad_s = plant.x.omega_rad_s;
        sample.i_a_a = plant.x.i_a_a;
        sample.i_b_a = plant.x.i_b_a;
        sample.load_nm = plant_load_torque(&plant.load, t_s, plant.x.omega_rad_s);

        t0 = now_s();
        if (rec == NULL) {
            pmstep_hal_control_period(&inst, &out);
        } else { /* pmstep_hal_control_period(), keeping the measurement for the record */
            pmstep_hal_read_measurements(&meas);
            pmstep_step(&inst, &meas, &out);
            pmstep_hal_apply_output(&out);
        }
        t1 = now_s();
        port = pmstep_hal_host_state();
        plant_advance(&plant, port->applied_a_v, port->applied_b_v, period_s, sc->substeps);
        t2 = now_s();
        if (rec != NULL) { /* outside both timed intervals */
            record_period(rec, &meas, &out);
        }
        s->firmware_time_s += t1 - t0;
        s->plant_time_s += t2 - t1;

        sample.step = k;
        sample.t_s = t_s;
        sample.cos_ptheta = cos(p * sample.theta_rad);
        sample.sin_ptheta = sin(p * sample.theta_rad);
        sample.u_a_v = port->applied_a_v;
        sample.u_b_v = port->applied_b_v;
        sample.out = &out;
        sample.inst = &inst;

        /* Metrics. */
        if (k == ts_step) {
            s->cos_ptheta_at_ts = sample.cos_ptheta;
            s->sin_ptheta_at_ts = sample.sin_ptheta;
            s->i_b_residual_at_ts_a = sample.i_b_a - (double)cfg->s_align_voltage_v / sc->motor.resistance_ohm;
        }
        if (k == tc_step) {
            s->cos_ptheta_at_tc = sample.cos_ptheta;
            s->sin_ptheta_at_tc = sample.sin_ptheta;
            s->i_a_residual_at_tc_a = sample.i_a_a - (double)cfg->c_align_voltage_v / sc->motor.resistance_ohm;
        }
        s->max_phase_voltage_v = fmax(s->max_phase_voltage_v, fmax(fabs(sample.u_a_v), fabs(sample.u_b_v)));
        s->max_phase_current_a = fmax(s->max_phase_current_a, fmax(fabs(sample.i_a_a), fabs(sample.i_b_a)));
        if (out.voltage_limited) {
            s->voltage_limited_periods++;
        }
        if (out.mode == PMSTEP_MODE_RUN) {
            const double speed_error = fabs(sample.omega_rad_s - (double)out.speed_ref_rad_s);
            s->max_cos_error = fmax(s->max_cos_error, fabs((double)out.cos_hat - sample.cos_ptheta));
            s->max_sin_error = fmax(s->max_sin_error, fabs((double)out.sin_hat - sample.sin_ptheta));
            if (k < transient_end_step) {
                s->transient_max_speed_error_rad_s = fmax(s->transient_max_speed_error_rad_s, speed_error);
                transient_sq += speed_error * speed_error;
                ++transient_n;
            } else {
                s->tracking_max_speed_error_rad_s = fmax(s->tracking_max_speed_error_rad_s, speed_error);
                tracking_sq += speed_error * speed_error;
                ++tracking_n;
            }
            s->final_load_hat_nm = (double)out.load_hat_nm;
            s->final_load_nm = sample.load_nm;
        }
        if (out.fault != PMSTEP_FAULT_NONE && s->fault == PMSTEP_FAULT_NONE) {
            s->fault = out.fault;
            s->fault_step = (long)out.fault_step;
            s->fault_time_s = t_s;
        }
        s->final_mode = out.mode;
        s->steps = k + 1;

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
    s->sim_time_s = (double)s->steps * period_s;
    s->real_time_factor = s->wall_time_s > 0.0 ? s->sim_time_s / s->wall_time_s : 0.0;
    s->transient_rms_speed_error_rad_s = transient_n ? sqrt(transient_sq / (double)transient_n) : 0.0;
    s->tracking_rms_speed_error_rad_s = tracking_n ? sqrt(tracking_sq / (double)tracking_n) : 0.0;
    s->final_load_error_nm = fabs(s->final_load_hat_nm - s->final_load_nm);
    s->inverter_limited_periods = (long)pmstep_hal_host_state()->inverter_limited_periods;
    if (rec != NULL) {
        const uint32_t end[] = {SIL_RECORD_TAG_END, (uint32_t)s->steps};
        record_words(rec, end, sizeof end / sizeof end[0]);
        return rec->failed ? -2 : 0;
    }
    return 0;
}
