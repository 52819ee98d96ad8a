/*
 * STEP/DIR input (pmstep_stepdir.c): settings refused by cause, the counter's wrap and direction,
 * the tracker's poles and its type (no steady error on a ramp or under constant acceleration, the
 * microsteps' staircase smoothed), DIAG in level and pulse mode.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_stepdir.h"
#include "../../firmware/src/pmstep_position_internal.h" /* the tracker's update, run by the position loop */

#define PERIOD_S 50e-6f
#define POLE_PAIRS 50

static pmstep_stepdir_config_t designed(uint32_t microsteps)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    pmstep_stepdir_config_t sd;
    assert_int_equal(pmstep_stepdir_design(&cfg, microsteps, &sd), PMSTEP_OK);
    return sd;
}

static void settings_refused_by_cause(void **state)
{
    pmstep_stepdir_t sd;
    pmstep_stepdir_config_t c = designed(16u);
    const pmstep_config_t cfg = pmstep_paper_config();
    (void)state;
    assert_int_equal(pmstep_stepdir_design(&cfg, 0u, &c), PMSTEP_ERR_STEPDIR_MICROSTEPS);
    assert_int_equal(pmstep_stepdir_design(&cfg, 257u, &c), PMSTEP_ERR_STEPDIR_MICROSTEPS);
    c = designed(16u);
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_OK);
    c.tracking_bandwidth_rad_s = 0.0f;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_ERR_STEPDIR_TRACKING);
    c = designed(16u);
    c.tracking_bandwidth_rad_s = 4.1f / (PMSTEP_POSITION_DECIMATION * PERIOD_S);
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_ERR_STEPDIR_TRACKING);
    c = designed(16u);
    c.following_error_limit_rad = NAN;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_ERR_STEPDIR_LIMIT);
    c = designed(16u);
    c.diag_pulse_periods = 0u;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_ERR_STEPDIR_LIMIT);
    c = designed(16u);
    c.microsteps = 300u;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_ERR_STEPDIR_MICROSTEPS);
    c = designed(16u);
    c.diag_mode = (pmstep_diag_mode_t)2;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_ERR_STEPDIR_DIAG_MODE);
    c = designed(16u);
    assert_true(c.stall_current_A == 0.0f); /* the designer's: off */
    c.stall_current_A = -0.1f;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_ERR_STEPDIR_STALL_CURRENT);
    c.stall_current_A = NAN;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_ERR_STEPDIR_STALL_CURRENT);
}

/* The 16-bit counter wraps; a difference is signed; DIR's sense can be reversed. */
/* The designer's w_t: varpi_0, or the stall detection's speed bound over the microstep where that is lower
 * (a microstep moves the tracker's speed by about q w_t); no bound with the stall detection off. */
static void designer_bounds_the_tracker_by_the_microstep(void **state)
{
    pmstep_config_t cfg = pmstep_paper_config();
    const float w0 = cfg.gains.reference_bandwidth_rad_s;
    uint32_t m;
    pmstep_stepdir_config_t c;
    (void)state;
    assert_true(cfg.detection.stall_speed_error_rad_s > 0.0f);
    for (m = 1u; m <= PMSTEP_STEPDIR_MAX_MICROSTEPS; m *= 2u) {
        const float q = 6.2831853f / (4.0f * (float)cfg.motor.pole_pairs * (float)m);
        const float bound = cfg.detection.stall_speed_error_rad_s / q;
        assert_int_equal(pmstep_stepdir_design(&cfg, m, &c), PMSTEP_OK);
        assert_true(c.tracking_bandwidth_rad_s <= w0);
        assert_true(c.tracking_bandwidth_rad_s * q <= cfg.detection.stall_speed_error_rad_s * 1.0001f);
        assert_true(c.tracking_bandwidth_rad_s >= 0.9999f * (bound < w0 ? bound : w0));
        assert_true(fabsf(c.stop_time_s * c.tracking_bandwidth_rad_s - 8.0f) < 1e-4f); /* 8 / w_t */
    }
    assert_int_equal(pmstep_stepdir_design(&cfg, 1u, &c), PMSTEP_OK);
    assert_true(c.tracking_bandwidth_rad_s < w0); /* one full step per count: the bound acts */
    cfg.detection.stall_speed_error_rad_s = 0.0f; /* the stall detection off: no bound */
    assert_int_equal(pmstep_stepdir_design(&cfg, 1u, &c), PMSTEP_OK);
    assert_true(c.tracking_bandwidth_rad_s == w0);
}

static void counter_wraps_and_direction(void **state)
{
    pmstep_stepdir_t sd;
    pmstep_stepdir_config_t c = designed(16u);
    (void)state;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 65530u), PMSTEP_OK);
    pmstep_stepdir_count(&sd, 5u); /* +11 through the wrap */
    assert_int_equal(sd.steps, 11);
    pmstep_stepdir_count(&sd, 0x10000u + 65000u); /* -541 through the wrap back; the high bits ignored */
    assert_int_equal(sd.steps, 11 - 541);
    c.invert_direction = true;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 100u), PMSTEP_OK);
    pmstep_stepdir_count(&sd, 125u);
    assert_int_equal(sd.steps, -25);
    /* one microstep: 2 pi / (4 p m) */
    assert_true(fabsf(sd.rad_per_microstep - 6.2831853f / (4.0f * 50.0f * 16.0f)) < 1e-9f);
}

