/*
 * Homing without a switch (pmstep_homing.c): settings refused by cause, the designer's rule, and the
 * homing run against a kinematic rotor that follows the speed reference exactly until a stop holds it:
 * found by the following error or by the q current once cruising, the zero at the stop, the back-off;
 * not found within the travel; aborted when RUN ends.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_homing.h"
#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_ref.h"
#include "pmstep/pmstep_stepdir.h"

#define PAPER_P 6.0

typedef struct {
    pmstep_config_t cfg;
    pmstep_t inst;
    pmstep_position_t pos;
    pmstep_homing_t homing;
    pmstep_homing_config_t homing_cfg;
    double theta_rad; /* the kinematic rotor, mechanical */
    double stop_rad;  /* it cannot pass this (+ side); HUGE_VAL: no stop */
    float i_q_ref_A;  /* the law's i_q* the homing reads */
    bool in_run;
} fixture_t;

static pmstep_output_t run_output(const fixture_t *f, double speed_rad_s)
{
    pmstep_output_t out = {0};
    out.mode = f->in_run ? PMSTEP_MODE_RUN : PMSTEP_MODE_FAULT;
    out.cos_hat = (float)cos(PAPER_P * f->theta_rad);
    out.sin_hat = (float)sin(PAPER_P * f->theta_rad);
    out.speed_hat_rad_s = (float)speed_rad_s;
    out.i_q_ref_A = f->i_q_ref_A;
    return out;
}

static void fixture_init(fixture_t *f)
{
    pmstep_position_config_t pos_cfg;
    pmstep_position_output_t pos_out;
    pmstep_output_t out;
    f->cfg = pmstep_paper_config();
    assert_int_equal(pmstep_init(&f->inst, &f->cfg), PMSTEP_OK);
    pos_cfg.gain_per_s = 25.0f;
    pos_cfg.integral_gain_per_s2 = 0.0f;
    pos_cfg.hold_current_A = 0.0f; /* the loop holds */
    assert_int_equal(pmstep_position_init(&f->pos, &f->inst, &pos_cfg), PMSTEP_OK);
    assert_int_equal(pmstep_homing_design(&f->cfg, &f->homing_cfg), PMSTEP_OK);
    f->theta_rad = 0.0;
    f->stop_rad = HUGE_VAL;
    f->i_q_ref_A = 0.0f;
    f->in_run = true;
    f->homing.state = PMSTEP_HOMING_IDLE;
    out = run_output(f, 0.0);
    pmstep_position_update(&f->pos, &out, &pos_out); /* RUN's first period: tracked at 0 */
}

/* @p periods of the kinematic rotor (w = w* of the core's reference channel, stopped at the stop) with the
 * homing's update after each; returns the last state. */
static pmstep_homing_state_t run(fixture_t *f, long periods)
{
    const double period = (double)f->cfg.timing.period_s;
    pmstep_homing_state_t state = f->homing.state;
    long n;
    for (n = 0; n < periods; ++n) {
        const pmstep_ref_out_t ref = pmstep_ref_output(&f->inst.derived.ref_coeffs, &f->inst.speed_ref);
        double speed = (double)ref.value;
        pmstep_output_t out;
        pmstep_position_output_t pos_out;
        f->theta_rad += period * speed;
        if (f->theta_rad >= f->stop_rad) {
            f->theta_rad = f->stop_rad;
            speed = 0.0;
        }
        pmstep_ref_advance(&f->inst.derived.ref_coeffs, &f->inst.speed_ref, f->cfg.timing.period_s);
        out = run_output(f, speed);
        pmstep_position_update(&f->pos, &out, &pos_out);
        state = pmstep_homing_update(&f->homing, &f->pos, &out, &pos_out);
    }
    return state;
}

static void designer_rule_from_the_motor_data(void **state)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    pmstep_homing_config_t h;
    const double full_step = 0.5 * M_PI / PAPER_P;
    const double k_m = (double)cfg.motor.torque_constant_Nm_A;
    const double stall = 0.5 * (double)cfg.motor.rated_current_A;
    const double push_speed =
        0.25 * k_m * stall / ((double)cfg.motor.inertia_kgm2 * (double)cfg.gains.speed_gain_per_s);
    const double bus_speed = 0.1 * (double)cfg.limits.min_bus_voltage_V / k_m;
    (void)state;
    assert_int_equal(pmstep_homing_design(NULL, &h), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_homing_design(&cfg, NULL), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_homing_design(&cfg, &h), PMSTEP_OK);
    assert_float_equal(h.stall_current_A, stall, 1e-6);
    assert_float_equal(h.speed_rad_s, fmin(push_speed, bus_speed), 1e-5 * fmin(push_speed, bus_speed));
    assert_float_equal(h.accel_rad_s2, 0.25 * k_m * stall / (double)cfg.motor.inertia_kgm2, 1e-3);
    assert_float_equal(h.stall_error_rad, 0.5 * full_step, 1e-7);
    assert_float_equal(h.back_off_rad, full_step, 1e-7);
    assert_float_equal(h.max_travel_rad, 2.0 * M_PI, 1e-6);
    assert_true(h.stall_current_A < cfg.limits.max_phase_current_A);
    {
        /* a trip below the rated current: half the trip, still below it */
        pmstep_config_t low_trip = cfg;
        low_trip.limits.max_phase_current_A = 0.6f * cfg.motor.rated_current_A;
        assert_int_equal(pmstep_homing_design(&low_trip, &h), PMSTEP_OK);
        assert_float_equal(h.stall_current_A, 0.5 * (double)low_trip.limits.max_phase_current_A, 1e-6);
    }
}

