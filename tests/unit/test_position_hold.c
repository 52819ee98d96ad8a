/* The position library's vector hold at the end of a move (pmstep_position_hold.c) against the
 * real modules on a paper-configured instance put in RUN: the aim (the estimate turned by
 * p (theta* - theta-hat), ahead by the load angle of T_L-hat), and the two refusals that leave
 * the position loop holding - a load beyond the vector's pull, a move ending more than 1
 * electrical rad off - until the next move; a re-aim at rest, which turns the kept estimate with
 * the vector; the rest told from motion by w-hat and by the flux integrals' reading (a swing
 * that w-hat misses, one noisy reading); and the T_L-hat a move or a stop from the hold starts
 * with. The rotor is held still by the test (the estimate stays where the test puts it), so the
 * error a move ends with is chosen exactly. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_position.h"
#include "../../firmware/src/pmstep_position_internal.h" /* the hold's stages */
#include "paper_in_run.h"

/* Paper: k_M = 2 N m/A, p = 6; hold current 7.5 A: the vector pulls at most 0.9 k_M I = 13.5 N m. */
#define HOLD_CURRENT_A 7.5f
#define REST_ELECTRICAL_RAD 0.3

typedef struct {
    pmstep_config_t cfg;
    pmstep_t inst;
    pmstep_position_t pos;
    pmstep_position_config_t pos_cfg;
} fixture_t;

static void fixture_in_run(fixture_t *f)
{
    assert_int_equal(paper_instance_in_run(&f->cfg, &f->inst), PMSTEP_OK);
    f->pos_cfg.gain_per_s = 25.0f;
    f->pos_cfg.integral_gain_per_s2 = 0.0f;
    f->pos_cfg.hold_current_A = HOLD_CURRENT_A;
    assert_int_equal(pmstep_position_init(&f->pos, &f->inst, &f->pos_cfg), PMSTEP_OK);
}

/* @p periods of RUN with the rotor and its estimate at rest at @p electrical_rad. */
static void rest_at(fixture_t *f, double electrical_rad, long periods)
{
    pmstep_output_t out = {0};
    pmstep_position_output_t pos_out;
    long n;
    out.mode = PMSTEP_MODE_RUN;
    out.cos_hat = (float)cos(electrical_rad);
    out.sin_hat = (float)sin(electrical_rad);
    for (n = 0; n < periods; ++n) {
        pmstep_position_update(&f->pos, &out, &pos_out);
    }
}

/* A move from the rest angle to @p error_electrical_rad beyond it, the rotor left where it was:
 * the move ends that far off. Runs until the library has aimed or refused (the profile takes
 * 0.1 s, the wait 2/k_theta 0.08 s), at most 1 s. */
static void move_and_stay(fixture_t *f, double error_electrical_rad, float load_hat_Nm)
{
    const float target_rad = (float)((REST_ELECTRICAL_RAD + error_electrical_rad) / 6.0);
    long n;
    f->inst.observer.load_hat_Nm = load_hat_Nm;
    assert_int_equal(pmstep_position_move_to(&f->pos, target_rad, 1.0f, 10.0f, 0.0f), PMSTEP_OK);
    assert_int_equal(f->pos.hold_stage, POSITION_HOLD_NONE);
    for (n = 0; n < 20000 && (f->pos.hold_stage == POSITION_HOLD_NONE || f->pos.hold_stage == POSITION_HOLD_WAITING);
         ++n) {
        rest_at(f, REST_ELECTRICAL_RAD, 1);
    }
    print_message("move ending %.2f electrical rad off, T_L-hat %.1f N m: aimed or refused after %.3f s\n",
                  error_electrical_rad, (double)load_hat_Nm, (double)n * 5e-5);
    assert_true(n < 20000);
}

/* In RUN at the rest angle, then a move ending @p error_electrical_rad off with T_L-hat
 * @p load_hat_Nm: the vector holds, settling. */
static void held_after_move(fixture_t *f, double error_electrical_rad, float load_hat_Nm)
{
    fixture_in_run(f);
    rest_at(f, REST_ELECTRICAL_RAD, 10);
    move_and_stay(f, error_electrical_rad, load_hat_Nm);
    assert_int_equal(f->pos.hold_stage, POSITION_HOLD_SETTLING);
}

static double vector_angle(const fixture_t *f)
{
    return atan2((double)f->inst.hold.sin_vector, (double)f->inst.hold.cos_vector);
}