/* A move at constant acceleration, then at constant speed, counted in microsteps: after the tracker's
 * transient its position is within a microstep of the commanded and its speed within 1 %: no lag. */
static void tracker_has_no_steady_lag(void **state)
{
    pmstep_stepdir_t sd;
    const pmstep_stepdir_config_t c = designed(16u);
    const pmstep_motion_sample_t rest = {0.0f, 0.0f, 0.0f, 0.0f};
    const double accel = 800.0; /* rad/s^2: 5000 mm/s^2 on a 40 mm belt pulley's turn */
    const double t_accel = 0.05;
    const int periods = 4000;
    double worst_position = 0.0;
    double worst_speed = 0.0;
    int k;
    (void)state;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_OK);
    pmstep_stepdir_start(&sd, &rest);
    for (k = 1; k <= periods; ++k) {
        const double t = (double)k * (double)PERIOD_S;
        const double theta =
            t < t_accel ? 0.5 * accel * t * t : 0.5 * accel * t_accel * t_accel + accel * t_accel * (t - t_accel);
        const double speed = t < t_accel ? accel * t : accel * t_accel;
        pmstep_stepdir_count(&sd, (uint32_t)(int32_t)floor(theta / (double)sd.rad_per_microstep));
        if (k % PMSTEP_POSITION_DECIMATION == 0) {
            pmstep_stepdir_track(&sd);
            /* after 10 tracker time constants into each segment */
            if ((t > 10.0 / (double)c.tracking_bandwidth_rad_s && t < t_accel)
                || t > t_accel + 10.0 / (double)c.tracking_bandwidth_rad_s) {
                worst_position = fmax(worst_position, fabs((double)sd.position_rad - theta));
                worst_speed = fmax(worst_speed, fabs((double)sd.speed_rad_s - speed) / (accel * t_accel));
            }
        }
    }
    print_message("tracker: worst position error %.3g rad (a microstep %.3g), speed %.3g of the cruise\n",
                  worst_position, (double)sd.rad_per_microstep, worst_speed);
    assert_true(worst_position < (double)sd.rad_per_microstep);
    assert_true(worst_speed < 0.01);
    assert_true(sd.moving);
}

/* No step for stop_time_s: at rest exactly on the last count. */
static void at_rest_on_the_last_count(void **state)
{
    pmstep_stepdir_t sd;
    const pmstep_stepdir_config_t c = designed(16u);
    const pmstep_motion_sample_t rest = {0.0f, 0.0f, 0.0f, 0.0f};
    int k;
    (void)state;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_OK);
    pmstep_stepdir_start(&sd, &rest);
    pmstep_stepdir_count(&sd, 37u);
    for (k = 0; k < 2 * (int)sd.stop_updates + 2; ++k) {
        pmstep_stepdir_track(&sd);
    }
    assert_false(sd.moving);
    assert_true(sd.position_rad == 37.0f * sd.rad_per_microstep);
    assert_true(sd.speed_rad_s == 0.0f && sd.accel_rad_s2 == 0.0f);
    pmstep_stepdir_count(&sd, 38u);
    pmstep_stepdir_track(&sd);
    assert_true(sd.moving);
}

static void diag_level_and_pulse(void **state)
{
    pmstep_stepdir_t sd;
    pmstep_stepdir_config_t c = designed(16u);
    const pmstep_motion_sample_t rest = {0.0f, 0.0f, 0.0f, 0.0f};
    const float beyond = 1.5f * c.following_error_limit_rad;
    uint32_t k;
    uint32_t asserted = 0u;
    (void)state;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_OK);
    assert_false(pmstep_stepdir_diag(&sd, PMSTEP_MODE_RUN, 0.0f, true));
    assert_true(pmstep_stepdir_diag(&sd, PMSTEP_MODE_FAULT, 0.0f, false)); /* a fault, even untracked */
    pmstep_stepdir_start(&sd, &rest);
    assert_false(pmstep_stepdir_diag(&sd, PMSTEP_MODE_RUN, 0.5f * c.following_error_limit_rad, true));
    assert_true(pmstep_stepdir_diag(&sd, PMSTEP_MODE_RUN, beyond, true)); /* theta-hat ahead: lost steps */
    assert_true(pmstep_stepdir_diag(&sd, PMSTEP_MODE_RUN, -beyond, true));
    assert_false(pmstep_stepdir_diag(&sd, PMSTEP_MODE_RUN, 0.0f, true)); /* level: released with the cause */
    c.diag_mode = PMSTEP_DIAG_PULSE;
    c.diag_pulse_periods = 20u;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_OK);
    pmstep_stepdir_start(&sd, &rest);
    for (k = 0; k < 100u; ++k) { /* the cause held for 100 periods: one pulse of 20 */
        asserted += pmstep_stepdir_diag(&sd, PMSTEP_MODE_RUN, beyond, true) ? 1u : 0u;
    }
    assert_int_equal(asserted, 20u);
}

