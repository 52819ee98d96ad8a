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
    print_message("10 rad/s, 10 s: max |c-hat - cos p theta| = %.3g, max |s-hat - sin p theta| = %.3g\n", cos_err,
                  sin_err);
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

/* The back-EMF option (pmstep_angle.h) on the paper's motor: the estimate set delta ahead of the
 * rotor's angle at 0.4 rad, the observer's d-axis residual as it settles for that error,
 * -k_M w delta / (R + L K_e); one period turns the estimate by -K_theta T_s delta w^2 / (w^2 + w_theta^2)
 * toward the rotor. Returns the turn (rad) and the estimate's magnitude after it. */
static double emf_turn(double speed_rad_s, double delta_rad, double *magnitude)
{
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_electrical_t model;
    pmstep_angle_coeffs_t coeffs;
    pmstep_angle_t angle;
    const double rotor_rad = 0.4;
    const double estimate_rad = rotor_rad + delta_rad;
    double residual_A;
    float c;
    float s;
    cfg.gains.emf_angle_gain_per_s = 1000.0f;
    cfg.gains.emf_angle_corner_rad_s = 5.0f;
    model = pmstep_configured_electrical(&cfg);
    pmstep_angle_coeffs_init(&coeffs, &cfg, &model);
    pmstep_angle_start(&angle, 1.5f, -0.5f);
    pmstep_angle_set(&angle, &coeffs, (float)cos(estimate_rad), (float)sin(estimate_rad));
    residual_A =
        -(double)cfg.motor.torque_constant_Nm_A * speed_rad_s * delta_rad
        / ((double)cfg.motor.resistance_Ohm + (double)cfg.motor.inductance_H * (double)cfg.gains.observer_gain_per_s);
    pmstep_angle_follow_emf(&angle, &coeffs, (float)cos(estimate_rad), (float)sin(estimate_rad), (float)residual_A,
                            (float)speed_rad_s);
    pmstep_angle_estimate(&angle, &coeffs, 1.5f, -0.5f, &c, &s);
    *magnitude = hypot((double)c, (double)s);
    return atan2((double)s, (double)c) - estimate_rad;
}

static void emf_correction_turns_the_estimate_toward_the_rotor(void **state)
{
    const double delta_rad = 0.02;
    const double corner_rad_s = 5.0;
    const double speeds[] = {20.0, -20.0, 5.0, -1.0};
    size_t k;
    (void)state;
    for (k = 0; k < sizeof speeds / sizeof speeds[0]; ++k) {
        const double w = speeds[k];
        const double expected_rad = -1000.0 * 5e-5 * delta_rad * w * w / (w * w + corner_rad_s * corner_rad_s);
        double magnitude;
        const double turn_rad = emf_turn(w, delta_rad, &magnitude);
        print_message("w %g rad/s: turn %.4g rad, expected %.4g\n", w, turn_rad, expected_rad);
        /* either direction of rotation: toward the rotor, by the faded-in share; the radius kept */
        assert_true(fabs(turn_rad - expected_rad) < 2e-3 * fabs(expected_rad) + 2e-7);
        assert_true(fabs(magnitude - 1.0) < 1e-5);
    }
    /* behind the rotor: turned forward */
    {
        double magnitude;
        assert_true(emf_turn(20.0, -delta_rad, &magnitude) > 0.0);
    }
}

static void emf_correction_is_off_at_rest(void **state)
{
    double magnitude;
    (void)state;
    /* at rest the residual carries no angle: the fade-in w / (w^2 + w_theta^2) is zero */
    assert_true(fabs(emf_turn(0.0, 0.02, &magnitude)) < 1e-6);
}

/* The smoothing over n periods of a rotor turning turn_rad a period, predicted to turn
 * predicted_rad, the readings exact but for a uniform noise of +-noise on each component (a fixed
 * LCG); the largest and the rms angle error of the smoothed estimate and of the readings after the
 * first 100 periods, and its last length. */
typedef struct {
    double max_rad;
    double rms_rad;
    double reading_rms_rad;
    double length;
} smoothing_run_t;

static double noise_sample(uint32_t *lcg, double amplitude)
{
    *lcg = *lcg * 1664525u + 1013904223u;
    return amplitude * (2.0 * (double)(*lcg >> 8) / 16777216.0 - 1.0);
}

