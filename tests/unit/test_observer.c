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
    const double i_q_A = 1.0;   /* q current held by the drive: balances 2 Nm */
    const double speed = 10.0;  /* rad/s */
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
    pmstep_observer_start(&assumed, 0.3f, 0.9f);
    assumed.speed_hat_rad_s = 8.0f;
    assumed.load_hat_Nm = 1.0f;
    actual = assumed;
    in.i_a_A = 0.35f;
    in.i_b_A = 0.85f;
    in.cos_hat = 0.6f;
    in.sin_hat = 0.8f;
    pmstep_park(in.cos_hat, in.sin_hat, in.i_a_A, in.i_b_A, &in.i_d_A, &in.i_q_A);
    in.i_d_err_A = 0.0f;
    in.i_q_err_A = 0.0f;
    in.known_load_Nm = 0.0f;
    in.detent_torque_Nm = 0.0f;
    mech = pmstep_observer_mech_rates(&assumed, &coeffs, &in, false);
    pmstep_observer_advance(&assumed, &coeffs, &in, &mech, 12.0f, -5.0f, cfg.timing.period_s);
    pmstep_observer_advance(&actual, &coeffs, &in, &mech, 12.4f, -5.3f, cfg.timing.period_s);
    assert_true(assumed.i_a_hat_A != actual.i_a_hat_A); /* the voltages make a difference ... */
    pmstep_observer_correct_voltage(&assumed, &coeffs, 0.4f, -0.3f);
    assert_float_equal(assumed.i_a_hat_A, actual.i_a_hat_A, 1e-6f); /* ... which the correction removes */
    assert_float_equal(assumed.i_b_hat_A, actual.i_b_hat_A, 1e-6f);
    assert_true(assumed.speed_hat_rad_s == actual.speed_hat_rad_s && assumed.load_hat_Nm == actual.load_hat_Nm);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(injection_gains_reduce_to_paper_values_without_friction),
        cmocka_unit_test(observer_converges_on_exact_samples),
        cmocka_unit_test(voltage_correction_redoes_the_advance),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