static void settings_refused_by_cause(void **state)
{
    fixture_t f;
    pmstep_homing_config_t c;
    (void)state;
    fixture_init(&f);
    c = f.homing_cfg;
    assert_int_equal(pmstep_homing_start(NULL, &f.pos, &c, 1), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_homing_start(&f.homing, NULL, &c, 1), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, NULL, 1), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 0), PMSTEP_ERR_HOMING);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 2), PMSTEP_ERR_HOMING);
    c.speed_rad_s = NAN;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_NONFINITE_PARAMETER);
    c = f.homing_cfg;
    c.back_off_rad = INFINITY;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_NONFINITE_PARAMETER);
    c = f.homing_cfg;
    c.speed_rad_s = 0.0f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_HOMING);
    c = f.homing_cfg;
    c.accel_rad_s2 = -1.0f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_HOMING);
    c = f.homing_cfg;
    c.max_travel_rad = 0.0f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_HOMING);
    c = f.homing_cfg;
    c.stall_error_rad = 0.0f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_HOMING);
    c = f.homing_cfg;
    c.back_off_rad = -1e-3f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_HOMING);
    c = f.homing_cfg;
    c.stall_current_A = 0.0f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_HOMING);
    c.stall_current_A = f.cfg.limits.max_phase_current_A; /* must stay below the trip */
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_HOMING);
    /* a travel beyond the position estimate's range (p |theta| above PMSTEP_POSITION_MAX_ELECTRICAL_RAD) */
    c = f.homing_cfg;
    c.max_travel_rad = 6000.0f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &c, 1), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(f.homing.state, PMSTEP_HOMING_IDLE); /* nothing refused started */
    f.in_run = false;
    (void)run(&f, 1);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_ERR_BAD_MODE);
}

/* The STEP/DIR input's stall current must stay below the trip, where a stall can be found. */
static void stepdir_stall_current_below_the_trip(void **state)
{
    fixture_t f;
    pmstep_stepdir_t sd;
    pmstep_stepdir_config_t c;
    (void)state;
    fixture_init(&f);
    assert_int_equal(pmstep_stepdir_design(&f.cfg, 16u, &c), PMSTEP_OK);
    c.stall_current_A = f.cfg.limits.max_phase_current_A;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, f.cfg.motor.pole_pairs, f.cfg.timing.period_s, 0u), PMSTEP_OK);
    assert_int_equal(pmstep_position_follow_steps(&f.pos, &sd), PMSTEP_ERR_STEPDIR_STALL_CURRENT);
    assert_false(f.pos.out.position_mode);
    c.stall_current_A = f.homing_cfg.stall_current_A;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, f.cfg.motor.pole_pairs, f.cfg.timing.period_s, 0u), PMSTEP_OK);
    assert_int_equal(pmstep_position_follow_steps(&f.pos, &sd), PMSTEP_OK);
}

/* The rotor meets a stop at 0.3 rad: found by the following error, the zero put there, one full step back. */
static void finds_the_stop_by_the_following_error_and_backs_off(void **state)
{
    fixture_t f;
    float position;
    const double full_step = 0.5 * M_PI / PAPER_P;
    (void)state;
    fixture_init(&f);
    f.stop_rad = 0.3;
    f.homing_cfg.speed_rad_s = 0.5f;
    f.homing_cfg.accel_rad_s2 = 5.0f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_OK);
    assert_int_equal(f.homing.state, PMSTEP_HOMING_SEEKING);
    assert_int_equal(run(&f, 40000), PMSTEP_HOMING_DONE); /* 0.7 s to the stop at 0.5 rad/s; 2 s */
    assert_false(f.homing.stalled_by_current);
    assert_float_equal(f.homing.stop_rad, 0.3, 1e-4); /* the kinematic rotor sits exactly at the stop */
    /* the zero at the stop: the rotor one full step back from it, and the drive says so */
    assert_float_equal(f.theta_rad, 0.3 - full_step, 1e-3);
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
    assert_float_equal(position, -full_step, 1e-3);
    assert_true(f.pos.out.position_mode);
    assert_false(f.pos.out.moving);
    assert_int_equal(run(&f, 10), PMSTEP_HOMING_DONE); /* stays done */
}

