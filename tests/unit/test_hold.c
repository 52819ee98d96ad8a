/* The core's vector hold (pmstep_hold.h) against the real module on a paper-configured
 * instance put in RUN: the command's refusals, the vector, spring and damping it derives, the
 * period's voltage (the law's current loop in the vector's frame), the release, the angle
 * estimate's set, and the standstill hold of speed mode. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_text.h"
#include "../../firmware/src/pmstep_internal.h" /* pmstep_hold_voltages, the period's part */
#include "paper_in_run.h"

/* Paper: k_M = 2 N m/A, J = 0.01 kg m^2, p = 6, R = 3 Ohm, current trip 15 A, 20 kHz. */
typedef struct {
    pmstep_config_t cfg;
    pmstep_t inst;
} fixture_t;

static void fixture_in_run(fixture_t *f)
{
    assert_int_equal(paper_instance_in_run(&f->cfg, &f->inst), PMSTEP_OK);
}

static void hold_refuses_with_named_codes(void **state)
{
    fixture_t f;
    pmstep_t idle;
    (void)state;
    fixture_in_run(&f);
    idle = f.inst;
    idle.mode = PMSTEP_MODE_IDLE;
    assert_int_equal(pmstep_hold_vector(NULL, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_hold_vector(&idle, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_ERR_BAD_MODE);
    assert_int_equal(pmstep_hold_vector(&f.inst, NAN, 0.0f, 7.5f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, INFINITY), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_hold_vector(&f.inst, 0.97f, 0.0f, 7.5f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_hold_vector(&f.inst, 0.0f, 0.0f, 7.5f, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 0.0f, 0.0f), PMSTEP_ERR_HOLD_CURRENT);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 15.0f, 0.0f), PMSTEP_ERR_HOLD_CURRENT); /* the trip */
    /* the load beyond 0.9 k_M I = 13.5 N m, either way */
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 13.6f), PMSTEP_ERR_HOLD_CURRENT);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, -13.6f), PMSTEP_ERR_HOLD_CURRENT);
    assert_false(f.inst.hold.active);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 13.4f), PMSTEP_OK);
    assert_true(f.inst.hold.active);
    f.cfg.known_load_mode = true; /* Remark 1: the law has the load, no hold */
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_ERR_BAD_MODE);
    assert_string_equal(pmstep_status_str(PMSTEP_ERR_HOLD_CURRENT),
                        "need 0 < hold current < max_phase_current_A and |T_L - T_detent| <= 0.9 k_M I");
}

static void hold_derives_vector_spring_and_damping(void **state)
{
    fixture_t f;
    const double rest = 2.0; /* electrical rad */
    const double delta = asin(4.8 / (2.0 * 7.5));
    const double w_n = sqrt(6.0 * 2.0 * 7.5 * cos(delta) / 0.01);
    (void)state;
    fixture_in_run(&f);
    f.inst.current_integral.i_d_error_integral_As = 0.1f;
    f.inst.current_integral.i_q_error_integral_As = -0.1f;
    assert_int_equal(pmstep_hold_vector(&f.inst, (float)cos(rest), (float)sin(rest), 7.5f, 4.8f), PMSTEP_OK);
    assert_float_equal(f.inst.hold.cos_vector, cos(rest + delta), 2e-6);
    assert_float_equal(f.inst.hold.sin_vector, sin(rest + delta), 2e-6);
    assert_float_equal(f.inst.hold.current_A, 7.5f, 0.0f);
    assert_float_equal(f.inst.hold.damping_s, 2.0 * 0.7 * 6.0 / w_n, 1e-6 * 2.0 * 0.7 * 6.0 / w_n);
    assert_float_equal(f.inst.hold.quiet_band_rad_s, 0.05 * w_n / 6.0, 1e-6 * w_n);
    assert_float_equal(f.inst.hold.bias_gain, w_n * 5e-5 / 20.0, 1e-6 * w_n * 5e-5);
    assert_int_equal(f.inst.hold.settle_periods, (uint32_t)(6.0 / (0.7 * w_n * 5e-5)));
    assert_float_equal(f.inst.current_integral.i_d_error_integral_As, 0.0f, 0.0f); /* restarted */
    assert_float_equal(f.inst.current_integral.i_q_error_integral_As, 0.0f, 0.0f);
    print_message("paper motor, 7.5 A, 4.8 N m: load angle %.4f rad, w_n %.2f rad/s, settling %u periods\n",
                  delta, w_n, (unsigned)f.inst.hold.settle_periods);
}

