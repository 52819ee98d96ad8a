/*
 * Processor in the loop, position control (issue 13): the paper's motor (plant model (1) on the
 * emulated target, as pil_closed_loop.c) under pmstep_step() from the port's control interrupt
 * and pmstep_position_update() after it, every period: the work of pmstep_position_step(), in two
 * calls so that tools/bench_position_target.py can count each with the QEMU plugin. Two moves
 * (0 -> 3 rad at 0.7 s, 3 -> -1 rad at 1.6 s, 5 rad/s, 50 rad/s^2), then a hold, no load: the
 * moves of sil/scenarios/position.ini's start.
 *
 * STEP/DIR mode (--stepdir M): the drive follows a step count instead of planning the moves
 * itself. The same two moves, planned by the SIL's step generator (sil/step_generator.h, with the
 * jerk the drive's own plan takes, a_max varpi_0), are sampled each period and quantised to M
 * microsteps per full step; the count advances an emulated 16-bit step counter (from
 * SIL_STEPDIR_COUNTER_START, so that it wraps). Every period, as the port does it: pmstep_step() in
 * the control interrupt, then after_step(): pmstep_stepdir_count() (the counter), then
 * pmstep_position_update(), then pmstep_stepdir_diag(), in one call out of line so that the bench
 * counts the whole (the count is inline). Following starts (pmstep_position_follow_steps()) at the
 * period after the position is first tracked; count 0 is where the reference then is.
 *
 * usage (semihosting command line): pil-position MODES_FILE [--duration S] [--stepdir M] [--updates FILE]
 *   MODES_FILE gets one character a period: 'p' position mode (RUN; following the steps in STEP/DIR
 *   mode), 'r' RUN in speed mode, 'a' any other mode; --updates FILE one a period too: 'u' where the
 *   position loop's update ran (every PMSTEP_POSITION_DECIMATION-th period in RUN), '.' elsewhere;
 *   stdout gets the last move's final error (electrical rad), in STEP/DIR mode against the count's
 *   final position, and the periods DIAG was asserted.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pmstep_hal_qemu_mps2.h"
#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_stepdir.h"
#include "pmstep/pmstep_text.h"
#include "sil/inverter.h"
#include "sil/plant.h"
#include "sil/scenario.h"
#include "sil/step_generator.h"
#include "sil/stepdir_run.h" /* SIL_STEPDIR_COUNTER_START */

#define MAX_PERIODS 200000L
#define MOVES 2

/* Out of line (GCC, Clang): one call in main's loop for the bench to count. */
#if defined(__GNUC__)
#define PIL_OUT_OF_LINE __attribute__((noinline))
#else
#define PIL_OUT_OF_LINE
#endif

static pmstep_t motor;
static pmstep_position_t position;
static pmstep_config_t config;
static pmstep_stepdir_t stepdir;
static sil_step_generator_t step_generator;
static char modes[MAX_PERIODS];
static char updates[MAX_PERIODS];

static const double move_time_s[MOVES] = {0.7, 1.6};
static const float move_target_rad[MOVES] = {3.0f, -1.0f};
static const float move_speed_rad_s = 5.0f;
static const float move_accel_rad_s2 = 50.0f;

PIL_OUT_OF_LINE bool after_step(const pmstep_output_t *out, uint32_t counter, pmstep_position_output_t *pos_out);

/* STEP/DIR mode, after the period's step: the counter, the position control, DIAG. */
PIL_OUT_OF_LINE bool after_step(const pmstep_output_t *out, uint32_t counter, pmstep_position_output_t *pos_out)
{
    pmstep_stepdir_count(&stepdir, counter);
    pmstep_position_update(&position, out, pos_out);
    return pmstep_stepdir_diag(&stepdir, out->mode, pos_out->position_rad, pos_out->tracked);
}

/* The step generator's plan of the two moves at @p microsteps, the drive's jerk (a_max varpi_0), and
 * the STEP/DIR input designed for the motor at the counter's start. */
static pmstep_status_t stepdir_setup(sil_scenario_t *sc, uint32_t microsteps)
{
    pmstep_stepdir_config_t sd;
    pmstep_status_t st;
    int n;
    sc->position_moves = MOVES;
    for (n = 0; n < MOVES; ++n) {
        sc->move_time_s[n] = move_time_s[n];
        sc->move_target_rad[n] = (double)move_target_rad[n];
    }
    sc->move_speed_rad_s = (double)move_speed_rad_s;
    sc->move_accel_rad_s2 = (double)move_accel_rad_s2;
    sc->move_jerk_rad_s3 = (double)(move_accel_rad_s2 * config.gains.reference_bandwidth_rad_s);
    sc->stepdir_microsteps = microsteps;
    sil_step_generator_plan(&step_generator, sc);
    st = pmstep_stepdir_design(&config, microsteps, &sd);
    if (st == PMSTEP_OK) {
        st = pmstep_stepdir_init(&stepdir, &sd, config.motor.pole_pairs, config.timing.period_s,
                                 (uint16_t)SIL_STEPDIR_COUNTER_START);
    }
    return st;
}

