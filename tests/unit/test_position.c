/* Position estimate (turn count + polynomial atan2), its API, and the position loop's
 * reference, against the real module (pmstep_position) on a paper-configured instance. The
 * estimate is driven with synthetic outputs of pmstep_step() (RUN, (c-hat, s-hat) of a known
 * angle) through pmstep_position_update(). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_position.h"

static const double two_pi = 6.283185307179586;

/* ---- polynomial atan2 ---- */

static void atan2_poly_accuracy_on_a_dense_circle_and_scales(void **state)
{
    double worst = 0.0;
    long n;
    (void)state;
    for (n = 0; n < 1000000; ++n) {
        const double angle = -M_PI + two_pi * ((double)n + 0.5) / 1000000.0;
        const double scale = 0.2 + 1.8 * (double)(n % 7) / 6.0; /* the estimate is not unit length */
        const float y = (float)(scale * sin(angle));
        const float x = (float)(scale * cos(angle));
        double err = (double)pmstep_atan2_poly(y, x) - atan2((double)y, (double)x);
        worst = fmax(worst, fabs(err));
    }
    print_message("atan2 polynomial: max |error| = %.3g rad over 1e6 angles\n", worst);
    assert_true(worst < 1.2e-5);
}

static void atan2_poly_axes_and_origin(void **state)
{
    (void)state;
    assert_float_equal(pmstep_atan2_poly(0.0f, 1.0f), 0.0f, 0.0f);
    assert_float_equal(pmstep_atan2_poly(1.0f, 0.0f), 1.5707963f, 2e-6f);
    assert_float_equal(pmstep_atan2_poly(-1.0f, 0.0f), -1.5707963f, 2e-6f);
    assert_float_equal(pmstep_atan2_poly(0.0f, -1.0f), 3.1415927f, 2e-6f); /* pi, not -pi */
    assert_float_equal(pmstep_atan2_poly(0.0f, 0.0f), 0.0f, 0.0f);
    assert_float_equal(pmstep_atan2_poly(1.0f, 1.0f), 0.7853982f, 1.2e-5f);
}

/* ---- the estimate through pmstep_position_update ---- */

typedef struct {
    pmstep_config_t cfg;
    pmstep_t inst;
    pmstep_position_t pos;
    pmstep_position_config_t pos_cfg;
    unsigned long updates; /* periods of sweep() that updated the output */
} fixture_t;

static void fixture_init(fixture_t *f)
{
    f->cfg = pmstep_paper_config();
    assert_int_equal(pmstep_init(&f->inst, &f->cfg), PMSTEP_OK);
    f->pos_cfg.gain_per_s = 25.0f;
    f->pos_cfg.integral_gain_per_s2 = 0.0f;
    f->pos_cfg.hold_current_A = 0.0f; /* the loop holds (the vector hold: closed_loop.position) */
    assert_int_equal(pmstep_position_init(&f->pos, &f->inst, &f->pos_cfg), PMSTEP_OK);
    f->updates = 0u;
}

/* A RUN output with the estimate at electrical angle @p angle (radius @p radius). */
static pmstep_output_t run_output(double angle, double radius, double speed_rad_s)
{
    pmstep_output_t out = {0};
    out.mode = PMSTEP_MODE_RUN;
    out.cos_hat = (float)(radius * cos(angle));
    out.sin_hat = (float)(radius * sin(angle));
    out.speed_hat_rad_s = (float)speed_rad_s;
    return out;
}

static void not_tracked_before_run(void **state)
{
    fixture_t f;
    pmstep_output_t out = {0};
    pmstep_position_output_t pos_out;
    float position;
    (void)state;
    fixture_init(&f);
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_ERR_BAD_MODE);
    assert_int_equal(pmstep_position_reference(&f.pos, &position), PMSTEP_ERR_BAD_MODE);
    assert_int_equal(pmstep_position_reference(NULL, &position), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_position_reference(&f.pos, NULL), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_position_set_zero(&f.pos), PMSTEP_ERR_BAD_MODE);
    assert_int_equal(pmstep_position_move_to(&f.pos, 1.0f, 1.0f, 1.0f, 0.0f), PMSTEP_ERR_BAD_MODE);
    assert_int_equal(pmstep_position_hold(&f.pos, 1.0f), PMSTEP_ERR_BAD_MODE);
    out.mode = PMSTEP_MODE_C_ALIGN;
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_false(pos_out.tracked);
    assert_float_equal(pos_out.position_rad, 0.0f, 0.0f);
    assert_int_equal(pmstep_get_position(NULL, &position), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_get_position(&f.pos, NULL), PMSTEP_ERR_NULL_ARGUMENT);
}