static void hold_voltage_is_the_current_loop_in_the_vector_frame(void **state)
{
    fixture_t f;
    pmstep_observer_input_t obs_in;
    pmstep_output_t out;
    const double v = 0.7; /* the vector's angle (no load) */
    (void)state;
    fixture_in_run(&f);
    assert_int_equal(pmstep_hold_vector(&f.inst, (float)cos(v), (float)sin(v), 7.5f, 0.0f), PMSTEP_OK);
    /* at rest, the current on the vector: u = R I along it (K_I = 0 in the paper's law) */
    f.inst.observer.speed_hat_rad_s = 0.0f;
    obs_in.i_a_A = (float)(7.5 * cos(v));
    obs_in.i_b_A = (float)(7.5 * sin(v));
    pmstep_hold_voltages(&f.inst, &obs_in, &out);
    assert_float_equal(out.u_a_V, 3.0 * 7.5 * cos(v), 2e-4);
    assert_float_equal(out.u_b_V, 3.0 * 7.5 * sin(v), 2e-4);
    assert_float_equal(obs_in.i_d_err_A, 0.0f, 2e-6);
    assert_float_equal(obs_in.i_q_err_A, 0.0f, 2e-6);
    /* 1 A short along the vector: u_d = L (R/L I - K_i e) = 22.5 + L K_i, K_i = 20 1/s, L = 6e-3 H */
    obs_in.i_a_A = (float)(6.5 * cos(v));
    obs_in.i_b_A = (float)(6.5 * sin(v));
    pmstep_hold_voltages(&f.inst, &obs_in, &out);
    assert_float_equal(obs_in.i_d_err_A, -1.0f, 2e-6);
    assert_float_equal(out.u_a_V * cos(v) + out.u_b_V * sin(v), 22.5 + 6e-3 * 20.0, 2e-4);
    /* the rotor moving forward: the frame turns back by the damping, g w-hat (w-bar still 0) */
    f.inst.observer.speed_hat_rad_s = 1.0f;
    pmstep_hold_voltages(&f.inst, &obs_in, &out);
    assert_float_equal(atan2(f.inst.hold.sin_frame, f.inst.hold.cos_frame), v - f.inst.hold.damping_s,
                       0.01 * f.inst.hold.damping_s);
    /* w-bar follows w-hat by the filter's gain each period */
    assert_float_equal(f.inst.hold.speed_bias_rad_s, f.inst.hold.bias_gain, 1e-7);
}

static void release_and_speed_command_end_the_hold(void **state)
{
    fixture_t f;
    (void)state;
    fixture_in_run(&f);
    pmstep_release_vector(&f.inst); /* none in force: nothing */
    pmstep_release_vector(NULL);
    assert_false(f.inst.hold.active);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
    f.inst.current_integral.i_d_error_integral_As = 0.1f;
    pmstep_release_vector(&f.inst);
    assert_false(f.inst.hold.active);
    assert_float_equal(f.inst.current_integral.i_d_error_integral_As, 0.0f, 0.0f);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 1.0f, 10.0f), PMSTEP_OK);
    assert_false(f.inst.hold.active);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
    assert_int_equal(pmstep_stop(&f.inst), PMSTEP_OK); /* leaving RUN */
    assert_false(f.inst.hold.active);
}