static int write_chars(const char *path, const char *chars, long n)
{
    FILE *f = fopen(path, "w");
    if (f == NULL || fwrite(chars, 1, (size_t)n, f) != (size_t)n || fclose(f) != 0) {
        fprintf(stderr, "pil-position: cannot write '%s'\n", path);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    static sil_scenario_t sc;
    double duration_s = 3.0;
    const char *modes_path;
    const char *updates_path = NULL;
    bool stepdir_mode = false; /* else the drive's own moves */
    uint32_t microsteps = 0u;
    bool following = false;
    uint32_t counter = SIL_STEPDIR_COUNTER_START;
    int32_t count = 0;
    long diag_periods = 0;
    int i;
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

    for (i = 2; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--duration") == 0) {
            duration_s = strtod(argv[i + 1], NULL);
        } else if (strcmp(argv[i], "--stepdir") == 0) {
            stepdir_mode = true;
            microsteps = (uint32_t)strtoul(argv[i + 1], NULL, 10);
        } else if (strcmp(argv[i], "--updates") == 0) {
            updates_path = argv[i + 1];
        } else {
            break;
        }
    }
    if (argc < 2 || i < argc) {
        fprintf(stderr, "usage: pil-position MODES_FILE [--duration S] [--stepdir M] [--updates FILE]\n");
        return 2;
    }
    modes_path = argv[1];
    sil_scenario_paper(&sc);
    config = sc.controller;
    st = pmstep_init(&motor, &config);
    if (st == PMSTEP_OK) {
        st = pmstep_position_design(&config, &pos_cfg);
    }
    if (st == PMSTEP_OK) {
        st = pmstep_position_init(&position, &motor, &pos_cfg);
    }
    if (st == PMSTEP_OK && stepdir_mode) {
        st = stepdir_setup(&sc, microsteps);
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
        if (stepdir_mode) {
            /* the edges put out by t_k: the counter the port reads after this period's step */
            count =
                sil_step_generator_count(&step_generator, sil_step_generator_sample(&step_generator, t_s).position_rad);
            counter = (uint32_t)(uint16_t)(SIL_STEPDIR_COUNTER_START + (uint32_t)count);
            if (!following && position.out.tracked) {
                following = pmstep_position_follow_steps(&position, &stepdir) == PMSTEP_OK;
            }
        } else if (next_move < MOVES && t_s >= move_time_s[next_move] && position.out.tracked) {
            (void)pmstep_position_move_to(&position, move_target_rad[next_move], move_speed_rad_s, move_accel_rad_s2,
                                          0.0f);
            next_move++;
        }
        meas.i_a_A = (float)plant.x.i_a_A;
        meas.i_b_A = (float)plant.x.i_b_A;
        meas.bus_voltage_V = (float)sil_inverter_bus_voltage(&inv, t_s);
        meas.load_torque_Nm = 0.0f;
        meas.phase_voltage_a_V = (float)inv.applied_a_V; /* the mean voltage of the period just ended */
        meas.phase_voltage_b_V = (float)inv.applied_b_V;
        mps2_pil_control_period(&meas, &out); /* pmstep_step() in the control interrupt */
        if (stepdir_mode) {
            diag_periods += after_step(&out, counter, &pos_out) ? 1 : 0;
        } else {
            pmstep_position_update(&position, &out, &pos_out);
        }
        sil_inverter_apply(&inv, &out, (double)meas.bus_voltage_V);
        sil_drive_advance(&plant, &inv, period_s, sc.substeps);
        if (pos_out.tracked && !origin_set) {
            const double pitch = 2.0 * 3.14159265358979323846 / (double)sc.motor.pole_pairs;
            origin_rad = floor(plant.x.theta_rad / pitch + 0.5) * pitch;
            origin_set = true;
        }
        modes[k] = out.mode != PMSTEP_MODE_RUN ? 'a' : (pos_out.position_mode ? 'p' : 'r');
        updates[k] = '.';
        if (out.mode == PMSTEP_MODE_RUN && position.loop_countdown == PMSTEP_POSITION_DECIMATION) {
            updates[k] = 'u'; /* in RUN only the update sets the countdown to N */
        }
    }
    if (write_chars(modes_path, modes, steps) != 0
        || (updates_path != NULL && write_chars(updates_path, updates, steps) != 0)) {
        return 2;
    }
    if (stepdir_mode) {
        /* the count's final position: count 0 is the reference where following started, at the equilibrium */
        const double target_rad = (double)count * step_generator.rad_per_microstep;
        printf("pil-position: STEP/DIR at %lu microsteps, %ld periods, fault %s, final position %.6f rad (count %ld, "
               "%.6f rad), error %.3g electrical rad, DIAG asserted %ld periods\n",
               (unsigned long)microsteps, steps, pmstep_fault_str(out.fault), plant.x.theta_rad - origin_rad,
               (long)count, target_rad, fabs(plant.x.theta_rad - origin_rad - target_rad) * (double)sc.motor.pole_pairs,
               diag_periods);
    } else {
        const double target_rad = (double)move_target_rad[MOVES - 1];
        printf("pil-position: %ld periods, fault %s, final position %.6f rad (target %.6f), error %.3g "
               "electrical rad\n",
               steps, pmstep_fault_str(out.fault), plant.x.theta_rad - origin_rad, target_rad,
               fabs(plant.x.theta_rad - origin_rad - target_rad) * (double)sc.motor.pole_pairs);
    }
    return out.fault != PMSTEP_FAULT_NONE ? 3 : 0;
}
