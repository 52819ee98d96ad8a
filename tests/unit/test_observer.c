/* Observer (6): w-hat and T_L-hat converge from wrong initial values on exact
 * plant samples (rotor held at constant speed by a dynamometer, so the load it
 * balances is T_L = k_M i_q). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "exact_plant.h"
#include "pmstep/pmstep.h"

static void observer_converges_on_exact_samples(void **state)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    const double period_s = cfg.timing.period_s;
    const double i_q_A = 1.0;  /* q current held by the drive: balances 2 Nm */
    const double speed = 10.0; /* rad/s */
    exact_plant_t plant = {3.0, 0.006, 2.0, 6.0, 0.0, 0.0, 0.0, 0.0};
    pmstep_observer_coeffs_t coeffs;
    pmstep_observer_t obs;
    double load_sum = 0.0;
    double speed_err_end = 0.0;
    long n_avg = 0;
    long k;
    (void)state;
    plant.speed_rad_s = speed;
    plant.i_a = 0.0;
    plant.i_b = i_q_A;
    pmstep_observer_coeffs_init(&coeffs, &cfg, &model);
    pmstep_observer_start(&obs, (float)plant.i_a, (float)plant.i_b);
    obs.speed_hat_rad_s = -5.0f; /* wrong start: true speed 10 rad/s, true load 2 Nm */
    obs.load_hat_Nm = 0.5f;
    for (k = 0; k < 60000; ++k) { /* 3 s */
        const double c = cos(6.0 * plant.theta_rad);
        const double s = sin(6.0 * plant.theta_rad);
        pmstep_observer_input_t in;
        pmstep_observer_mech_rates_t mech;
        /* Voltage (2) that holds i_d = 0, i_q = 1 A at this speed, at the mid-period angle. */
        const double mid = 6.0 * (plant.theta_rad + 0.5 * speed * period_s);
        const double u_d = -0.006 * 6.0 * speed * i_q_A;
        const double u_q = 3.0 * i_q_A + 2.0 * speed;
        const float u_a = (float)(cos(mid) * u_d - sin(mid) * u_q);
        const float u_b = (float)(sin(mid) * u_d + cos(mid) * u_q);
        in.i_a_A = (float)plant.i_a;
        in.i_b_A = (float)plant.i_b;
        in.cos_hat = (float)c;
        in.sin_hat = (float)s;
        pmstep_park(in.cos_hat, in.sin_hat, in.i_a_A, in.i_b_A, &in.i_d_A, &in.i_q_A);
        in.i_d_err_A = 0.0f;
        in.i_q_err_A = 0.0f;
        in.known_load_Nm = 0.0f;
        in.detent_torque_Nm = 0.0f; /* the paper's motor */
        mech = pmstep_observer_mech_rates(&obs, &coeffs, &in, false);
        pmstep_observer_advance(&obs, &coeffs, &in, &mech, u_a, u_b, (float)period_s);
        exact_plant_advance(&plant, u_a, u_b, period_s);
        if (k >= 40000) {
            /* Balanced load k_M i_q over the last second. */
            load_sum += obs.load_hat_Nm - 2.0 * (-s * plant.i_a + c * plant.i_b);
            speed_err_end = fmax(speed_err_end, fabs(obs.speed_hat_rad_s - speed));
            ++n_avg;
        }
    }
    print_message("after 2-3 s: max |w-hat - w| = %.3g rad/s, mean (T_L-hat - k_M i_q) = %.3g Nm, T_L-hat = %.5f\n",
                  speed_err_end, load_sum / (double)n_avg, obs.load_hat_Nm);
    assert_true(speed_err_end < 1e-2);
    assert_true(fabs(load_sum / (double)n_avg) < 1e-2);
}

static void injection_gains_reduce_to_paper_values_without_friction(void **state)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    pmstep_observer_coeffs_t coeffs;
    (void)state;
    pmstep_observer_coeffs_init(&coeffs, &cfg, &model);
    /* F = 0: g_w = 2/lambda = 10, g_T = J/gamma = 9. */
    assert_true(fabs(coeffs.speed_injection_gain - 10.0) < 1e-5);
    assert_true(fabs(coeffs.load_injection_gain - 9.0) < 1e-4);
}

