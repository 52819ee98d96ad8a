/* Reference generator: H(s) = w0^3/(s+w0)^3 after a ramp-limited set-point. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "pmstep/pmstep.h"

#define PERIOD_S 50e-6
#define W0 300.0

static void filter_has_unit_steady_state_gain(void **state)
{
    pmstep_ref_coeffs_t coeffs;
    pmstep_ref_t ref;
    pmstep_ref_out_t out;
    int k;
    (void)state;
    pmstep_ref_coeffs_init(&coeffs, (float)W0, (float)PERIOD_S);
    pmstep_ref_reset(&ref, 0.0f);
    pmstep_ref_set_target(&ref, 7.5f, 0.0f); /* a step */
    for (k = 0; k < 20000; ++k) {            /* 1 s = 300 time constants */
        pmstep_ref_advance(&coeffs, &ref, (float)PERIOD_S);
    }
    out = pmstep_ref_output(&coeffs, &ref);
    print_message("step 7.5 after 1 s: y = %.9g, y' = %.3g, y'' = %.3g\n", out.value, out.rate, out.accel);
    assert_true(fabs(out.value - 7.5) < 1e-6);
    assert_true(fabs(out.rate) < 1e-4);
    assert_true(fabs(out.accel) < 1e-2);
}

/* Continuous chain x1' = w0(r - x1), ... integrated by fine RK4 in double. */
static void chain_rate(const double x[3], double r, double dx[3])
{
    dx[0] = W0 * (r - x[0]);
    dx[1] = W0 * (x[0] - x[1]);
    dx[2] = W0 * (x[1] - x[2]);
}

/* One period of the chain from t0, 50 RK4 substeps, set-point r(t). */
static void chain_period(double x[3], double t0, double (*setpoint)(double))
{
    const int substeps = 50;
    const double h = PERIOD_S / substeps;
    int s;
    for (s = 0; s < substeps; ++s) {
        const double t = t0 + s * h;
        double k1[3], k2[3], k3[3], k4[3], tmp[3];
        int n;
        chain_rate(x, setpoint(t), k1);
        for (n = 0; n < 3; ++n)
            tmp[n] = x[n] + 0.5 * h * k1[n];
        chain_rate(tmp, setpoint(t + 0.5 * h), k2);
        for (n = 0; n < 3; ++n)
            tmp[n] = x[n] + 0.5 * h * k2[n];
        chain_rate(tmp, setpoint(t + 0.5 * h), k3);
        for (n = 0; n < 3; ++n)
            tmp[n] = x[n] + h * k3[n];
        chain_rate(tmp, setpoint(t + h), k4);
        for (n = 0; n < 3; ++n)
            x[n] += h / 6.0 * (k1[n] + 2.0 * k2[n] + 2.0 * k3[n] + k4[n]);
    }
}

static double ramp_to_10(double t) { return fmin(50.0 * t, 10.0); }

static double held_at_5(double t)
{
    (void)t;
    return 5.0;
}

static void filter_is_exact_for_a_ramp_and_derivatives_match_differences(void **state)
{
    pmstep_ref_coeffs_t coeffs;
    pmstep_ref_t ref;
    const int steps = 8000; /* 0.4 s: ramp 0 -> 10 at 50 rad/s^2 takes 0.2 s */
    double x[3] = {0.0, 0.0, 0.0};
    static double value[8001];
    static double rate[8001];
    static double accel[8001];
    double max_value_err = 0.0;
    double max_rate_err = 0.0;
    double max_accel_err = 0.0;
    double max_rate_diff_err = 0.0;
    double max_accel_diff_err = 0.0;
    double peak_rate = 0.0;
    double peak_accel = 0.0;
    int k;
    (void)state;
    pmstep_ref_coeffs_init(&coeffs, (float)W0, (float)PERIOD_S);
    pmstep_ref_reset(&ref, 0.0f);
    pmstep_ref_set_target(&ref, 10.0f, 50.0f);
    for (k = 0; k <= steps; ++k) {
        const pmstep_ref_out_t out = pmstep_ref_output(&coeffs, &ref);
        const double t0 = k * PERIOD_S;
        value[k] = out.value;
        rate[k] = out.rate;
        accel[k] = out.accel;
        max_value_err = fmax(max_value_err, fabs(out.value - x[2]));
        max_rate_err = fmax(max_rate_err, fabs(out.rate - W0 * (x[1] - x[2])));
        max_accel_err = fmax(max_accel_err, fabs(out.accel - W0 * W0 * (x[0] - 2.0 * x[1] + x[2])));
        peak_rate = fmax(peak_rate, fabs(out.rate));
        peak_accel = fmax(peak_accel, fabs(out.accel));
        pmstep_ref_advance(&coeffs, &ref, (float)PERIOD_S);
        chain_period(x, t0, ramp_to_10);
    }
    for (k = 1; k < steps; ++k) {
        const double rate_diff = (value[k + 1] - value[k - 1]) / (2.0 * PERIOD_S);
        const double accel_diff = (rate[k + 1] - rate[k - 1]) / (2.0 * PERIOD_S);
        max_rate_diff_err = fmax(max_rate_diff_err, fabs(rate[k] - rate_diff));
        max_accel_diff_err = fmax(max_accel_diff_err, fabs(accel[k] - accel_diff));
    }
    print_message("vs continuous: |dy| %.3g, |dy'| %.3g, |dy''| %.3g (peaks y' %.3g, y'' %.3g)\n", max_value_err,
                  max_rate_err, max_accel_err, peak_rate, peak_accel);
    print_message("vs central differences: |y' - Dy| %.3g, |y'' - Dy'| %.3g\n", max_rate_diff_err, max_accel_diff_err);
    assert_true(max_value_err < 1e-5 * 10.0);
    assert_true(max_rate_err < 1e-5 * peak_rate);
    assert_true(max_accel_err < 1e-4 * peak_accel);
    /* Central differences carry an O(T^2) truncation error: 1e-3 of the peak. */
    assert_true(max_rate_diff_err < 1e-3 * peak_rate);
    assert_true(max_accel_diff_err < 1e-3 * peak_accel);
}