static void angle_estimate_set_gives_that_estimate(void **state)
{
    fixture_t f;
    float c;
    float s;
    pmstep_t idle;
    (void)state;
    fixture_in_run(&f);
    pmstep_angle_update(&f.inst.angle, &f.inst.angle_coeffs, 1.5f, -0.5f, 10.0f, 3.0f); /* some history */
    assert_int_equal(pmstep_set_angle_estimate(&f.inst, 0.6f, -0.8f), PMSTEP_OK);
    pmstep_angle_estimate(&f.inst.angle, &f.inst.angle_coeffs, 1.5f, -0.5f, &c, &s);
    assert_float_equal(c, 0.6f, 1e-6f);
    assert_float_equal(s, -0.8f, 1e-6f);
    assert_int_equal(pmstep_set_angle_estimate(NULL, 1.0f, 0.0f), PMSTEP_ERR_NULL_ARGUMENT);
    assert_int_equal(pmstep_set_angle_estimate(&f.inst, NAN, 0.0f), PMSTEP_ERR_BAD_COMMAND_VALUE);
    idle = f.inst;
    idle.mode = PMSTEP_MODE_IDLE;
    assert_int_equal(pmstep_set_angle_estimate(&idle, 1.0f, 0.0f), PMSTEP_ERR_BAD_MODE);
}

/* The settling count is the longest (10^6 periods) where the model gives no finite, non-negative
 * time below that: J/k_M negative (a NaN natural frequency), +Inf (zero), -Inf (-0: a time of
 * -Inf), huge (a time beyond the count); never an undefined float-to-integer conversion. The
 * validated model cannot give these; the instance is set by hand. */
static void hold_settling_count_defined_for_any_model(void **state)
{
    static const float j_over_km[] = {-0.005f, INFINITY, -INFINITY, 1e30f};
    size_t n;
    (void)state;
    for (n = 0; n < sizeof j_over_km / sizeof j_over_km[0]; ++n) {
        fixture_t f;
        fixture_in_run(&f);
        f.inst.law_coeffs.j_over_km = j_over_km[n];
        assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
        assert_int_equal(f.inst.hold.settle_periods, 1000000u);
    }
}

/* Standstill hold in speed mode (pmstep_hold.h): the paper instance in RUN with a hold current of
 * 7.5 A, pmstep_standstill_advance() driven with hand-made period outputs. */
static void fixture_with_standstill(fixture_t *f)
{
    fixture_in_run(f);
    f->cfg.standstill.hold_current_A = 7.5f;
    pmstep_standstill_start(&f->inst);
}

static pmstep_output_t at_rest_output(float cos_hat, float sin_hat)
{
    pmstep_output_t out = {0};
    out.cos_hat = cos_hat;
    out.sin_hat = sin_hat;
    return out;
}

static void standstill_engages_after_the_engage_time_at_rest(void **state)
{
    fixture_t f;
    const double w_n = sqrt(6.0 * 2.0 * 7.5 / 0.01);
    pmstep_output_t out = at_rest_output(0.6f, 0.8f);
    uint32_t engage;
    uint32_t n;
    (void)state;
    fixture_with_standstill(&f);
    engage = f.inst.scratch.run.standstill.engage_periods;
    assert_true(f.inst.hold.standstill_armed);
    assert_int_equal(engage, (uint32_t)(2.0f / (f.cfg.gains.speed_gain_per_s * f.cfg.timing.period_s)));
    assert_float_equal(f.inst.scratch.run.standstill.quiet_band_rad_s, 0.05 * w_n / 6.0, 1e-6 * w_n);
    /* a rotor not at rest (|w-hat| over the band) restarts the count */
    for (n = 1; n < engage; ++n) {
        pmstep_standstill_advance(&f.inst, &out);
    }
    out.speed_hat_rad_s = 1.1f * f.inst.scratch.run.standstill.quiet_band_rad_s;
    pmstep_standstill_advance(&f.inst, &out);
    assert_false(f.inst.hold.active);
    out.speed_hat_rad_s = 0.0f;
    for (n = 1; n < engage; ++n) {
        pmstep_standstill_advance(&f.inst, &out);
    }
    assert_false(f.inst.hold.active);
    pmstep_standstill_advance(&f.inst, &out);
    assert_true(f.inst.hold.active && f.inst.hold.standstill_engaged);
    /* aimed at the estimate's direction (T_L-hat 0, no detent torque), at the hold's current */
    assert_float_equal(f.inst.hold.cos_vector, 0.6f, 1e-6f);
    assert_float_equal(f.inst.hold.sin_vector, 0.8f, 1e-6f);
    assert_float_equal(f.inst.hold.current_A, 7.5f, 0.0f);
}

