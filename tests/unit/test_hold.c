/* The core's vector hold (pmstep_hold.h) against the real module on a paper-configured
 * instance put in RUN: the command's refusals, the vector, spring and damping it derives, the
 * period's voltage (the law's current loop in the vector's frame), the release and the angle
 * estimate's set. The standstill hold of speed mode: test_standstill.c. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <complex.h>
#include <math.h>
#include <string.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_text.h"
#include "../../firmware/src/pmstep_internal.h" /* pmstep_hold_voltages */
#include "paper_in_run.h"

/* Paper: k_M = 2 N m/A, J = 0.01 kg m^2, p = 6, R = 3 Ohm, current trip 15 A, 20 kHz. */
static void fixture_in_run(paper_run_t *f) { assert_int_equal(paper_instance_in_run(&f->cfg, &f->inst), PMSTEP_OK); }

static void hold_refuses_with_named_codes(void **state)
{
    paper_run_t f;
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
    paper_run_t f;
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
    print_message("paper motor, 7.5 A, 4.8 N m: load angle %.4f rad, w_n %.2f rad/s, settling %u periods\n", delta, w_n,
                  (unsigned)f.inst.hold.settle_periods);
}

/* The damping term needs a speed estimate in phase with the swing. With the observer placed at a
 * triple pole w_o (docs/design/03-observer.md) and the estimate kept (no restoring torque in its model),
 * w-hat/w = N(s)/P(s), N = P - s^2 (s + a_e): computed here in complex double, the hold damps
 * (g = 2 zeta p / w_n) where Re(w-hat/w) at w_n is at least 0.5 and not at all below: for the
 * triple pole that is w_n <= w_o (Re exactly 0.5 at w_n = w_o, F = 0). The hybrid presets sit at
 * w_n / w_o = 1.1 to 1.6 (Re 0.37 to -0.06): no damping. */
static void hold_damps_only_where_the_estimate_follows_the_swing(void **state)
{
    const double ratios[] = {0.25, 0.5, 0.7, 0.9, 0.95, 1.05, 1.09, 1.38, 1.57, 2.5};
    const double w_n = sqrt(6.0 * 2.0 * 7.5 / 0.01); /* no load, 7.5 A */
    size_t k;
    int damped = 0;
    (void)state;
    for (k = 0; k < sizeof ratios / sizeof ratios[0]; ++k) {
        paper_run_t f;
        pmstep_observer_coeffs_t *obs;
        double w_o, f_j, a_e, c0, c1, c2, re;
        double complex s_jw, n, p;
        fixture_in_run(&f);
        obs = &f.inst.derived.observer_coeffs;
        w_o = w_n / ratios[k];
        f_j = obs->f_over_j_per_s;
        a_e = paper_observer_at_triple_pole(obs, w_o);
        c2 = a_e + f_j;
        c1 = 3.0 * w_o * w_o; /* a_e F/J + g_w b^2 */
        c0 = w_o * w_o * w_o;
        s_jw = I * w_n;
        p = s_jw * s_jw * s_jw + c2 * s_jw * s_jw + c1 * s_jw + c0;
        n = p - s_jw * s_jw * (s_jw + a_e);
        re = creal(n / p);
        assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
        print_message("w_n / w_o %.2f: Re(w-hat/w) %+.3f, g %.4g\n", ratios[k], re, (double)f.inst.hold.damping_s);
        assert_true(fabs(re - 0.5) > 0.01); /* no ratio on the edge */
        if (re >= 0.5) {
            assert_float_equal(f.inst.hold.damping_s, 2.0 * 0.7 * 6.0 / w_n, 1e-5 * 2.0 * 0.7 * 6.0 / w_n);
            damped++;
        } else {
            assert_float_equal(f.inst.hold.damping_s, 0.0f, 0.0f);
        }
    }
    assert_true(damped >= 3 && damped <= 7); /* both sides of the rule seen */
}

