/*
 * Processor in the loop, closed loop: the plant model (1) (sil/src/plant.c, double
 * precision, soft-float on the Cortex-M4) runs on the emulated target with the real
 * core, which runs from the port's control interrupt. The scenario is the SIL's
 * built-in paper scenario (sil_scenario_paper() in sil/src/scenario.c: 2 Nm load step
 * at 0.63 s, theta0 = 30 deg, 48 V bus, set-point 0 -> 10 -> -10 -> 0 rad/s), shortened
 * by --duration; the loop, the inverter model and every metric are those of
 * sil/src/runner.c and hal/host/pmstep_hal_host.c, so the summary can be compared
 * key by key with `pmstep-sil --set run.duration_s=... --set run.substeps=...`.
 *
 * usage (semihosting command line): pil-closed-loop [--duration S] [--substeps N] [--summary FILE]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pmstep_hal_qemu_mps2.h"
#include "sil/plant.h"

#define PI 3.14159265358979323846

/* The paper scenario, as sil_scenario_paper() sets it. */
static const double speed_time_s[] = {0.0, 0.65, 0.85, 1.2, 1.5, 1.8, 2.0, 2.4};
static const double speed_value_rad_s[] = {0.0, 0.0, 10.0, 10.0, -10.0, -10.0, 0.0, 0.0};
#define SPEED_POINTS ((int)(sizeof speed_time_s / sizeof speed_time_s[0]))
#define BUS_VOLTAGE_V 48.0
#define THETA0_RAD (30.0 * PI / 180.0)
#define LOAD_STEP_NM 2.0
#define LOAD_STEP_TIME_S 0.63
#define TRANSIENT_WINDOW_S 0.2
#define ID_TARGET_A 0.0

static pmstep_t motor;
static pmstep_config_t config;

/* The "hardware" behind the port's output block: the host port's averaged inverter
 * (hal/host/pmstep_hal_host.c): optional one-period delay, bridge off = 0 V, clip to +/- bus. */
typedef struct {
    unsigned delay_periods;
    double pending_a_v, pending_b_v;
    double applied_a_v, applied_b_v;
    long limited_periods;
} inverter_t;

static double clip(double u_v, double limit_v, int *clipped)
{
    if (u_v > limit_v) {
        *clipped = 1;
        return limit_v;
    }
    if (u_v < -limit_v) {
        *clipped = 1;
        return -limit_v;
    }
    return u_v;
}

static void inverter_apply(inverter_t *inv, const pmstep_output_t *out)
{
    const double u_a_v = out->bridge_enable ? (double)out->u_a_v : 0.0;
    const double u_b_v = out->bridge_enable ? (double)out->u_b_v : 0.0;
    double next_a_v = u_a_v;
    double next_b_v = u_b_v;
    int clipped = 0;
    if (inv->delay_periods == 1u) {
        next_a_v = inv->pending_a_v;
        next_b_v = inv->pending_b_v;
        inv->pending_a_v = u_a_v;
        inv->pending_b_v = u_b_v;
        if (!out->bridge_enable) {
            next_a_v = 0.0;
            next_b_v = 0.0;
            inv->pending_a_v = 0.0;
            inv->pending_b_v = 0.0;
        }
    }
    inv->applied_a_v = clip(next_a_v, BUS_VOLTAGE_V, &clipped);
    inv->applied_b_v = clip(next_b_v, BUS_VOLTAGE_V, &clipped);
    if (clipped) {
        inv->limited_periods++;
    }
}

static long periods_in(double duration_s, double period_s)
{
    return (long)floor(duration_s / period_s + 0.5);
}

static void command_speed(pmstep_t *inst, double t_s, int *next_segment)
{
    while (*next_segment + 1 < SPEED_POINTS && t_s >= speed_time_s[*next_segment]) {
        const int k = *next_segment;
        const double dv = speed_value_rad_s[k + 1] - speed_value_rad_s[k];
        const double dt = speed_time_s[k + 1] - speed_time_s[k];
        if (dv != 0.0) {
            (void)pmstep_set_speed_target(inst, (float)speed_value_rad_s[k + 1], (float)(fabs(dv) / dt));
        }
        ++*next_segment;
    }
}

typedef struct {
    long steps;
    double cos_ptheta_at_ts, sin_ptheta_at_ts, i_b_residual_at_ts_a;
    double cos_ptheta_at_tc, sin_ptheta_at_tc, i_a_residual_at_tc_a;
    double transient_max, transient_rms, tracking_max, tracking_rms;
    double final_load_hat_nm, final_load_nm;
    double max_cos_error, max_sin_error, max_phase_voltage_v, max_phase_current_a;
    long voltage_limited_periods, inverter_limited_periods;
    pmstep_mode_t final_mode;
    pmstep_fault_t fault;
    long fault_step;
    double fault_time_s;
} summary_t;

