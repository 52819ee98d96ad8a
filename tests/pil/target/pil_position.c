/*
 * Processor in the loop, position control (issue 13): the paper's motor (plant model (1) on the
 * emulated target, as pil_closed_loop.c) under pmstep_step() from the port's control interrupt
 * and pmstep_position_update() after it, every period: the work of pmstep_position_step(), in two
 * calls so that tools/bench_position_target.py can count each with the QEMU plugin. Two moves
 * (0 -> 3 rad at 0.7 s, 3 -> -1 rad at 1.6 s, 5 rad/s, 50 rad/s^2), then a hold, no load: the
 * moves of sil/scenarios/position.ini's start.
 *
 * usage (semihosting command line): pil-position MODES_FILE [--duration S]
 *   MODES_FILE gets one character a period: 'p' position mode (RUN), 'r' RUN in speed mode,
 *   'a' any other mode; stdout gets the last move's final error (electrical rad).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pmstep_hal_qemu_mps2.h"
#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_text.h"
#include "sil/inverter.h"
#include "sil/plant.h"
#include "sil/scenario.h"

#define MAX_PERIODS 200000L

static pmstep_t motor;
static pmstep_position_t position;
static pmstep_config_t config;
static char modes[MAX_PERIODS];

static const double move_time_s[] = {0.7, 1.6};
static const float move_target_rad[] = {3.0f, -1.0f};

int main(int argc, char **argv)
{
    static sil_scenario_t sc;
    double duration_s = 3.0;
    const char *modes_path;
    plant_t plant;
    sil_inverter_t inv;
    pmstep_output_t out;
    pmstep_position_output_t pos_out;
    pmstep_position_config_t pos_cfg;
    pmstep_status_t st;
    double period_s;
    double origin_rad = 0.0;
    bool origin_set = false;
    long steps, k;
    size_t next_move = 0u;
    FILE *f;

    if (argc < 2) {
        fprintf(stderr, "usage: pil-position MODES_FILE [--duration S]\n");
        return 2;
    }
    modes_path = argv[1];
    if (argc == 4 && strcmp(argv[2], "--duration") == 0) {
        duration_s = strtod(argv[3], NULL);
    }
    sil_scenario_paper(&sc);
    config = sc.controller;
    st = pmstep_init(&motor, &config);
    if (st == PMSTEP_OK) {
        st = pmstep_position_design(&config, &pos_cfg);
    }
    if (st == PMSTEP_OK) {
        st = pmstep_position_init(&position, &motor, &pos_cfg);
    }
    if (st != PMSTEP_OK) {
        fprintf(stderr, "pil-position: init: %s\n", pmstep_status_str(st));
        return 2;
    }
    period_s = (double)config.timing.period_s;
    steps = (long)(duration_s / period_s + 0.5);
    if (steps > MAX_PERIODS) {
        steps = MAX_PERIODS;
    }

    memset(&plant, 0, sizeof plant);
    plant.params = sc.motor;
    plant.load.kind = PLANT_LOAD_NONE;
    plant.x.theta_rad = sc.theta0_rad;
    plant.integrator = sc.integrator;
    sil_inverter_init(&inv, &sc.inverter, &sc.bus, sc.bus_voltage_V, config.timing.computational_delay_periods);
    (void)pmstep_start(&motor);
    mps2_pil_init(&motor);

    for (k = 0; k < steps; ++k) {
        const double t_s = (double)k * period_s;
        pmstep_meas_t meas;
        plant.time_s = t_s;
        if (next_move < sizeof move_time_s / sizeof move_time_s[0] && t_s >= move_time_s[next_move]
            && position.out.tracked) {
            (void)pmstep_position_move_to(&position, move_target_rad[next_move], 5.0f, 50.0f, 0.0f);
            next_move++;
        }
        meas.i_a_A = (float)plant.x.i_a_A;
        meas.i_b_A = (float)plant.x.i_b_A;
        meas.bus_voltage_V = (float)sil_inverter_bus_voltage(&inv, t_s);
        meas.load_torque_Nm = 0.0f;
        meas.phase_voltage_a_V = (float)inv.applied_a_V; /* the mean voltage of the period just ended */
        meas.phase_voltage_b_V = (float)inv.applied_b_V;
        mps2_pil_control_period(&meas, &out);      /* pmstep_step() in the control interrupt */
        pmstep_position_update(&position, &out, &pos_out);
        sil_inverter_apply(&inv, &out, (double)meas.bus_voltage_V);
        sil_drive_advance(&plant, &inv, period_s, sc.substeps);
        if (pos_out.tracked && !origin_set) {
            const double pitch = 2.0 * 3.14159265358979323846 / (double)sc.motor.pole_pairs;
            origin_rad = floor(plant.x.theta_rad / pitch + 0.5) * pitch;
            origin_set = true;
        }
        modes[k] = out.mode != PMSTEP_MODE_RUN ? 'a' : (pos_out.position_mode ? 'p' : 'r');
    }
    f = fopen(modes_path, "w");
    if (f == NULL || fwrite(modes, 1, (size_t)steps, f) != (size_t)steps || fclose(f) != 0) {
        fprintf(stderr, "pil-position: cannot write '%s'\n", modes_path);
        return 2;
    }
    printf("pil-position: %ld periods, fault %s, final position %.6f rad (target %.6f), error %.3g electrical rad\n",
           steps, pmstep_fault_str(out.fault), plant.x.theta_rad - origin_rad, (double)move_target_rad[1],
           fabs(plant.x.theta_rad - origin_rad - (double)move_target_rad[1]) * (double)sc.motor.pole_pairs);
    return out.fault != PMSTEP_FAULT_NONE ? 3 : 0;
}
