/* Adaptive law (6): smooth saturation, Park transforms, and the current loop
 * closing to the error dynamics (8) on the d-q model (2). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "pmstep/pmstep.h"

static void saturation_is_smooth_odd_bounded_with_unit_slope(void **state)
{
    const float kappa = 9.0f;
    float x;
    (void)state;
    for (x = -200.0f; x <= 200.0f; x += 0.25f) {
        float s, ds, s_plus, ds_plus, s_minus, ds_minus, s_neg, ds_neg;
        const float h = 1e-2f;
        pmstep_sat(x, kappa, &s, &ds);
        pmstep_sat(-x, kappa, &s_neg, &ds_neg);
        pmstep_sat(x + h, kappa, &s_plus, &ds_plus);
        pmstep_sat(x - h, kappa, &s_minus, &ds_minus);
        assert_true(s == -s_neg);      /* odd */
        assert_true(fabsf(s) < kappa); /* bounded by kappa */
        assert_true(ds > 0.0f && ds <= 1.0f);
        /* derivative against a central difference */
        assert_true(fabsf(ds - (s_plus - s_minus) / (2.0f * h)) < 2e-3f);
    }
    {
        float s, ds;
        pmstep_sat(0.0f, kappa, &s, &ds);
        assert_true(s == 0.0f && ds == 1.0f); /* slope 1 at 0 */
        pmstep_sat(1e-3f, kappa, &s, &ds);
        assert_true(fabsf(s - 1e-3f) < 1e-8f);
    }
}

static void park_and_inverse_are_orthogonal(void **state)
{
    float angle;
    (void)state;
    for (angle = -3.0f; angle < 3.0f; angle += 0.37f) {
        const float c = cosf(angle), s = sinf(angle);
        float d, q;
        pmstep_park(c, s, 1.5f, -0.5f, &d, &q);
        /* inverse Park as used for the voltages: a = c d - s q, b = s d + c q */
        assert_true(fabsf(c * d - s * q - 1.5f) < 1e-6f);
        assert_true(fabsf(s * d + c * q + 0.5f) < 1e-6f);
    }
}

static void current_loop_gives_error_dynamics_8(void **state)
{
    /* With the exact angle and w-hat = w, (6) on model (2) must give
     * d(i_q - i_q*)/dt = -(R/L + K_i)(i_q - i_q*) (first lines of (8) with e_w = 0).
     * The law places its voltage at the angle it acts at (p w T_s / 2 on, no delay) and
     * shortens it by 1 - (p w T_s)^2/24 for the hold: undo both to read (u_d, u_q). */
    const pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    pmstep_law_coeffs_t coeffs;
    pmstep_law_refs_t refs = {3.0f, 20.0f, 0.0f, 0.0f, 0.0f};
    const pmstep_law_integral_t no_integral = {0.0f, 0.0f};
    const float angle = 0.8f, speed = 3.0f, i_d = 0.3f, i_q = 1.7f, load = 1.0f;
    const float c = cosf(angle), s = sinf(angle);
    const double turn = 6.0 * speed * 5e-5;
    const double held_gain = 1.0 - turn * turn / 24.0;
    const float c_act = (float)cos(angle + 0.5 * turn), s_act = (float)sin(angle + 0.5 * turn);
    float u_a, u_b, u_d, u_q, i_q_ref, i_q_ref_rate;
    pmstep_speed_term_t speed_term;
    double di_q, di_d;
    (void)state;
    pmstep_law_coeffs_init(&coeffs, &cfg, &model);
    speed_term = pmstep_law_speed_term(&coeffs, speed - refs.speed_ref_rad_s);
    i_q_ref = pmstep_law_iq_ref(&coeffs, &refs, speed_term.term, load);
    i_q_ref_rate = pmstep_law_iq_ref_rate(&coeffs, &refs, speed_term.slope, 0.0f, 0.0f);
    pmstep_law_voltages(&coeffs, &refs, c, s, i_d, i_q, speed, i_q_ref, i_q_ref_rate, &no_integral, &u_a, &u_b);
    pmstep_park(c_act, s_act, u_a, u_b, &u_d, &u_q);
    u_d = (float)(u_d / held_gain);
    u_q = (float)(u_q / held_gain);
    /* (2): di_q/dt = -(R/L) i_q - p w i_d - (k_M/L) w + u_q/L, di_d/dt = -(R/L) i_d + p w i_q + u_d/L */
    di_q = -500.0 * i_q - 6.0 * speed * i_d - (2.0 / 0.006) * speed + u_q / 0.006;
    di_d = -500.0 * i_d + 6.0 * speed * i_q + u_d / 0.006;
    assert_true(fabs((di_q - i_q_ref_rate) - (-(520.0) * (i_q - i_q_ref))) < 1e-2);
    assert_true(fabs(di_d - (-(520.0) * i_d)) < 1e-2);
}