static void write_summary(FILE *f, const summary_t *s, double duration_s, int substeps)
{
    fprintf(f, "{\n");
    fprintf(f, "  \"scenario\": \"paper\",\n  \"target\": \"qemu mps2-an386 (Cortex-M4F)\",\n");
    fprintf(f, "  \"duration_s\": %.17g,\n  \"substeps\": %d,\n", duration_s, substeps);
    fprintf(f, "  \"alignment\": {\n");
    fprintf(f, "    \"cos_ptheta_at_ts\": %.17g,\n    \"sin_ptheta_at_ts\": %.17g,\n", s->cos_ptheta_at_ts,
            s->sin_ptheta_at_ts);
    fprintf(f, "    \"i_b_minus_ucs_over_r_at_ts_a\": %.17g,\n", s->i_b_residual_at_ts_a);
    fprintf(f, "    \"cos_ptheta_at_tc\": %.17g,\n    \"sin_ptheta_at_tc\": %.17g,\n", s->cos_ptheta_at_tc,
            s->sin_ptheta_at_tc);
    fprintf(f, "    \"i_a_minus_ucc_over_r_at_tc_a\": %.17g\n  },\n", s->i_a_residual_at_tc_a);
    fprintf(f, "  \"speed\": {\n");
    fprintf(f, "    \"transient_max_abs_error_rad_s\": %.17g,\n    \"transient_rms_error_rad_s\": %.17g,\n",
            s->transient_max, s->transient_rms);
    fprintf(f, "    \"tracking_max_abs_error_rad_s\": %.17g,\n    \"tracking_rms_error_rad_s\": %.17g\n  },\n",
            s->tracking_max, s->tracking_rms);
    fprintf(f, "  \"final_load_hat_nm\": %.17g,\n  \"final_load_nm\": %.17g,\n", s->final_load_hat_nm,
            s->final_load_nm);
    fprintf(f, "  \"final_load_abs_error_nm\": %.17g,\n", fabs(s->final_load_hat_nm - s->final_load_nm));
    fprintf(f, "  \"angle_estimate\": {\n    \"max_abs_cos_error\": %.17g,\n    \"max_abs_sin_error\": %.17g\n  },\n",
            s->max_cos_error, s->max_sin_error);
    fprintf(f, "  \"max_abs_phase_voltage_v\": %.17g,\n  \"max_abs_phase_current_a\": %.17g,\n",
            s->max_phase_voltage_v, s->max_phase_current_a);
    fprintf(f, "  \"voltage_limited_periods\": %ld,\n  \"inverter_clipped_periods\": %ld,\n",
            s->voltage_limited_periods, s->inverter_limited_periods);
    fprintf(f, "  \"final_mode\": \"%s\",\n", pmstep_mode_str(s->final_mode));
    fprintf(f, "  \"fault\": {\n    \"code\": %d,\n    \"text\": \"%s\",\n    \"step\": %ld,\n    \"time_s\": %.17g\n  },\n",
            (int)s->fault, pmstep_fault_str(s->fault), s->fault_step, s->fault_time_s);
    fprintf(f, "  \"timing\": {\n    \"steps\": %ld\n  }\n}\n", s->steps);
}