/* The observer started at i-hat = (0.3, 0.9) with w-hat 8 rad/s and T_L-hat 1 N m, and an input at
 * the estimate (0.6, 0.8) with the samples (i_a, i_b), no current error, load or detent. */
static void observer_and_input(pmstep_observer_t *obs, pmstep_observer_input_t *in, float i_a_A, float i_b_A)
{
    pmstep_observer_start(obs, 0.3f, 0.9f);
    obs->speed_hat_rad_s = 8.0f;
    obs->load_hat_Nm = 1.0f;
    in->i_a_A = i_a_A;
    in->i_b_A = i_b_A;
    in->cos_hat = 0.6f;
    in->sin_hat = 0.8f;
    pmstep_park(in->cos_hat, in->sin_hat, in->i_a_A, in->i_b_A, &in->i_d_A, &in->i_q_A);
    in->i_d_err_A = 0.0f;
    in->i_q_err_A = 0.0f;
    in->known_load_Nm = 0.0f;
    in->detent_torque_Nm = 0.0f;
}

/* An advance with the assumed voltage, corrected by the difference, equals the advance with the
 * actual voltage (to float rounding); the mechanical states do not depend on u in one step. */
static void voltage_correction_redoes_the_advance(void **state)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    pmstep_observer_coeffs_t coeffs;
    pmstep_observer_t assumed;
    pmstep_observer_t actual;
    pmstep_observer_input_t in;
    pmstep_observer_mech_rates_t mech;
    (void)state;
    pmstep_observer_coeffs_init(&coeffs, &cfg, &model);
    observer_and_input(&assumed, &in, 0.35f, 0.85f);
    actual = assumed;
    mech = pmstep_observer_mech_rates(&assumed, &coeffs, &in, false);
    pmstep_observer_advance(&assumed, &coeffs, &in, &mech, 12.0f, -5.0f, cfg.timing.period_s);
    pmstep_observer_advance(&actual, &coeffs, &in, &mech, 12.4f, -5.3f, cfg.timing.period_s);
    assert_true(assumed.i_a_hat_A != actual.i_a_hat_A); /* the voltages make a difference ... */
    pmstep_observer_correct_voltage(&assumed, &coeffs, 0.4f, -0.3f);
    assert_float_equal(assumed.i_a_hat_A, actual.i_a_hat_A, 1e-6f); /* ... which the correction removes */
    assert_float_equal(assumed.i_b_hat_A, actual.i_b_hat_A, 1e-6f);
    assert_true(assumed.speed_hat_rad_s == actual.speed_hat_rad_s && assumed.load_hat_Nm == actual.load_hat_Nm);
}

/* The transient observer boost: within the residual bound the rates stay (6)'s; beyond it the speed
 * injection is k and the load injection k^2 times (6)'s, the rest of the rates unchanged. Paper motor:
 * g_w = 10, g_T = 9, k_M/L = 100; estimate at (0.6, 0.8). */