static void ramp_rate_limits_the_setpoint(void **state)
{
    pmstep_ref_coeffs_t coeffs;
    pmstep_ref_t ref;
    int k;
    (void)state;
    pmstep_ref_coeffs_init(&coeffs, (float)W0, (float)PERIOD_S);
    pmstep_ref_reset(&ref, 0.0f);
    pmstep_ref_set_target(&ref, -10.0f, 100.0f);
    for (k = 0; k < 1000; ++k) { /* 0.05 s at 100 rad/s^2 -> -5 */
        pmstep_ref_advance(&coeffs, &ref, (float)PERIOD_S);
    }
    assert_true(fabs(ref.setpoint + 5.0) < 1e-4);
    for (k = 0; k < 2000; ++k) {
        pmstep_ref_advance(&coeffs, &ref, (float)PERIOD_S);
    }
    assert_true(ref.setpoint == -10.0f);
}

/* A state placed from outside (the position loop's) runs on as H(s) from it, settles on its
 * set-point and then stays put until a new target; a target equal to the output keeps it put. */
static void placed_state_runs_on_and_settles(void **state)
{
    pmstep_ref_coeffs_t coeffs;
    pmstep_ref_t ref;
    /* y = 2, y' = 300 /s, y'' = -9000 /s^2 with w0 = 300: x2 - x3 = 1, x1 - x2 = -0.1 + 1 */
    double x[3] = {2.0 + 1.0 + 0.9, 2.0 + 1.0, 2.0};
    double max_value_err = 0.0;
    int k;
    (void)state;
    pmstep_ref_coeffs_init(&coeffs, (float)W0, (float)PERIOD_S);
    pmstep_ref_reset(&ref, 0.0f);
    pmstep_ref_place(&ref, 5.0f, 2.0f, 0.9f, 1.0f);
    for (k = 0; k < 200; ++k) { /* 10 ms, 3 time constants */
        pmstep_ref_advance(&coeffs, &ref, (float)PERIOD_S);
        chain_period(x, k * PERIOD_S, held_at_5);
        max_value_err = fmax(max_value_err, fabs(ref.value - x[2]));
    }
    print_message("placed state vs continuous over 10 ms: |dy| %.3g\n", max_value_err);
    assert_true(max_value_err < 1e-5 * 5.0);
    for (k = 0; k < 20000 && !ref.settled; ++k) {
        pmstep_ref_advance(&coeffs, &ref, (float)PERIOD_S);
    }
    assert_true(ref.settled);
    assert_true(ref.value == 5.0f && ref.setpoint == 5.0f && ref.diff12 == 0.0f && ref.diff23 == 0.0f);
    pmstep_ref_set_target(&ref, 5.0f, 0.0f);
    assert_true(ref.settled);
    pmstep_ref_set_target(&ref, 6.0f, 0.0f);
    assert_false(ref.settled);
    pmstep_ref_advance(&coeffs, &ref, (float)PERIOD_S);
    assert_true(ref.value > 5.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(filter_has_unit_steady_state_gain),
        cmocka_unit_test(filter_is_exact_for_a_ramp_and_derivatives_match_differences),
        cmocka_unit_test(ramp_rate_limits_the_setpoint),
        cmocka_unit_test(placed_state_runs_on_and_settles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