int main(int argc, char **argv)
{
    double duration_s = 0.9;
    int substeps = 2;
    const char *summary_path = NULL;
    plant_t plant;
    inverter_t inv;
    summary_t s;
    pmstep_output_t out;
    pmstep_status_t st;
    double period_s;
    long steps, ts_step, tc_step, transient_end_step, k;
    double transient_sq = 0.0, tracking_sq = 0.0;
    long transient_n = 0, tracking_n = 0;
    int next_segment = 0;
    double p;
    int i;

    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--duration") == 0 && i + 1 < argc) {
            duration_s = strtod(argv[++i], NULL);
        } else if (strcmp(argv[i], "--substeps") == 0 && i + 1 < argc) {
            substeps = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--summary") == 0 && i + 1 < argc) {
            summary_path = argv[++i];
        } else {
            fprintf(stderr, "usage: pil-closed-loop [--duration S] [--substeps N] [--summary FILE]\n");
            return 2;
        }
    }
    if (!(duration_s > 0.0) || substeps < 1) {
        fprintf(stderr, "pil-closed-loop: --duration must be > 0 and --substeps >= 1\n");
        return 2;
    }

    config = pmstep_paper_config();
    st = pmstep_init(&motor, &config);
    if (st != PMSTEP_OK) {
        fprintf(stderr, "pil-closed-loop: pmstep_init: %s\n", pmstep_status_str(st));
        return 2;
    }
    period_s = (double)config.period_s;
    steps = periods_in(duration_s, period_s);
    ts_step = periods_in((double)config.s_align_time_s, period_s);
    tc_step = periods_in((double)config.c_align_time_s, period_s);
    transient_end_step = tc_step + periods_in(TRANSIENT_WINDOW_S, period_s);

    memset(&plant, 0, sizeof plant);
    plant.params = plant_paper_params();
    plant.load.kind = PLANT_LOAD_STEP;
    plant.load.torque_nm = LOAD_STEP_NM;
    plant.load.step_time_s = LOAD_STEP_TIME_S;
    plant.x.theta_rad = THETA0_RAD;
    p = (double)plant.params.pole_pairs;
    memset(&inv, 0, sizeof inv);
    inv.delay_periods = config.computational_delay_periods;
    memset(&s, 0, sizeof s);
    s.fault_step = -1;
    s.fault_time_s = -1.0;

    (void)pmstep_set_id_target(&motor, (float)ID_TARGET_A);
    (void)pmstep_start(&motor);
    mps2_pil_init(&motor);

    for (k = 0; k < steps; ++k) {
        const double t_s = (double)k * period_s;
        pmstep_meas_t meas;
        double theta, omega, i_a, i_b, load_nm, c, sn;

        plant.time_s = t_s;
        command_speed(&motor, t_s, &next_segment);
        theta = plant.x.theta_rad;
        omega = plant.x.omega_rad_s;
        i_a = plant.x.i_a_a;
        i_b = plant.x.i_b_a;
        load_nm = plant_load_torque(&plant.load, t_s, omega);

        /* Sample (what the host port reads), control interrupt, inverter, plant. */
        meas.i_a_a = (float)i_a;
        meas.i_b_a = (float)i_b;
        meas.bus_voltage_v = (float)BUS_VOLTAGE_V;
        meas.load_torque_nm = (float)load_nm;
        mps2_pil_control_period(&meas, &out);
        inverter_apply(&inv, &out);
        plant_advance(&plant, inv.applied_a_v, inv.applied_b_v, period_s, substeps);

        /* Metrics, as sil/src/runner.c computes them. */
        c = cos(p * theta);
        sn = sin(p * theta);
        if (k == ts_step) {
            s.cos_ptheta_at_ts = c;
            s.sin_ptheta_at_ts = sn;
            s.i_b_residual_at_ts_a = i_b - (double)config.s_align_voltage_v / plant.params.resistance_ohm;
        }
        if (k == tc_step) {
            s.cos_ptheta_at_tc = c;
            s.sin_ptheta_at_tc = sn;
            s.i_a_residual_at_tc_a = i_a - (double)config.c_align_voltage_v / plant.params.resistance_ohm;
        }
        s.max_phase_voltage_v = fmax(s.max_phase_voltage_v, fmax(fabs(inv.applied_a_v), fabs(inv.applied_b_v)));
        s.max_phase_current_a = fmax(s.max_phase_current_a, fmax(fabs(i_a), fabs(i_b)));
        if (out.voltage_limited) {
            s.voltage_limited_periods++;
        }
        if (out.mode == PMSTEP_MODE_RUN) {
            const double speed_error = fabs(omega - (double)out.speed_ref_rad_s);
            s.max_cos_error = fmax(s.max_cos_error, fabs((double)out.cos_hat - c));
            s.max_sin_error = fmax(s.max_sin_error, fabs((double)out.sin_hat - sn));
            if (k < transient_end_step) {
                s.transient_max = fmax(s.transient_max, speed_error);
                transient_sq += speed_error * speed_error;
                ++transient_n;
            } else {
                s.tracking_max = fmax(s.tracking_max, speed_error);
                tracking_sq += speed_error * speed_error;
                ++tracking_n;
            }
            s.final_load_hat_nm = (double)out.load_hat_nm;
            s.final_load_nm = load_nm;
        }
        if (out.fault != PMSTEP_FAULT_NONE && s.fault == PMSTEP_FAULT_NONE) {
            s.fault = out.fault;
            s.fault_step = (long)out.fault_step;
            s.fault_time_s = t_s;
        }
        s.final_mode = out.mode;
        s.steps = k + 1;
    }
    s.transient_rms = transient_n ? sqrt(transient_sq / (double)transient_n) : 0.0;
    s.tracking_rms = tracking_n ? sqrt(tracking_sq / (double)tracking_n) : 0.0;
    s.inverter_limited_periods = inv.limited_periods;

    write_summary(stdout, &s, duration_s, substeps);
    if (summary_path != NULL) {
        FILE *f = fopen(summary_path, "w");
        if (f == NULL) {
            fprintf(stderr, "pil-closed-loop: cannot write '%s'\n", summary_path);
            return 2;
        }
        write_summary(f, &s, duration_s, substeps);
        if (fclose(f) != 0) {
            fprintf(stderr, "pil-closed-loop: error writing '%s'\n", summary_path);
            return 2;
        }
    }
    return s.fault != PMSTEP_FAULT_NONE ? 3 : 0;
}
