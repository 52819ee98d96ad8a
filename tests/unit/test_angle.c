/* Angle reconstruction (6) against an analytic trajectory: rotor at constant
 * speed, currents of model (1) sampled exactly, 10 s of 20 kHz steps. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "exact_plant.h"
#include "pmstep/pmstep.h"

static void run_constant_speed(double speed_rad_s, double duration_s, double *max_cos_err, double *max_sin_err)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    pmstep_angle_coeffs_t coeffs;
    pmstep_angle_t angle;
    /* Start where c-alignment leaves the motor: cos p theta = 1, i_a = u_cc/R. */
    exact_plant_t plant = {3.0, 0.006, 2.0, 6.0, 0.0, 0.0, 8.0, 0.0};
    const double period_s = cfg.timing.period_s;
    const long steps = (long)(duration_s / period_s + 0.5);
    long k;
    plant.speed_rad_s = speed_rad_s;
    pmstep_angle_coeffs_init(&coeffs, &cfg, &model);
    pmstep_angle_start(&angle, (float)plant.i_a, (float)plant.i_b);
    *max_cos_err = 0.0;
    *max_sin_err = 0.0;
    for (k = 0; k < steps; ++k) {
        /* A rotating voltage with a slow amplitude change, held over the period. */
        const double ptheta = plant.pole_pairs * plant.theta_rad;
        const double amplitude = 12.0 + 6.0 * sin(0.7 * (double)k * period_s);
        const float u_a = (float)(amplitude * cos(ptheta + 1.2));
        const float u_b = (float)(amplitude * sin(ptheta + 1.2));
        float cos_hat;
        float sin_hat;
        exact_plant_advance(&plant, u_a, u_b, period_s);
        pmstep_angle_update(&angle, &coeffs, (float)plant.i_a, (float)plant.i_b, u_a, u_b);
        pmstep_angle_estimate(&angle, &coeffs, (float)plant.i_a, (float)plant.i_b, &cos_hat, &sin_hat);
        *max_cos_err = fmax(*max_cos_err, fabs(cos_hat - cos(plant.pole_pairs * plant.theta_rad)));
        *max_sin_err = fmax(*max_sin_err, fabs(sin_hat - sin(plant.pole_pairs * plant.theta_rad)));
    }
}

static void angle_tracks_constant_speed_rotor_for_10s(void **state)
{
    double cos_err;
    double sin_err;
    (void)state;
    run_constant_speed(10.0, 10.0, &cos_err, &sin_err);
    print_message("10 rad/s, 10 s: max |c-hat - cos p theta| = %.3g, max |s-hat - sin p theta| = %.3g\n", cos_err, sin_err);
    assert_true(cos_err < 1e-4);
    assert_true(sin_err < 1e-4);
}

static void angle_tracks_reverse_and_fast_rotation(void **state)
{
    double cos_err;
    double sin_err;
    (void)state;
    run_constant_speed(-40.0, 2.0, &cos_err, &sin_err);
    print_message("-40 rad/s, 2 s: max errors %.3g, %.3g\n", cos_err, sin_err);
    assert_true(cos_err < 1e-4);
    assert_true(sin_err < 1e-4);
}

static void angle_starts_at_cos_one(void **state)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    pmstep_angle_coeffs_t coeffs;
    pmstep_angle_t angle;
    float c;
    float s;
    (void)state;
    pmstep_angle_coeffs_init(&coeffs, &cfg, &model);
    pmstep_angle_start(&angle, 8.0f, -0.25f);
    pmstep_angle_estimate(&angle, &coeffs, 8.0f, -0.25f, &c, &s);
    assert_true(c == 1.0f);
    assert_true(s == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(angle_starts_at_cos_one),
        cmocka_unit_test(angle_tracks_constant_speed_rotor_for_10s),
        cmocka_unit_test(angle_tracks_reverse_and_fast_rotation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