/* No stop, the law's i_q* above the stall current: not taken for a stop while the profile accelerates,
 * found by the current as soon as the reference cruises. */
static void finds_the_stop_by_the_current_once_cruising(void **state)
{
    fixture_t f;
    (void)state;
    fixture_init(&f);
    f.homing_cfg.speed_rad_s = 1.0f;
    f.homing_cfg.accel_rad_s2 = 5.0f; /* 0.2 s of acceleration, and the jerk's rounding */
    f.homing_cfg.back_off_rad = 0.0f;
    f.i_q_ref_A = 1.1f * f.homing_cfg.stall_current_A;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_OK);
    assert_int_equal(run(&f, 3000), PMSTEP_HOMING_SEEKING); /* 0.15 s: accelerating */
    assert_int_equal(run(&f, 10000), PMSTEP_HOMING_DONE);   /* held where found: no back-off */
    assert_true(f.homing.stalled_by_current);
    assert_true(f.homing.stop_rad > 0.1f); /* after the acceleration's 0.1 rad */
    /* the opposite sign of i_q* pushes away from the stop: not a stall */
    fixture_init(&f);
    f.homing_cfg.speed_rad_s = 1.0f;
    f.homing_cfg.accel_rad_s2 = 5.0f;
    f.homing_cfg.max_travel_rad = 0.5f;
    f.i_q_ref_A = -1.1f * f.homing_cfg.stall_current_A;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_OK);
    assert_int_equal(run(&f, 40000), PMSTEP_HOMING_NOT_FOUND);
}

/* No stop within the travel: not found, stopped at the travel's end and holding there. */
static void not_found_within_the_travel(void **state)
{
    fixture_t f;
    float position;
    (void)state;
    fixture_init(&f);
    f.homing_cfg.speed_rad_s = 1.0f;
    f.homing_cfg.accel_rad_s2 = 10.0f;
    f.homing_cfg.max_travel_rad = 0.8f;
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, -1), PMSTEP_OK);
    assert_int_equal(run(&f, 40000), PMSTEP_HOMING_NOT_FOUND);
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
    assert_float_equal(position, -0.8f, 1e-3f);
    assert_float_equal(f.theta_rad, -0.8, 1e-3);
    assert_int_equal(run(&f, 10), PMSTEP_HOMING_NOT_FOUND);
}

/* Leaving RUN (a fault) or a speed command while seeking: aborted. */
static void aborted_when_run_ends_or_a_command_takes_over(void **state)
{
    fixture_t f;
    (void)state;
    fixture_init(&f);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_OK);
    assert_int_equal(run(&f, 100), PMSTEP_HOMING_SEEKING);
    f.in_run = false;
    assert_int_equal(run(&f, 1), PMSTEP_HOMING_ABORTED);
    fixture_init(&f);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_OK);
    assert_int_equal(run(&f, 100), PMSTEP_HOMING_SEEKING);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 1.0f), PMSTEP_OK);
    assert_int_equal(run(&f, 2 * PMSTEP_POSITION_DECIMATION), PMSTEP_HOMING_ABORTED);
    /* a move, a stop or a new zero given while it seeks: aborted, never taken for the stop */
    fixture_init(&f);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_OK);
    assert_int_equal(run(&f, 100), PMSTEP_HOMING_SEEKING);
    assert_int_equal(pmstep_position_move_to(&f.pos, -0.5f, 1.0f, 10.0f, 0.0f), PMSTEP_OK);
    assert_int_equal(run(&f, 1), PMSTEP_HOMING_ABORTED);
    fixture_init(&f);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_OK);
    assert_int_equal(pmstep_position_hold(&f.pos, 10.0f), PMSTEP_OK);
    assert_int_equal(run(&f, 1), PMSTEP_HOMING_ABORTED);
    fixture_init(&f);
    assert_int_equal(pmstep_homing_start(&f.homing, &f.pos, &f.homing_cfg, 1), PMSTEP_OK);
    assert_int_equal(run(&f, 100), PMSTEP_HOMING_SEEKING);
    assert_int_equal(pmstep_position_set_zero(&f.pos), PMSTEP_OK);
    assert_int_equal(run(&f, 1), PMSTEP_HOMING_ABORTED);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(designer_rule_from_the_motor_data),
        cmocka_unit_test(settings_refused_by_cause),
        cmocka_unit_test(stepdir_stall_current_below_the_trip),
        cmocka_unit_test(finds_the_stop_by_the_following_error_and_backs_off),
        cmocka_unit_test(finds_the_stop_by_the_current_once_cruising),
        cmocka_unit_test(not_found_within_the_travel),
        cmocka_unit_test(aborted_when_run_ends_or_a_command_takes_over),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