static void standstill_waits_for_the_zero_command_reached(void **state)
{
    fixture_t f;
    pmstep_output_t out = at_rest_output(1.0f, 0.0f);
    uint32_t n;
    (void)state;
    fixture_with_standstill(&f);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 5.0f, 100.0f), PMSTEP_OK);
    for (n = 0; n < 4u * f.inst.scratch.run.standstill.engage_periods; ++n) {
        pmstep_standstill_advance(&f.inst, &out); /* a non-zero command */
    }
    assert_false(f.inst.hold.active);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 100.0f), PMSTEP_OK);
    out.speed_ref_rad_s = 0.02f * f.inst.scratch.run.standstill.quiet_band_rad_s; /* w* still on its way */
    for (n = 0; n < 4u * f.inst.scratch.run.standstill.engage_periods; ++n) {
        pmstep_standstill_advance(&f.inst, &out);
    }
    assert_false(f.inst.hold.active);
}

/* The hold engaged on an estimate at (1, 0) and settled with the integrals on the aim: the
 * estimate kept there from the settling on; @return the settling periods. */
static uint32_t standstill_settled(fixture_t *f)
{
    const pmstep_output_t out = at_rest_output(1.0f, 0.0f);
    uint32_t settle;
    uint32_t n;
    fixture_with_standstill(f);
    while (!f->inst.hold.active) {
        pmstep_standstill_advance(&f->inst, &out);
    }
    settle = f->inst.hold.settle_periods;
    for (n = 0; n < settle; ++n) {
        pmstep_standstill_advance(&f->inst, &out);
    }
    assert_true(f->inst.hold.standstill_settled);
    assert_float_equal(f->inst.scratch.run.standstill.keep_cos, 1.0f, 0.0f);
    assert_float_equal(f->inst.scratch.run.standstill.keep_sin, 0.0f, 0.0f);
    assert_true(f->inst.scratch.run.standstill.rest_periods > settle); /* nothing to take: kept from now */
    return settle;
}

static float estimate_angle(const fixture_t *f)
{
    return paper_estimate_angle(&f->inst);
}

/* Settled, the estimate is put back every period: a drift of the integrals whose rate times the
 * settling time is 0.9 x the motion bound is learnt before the sum reaches the bound (the sum
 * then falls back as the learnt drift is taken off the turns); while the rotor moves (w-hat) the
 * estimate follows the integrals. */
static void standstill_keeps_the_estimate_while_the_rotor_rests(void **state)
{
    fixture_t f;
    pmstep_output_t out;
    uint32_t settle;
    uint32_t n;
    float drift_rad;
    float largest_sum_rad = 0.0f;
    float c;
    float s;
    (void)state;
    settle = standstill_settled(&f);
    drift_rad = 0.9f * PMSTEP_HOLD_MOTION_BOUND_RAD / (float)(settle + 1u);
    for (n = 0; n < 10u * settle; ++n) {
        out = at_rest_output(cosf(drift_rad), sinf(drift_rad)); /* the kept (1, 0) turned on by the drift */
        pmstep_standstill_advance(&f.inst, &out);
        assert_float_equal(estimate_angle(&f), 0.0f, 1e-6f);
        if (f.inst.scratch.run.standstill.motion_rad > largest_sum_rad) {
            largest_sum_rad = f.inst.scratch.run.standstill.motion_rad;
        }
    }
    assert_true(largest_sum_rad > 0.3f * PMSTEP_HOLD_MOTION_BOUND_RAD); /* it was seen */
    assert_true(largest_sum_rad < PMSTEP_HOLD_MOTION_BOUND_RAD);
    assert_true(f.inst.scratch.run.standstill.motion_rad < 0.2f * PMSTEP_HOLD_MOTION_BOUND_RAD);
    assert_float_equal(f.inst.scratch.run.standstill.drift_rad, drift_rad, 0.1f * drift_rad);
    assert_true(f.inst.scratch.run.standstill.rest_periods > 10u * settle);
    /* moving (|w-hat - w-bar| over the hold's band): the estimate is left to the integrals */
    pmstep_angle_set(&f.inst.angle, &f.inst.angle_coeffs, 0.8f, 0.6f);
    f.inst.observer.speed_hat_rad_s = 2.0f * f.inst.hold.quiet_band_rad_s; /* the observer's, after the period */
    pmstep_standstill_advance(&f.inst, &out);
    pmstep_angle_estimate(&f.inst.angle, &f.inst.angle_coeffs, f.inst.angle.i_a_prev_A, f.inst.angle.i_b_prev_A, &c,
                          &s);
    assert_float_equal(c, 0.8f, 1e-6f);
    assert_float_equal(s, 0.6f, 1e-6f);
    assert_int_equal(f.inst.scratch.run.standstill.rest_periods, 0u);
}