static void boost_scales_the_injections_beyond_the_residual_bound(void **state)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    const float boost = 3.0f;
    const float bound_A = 0.3f;
    pmstep_observer_coeffs_t coeffs;
    pmstep_observer_t obs;
    pmstep_observer_input_t in;
    pmstep_observer_mech_rates_t plain;
    pmstep_observer_mech_rates_t boosted;
    float residual_A;
    float eps;
    float speed_added;
    float load_added;
    (void)state;
    pmstep_observer_coeffs_init(&coeffs, &cfg, &model);
    /* a residual of 0.2 A along (s-hat, -c-hat): within the bound */
    observer_and_input(&obs, &in, 0.3f + 0.2f * 0.8f, 0.9f - 0.2f * 0.6f);
    plain = pmstep_observer_mech_rates(&obs, &coeffs, &in, false);
    boosted = plain;
    pmstep_observer_boost_in_transient(&obs, &coeffs, &in, boost, bound_A, &boosted);
    assert_true(boosted.speed_hat_rate_rad_s2 == plain.speed_hat_rate_rad_s2
                && boosted.load_hat_rate_Nm_s == plain.load_hat_rate_Nm_s);
    /* 0.5 A, and -0.5 A: beyond it */
    for (residual_A = -0.5f; residual_A < 1.0f; residual_A += 1.0f) {
        observer_and_input(&obs, &in, 0.3f + residual_A * 0.8f, 0.9f - residual_A * 0.6f);
        plain = pmstep_observer_mech_rates(&obs, &coeffs, &in, false);
        boosted = plain;
        pmstep_observer_boost_in_transient(&obs, &coeffs, &in, boost, bound_A, &boosted);
        eps = coeffs.km_over_l * residual_A;
        speed_added = (boost - 1.0f) * coeffs.speed_injection_gain * eps;
        load_added = -(boost * boost - 1.0f) * coeffs.load_injection_gain * eps;
        /* to float32 rounding of rates of 10^3-10^4 (a few units in the last place) */
        assert_float_equal(boosted.speed_hat_rate_rad_s2 - plain.speed_hat_rate_rad_s2, speed_added,
                           1e-6f * fabsf(speed_added));
        assert_float_equal(boosted.load_hat_rate_Nm_s - plain.load_hat_rate_Nm_s, load_added,
                           1e-6f * fabsf(load_added));
        assert_true(fabsf(boosted.speed_hat_rate_rad_s2 - plain.speed_hat_rate_rad_s2) > 500.0f);
    }
}

/* A lost observer: the full bus on phase a while the samples read no current (an open winding the
 * open-phase detection has not yet caught), at a fixed angle estimate. The injections integrate an
 * error that never closes. The speed estimate stays within the range the supervision checks
 * (PMSTEP_ESTIMATE_RANGE_FACTOR x max_bus_voltage_V / k_M) and reaches its edge, where the
 * supervision's next check faults ESTIMATE_RANGE; every state stays finite. */
static void lost_observer_speed_stays_within_its_range(void **state)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    const float bus_V = cfg.limits.max_bus_voltage_V;
    pmstep_observer_coeffs_t coeffs;
    pmstep_observer_t obs;
    pmstep_observer_input_t in;
    float max_speed = 0.0f;
    float max_load = 0.0f;
    long k;
    (void)state;
    pmstep_observer_coeffs_init(&coeffs, &cfg, &model);
    assert_float_equal(coeffs.speed_bound_rad_s, PMSTEP_ESTIMATE_RANGE_FACTOR * bus_V / model.torque_constant_Nm_A,
                       1e-3f);
    observer_and_input(&obs, &in, 0.0f, 0.0f);
    in.cos_hat = 0.03f; /* the flux integrals' magnitude collapsed */
    in.sin_hat = 0.01f;
    for (k = 0; k < 200000; ++k) { /* 10 s */
        pmstep_observer_mech_rates_t mech = pmstep_observer_mech_rates(&obs, &coeffs, &in, false);
        pmstep_observer_advance(&obs, &coeffs, &in, &mech, bus_V, 0.0f, cfg.timing.period_s);
        assert_true(isfinite(obs.i_a_hat_A) && isfinite(obs.i_b_hat_A));
        assert_true(isfinite(obs.speed_hat_rad_s) && isfinite(obs.load_hat_Nm));
        assert_true(fabsf(obs.speed_hat_rad_s) <= coeffs.speed_bound_rad_s);
        max_speed = fmaxf(max_speed, fabsf(obs.speed_hat_rad_s));
        max_load = fmaxf(max_load, fabsf(obs.load_hat_Nm));
    }
    print_message("largest |w-hat| %.1f of %.1f rad/s, |T_L-hat| %.2f of %.2f N m\n", (double)max_speed,
                  (double)coeffs.speed_bound_rad_s, (double)max_load, (double)coeffs.load_bound_Nm);
    assert_true(max_speed == coeffs.speed_bound_rad_s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(injection_gains_reduce_to_paper_values_without_friction),
        cmocka_unit_test(observer_converges_on_exact_samples),
        cmocka_unit_test(voltage_correction_redoes_the_advance),
        cmocka_unit_test(lost_observer_speed_stays_within_its_range),
        cmocka_unit_test(boost_scales_the_injections_beyond_the_residual_bound),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
