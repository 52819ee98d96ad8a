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
        assert_true(s == -s_neg);              /* odd */
        assert_true(fabsf(s) < kappa);         /* bounded by kappa */
        assert_true(ds > 0.0f && ds <= 1.0f);
        /* derivative against a central difference */
        assert_true(fabsf(ds - (s_plus - s_minus) / (2.0f * h)) < 2e-3f);
    }
    {
        float s, ds;
        pmstep_sat(0.0f, kappa, &s, &ds);
        assert_true(s == 0.0f && ds == 1.0f);  /* slope 1 at 0 */
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
    const float angle = 0.8f, speed = 3.0f, i_d = 0.3f, i_q = 1.7f, load = 1.0f;
    const float c = cosf(angle), s = sinf(angle);
    const double turn = 6.0 * speed * 5e-5;
    const double held_gain = 1.0 - turn * turn / 24.0;
    const float c_act = (float)cos(angle + 0.5 * turn), s_act = (float)sin(angle + 0.5 * turn);
    float u_a, u_b, u_d, u_q, i_q_ref, i_q_ref_rate;
    double di_q, di_d;
    (void)state;
    pmstep_law_coeffs_init(&coeffs, &cfg, &model);
    i_q_ref = pmstep_law_iq_ref(&coeffs, &refs, speed, load);
    i_q_ref_rate = pmstep_law_iq_ref_rate(&coeffs, &refs, speed, 0.0f, 0.0f);
    pmstep_law_voltages(&coeffs, &refs, c, s, i_d, i_q, speed, i_q_ref, i_q_ref_rate, &u_a, &u_b);
    pmstep_park(c_act, s_act, u_a, u_b, &u_d, &u_q);
    u_d = (float)(u_d / held_gain);
    u_q = (float)(u_q / held_gain);
    /* (2): di_q/dt = -(R/L) i_q - p w i_d - (k_M/L) w + u_q/L, di_d/dt = -(R/L) i_d + p w i_q + u_d/L */
    di_q = -500.0 * i_q - 6.0 * speed * i_d - (2.0 / 0.006) * speed + u_q / 0.006;
    di_d = -500.0 * i_d + 6.0 * speed * i_q + u_d / 0.006;
    assert_true(fabs((di_q - i_q_ref_rate) - (-(520.0) * (i_q - i_q_ref))) < 1e-2);
    assert_true(fabs(di_d - (-(520.0) * i_d)) < 1e-2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(saturation_is_smooth_odd_bounded_with_unit_slope),
        cmocka_unit_test(park_and_inverse_are_orthogonal),
        cmocka_unit_test(current_loop_gives_error_dynamics_8),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