static void move_end_aims_at_the_target_ahead_by_the_load_angle(void **state)
{
    fixture_t f;
    const double delta = asin(4.8 / (2.0 * (double)HOLD_CURRENT_A));
    (void)state;
    held_after_move(&f, 0.4, 4.8f);
    assert_true(f.inst.hold.active);
    assert_float_equal(f.inst.hold.current_A, HOLD_CURRENT_A, 0.0f);
    /* the target's direction, 0.3 + 0.4 electrical rad, and the load angle ahead of it */
    assert_float_equal(atan2((double)f.pos.rest_sin, (double)f.pos.rest_cos), REST_ELECTRICAL_RAD + 0.4, 2e-5);
    assert_float_equal(vector_angle(&f), REST_ELECTRICAL_RAD + 0.4 + delta, 2e-5);
    print_message("aim at 0.7 electrical rad with T_L-hat 4.8 N m: vector at %.5f (0.7 + load angle %.5f)\n",
                  vector_angle(&f), delta);
}

static void load_beyond_the_vectors_pull_leaves_the_loop_holding(void **state)
{
    fixture_t f;
    (void)state;
    fixture_in_run(&f);
    rest_at(&f, REST_ELECTRICAL_RAD, 10);
    move_and_stay(&f, 0.4, 13.6f); /* 0.9 k_M I = 13.5 N m */
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_REFUSED);
    assert_false(f.inst.hold.active);
    assert_true(f.pos.out.position_mode); /* the position loop holds on the estimate */
    assert_false(f.pos.out.moving);
    assert_float_equal(f.pos.out.position_error_rad, 0.4f / 6.0f, 1e-6f); /* theta* - theta-hat */
    /* the loop drives the speed reference towards the target: k_theta (theta* - theta-hat) */
    assert_float_equal(f.inst.speed_ref.value, 25.0f * 0.4f / 6.0f, 1e-4f);
    /* the same load the other way */
    fixture_in_run(&f);
    rest_at(&f, REST_ELECTRICAL_RAD, 10);
    move_and_stay(&f, 0.4, -13.6f);
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_REFUSED);
    assert_false(f.inst.hold.active);
    /* the next move tries again: within the pull it is held */
    move_and_stay(&f, 0.2, 13.4f);
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_SETTLING);
    assert_true(f.inst.hold.active);
}

static void move_ending_more_than_a_radian_off_is_not_aimed(void **state)
{
    fixture_t f;
    (void)state;
    fixture_in_run(&f);
    rest_at(&f, REST_ELECTRICAL_RAD, 10);
    move_and_stay(&f, 1.05, 0.0f); /* 1 electrical rad is the bound */
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_REFUSED);
    assert_false(f.inst.hold.active);
    assert_true(f.pos.out.position_mode);
    assert_float_equal(f.pos.out.position_error_rad, 1.05f / 6.0f, 1e-6f);
    move_and_stay(&f, -1.05, 0.0f);
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_REFUSED);
    assert_false(f.inst.hold.active);
    move_and_stay(&f, 0.95, 0.0f); /* within the bound: aimed */
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_SETTLING);
    /* the turn's Taylor polynomials (pmstep_rotation.h) err by below 0.95^6/720 + 0.95^7/5040 */
    assert_float_equal(atan2((double)f.pos.rest_sin, (double)f.pos.rest_cos), REST_ELECTRICAL_RAD + 0.95,
                       pow(0.95, 6) / 720.0 + pow(0.95, 7) / 5040.0);
}

/* The core's angle estimate for its last sampled currents (what pmstep_set_angle_estimate put). */
static double core_estimate(const fixture_t *f)
{
    float c;
    float s;
    pmstep_angle_estimate(&f->inst.angle, &f->inst.derived.angle_coeffs, f->inst.angle.i_a_prev_A,
                          f->inst.angle.i_b_prev_A, &c, &s);
    return atan2((double)s, (double)c);
}

/* @p periods of RUN with the estimate the core has (the rotor where the hold's estimate says). */
static void rest_on_core_estimate(fixture_t *f, long periods)
{
    long n;
    for (n = 0; n < periods; ++n) {
        rest_at(f, core_estimate(f), 1);
    }
}

/* A re-aim: the rotor rests 0.4 electrical rad short of the target, the vector is turned by 0.4,
 * and the kept estimate with it, through the settling (the flux integrals' own reading, here
 * left at the old rest, is not taken again); at rest on the kept estimate nothing more moves. */