/* The law's coefficients on the paper's configuration (p = 6) with this detent torque. */
static void paper_law_with_detent(pmstep_law_coeffs_t *coeffs, float detent_torque_Nm)
{
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_electrical_t model;
    cfg.motor.detent_torque_Nm = detent_torque_Nm;
    model = pmstep_configured_electrical(&cfg);
    pmstep_law_coeffs_init(coeffs, &cfg, &model);
}

static void detent_torque_and_rate_follow_the_angle(void **state)
{
    /* -T_d sin(4x) and -4 p T_d w cos(4x), from (cos x, sin x) by polynomials. */
    pmstep_law_coeffs_t coeffs;
    const float speed = 7.0f;
    double worst_torque = 0.0, worst_rate = 0.0;
    int k;
    (void)state;
    paper_law_with_detent(&coeffs, 0.05f);
    for (k = 0; k < 360; ++k) {
        const double x = 2.0 * 3.14159265358979 * k / 360.0;
        const pmstep_detent_t d = pmstep_law_detent(&coeffs, (float)cos(x), (float)sin(x), speed);
        const double torque = -0.05 * sin(4.0 * x);
        const double rate = -0.05 * 4.0 * 6.0 * (double)speed * cos(4.0 * x);
        worst_torque = fmax(worst_torque, fabs((double)d.torque_Nm - torque));
        worst_rate = fmax(worst_rate, fabs((double)d.rate_Nm_s - rate));
    }
    print_message("detent: worst torque error %.3g Nm, rate error %.3g Nm/s\n", worst_torque, worst_rate);
    assert_true(worst_torque < 1e-6 * 0.05);
    assert_true(worst_rate < 1e-6 * 0.05 * 4.0 * 6.0 * (double)speed);
    /* No detent torque in the model: exactly zero. */
    paper_law_with_detent(&coeffs, 0.0f);
    {
        const pmstep_detent_t d = pmstep_law_detent(&coeffs, 0.6f, 0.8f, speed);
        assert_true(d.torque_Nm == 0.0f && d.rate_Nm_s == 0.0f);
    }
}

static pmstep_detent_t faded_detent_at(const pmstep_law_coeffs_t *coeffs, double t_s, float fade_speed_rad_s)
{
    /* w-hat(t) = 5 + 300 t rad/s, theta(t) its integral, p = 6. */
    const double speed = 5.0 + 300.0 * t_s;
    const double x = 6.0 * (5.0 * t_s + 150.0 * t_s * t_s);
    pmstep_detent_t d = pmstep_law_detent(coeffs, (float)cos(x), (float)sin(x), (float)speed);
    pmstep_law_fade_detent(fade_speed_rad_s, (float)speed, 300.0f, &d);
    return d;
}