/* At the settling the estimate is put where the vector holds the rotor: the aim, T_L-hat's load
 * angle behind the vector, however far the integrals drifted while the current stepped up, as
 * long as that is within the motion bound; beyond it the rotor went elsewhere (a load that
 * T_L-hat did not know), and the integrals' estimate is kept. T_L-hat is the held rotor's balance
 * at the estimate kept. */
static void standstill_settles_on_the_aim(void **state)
{
    static const float drifted_rad[] = {0.04f, -0.04f, 0.08f};
    size_t k;
    (void)state;
    for (k = 0; k < sizeof drifted_rad / sizeof drifted_rad[0]; ++k) {
        fixture_t f;
        const float aim_rad = 0.3f;
        const float load_Nm = 3.0f; /* k_M I = 15 N m: a load angle of asin(0.2) */
        pmstep_output_t out = at_rest_output(cosf(aim_rad), sinf(aim_rad));
        const float kept_rad = pmstep_abs(drifted_rad[k]) > PMSTEP_HOLD_MOTION_BOUND_RAD ? aim_rad + drifted_rad[k]
                                                                                         : aim_rad;
        uint32_t n;
        fixture_with_standstill(&f);
        f.inst.observer.load_hat_Nm = load_Nm;
        while (!f.inst.hold.active) {
            pmstep_standstill_advance(&f.inst, &out);
        }
        f.inst.observer.speed_hat_rad_s = 0.3f; /* the observer's transient from the current step */
        assert_float_equal(atan2f(f.inst.hold.sin_vector, f.inst.hold.cos_vector), aim_rad + asinf(0.2f), 1e-5f);
        out = at_rest_output(cosf(aim_rad + drifted_rad[k]), sinf(aim_rad + drifted_rad[k]));
        for (n = 0; n < f.inst.hold.settle_periods; ++n) {
            assert_false(f.inst.hold.standstill_settled);
            pmstep_standstill_advance(&f.inst, &out);
        }
        assert_true(f.inst.hold.standstill_settled);
        assert_float_equal(estimate_angle(&f), kept_rad, 1e-5f);
        assert_float_equal(f.inst.observer.speed_hat_rad_s, f.inst.hold.speed_bias_rad_s, 0.0f);
        assert_float_equal(f.inst.observer.load_hat_Nm, 15.0f * sinf(aim_rad + asinf(0.2f) - kept_rad), 1e-3f);
    }
}

/* A load step on the held rotor: the integrals turn the estimate by 0.01 rad a period, which
 * w-hat does not see. Once the summed turn passes the bound the estimate is turned by it,
 * T_L-hat set to the held rotor's balance there, and the rest starts again. */