/* The electrical angle swept along @p path (piecewise linear, rad), @p steps_per_rad samples a
 * radian, with noise of amplitude @p wobble on the angle and 0.9..1.1 radius: the estimate must
 * follow angle/p within the atan2's error at every sample. */
static double sweep(fixture_t *f, const double *path, int points, double steps_per_rad, double wobble)
{
    double worst = 0.0;
    int seg;
    unsigned long k = 0;
    for (seg = 0; seg + 1 < points; ++seg) {
        const double span = path[seg + 1] - path[seg];
        const long steps = (long)(fabs(span) * steps_per_rad) + 1;
        long n;
        for (n = 1; n <= steps; ++n, ++k) {
            const double angle = path[seg] + span * (double)n / (double)steps;
            const double noise = wobble * sin(1.7 * (double)k) * sin(0.31 * (double)k);
            const double radius = 1.0 + 0.1 * sin(0.05 * (double)k);
            const pmstep_output_t out = run_output(angle + noise, radius, 0.0);
            pmstep_position_output_t pos_out;
            float now;
            pmstep_position_update(&f->pos, &out, &pos_out);
            assert_true(pos_out.tracked);
            assert_int_equal(pmstep_get_position(&f->pos, &now), PMSTEP_OK); /* the present period's */
            worst = fmax(worst, fabs((double)now - (angle + noise) / 6.0));
            /* the output's estimate is the last update's: every PMSTEP_POSITION_DECIMATION periods */
            if (f->pos.loop_countdown == PMSTEP_POSITION_DECIMATION) {
                assert_float_equal(pos_out.position_rad, now, 0.0f);
                f->updates++;
            }
        }
    }
    return worst;
}

static void turn_count_follows_many_turns_both_ways(void **state)
{
    fixture_t f;
    /* 0 -> +200 turns -> -150 turns -> +3.3 rad, fast (0.3 rad a period) and slowly. */
    const double path[] = {0.0, 200.0 * 6.283185307179586, -150.0 * 6.283185307179586, 3.3};
    double worst_fast;
    double worst_slow;
    float position;
    (void)state;
    fixture_init(&f);
    worst_fast = sweep(&f, path, 4, 1.0 / 0.3, 0.0);
    assert_true(f.updates > 1000u); /* the output's contract was checked */
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
    assert_float_equal(position, 3.3f / 6.0f, 1e-4f);
    fixture_init(&f);
    worst_slow = sweep(&f, path, 4, 1000.0, 0.02); /* slow, with a noisy estimate crossing +-pi back and forth */
    print_message("position estimate over 350 electrical turns: max error %.3g rad (fast), %.3g rad (slow, noisy)\n",
                  worst_fast, worst_slow);
    /* float32 resolution: one ulp of the electrical angle at 200 turns (1257 rad) is 1.2e-4 rad, 2e-5 rad
     * mechanical; the roundings of the sum, of 1/p and of the result, and the atan2's 1.2e-5/6 stay below
     * 3e-5 rad (no error growing with the turns: 2 pi n is formed exactly). */
    assert_true(worst_fast < 3e-5);
    assert_true(worst_slow < 3e-5);
}

static void position_zero_moves_the_origin(void **state)
{
    fixture_t f;
    const double path[] = {0.0, 10.0 * 6.283185307179586 + 1.0};
    const double on[] = {10.0 * 6.283185307179586 + 1.0, 10.0 * 6.283185307179586 + 1.0 - 2.5 * 6.283185307179586};
    float position;
    (void)state;
    fixture_init(&f);
    (void)sweep(&f, path, 2, 10.0, 0.0);
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
    assert_float_equal(position, (float)((10.0 * two_pi + 1.0) / 6.0), 1e-4f);
    assert_int_equal(pmstep_position_set_zero(&f.pos), PMSTEP_OK);
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
    assert_float_equal(position, 0.0f, 1e-6f);
    {
        pmstep_position_output_t pos_out;
        int n;
        for (n = 1; n <= 100; ++n) { /* 2.5 turns back */
            const pmstep_output_t out = run_output(on[0] + (on[1] - on[0]) * n / 100.0, 1.0, 0.0);
            pmstep_position_update(&f.pos, &out, &pos_out);
        }
        assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
        assert_float_equal(position, (float)(-2.5 * two_pi / 6.0), 1e-4f);
    }
}