static void re_aim_turns_the_kept_estimate_with_the_vector(void **state)
{
    fixture_t f;
    long n;
    (void)state;
    held_after_move(&f, 0.4, 0.0f);
    assert_float_equal(vector_angle(&f), REST_ELECTRICAL_RAD + 0.4, 2e-5);
    for (n = 0; n < 20000 && f.pos.hold_stage != POSITION_HOLD_REAIMED; ++n) {
        rest_at(&f, REST_ELECTRICAL_RAD, 1); /* the estimate says the rotor stayed at 0.3 */
    }
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_REAIMED);
    print_message("re-aim after %.4f s at rest 0.4 electrical rad short\n", (double)n * 5e-5);
    assert_float_equal(vector_angle(&f), REST_ELECTRICAL_RAD + 0.8, 1e-4);
    rest_at(&f, REST_ELECTRICAL_RAD, PMSTEP_POSITION_DECIMATION); /* the next update puts the estimate */
    assert_float_equal(core_estimate(&f), REST_ELECTRICAL_RAD + 0.4, 1e-4);
    for (n = 0; n < 20000 && f.pos.hold_stage == POSITION_HOLD_REAIMED; ++n) {
        rest_at(&f, REST_ELECTRICAL_RAD, 1); /* the integrals unmoved: the estimate is still put */
    }
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_ANCHORED);
    assert_float_equal(core_estimate(&f), REST_ELECTRICAL_RAD + 0.4, 1e-4);
    rest_on_core_estimate(&f, 4 * (long)f.inst.hold.settle_periods + 2000); /* beyond a re-aim's 200 periods */
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_ANCHORED);
    assert_float_equal(vector_angle(&f), REST_ELECTRICAL_RAD + 0.8, 1e-4);
    assert_float_equal(core_estimate(&f), REST_ELECTRICAL_RAD + 0.4, 1e-4);
}

/* A load step swings the held rotor at the hold's natural frequency, which w-hat does not follow
 * (here it stays 0): the flux integrals' reading turning by more than
 * POSITION_READING_MOTION_BANDS quiet bands' turn an update (p w_band N T_s a band) is not rest.
 * Nothing is re-aimed during the swing, though the rotor is far from the target for longer than
 * the re-aim's 200 periods; once it rests displaced, the vector is turned by the displacement,
 * and the kept estimate with it. */
static void swing_that_w_hat_misses_is_not_rest(void **state)
{
    fixture_t f;
    double turn_limit_rad;
    double reading_rad = REST_ELECTRICAL_RAD;
    long n;
    (void)state;
    held_after_move(&f, 0.0, 0.0f);
    turn_limit_rad = POSITION_READING_MOTION_BANDS * (double)f.inst.hold.quiet_band_rad_s * PMSTEP_POSITION_DECIMATION
                     * (double)f.cfg.timing.period_s * (double)f.cfg.motor.pole_pairs;
    rest_at(&f, REST_ELECTRICAL_RAD, 4 * (long)f.inst.hold.settle_periods + 2000); /* anchored, estimate kept */
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_ANCHORED);
    /* the rotor swings 0.3 electrical rad off at twice the limit an update, and half back */
    for (n = 0; reading_rad > REST_ELECTRICAL_RAD - 0.3; ++n) {
        reading_rad -= 2.0 * turn_limit_rad / PMSTEP_POSITION_DECIMATION;
        rest_at(&f, reading_rad, 1);
        assert_int_equal(f.pos.hold_stage, POSITION_HOLD_ANCHORED);
    }
    for (; reading_rad < REST_ELECTRICAL_RAD - 0.15; ++n) {
        reading_rad += 2.0 * turn_limit_rad / PMSTEP_POSITION_DECIMATION;
        rest_at(&f, reading_rad, 1);
        assert_int_equal(f.pos.hold_stage, POSITION_HOLD_ANCHORED);
    }
    print_message("swing of %ld periods at %.4f electrical rad an update (limit %.4f): no re-aim\n", n,
                  2.0 * turn_limit_rad, turn_limit_rad);
    assert_true(n > 200);
    assert_float_equal(vector_angle(&f), REST_ELECTRICAL_RAD, 1e-4);
    /* at rest 0.15 short: the re-aim turns the vector and the kept estimate by it */
    for (n = 0; n < 20000 && f.pos.hold_stage != POSITION_HOLD_REAIMED; ++n) {
        rest_at(&f, reading_rad, 1);
    }
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_REAIMED);
    assert_float_equal(vector_angle(&f), REST_ELECTRICAL_RAD + (REST_ELECTRICAL_RAD - reading_rad), 1e-4);
    assert_float_equal(atan2((double)f.pos.frozen_sin, (double)f.pos.frozen_cos), REST_ELECTRICAL_RAD, 1e-4);
}

/* One update's reading turned beyond the limit (a swing's first, or noise at its rarest) is
 * neither rest nor motion: the rest count and the kept estimate go on; two running are motion. */