static void standstill_follows_a_held_rotor_that_moves(void **state)
{
    fixture_t f;
    pmstep_output_t out;
    float kept_rad;
    float moved_rad = 0.0f;
    float estimate_rad;
    uint32_t periods = 0u;
    (void)state;
    (void)standstill_settled(&f);
    kept_rad = atan2f(f.inst.scratch.run.standstill.keep_sin, f.inst.scratch.run.standstill.keep_cos);
    f.inst.observer.load_hat_Nm = 0.0f;
    while (f.inst.scratch.run.standstill.rest_periods > 0u) {
        /* the kept estimate turned on by this period's 0.01 rad */
        out = at_rest_output(cosf(kept_rad - 0.01f), sinf(kept_rad - 0.01f));
        moved_rad = f.inst.scratch.run.standstill.motion_rad;
        pmstep_standstill_advance(&f.inst, &out);
        assert_true(++periods < 10u);
    }
    /* 6 periods: the sum (leaking by 1/(settle + 1) a period) passes 0.05 rad at the sixth */
    assert_int_equal(periods, 6u);
    assert_true(-moved_rad < PMSTEP_HOLD_MOTION_BOUND_RAD);
    estimate_rad = estimate_angle(&f);
    assert_true(estimate_rad < kept_rad - PMSTEP_HOLD_MOTION_BOUND_RAD);
    assert_true(estimate_rad > kept_rad - 0.06f);
    assert_float_equal(f.inst.scratch.run.standstill.motion_rad, 0.0f, 0.0f);
    /* T_L-hat = k_M I sin(v - x-hat): v the vector aimed at engagement, (1, 0); no detent torque */
    assert_float_equal(f.inst.hold.cos_vector, 1.0f, 0.0f);
    assert_float_equal(f.inst.observer.load_hat_Nm, 2.0f * 7.5f * sinf(-estimate_rad), 1e-3f);
    /* the rest's first settling time again: the estimate taken where the integrals go */
    out = at_rest_output(cosf(estimate_rad - 0.01f), sinf(estimate_rad - 0.01f));
    pmstep_standstill_advance(&f.inst, &out);
    assert_float_equal(f.inst.scratch.run.standstill.keep_cos, cosf(estimate_rad - 0.01f), 1e-6f);
    assert_float_equal(f.inst.scratch.run.standstill.keep_sin, sinf(estimate_rad - 0.01f), 1e-6f);
}

/* With a compensation band the standstill aims its vector so that both phase currents are
 * PMSTEP_HOLD_PHASE_CLEARANCE_BANDS bands clear of zero; without one, at the estimate. The
 * clearance is of the vector, T_L-hat's load angle ahead of the rest: with k_M I = 15 N m and
 * T_L-hat = 3 N m (delta = asin 0.2), an estimate at 0.01 - delta put the vector 0.01 rad off phase
 * a's axis, with phase b's current almost zero; the rest is turned with the vector. */
static void standstill_aims_clear_of_the_phase_axes(void **state)
{
    static const struct {
        float cos_hat, sin_hat, band_A, load_Nm, cos_vector, sin_vector;
    } cases[] = {
        /* 25 x 0.01 A of 7.5 A: the smaller component at least 1/30 */
        {1.0f, 0.0f, 0.01f, 0.0f, 0.99944427f, 1.0f / 30.0f},
        {-0.9999f, -0.0141418f, 0.01f, 0.0f, -0.99944427f, -1.0f / 30.0f},
        {0.02f, -0.9998f, 0.01f, 0.0f, 1.0f / 30.0f, -0.99944427f},
        {0.6f, 0.8f, 0.01f, 0.0f, 0.6f, 0.8f},    /* clear already */
        {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f},     /* no band: at the estimate */
        {1.0f, 0.0f, 1.0f, 0.0f, 0.70710678f, 0.70710678f}, /* a clearance beyond the diagonal: the diagonal */
        /* the estimate clear, its vector not: at 0.01 rad from phase a's axis */
        {0.9817469f, -0.1901922f, 0.01f, 3.0f, 0.99944427f, 1.0f / 30.0f},
        {0.9817469f, 0.1901922f, 0.01f, -3.0f, 0.99944427f, -1.0f / 30.0f},
    };
    size_t k;
    (void)state;
    for (k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        fixture_t f;
        pmstep_output_t out = at_rest_output(cases[k].cos_hat, cases[k].sin_hat);
        const float delta_rad = asinf(cases[k].load_Nm / 15.0f);
        float rest_rad;
        fixture_with_standstill(&f);
        f.cfg.inverter.dead_time_current_band_A = cases[k].band_A;
        f.inst.observer.load_hat_Nm = cases[k].load_Nm;
        while (!f.inst.hold.active) {
            pmstep_standstill_advance(&f.inst, &out);
        }
        assert_float_equal(f.inst.hold.cos_vector, cases[k].cos_vector, 1e-5f);
        assert_float_equal(f.inst.hold.sin_vector, cases[k].sin_vector, 1e-5f);
        /* the rest the vector holds: the load angle behind it */
        rest_rad = atan2f(f.inst.scratch.run.standstill.keep_sin, f.inst.scratch.run.standstill.keep_cos);
        assert_float_equal(rest_rad, atan2f(cases[k].sin_vector, cases[k].cos_vector) - delta_rad, 1e-5f);
    }
}