/* @p steps counted (microsteps, signed), then one tracker update. */
static void count_and_track(pmstep_stepdir_t *sd, int32_t steps)
{
    pmstep_stepdir_count(sd, (uint32_t)(uint16_t)((int32_t)sd->last_counter + steps));
    pmstep_stepdir_track(sd);
}

/* With a stall current: the following error beyond the limit, or the push beyond the stall current toward
 * the count, is a stall (DIAG); the tracker rests on theta-hat, steps toward the block are dropped, the
 * first step away releases it and is followed from there. Off (0): never a stall. */
static void stall_drops_the_steps_toward_the_block(void **state)
{
    pmstep_stepdir_t sd;
    pmstep_stepdir_config_t c = designed(16u);
    const pmstep_motion_sample_t rest = {0.0f, 0.0f, 0.0f, 0.0f};
    const float limit = c.following_error_limit_rad;
    float microstep;
    (void)state;
    c.stall_current_A = 1.0f;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_OK);
    microstep = sd.rad_per_microstep;
    pmstep_stepdir_start(&sd, &rest);
    /* 60 microsteps toward +, the rotor blocked at 0.01 rad: the error within the limit, the push below */
    count_and_track(&sd, 60);
    assert_true(pmstep_stepdir_following_error(&sd, 0.01f) < limit);
    assert_false(pmstep_stepdir_stall(&sd, 0.01f, 0.5f));
    count_and_track(&sd, 140);
    assert_true(pmstep_stepdir_following_error(&sd, 0.01f) > limit);
    assert_true(pmstep_stepdir_stall(&sd, 0.01f, 0.5f)); /* the following error: a stall */
    assert_true(sd.stalled);
    assert_int_equal(sd.stall_direction, 1);
    assert_float_equal(sd.position_rad, 0.01f, 1e-7f);
    assert_float_equal(sd.speed_rad_s, 0.0f, 0.0f);
    assert_float_equal(pmstep_stepdir_following_error(&sd, 0.01f), 0.0f, 1e-6f);
    assert_true(pmstep_stepdir_diag(&sd, PMSTEP_MODE_RUN, 0.01f, true)); /* level: while stalled */
    /* more steps toward the block: dropped, the tracker stays on the rotor */
    count_and_track(&sd, 16);
    assert_false(pmstep_stepdir_stall(&sd, 0.01f, 0.0f));
    assert_float_equal(sd.position_rad, 0.01f, 1e-7f);
    assert_float_equal(pmstep_stepdir_commanded(&sd), 0.01f, 1e-6f);
    assert_true(sd.stalled);
    /* steps away: released, followed from where the rotor rests */
    count_and_track(&sd, -8);
    assert_false(pmstep_stepdir_stall(&sd, 0.01f, 0.0f));
    assert_false(sd.stalled);
    assert_float_equal(pmstep_stepdir_commanded(&sd), 0.01f - 8.0f * microstep, 1e-6f);
    assert_false(pmstep_stepdir_diag(&sd, PMSTEP_MODE_RUN, 0.01f, true));
    /* the push beyond the stall current toward the count is a stall too, with no following error yet */
    count_and_track(&sd, -4);
    assert_true(pmstep_stepdir_following_error(&sd, 0.01f) < 0.0f); /* the count below the rotor */
    assert_false(pmstep_stepdir_stall(&sd, 0.01f, 1.1f));           /* a push up, away from the count: not a stall */
    count_and_track(&sd, 4);
    assert_true(pmstep_stepdir_following_error(&sd, -0.02f) > 0.0f);
    assert_true(pmstep_stepdir_following_error(&sd, -0.02f) < limit);
    assert_true(pmstep_stepdir_stall(&sd, -0.02f, 1.1f));
    assert_int_equal(sd.stall_direction, 1);
    /* off: the same error and push are not a stall */
    c.stall_current_A = 0.0f;
    assert_int_equal(pmstep_stepdir_init(&sd, &c, POLE_PAIRS, PERIOD_S, 0u), PMSTEP_OK);
    pmstep_stepdir_start(&sd, &rest);
    count_and_track(&sd, 200);
    assert_true(pmstep_stepdir_following_error(&sd, 0.01f) > limit);
    assert_false(pmstep_stepdir_stall(&sd, 0.01f, 5.0f));
    assert_false(sd.stalled);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(settings_refused_by_cause),
        cmocka_unit_test(designer_bounds_the_tracker_by_the_microstep),
        cmocka_unit_test(counter_wraps_and_direction),
        cmocka_unit_test(tracker_has_no_steady_lag),
        cmocka_unit_test(at_rest_on_the_last_count),
        cmocka_unit_test(diag_level_and_pulse),
        cmocka_unit_test(stall_drops_the_steps_toward_the_block),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