static void detent_compensation_fades_with_the_speed(void **state)
{
    /* g = w_f^2 / (w_f^2 + w-hat^2); the faded rate is the faded torque's derivative along the
     * trajectory (central differences), w-hat passing w_f = 20 rad/s. */
    pmstep_law_coeffs_t coeffs;
    const double h_s = 1e-5;
    double worst_rate = 0.0, largest_rate = 0.0;
    int k;
    (void)state;
    paper_law_with_detent(&coeffs, 0.05f);
    for (k = 1; k < 200; ++k) {
        const double t_s = 0.001 * k;
        const pmstep_detent_t d = faded_detent_at(&coeffs, t_s, 20.0f);
        const double slope = ((double)faded_detent_at(&coeffs, t_s + h_s, 20.0f).torque_Nm
                              - (double)faded_detent_at(&coeffs, t_s - h_s, 20.0f).torque_Nm)
                             / (2.0 * h_s);
        const pmstep_detent_t whole = faded_detent_at(&coeffs, t_s, 0.0f);
        const double speed = 5.0 + 300.0 * t_s;
        const double gain = 400.0 / (400.0 + speed * speed);
        assert_true(fabs((double)d.torque_Nm - gain * (double)whole.torque_Nm) < 1e-6 * 0.05);
        worst_rate = fmax(worst_rate, fabs((double)d.rate_Nm_s - slope));
        largest_rate = fmax(largest_rate, fabs(slope));
    }
    print_message("detent fade: worst rate error %.3g of %.3g Nm/s\n", worst_rate, largest_rate);
    assert_true(worst_rate < 1e-3 * largest_rate);
    {
        /* At w-hat = 0 and with w_f = 0: the whole compensation. */
        pmstep_detent_t d = {0.04f, 3.0f};
        pmstep_law_fade_detent(20.0f, 0.0f, 100.0f, &d);
        assert_true(d.torque_Nm == 0.04f && d.rate_Nm_s == 3.0f);
        pmstep_law_fade_detent(0.0f, 50.0f, 100.0f, &d);
        assert_true(d.torque_Nm == 0.04f && d.rate_Nm_s == 3.0f);
    }
}

static void current_integral_adds_its_voltage_and_integrates(void **state)
{
    /* u_d changes by -L K_I z_d and u_q by -L K_I,q z_q with the integrals z; z advances by T_s (i - i*)
     * only with K_I > 0 or K_I,q > 0. */
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_law_coeffs_t coeffs;
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    const pmstep_law_refs_t refs = {3.0f, 0.0f, 0.0f, 0.5f, 0.0f};
    const pmstep_law_integral_t none = {0.0f, 0.0f};
    const pmstep_law_integral_t some = {2e-4f, -3e-4f};
    pmstep_law_integral_t z = {0.0f, 0.0f};
    float u_a0, u_b0, u_a1, u_b1, du_d, du_q;
    (void)state;
    cfg.gains.current_integral_gain_per_s2 = 5e4f;
    cfg.gains.current_integral_gain_q_per_s2 = 1e4f;
    pmstep_law_coeffs_init(&coeffs, &cfg, &model);
    pmstep_law_voltages(&coeffs, &refs, 1.0f, 0.0f, 0.4f, 1.0f, 0.0f, 1.2f, 0.0f, &none, &u_a0, &u_b0);
    pmstep_law_voltages(&coeffs, &refs, 1.0f, 0.0f, 0.4f, 1.0f, 0.0f, 1.2f, 0.0f, &some, &u_a1, &u_b1);
    /* At w-hat = 0 the turn is zero: (u_a, u_b) = (u_d, u_q). */
    du_d = u_a1 - u_a0;
    du_q = u_b1 - u_b0;
    assert_float_equal(du_d, -0.006f * 5e4f * 2e-4f, 1e-5f);
    assert_float_equal(du_q, -0.006f * 1e4f * -3e-4f, 1e-5f);
    pmstep_law_integrate(&z, &coeffs, 0.1f, -0.2f, 5e-5f);
    assert_float_equal(z.i_d_error_integral_As, 5e-6f, 1e-12f);
    assert_float_equal(z.i_q_error_integral_As, -1e-5f, 1e-12f);
    cfg.gains.current_integral_gain_per_s2 = 0.0f;
    pmstep_law_coeffs_init(&coeffs, &cfg, &model);
    pmstep_law_integrate(&z, &coeffs, 0.1f, -0.2f, 5e-5f);
    assert_float_equal(z.i_q_error_integral_As, -2e-5f, 1e-12f); /* the q axis's integral alone still runs */
    cfg.gains.current_integral_gain_q_per_s2 = 0.0f;
    pmstep_law_coeffs_init(&coeffs, &cfg, &model);
    pmstep_law_integrate(&z, &coeffs, 0.1f, -0.2f, 5e-5f);
    assert_float_equal(z.i_d_error_integral_As, 1e-5f, 1e-12f); /* unchanged: the paper's law */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(saturation_is_smooth_odd_bounded_with_unit_slope),
        cmocka_unit_test(park_and_inverse_are_orthogonal),
        cmocka_unit_test(current_loop_gives_error_dynamics_8),
        cmocka_unit_test(detent_torque_and_rate_follow_the_angle),
        cmocka_unit_test(detent_compensation_fades_with_the_speed),
        cmocka_unit_test(current_integral_adds_its_voltage_and_integrates),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
