/*
 * Processor in the loop, closed loop: the plant model (1) (sil/src/plant.c, double
 * precision, soft-float on the Cortex-M4) runs on the emulated target with the real
 * core, which runs from the port's control interrupt. The scenario is the SIL's
 * built-in paper scenario (sil_scenario_paper() in sil/src/scenario.c: 2 Nm load step
 * at 0.63 s, theta0 = 30 deg, 48 V bus, set-point 0 -> 10 -> -10 -> 0 rad/s), shortened
 * by --duration. The scenario, its speed commands, the inverter and bus model
 * (sil_drive_advance) and every metric come from sil/ (scenario_profile.c,
 * inverter.c, metrics.c), as in the host runner, so the summary can be compared key
 * by key with
 * `pmstep-sil --set run.duration_s=... --set run.substeps=...` (the plant integrator is
 * the scenario's default, run.integrator, on both sides).
 *
 * usage (semihosting command line): pil-closed-loop [--duration S] [--substeps N] [--summary FILE]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pmstep_hal_qemu_mps2.h"
#include "sil/inverter.h"
#include "sil/metrics.h"
#include "pil_summary.h"
#include "sil/plant.h"
#include "pmstep/pmstep_text.h"

static pmstep_t motor;
static pmstep_config_t config; /* outlives the instance, as pmstep_init() requires */

int main(int argc, char **argv)
{
    static sil_scenario_t sc;
    double duration_s = 0.9;
    int substeps = 0; /* 0: the scenario's default */
    const char *summary_path = NULL;
    plant_t plant;
    sil_inverter_t inv;
    sil_metrics_t metrics;
    sil_summary_t s;
    pmstep_output_t out;
    pmstep_status_t st;
    double period_s, p;
    long steps, k;
    int next_segment = 0;
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
    if (!(duration_s > 0.0) || substeps < 0) {
        fprintf(stderr, "pil-closed-loop: --duration must be > 0 and --substeps >= 1 (0: the scenario's)\n");
        return 2;
    }

    sil_scenario_paper(&sc);
    sc.duration_s = duration_s;
    if (substeps > 0) {
        sc.substeps = substeps;
    }
    substeps = sc.substeps;
    config = sc.controller;
    st = pmstep_init(&motor, &config);
    if (st != PMSTEP_OK) {
        fprintf(stderr, "pil-closed-loop: pmstep_init: %s\n", pmstep_status_str(st));
        return 2;
    }
    period_s = (double)config.timing.period_s;
    steps = sil_periods_in(sc.duration_s, period_s);
    sil_metrics_init(&metrics, &sc, &s);

    memset(&plant, 0, sizeof plant);
    plant.params = sc.motor;
    plant.load = sc.load;
    plant.x.theta_rad = sc.theta0_rad;
    plant.x.omega_rad_s = sc.omega0_rad_s;
    plant.x.i_a_A = sc.i_a0_A;
    plant.x.i_b_A = sc.i_b0_A;
    plant.integrator = sc.integrator; /* as the host runner */
    p = (double)plant.params.pole_pairs;
    sil_inverter_init(&inv, &sc.inverter, &sc.bus, sc.bus_voltage_V, config.timing.computational_delay_periods);

    (void)pmstep_set_id_target(&motor, (float)sc.id_target_A);
    (void)pmstep_start(&motor);
    mps2_pil_init(&motor);

    for (k = 0; k < steps; ++k) {
        const double t_s = (double)k * period_s;
        pmstep_meas_t meas;
        sil_sample_t sample;
        float target_rad_s, ramp_rate_rad_s2;

        plant.time_s = t_s;
        while (sil_scenario_speed_command(&sc, t_s, &next_segment, &target_rad_s, &ramp_rate_rad_s2)) {
            (void)pmstep_set_speed_target(&motor, target_rad_s, ramp_rate_rad_s2);
        }
        sample.step = k;
        sample.t_s = t_s;
        sample.theta_rad = plant.x.theta_rad;
        sample.omega_rad_s = plant.x.omega_rad_s;
        sample.i_a_A = plant.x.i_a_A;
        sample.i_b_A = plant.x.i_b_A;
        sample.load_Nm = plant_load_torque(&plant.load, t_s, plant.x.omega_rad_s);

        /* Sample (what the host port reads with the ideal measurement chain: no GSL here),
         * control interrupt, inverter, plant. */
        meas.i_a_A = (float)sample.i_a_A;
        meas.i_b_A = (float)sample.i_b_A;
        meas.bus_voltage_V = (float)sil_inverter_bus_voltage(&inv, t_s);
        meas.load_torque_Nm = (float)sample.load_Nm;
        meas.phase_voltage_a_V = (float)inv.applied_a_V; /* the mean voltage of the period just ended */
        meas.phase_voltage_b_V = (float)inv.applied_b_V;
        mps2_pil_control_period(&meas, &out);
        sil_inverter_apply(&inv, &out, (double)meas.bus_voltage_V);
        sil_drive_advance(&plant, &inv, period_s, substeps);

        sample.cos_ptheta = cos(p * sample.theta_rad);
        sample.sin_ptheta = sin(p * sample.theta_rad);
        sample.u_a_V = inv.applied_a_V;
        sample.u_b_V = inv.applied_b_V;
        sample.out = &out;
        sample.inst = &motor;
        sil_metrics_add(&metrics, &sample, &s);
    }
    sil_metrics_finish(&metrics, &s);
    s.inverter_limited_periods = (long)inv.limited_periods;

    pil_write_summary(stdout, "qemu mps2-an386 (Cortex-M4F)", &s, duration_s, substeps);
    if (summary_path != NULL) {
        FILE *f = fopen(summary_path, "w");
        if (f == NULL) {
            fprintf(stderr, "pil-closed-loop: cannot write '%s'\n", summary_path);
            return 2;
        }
        pil_write_summary(f, "qemu mps2-an386 (Cortex-M4F)", &s, duration_s, substeps);
        if (fclose(f) != 0) {
            fprintf(stderr, "pil-closed-loop: error writing '%s'\n", summary_path);
            return 2;
        }
    }
    return s.fault != PMSTEP_FAULT_NONE ? 3 : 0;
}