static void leaving_run_loses_the_position_and_run_restarts_at_zero(void **state)
{
    fixture_t f;
    const double path[] = {0.0, 7.0};
    pmstep_output_t out = {0};
    pmstep_position_output_t pos_out;
    float position;
    (void)state;
    fixture_init(&f);
    (void)sweep(&f, path, 2, 10.0, 0.0);
    out.mode = PMSTEP_MODE_S_ALIGN; /* a re-alignment */
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_false(pos_out.tracked);
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_ERR_BAD_MODE);
    out = run_output(0.0, 1.0, 0.0);
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_true(pos_out.tracked);
    assert_float_equal(pos_out.position_rad, 0.0f, 0.0f);
}

/* ---- position loop ---- */

static void init_validates_the_gains_with_named_codes(void **state)
{
    fixture_t f;
    pmstep_position_config_t c;
    pmstep_t fresh = {0};
    (void)state;
    fixture_init(&f); /* paper: k_w = 100 1/s */
    c.gain_per_s = 25.0f;
    c.integral_gain_per_s2 = 0.0f;
    c.hold_current_A = 0.0f;
    assert_int_equal(pmstep_position_init(NULL, &f.inst, &c), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_position_init(&f.pos, NULL, &c), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, NULL), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_position_init(&f.pos, &fresh, &c), PMSTEP_ERR_NULL_ARGUMENT); /* not initialised */
    c.gain_per_s = NAN;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_NONFINITE_PARAMETER);
    c.gain_per_s = 25.0f;
    c.integral_gain_per_s2 = INFINITY;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_NONFINITE_PARAMETER);
    c.integral_gain_per_s2 = 0.0f;
    c.gain_per_s = 0.0f;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_POSITION_GAIN);
    c.gain_per_s = 50.5f; /* above k_w/2 */
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_POSITION_GAIN);
    c.gain_per_s = 50.0f; /* at it */
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_OK);
    c.integral_gain_per_s2 = -1.0f;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_POSITION_INTEGRAL_GAIN);
    c.integral_gain_per_s2 = 626.0f; /* above 50^2/4 */
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_POSITION_INTEGRAL_GAIN);
    c.integral_gain_per_s2 = 625.0f;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_OK);
    /* the hold current: finite, >= 0 (0: no vector hold), below the current trip (15 A) */
    c.hold_current_A = NAN;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_NONFINITE_PARAMETER);
    c.hold_current_A = -0.1f;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_HOLD_CURRENT);
    c.hold_current_A = 15.0f;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_ERR_HOLD_CURRENT);
    c.hold_current_A = 14.9f;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_OK);
    /* the designer's rule passes validation */
    assert_int_equal(pmstep_position_design(&f.cfg, &c), PMSTEP_OK);
    assert_float_equal(c.gain_per_s, 25.0f, 0.0f);
    assert_float_equal(c.integral_gain_per_s2, 25.0f * 25.0f / 8.0f, 1e-4f);
    assert_float_equal(c.hold_current_A, 7.5f, 0.0f);
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &c), PMSTEP_OK);
    assert_int_equal(pmstep_position_design(NULL, &c), PMSTEP_ERR_NULL_ARGUMENT);
}