static void hold_voltage_is_the_current_loop_in_the_vector_frame(void **state)
{
    paper_run_t f;
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
    paper_run_t f;
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
    paper_run_t f;
    float c;
    float s;
    pmstep_t idle;
    (void)state;
    fixture_in_run(&f);
    pmstep_angle_update(&f.inst.angle, &f.inst.derived.angle_coeffs, 1.5f, -0.5f, 10.0f, 3.0f); /* some history */
    assert_int_equal(pmstep_set_angle_estimate(&f.inst, 0.6f, -0.8f), PMSTEP_OK);
    pmstep_angle_estimate(&f.inst.angle, &f.inst.derived.angle_coeffs, 1.5f, -0.5f, &c, &s);
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
        paper_run_t f;
        fixture_in_run(&f);
        f.inst.derived.law_coeffs.j_over_km = j_over_km[n];
        assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
        assert_int_equal(f.inst.hold.settle_periods, 1000000u);
    }
}

/* The back-EMF angle correction (pmstep_angle.h) acts outside the vector holds, the speed law's
 * and the position library's loop alike: the paper's configuration with the correction on, a d
 * residual of 0.05 A at 20 rad/s, a reading of (R + L K_e) 0.05 A / (k_M 20 rad/s) = 0.0045 rad,
 * within both of its pauses. */
static float phi_step_after_advance(bool hold_active)
{
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_t inst;
    pmstep_control_scratch_t scratch;
    pmstep_meas_t meas;
    pmstep_output_t out;
    float phi_b_before;
    memset(&scratch, 0, sizeof scratch);
    memset(&meas, 0, sizeof meas);
    memset(&out, 0, sizeof out);
    cfg.gains.emf_angle_gain_per_s = 300.0f; /* below R/L + K_e = 600 1/s */
    cfg.gains.emf_angle_corner_rad_s = 5.0f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    inst.mode = PMSTEP_MODE_RUN;
    inst.run_started = true;
    inst.hold.active = hold_active;
    pmstep_angle_start(&inst.angle, 0.0f, 0.0f);
    inst.observer.i_a_hat_A = 0.0f;
    inst.observer.i_b_hat_A = 0.0f;
    inst.observer.speed_hat_rad_s = 20.0f;
    scratch.observer_input.i_a_A = 0.05f; /* the residual on d (c-hat = 1) */
    scratch.observer_input.cos_hat = 1.0f;
    out.cos_hat = 1.0f;
    out.sin_hat = 0.0f;
    out.speed_hat_rad_s = 20.0f;
    phi_b_before = inst.angle.phi_b;
    (void)pmstep_control_advance(&inst, &scratch, &meas, &out);
    return inst.angle.phi_b - phi_b_before; /* the turn moves phi along (-s-hat, c-hat) = (0, 1) */
}

static void emf_correction_runs_outside_holds(void **state)
{
    (void)state;
    /* the turn K_theta T_s (R + L K_e) i~_d w / (k_M (L p / k_M) (w^2 + w_theta^2)) of phi_b */
    /* paper: R 3 ohm, L 6 mH, K_e 100 1/s, k_M 2 N m/A, p 6: 1.5 x 0.05 x 20 / 425 = 3.529e-3 A */
    assert_float_equal(phi_step_after_advance(false),
                       300.0f * 50e-6f * (3.0f + 0.006f * 100.0f) * 0.05f * 20.0f
                           / (2.0f * (0.006f * 6.0f / 2.0f) * (400.0f + 25.0f)),
                       1e-8f);
    assert_true(phi_step_after_advance(true) == 0.0f); /* a vector hold */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(hold_refuses_with_named_codes),
        cmocka_unit_test(hold_derives_vector_spring_and_damping),
        cmocka_unit_test(hold_damps_only_where_the_estimate_follows_the_swing),
        cmocka_unit_test(hold_voltage_is_the_current_loop_in_the_vector_frame),
        cmocka_unit_test(release_and_speed_command_end_the_hold),
        cmocka_unit_test(angle_estimate_set_gives_that_estimate),
        cmocka_unit_test(hold_settling_count_defined_for_any_model),
        cmocka_unit_test(emf_correction_runs_outside_holds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