static void standstill_zero_command_keeps_it_other_commands_end_it(void **state)
{
    fixture_t f;
    pmstep_output_t out = at_rest_output(1.0f, 0.0f);
    (void)state;
    fixture_with_standstill(&f);
    while (!f.inst.hold.active) {
        pmstep_standstill_advance(&f.inst, &out);
    }
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    assert_true(f.inst.hold.active); /* a repeated zero: held on */
    assert_int_equal(pmstep_set_speed_target(&f.inst, -2.0f, 50.0f), PMSTEP_OK);
    assert_false(f.inst.hold.active || f.inst.hold.standstill_engaged);
    assert_true(f.inst.hold.standstill_armed); /* armed for the next zero */
    /* the position library takes the reference: released, and off until a speed command */
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    while (!f.inst.hold.active) {
        pmstep_standstill_advance(&f.inst, &out);
    }
    pmstep_leave_speed_mode(&f.inst);
    pmstep_leave_speed_mode(NULL);
    assert_false(f.inst.hold.active || f.inst.hold.standstill_armed);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    assert_true(f.inst.hold.standstill_armed);
    /* an application's own hold is not the standstill's: a zero command ends it */
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
    pmstep_standstill_advance(&f.inst, &out);
    assert_false(f.inst.hold.standstill_engaged);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    assert_false(f.inst.hold.active);
}

static void standstill_off_without_a_current_and_validated(void **state)
{
    fixture_t f;
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_t inst;
    (void)state;
    fixture_in_run(&f);
    pmstep_standstill_start(&f.inst); /* paper: hold current 0 */
    assert_false(f.inst.hold.standstill_armed);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    assert_false(f.inst.hold.standstill_armed);
    cfg.standstill.hold_current_A = -0.1f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_HOLD_CURRENT);
    cfg.standstill.hold_current_A = cfg.limits.max_phase_current_A; /* the trip itself */
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_HOLD_CURRENT);
    cfg.standstill.hold_current_A = NAN;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_NONFINITE_PARAMETER);
    cfg.standstill.hold_current_A = 7.5f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    cfg.known_load_mode = true;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_STANDSTILL_KNOWN_LOAD);
    assert_string_equal(pmstep_status_str(PMSTEP_ERR_STANDSTILL_KNOWN_LOAD), "standstill hold not with known_load_mode");
    cfg.standstill.hold_current_A = 0.0f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(hold_refuses_with_named_codes),
        cmocka_unit_test(hold_derives_vector_spring_and_damping),
        cmocka_unit_test(hold_voltage_is_the_current_loop_in_the_vector_frame),
        cmocka_unit_test(release_and_speed_command_end_the_hold),
        cmocka_unit_test(angle_estimate_set_gives_that_estimate),
        cmocka_unit_test(hold_settling_count_defined_for_any_model),
        cmocka_unit_test(standstill_engages_after_the_engage_time_at_rest),
        cmocka_unit_test(standstill_waits_for_the_zero_command_reached),
        cmocka_unit_test(standstill_keeps_the_estimate_while_the_rotor_rests),
        cmocka_unit_test(standstill_settles_on_the_aim),
        cmocka_unit_test(standstill_follows_a_held_rotor_that_moves),
        cmocka_unit_test(standstill_aims_clear_of_the_phase_axes),
        cmocka_unit_test(standstill_zero_command_keeps_it_other_commands_end_it),
        cmocka_unit_test(standstill_off_without_a_current_and_validated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