static smoothing_run_t run_smoothing(float share, double turn_rad, double predicted_rad, double noise, int n)
{
    smoothing_run_t run = {0.0, 0.0, 0.0, 0.0};
    uint32_t lcg = 12345u;
    pmstep_angle_smoother_t smoother;
    double sum_sq = 0.0;
    double reading_sum_sq = 0.0;
    int counted = 0;
    pmstep_angle_smoother_set(&smoother, 1.0f, 0.0f);
    for (int k = 1; k <= n; ++k) {
        const double angle = turn_rad * k;
        float c = (float)(cos(angle) + noise_sample(&lcg, noise));
        float s = (float)(sin(angle) + noise_sample(&lcg, noise));
        const double reading_err =
            atan2((double)s * cos(angle) - (double)c * sin(angle), (double)c * cos(angle) + (double)s * sin(angle));
        double err;
        pmstep_angle_smooth(share, (float)predicted_rad, &smoother, &c, &s);
        err = atan2((double)s * cos(angle) - (double)c * sin(angle), (double)c * cos(angle) + (double)s * sin(angle));
        if (k > 100) {
            run.max_rad = fmax(run.max_rad, fabs(err));
            sum_sq += err * err;
            reading_sum_sq += reading_err * reading_err;
            ++counted;
        }
        run.length = hypot((double)c, (double)s);
    }
    run.rms_rad = sqrt(sum_sq / counted);
    run.reading_rms_rad = sqrt(reading_sum_sq / counted);
    return run;
}

static void smoothing_follows_a_fast_steady_turn(void **state)
{
    (void)state;
    /* exact readings: the estimate turns with them (pmstep_small_rotation's turn within 1e-5 rad
     * at 0.4 rad a period; float32 round-off over 2000 periods) */
    for (double turn = -0.4; turn <= 0.41; turn += 0.1) {
        const smoothing_run_t run = run_smoothing(0.5f, turn, turn, 0.0, 2000);
        assert_true(run.max_rad < 1e-4);
        assert_true(fabs(run.length - 1.0) < 1e-4);
    }
}

static void smoothing_cuts_the_readings_noise(void **state)
{
    (void)state;
    /* white noise through e_k = a e_(k-1) + (1 - a) n_k: rms x sqrt((1 - a) / (1 + a)), 0.577 at a = 1/2 */
    const smoothing_run_t run = run_smoothing(0.5f, 0.05, 0.05, 0.01, 20000);
    const double ratio = run.rms_rad / run.reading_rms_rad;
    assert_true(run.reading_rms_rad > 0.005);
    assert_true(ratio > 0.52 && ratio < 0.63);
}

static void smoothing_takes_the_readings_where_the_prediction_misses_a_turn(void **state)
{
    (void)state;
    /* the rotor stopped, w-hat still at 30 rad/s on p = 50 at 20 kHz: predicted 0.075 rad a period;
     * smoothed regardless, the estimate would run 0.075 rad ahead; the gate takes the readings */
    const smoothing_run_t stopped = run_smoothing(0.5f, 0.0, 0.075, 0.002, 2000);
    /* a small miss (w~ = 2 rad/s: 0.005 rad a period) stays smoothed: 0.005 rad behind */
    const smoothing_run_t slow = run_smoothing(0.5f, 0.0, 0.005, 0.0, 2000);
    assert_true(stopped.max_rad < 0.004);
    assert_true(fabs(slow.max_rad - 0.005) < 2e-4);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(angle_starts_at_cos_one),
        cmocka_unit_test(angle_tracks_constant_speed_rotor_for_10s),
        cmocka_unit_test(angle_tracks_reverse_and_fast_rotation),
        cmocka_unit_test(emf_correction_turns_the_estimate_toward_the_rotor),
        cmocka_unit_test(emf_correction_is_off_at_rest),
        cmocka_unit_test(smoothing_follows_a_fast_steady_turn),
        cmocka_unit_test(smoothing_cuts_the_readings_noise),
        cmocka_unit_test(smoothing_takes_the_readings_where_the_prediction_misses_a_turn),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