static void move_commands_refuse_bad_values(void **state)
{
    fixture_t f;
    pmstep_position_output_t pos_out;
    const pmstep_output_t out = run_output(0.0, 1.0, 0.0);
    (void)state;
    fixture_init(&f);
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_int_equal(pmstep_position_move_to(NULL, 1.0f, 1.0f, 1.0f, 0.0f), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_position_move_to(&f.pos, NAN, 1.0f, 1.0f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_position_move_to(&f.pos, INFINITY, 1.0f, 1.0f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_position_move_to(&f.pos, 1.0f, 0.0f, 1.0f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_position_move_to(&f.pos, 1.0f, INFINITY, 1.0f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_position_move_to(&f.pos, 1.0f, 1.0f, -1.0f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_position_move_to(&f.pos, 1.0f, 1.0f, NAN, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_position_move_to(&f.pos, 1.0f, 1.0f, 1.0f, -1.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_position_move_to(&f.pos, 1.0f, 1.0f, 1.0f, INFINITY), PMSTEP_ERR_BAD_COMMAND_VALUE);
    /* p |target| beyond PMSTEP_POSITION_MAX_ELECTRICAL_RAD (paper: p = 6) */
    assert_int_equal(pmstep_position_move_to(&f.pos, 5462.0f, 1.0f, 1.0f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_position_move_to(&f.pos, -5461.0f, 1.0f, 1.0f, 0.0f), PMSTEP_OK);
    assert_int_equal(pmstep_position_hold(NULL, 1.0f), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_position_move_to(&f.pos, 1.0f, 1.0f, 1.0f, 0.0f), PMSTEP_OK);
    assert_int_equal(pmstep_position_hold(&f.pos, NAN), PMSTEP_OK); /* in position mode: the move's limits */
}

/* A rotor that follows the speed reference exactly (w = w-hat = w*, read back from the core's
 * reference channel as the law would read it, which then advances as in pmstep_step): after each
 * period the estimate is the rotor's angle.
 * A bias @p speed_bias is added to w-hat (a speed-estimate error the loop must absorb). */
typedef struct {
    double theta_rad;
    double max_overshoot;
    double max_error;
    double max_reference_gap; /* |theta* of the period (pmstep_position_reference) - theta| */
} kinematic_t;

static void kinematic_run(fixture_t *f, kinematic_t *k, long periods, double target, double start, double speed_bias)
{
    const double period = (double)f->cfg.timing.period_s;
    const double direction = target >= start ? 1.0 : -1.0;
    long n;
    for (n = 0; n < periods; ++n) {
        const pmstep_ref_out_t ref = pmstep_ref_output(&f->inst.derived.ref_coeffs, &f->inst.speed_ref);
        pmstep_output_t out;
        pmstep_position_output_t pos_out;
        k->theta_rad += period * (double)ref.value;
        pmstep_ref_advance(&f->inst.derived.ref_coeffs, &f->inst.speed_ref,
                           f->cfg.timing.period_s); /* as pmstep_step */
        out = run_output(6.0 * k->theta_rad, 1.0, (double)ref.value + speed_bias);
        out.speed_ref_rad_s = ref.value;
        pmstep_position_update(&f->pos, &out, &pos_out);
        k->max_overshoot = fmax(k->max_overshoot, direction * (k->theta_rad - target));
        k->max_error = fmax(k->max_error, fabs((double)pos_out.position_error_rad));
        {
            float reference;
            assert_int_equal(pmstep_position_reference(&f->pos, &reference), PMSTEP_OK);
            k->max_reference_gap = fmax(k->max_reference_gap, fabs((double)reference - k->theta_rad));
        }
    }
}

static void loop_drives_the_reference_to_the_target_and_holds(void **state)
{
    fixture_t f;
    kinematic_t k = {0.0, 0.0, 0.0, 0.0};
    pmstep_position_output_t pos_out;
    const pmstep_output_t out = run_output(0.0, 1.0, 0.0);
    float position;
    (void)state;
    fixture_init(&f);
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_int_equal(pmstep_position_move_to(&f.pos, 3.0f, 2.0f, 20.0f, 0.0f), PMSTEP_OK);
    kinematic_run(&f, &k, 60000, 3.0, 0.0, 0.0); /* the move takes 1.6 s; 3 s */
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
    print_message("kinematic move of 3 rad: final error %.3g rad, overshoot %.3g rad, max |theta* - theta-hat| %.3g, "
                  "|theta* - theta| every period %.3g\n",
                  3.0 - k.theta_rad, k.max_overshoot, k.max_error, k.max_reference_gap);
    assert_true(fabs(k.theta_rad - 3.0) < 1e-4);
    assert_true(k.max_overshoot < 1e-4);
    assert_true(k.max_error < 1e-3);
    assert_true(k.max_reference_gap < 1e-3);
    assert_float_equal(position, 3.0f, 1e-4f);
    assert_int_equal(pmstep_position_reference(&f.pos, &position), PMSTEP_OK);
    assert_float_equal(position, 3.0f, 0.0f); /* the profile ended: exactly its target */
}

static void loop_absorbs_a_speed_estimate_bias_with_the_integral(void **state)
{
    fixture_t f;
    kinematic_t k = {0.0, 0.0, 0.0, 0.0};
    pmstep_position_output_t pos_out;
    const pmstep_output_t out = run_output(0.0, 1.0, 0.0);
    (void)state;
    fixture_init(&f);
    f.pos_cfg.integral_gain_per_s2 = 25.0f * 25.0f / 8.0f;
    assert_int_equal(pmstep_position_init(&f.pos, &f.inst, &f.pos_cfg), PMSTEP_OK);
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_int_equal(pmstep_position_hold(&f.pos, 10.0f), PMSTEP_OK);
    /* w-hat reads 0.05 rad/s more than the rotor turns: a P loop alone would sit 0.05/25 = 2 mrad off */
    kinematic_run(&f, &k, 100000, 0.0, 0.0, 0.05);
    print_message("speed-estimate bias 0.05 rad/s, 5 s hold with k_I: position %.3g rad\n", k.theta_rad);
    assert_true(fabs(k.theta_rad) < 1e-4);
}

static void speed_command_leaves_position_mode_and_hold_stops(void **state)
{
    fixture_t f;
    kinematic_t k = {0.0, 0.0, 0.0, 0.0};
    pmstep_position_output_t pos_out;
    const pmstep_output_t out = run_output(0.0, 1.0, 0.0);
    pmstep_ref_out_t ref;
    float position;
    (void)state;
    fixture_init(&f);
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_int_equal(pmstep_position_move_to(&f.pos, 30.0f, 2.0f, 20.0f, 0.0f), PMSTEP_OK);
    kinematic_run(&f, &k, 20000, 30.0, 0.0, 0.0); /* 1 s: cruising at 2 rad/s */
    assert_int_equal(pmstep_set_speed_target(&f.inst, -1.0f, 10.0f), PMSTEP_OK);
    kinematic_run(&f, &k, 1, 30.0, 0.0, 0.0);
    assert_false(f.pos.out.position_mode);
    kinematic_run(&f, &k, 20000, 30.0, 0.0, 0.0);
    ref = pmstep_ref_output(&f.inst.derived.ref_coeffs, &f.inst.speed_ref);
    assert_float_equal(ref.value, -1.0f, 1e-4f); /* the speed command, ramped from where the move was */
    /* hold from speed mode: stops at 10 rad/s^2 and stays where the stop ends */
    assert_int_equal(pmstep_position_hold(&f.pos, 10.0f), PMSTEP_OK);
    assert_true(f.pos.out.position_mode);
    kinematic_run(&f, &k, 40000, f.pos.motion.target, 0.0, 0.0);
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
    assert_float_equal(position, f.pos.motion.target, 1e-4f);
    assert_float_equal((float)k.theta_rad, f.pos.motion.target, 1e-4f);
    /* set zero in position mode: theta*, the target and theta-hat move together */
    assert_int_equal(pmstep_position_set_zero(&f.pos), PMSTEP_OK);
    kinematic_run(&f, &k, 1000, 0.0, 0.0, 0.0);
    assert_int_equal(pmstep_get_position(&f.pos, &position), PMSTEP_OK);
    assert_float_equal(position, 0.0f, 1e-4f);
    assert_float_equal(f.pos.motion.target, 0.0f, 1e-4f);
}

static void leaving_run_in_position_mode_leaves_no_speed_command(void **state)
{
    fixture_t f;
    kinematic_t k = {0.0, 0.0, 0.0, 0.0};
    pmstep_position_output_t pos_out;
    pmstep_output_t out = run_output(0.0, 1.0, 0.0);
    (void)state;
    fixture_init(&f);
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_int_equal(pmstep_position_move_to(&f.pos, 30.0f, 2.0f, 20.0f, 0.0f), PMSTEP_OK);
    kinematic_run(&f, &k, 20000, 30.0, 0.0, 0.0); /* cruising at 2 rad/s */
    assert_true(f.inst.speed_ref.target > 1.9f);
    out.mode = PMSTEP_MODE_S_ALIGN; /* a re-alignment mid-move */
    pmstep_position_update(&f.pos, &out, &pos_out);
    assert_false(f.pos.out.position_mode);
    assert_float_equal(f.inst.speed_ref.target, 0.0f, 0.0f); /* the next RUN starts at rest */
    assert_float_equal(f.inst.speed_ref.value, 0.0f, 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(atan2_poly_accuracy_on_a_dense_circle_and_scales),
        cmocka_unit_test(atan2_poly_axes_and_origin),
        cmocka_unit_test(not_tracked_before_run),
        cmocka_unit_test(turn_count_follows_many_turns_both_ways),
        cmocka_unit_test(position_zero_moves_the_origin),
        cmocka_unit_test(leaving_run_loses_the_position_and_run_restarts_at_zero),
        cmocka_unit_test(init_validates_the_gains_with_named_codes),
        cmocka_unit_test(move_commands_refuse_bad_values),
        cmocka_unit_test(loop_drives_the_reference_to_the_target_and_holds),
        cmocka_unit_test(loop_absorbs_a_speed_estimate_bias_with_the_integral),
        cmocka_unit_test(speed_command_leaves_position_mode_and_hold_stops),
        cmocka_unit_test(leaving_run_in_position_mode_leaves_no_speed_command),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