static void one_turned_reading_is_not_motion(void **state)
{
    fixture_t f;
    double turn_limit_rad;
    int32_t periods_before;
    long n;
    (void)state;
    held_after_move(&f, 0.0, 0.0f);
    turn_limit_rad = POSITION_READING_MOTION_BANDS * (double)f.inst.hold.quiet_band_rad_s * PMSTEP_POSITION_DECIMATION
                     * (double)f.cfg.timing.period_s * (double)f.cfg.motor.pole_pairs;
    rest_at(&f, REST_ELECTRICAL_RAD, 4 * (long)f.inst.hold.settle_periods); /* anchored, estimate kept */
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_ANCHORED);
    periods_before = f.pos.hold_periods;
    assert_true(periods_before > (int32_t)f.inst.hold.settle_periods);
    for (n = 0; n < 10; ++n) {
        /* one update's reading 3 limits off, then back at rest */
        rest_at(&f, REST_ELECTRICAL_RAD + 3.0 * turn_limit_rad, PMSTEP_POSITION_DECIMATION);
        assert_true(f.pos.reading_turned);
        rest_at(&f, REST_ELECTRICAL_RAD, PMSTEP_POSITION_DECIMATION);
        assert_false(f.pos.reading_turned);
    }
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_ANCHORED);
    assert_int_equal(f.pos.hold_periods, periods_before + 10 * PMSTEP_POSITION_DECIMATION);
    assert_float_equal(atan2((double)f.pos.frozen_sin, (double)f.pos.frozen_cos), REST_ELECTRICAL_RAD, 1e-5);
    /* two running: motion, the count starts again from the reading */
    rest_at(&f, REST_ELECTRICAL_RAD + 3.0 * turn_limit_rad, 2 * PMSTEP_POSITION_DECIMATION);
    assert_int_equal(f.pos.hold_periods, 0);
    assert_float_equal(atan2((double)f.pos.frozen_sin, (double)f.pos.frozen_cos),
                       REST_ELECTRICAL_RAD + 3.0 * turn_limit_rad, 1e-5);
}

/* Held, the observer balances the vector's torque at the estimated angle: an angle error puts
 * part of the hold current into T_L-hat. A move from the hold gives the law the aim's T_L-hat
 * back; a move from a refused hold (no vector) leaves T_L-hat as the observer has it. */
static void move_from_the_hold_starts_from_the_aims_load(void **state)
{
    fixture_t f;
    (void)state;
    held_after_move(&f, 0.4, 4.8f);
    assert_float_equal(f.pos.aim_load_Nm, 4.8f, 0.0f);
    f.inst.observer.load_hat_Nm = 6.3f; /* 2 N m/A x 7.5 A x sin(0.1): an estimate 0.1 rad off */
    assert_int_equal(pmstep_position_move_to(&f.pos, 0.0f, 1.0f, 10.0f, 0.0f), PMSTEP_OK);
    assert_false(f.inst.hold.active);
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_NONE);
    assert_float_equal(f.inst.observer.load_hat_Nm, 4.8f, 0.0f);
    /* the same from a stop (pmstep_position_hold) once held again */
    move_and_stay(&f, 0.2, 3.0f);
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_SETTLING);
    f.inst.observer.load_hat_Nm = 1.5f;
    assert_int_equal(pmstep_position_hold(&f.pos, 10.0f), PMSTEP_OK);
    assert_float_equal(f.inst.observer.load_hat_Nm, 3.0f, 0.0f);
    /* refused (beyond the pull): no vector held, T_L-hat is the observer's own */
    fixture_in_run(&f);
    rest_at(&f, REST_ELECTRICAL_RAD, 10);
    move_and_stay(&f, 0.4, 13.6f);
    assert_int_equal(f.pos.hold_stage, POSITION_HOLD_REFUSED);
    f.inst.observer.load_hat_Nm = 12.0f;
    assert_int_equal(pmstep_position_move_to(&f.pos, 0.0f, 1.0f, 10.0f, 0.0f), PMSTEP_OK);
    assert_float_equal(f.inst.observer.load_hat_Nm, 12.0f, 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(move_end_aims_at_the_target_ahead_by_the_load_angle),
        cmocka_unit_test(load_beyond_the_vectors_pull_leaves_the_loop_holding),
        cmocka_unit_test(move_ending_more_than_a_radian_off_is_not_aimed),
        cmocka_unit_test(move_from_the_hold_starts_from_the_aims_load),
        cmocka_unit_test(re_aim_turns_the_kept_estimate_with_the_vector),
        cmocka_unit_test(swing_that_w_hat_misses_is_not_rest),
        cmocka_unit_test(one_turned_reading_is_not_motion),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
