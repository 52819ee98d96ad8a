/* Identification of J and F (pmstep_identify.c): the least-squares solver on synthetic data
 * with known coefficients, its refusal of poorly excited data, the judgement of the result,
 * the configuration's checks, and the coefficients an identified model gives the law and the
 * observer. The closed-loop figures per motor preset are ctest closed_loop.identify_*. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_identify.h"
#include "pmstep/pmstep_law.h"
#include "pmstep/pmstep_observer.h"

#define PERIOD_S 5e-5f

/* A speed profile like the one commissioning sees: hold, ramp to +w1, hold, ramp to -w1, hold;
 * returns w* and w*' at sample k of n. */
static void profile(uint32_t k, uint32_t n, float w1, float *w, float *a)
{
    const float t = (float)k / (float)n; /* 0 .. 1 */
    const float ramp = 0.05f;            /* of the window */
    const float rate = 2.0f * w1 / ramp;
    if (t < 0.1f) {
        *w = 0.0f;
        *a = 0.0f;
    } else if (t < 0.1f + 0.5f * ramp) {
        *w = rate * (t - 0.1f);
        *a = rate;
    } else if (t < 0.5f) {
        *w = w1;
        *a = 0.0f;
    } else if (t < 0.5f + ramp) {
        *w = w1 - rate * (t - 0.5f);
        *a = -rate;
    } else {
        *w = -w1;
        *a = 0.0f;
    }
    *a /= (float)n * PERIOD_S; /* per second of a window of n periods */
}

/* Deterministic noise in [-1, 1]. */
static float noise(uint32_t *state)
{
    *state = *state * 1664525u + 1013904223u;
    return (float)(*state >> 8) / 8388608.0f - 1.0f;
}

/* One sample through the core's own accumulation (every speed enters: lowest speed 0). */
static void add(pmstep_identify_sums_t *sums, float a, float w, float y)
{
    pmstep_commissioning_config_t comm;
    pmstep_output_t out;
    memset(&comm, 0, sizeof comm);
    memset(&out, 0, sizeof out);
    out.speed_ref_rate_rad_s2 = a;
    out.speed_ref_rad_s = w;
    out.i_q_A = y;
    (void)pmstep_identify_sample(sums, &comm, UINT32_MAX, &out);
}

/* Sums of y = c0 + ca a + cw w (+ noise of amplitude @p noise_A) over @p n samples. */
static pmstep_identify_sums_t synthetic(uint32_t n, float c0, float ca, float cw, float noise_A)
{
    pmstep_identify_sums_t sums;
    uint32_t state = 12345u;
    uint32_t k;
    pmstep_identify_clear(&sums);
    for (k = 0; k < n; ++k) {
        float w;
        float a;
        profile(k, n, 55.0f, &w, &a);
        add(&sums, a, w, c0 + ca * a + cw * w + noise_A * noise(&state));
    }
    return sums;
}

static void solver_recovers_known_coefficients(void **state)
{
    /* 17HS4401-like: J/k_M = 3.2e-5 A s^2/rad, F/k_M = 6e-4 A s/rad, a 0.05 A load; 0.8 s at 20 kHz. */
    const pmstep_identify_sums_t sums = synthetic(16000u, 0.05f, 3.2e-5f, 6e-4f, 0.0f);
    pmstep_identify_fit_t fit;
    (void)state;
    assert_true(pmstep_identify_solve(&sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit));
    assert_float_equal(fit.accel_coeff, 3.2e-5f, 3.2e-5f * 1e-3f);
    assert_float_equal(fit.speed_coeff, 6e-4f, 6e-4f * 1e-3f);
    assert_float_equal(fit.offset, 0.05f, 0.05f * 1e-3f);
}

static void solver_averages_noise(void **state)
{
    /* 20 mA of uniform noise on each sample (the q current's is a few mA): J within 1 %. */
    const pmstep_identify_sums_t sums = synthetic(16000u, 0.05f, 3.2e-5f, 6e-4f, 0.02f);
    pmstep_identify_fit_t fit;
    (void)state;
    assert_true(pmstep_identify_solve(&sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit));
    assert_float_equal(fit.accel_coeff, 3.2e-5f, 3.2e-5f * 0.01f);
    assert_float_equal(fit.speed_coeff, 6e-4f, 6e-4f * 0.01f);
}

static void solver_refuses_poor_excitation(void **state)
{
    pmstep_identify_sums_t sums;
    pmstep_identify_fit_t fit = {1.0f, 2.0f, 3.0f};
    uint32_t k;
    (void)state;
    /* Nothing at all. */
    pmstep_identify_clear(&sums);
    assert_false(pmstep_identify_solve(&sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit));
    /* A constant speed: no acceleration at all. */
    pmstep_identify_clear(&sums);
    for (k = 0; k < 1000u; ++k) {
        add(&sums, 0.0f, 20.0f, 0.1f);
    }
    assert_false(pmstep_identify_solve(&sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit));
    /* A constant acceleration from rest, w = a t: the columns 1, a are collinear. */
    pmstep_identify_clear(&sums);
    for (k = 0; k < 1000u; ++k) {
        add(&sums, 1000.0f, 1000.0f * (float)k * PERIOD_S, 0.1f);
    }
    assert_false(pmstep_identify_solve(&sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit));
    /* Acceleration proportional to speed (w = e^t): the columns a, w are collinear. */
    pmstep_identify_clear(&sums);
    for (k = 0; k < 1000u; ++k) {
        const float w = 1.0f + 0.001f * (float)k;
        add(&sums, 3.0f * w, w, 0.1f * w);
    }
    assert_false(pmstep_identify_solve(&sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit));
    /* A sum that is not a number. */
    sums = synthetic(1000u, 0.05f, 3.2e-5f, 6e-4f, 0.0f);
    sums.aa = NAN;
    assert_false(pmstep_identify_solve(&sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit));
    /* The fit is left as it was. */
    assert_true(fit.offset == 1.0f && fit.accel_coeff == 2.0f && fit.speed_coeff == 3.0f);
}

static void solver_threshold_is_the_normalised_determinant(void **state)
{
    /* Only a ramp up and a hold (no reversal): 1 and w are close to collinear. The same data
     * pass with a threshold below their determinant and fail above it. */
    pmstep_identify_sums_t sums;
    pmstep_identify_fit_t fit;
    uint32_t k;
    float det;
    (void)state;
    pmstep_identify_clear(&sums);
    for (k = 0; k < 4000u; ++k) {
        const float a = k < 200u ? 5000.0f : 0.0f;
        const float w = k < 200u ? 5000.0f * PERIOD_S * (float)k : 50.0f;
        add(&sums, a, w, 0.05f + 3.2e-5f * a + 6e-4f * w);
    }
    {
        const float c1a = sums.a / sqrtf(sums.n * sums.aa);
        const float c1w = sums.w / sqrtf(sums.n * sums.ww);
        const float caw = sums.aw / sqrtf(sums.aa * sums.ww);
        det = 1.0f - c1a * c1a - c1w * c1w - caw * caw + 2.0f * c1a * c1w * caw;
    }
    assert_true(det > 0.0f && det < 0.5f);
    assert_true(pmstep_identify_solve(&sums, 0.5f * det, &fit));
    assert_float_equal(fit.accel_coeff, 3.2e-5f, 3.2e-5f * 1e-2f);
    assert_false(pmstep_identify_solve(&sums, 2.0f * det, &fit));
}

static void sample_skips_low_speeds_and_closes_the_window(void **state)
{
    pmstep_identify_sums_t sums;
    pmstep_commissioning_config_t comm;
    pmstep_output_t out;
    (void)state;
    memset(&comm, 0, sizeof comm);
    memset(&out, 0, sizeof out);
    comm.identification_min_speed_rad_s = 10.0f;
    pmstep_identify_clear(&sums);
    out.speed_ref_rad_s = -9.9f;
    assert_false(pmstep_identify_sample(&sums, &comm, 3u * PMSTEP_IDENTIFICATION_DECIMATION, &out));
    assert_true(sums.n == 0.0f);
    out.speed_ref_rad_s = -10.0f;
    out.speed_ref_rate_rad_s2 = 100.0f;
    out.i_q_A = 0.5f;
    assert_false(pmstep_identify_sample(&sums, &comm, 3u * PMSTEP_IDENTIFICATION_DECIMATION, &out));
    assert_true(sums.n == 1.0f && sums.w == -10.0f && sums.aw == -1000.0f && sums.wy == -5.0f && sums.ay == 50.0f);
    /* the third sample covers 3 x PMSTEP_IDENTIFICATION_DECIMATION periods: the window's end */
    assert_true(pmstep_identify_sample(&sums, &comm, 3u * PMSTEP_IDENTIFICATION_DECIMATION, &out));
    assert_int_equal(sums.periods, 3u * PMSTEP_IDENTIFICATION_DECIMATION);
}

static void finish_judges_the_result(void **state)
{
    const float k_m = 0.16638f;
    const float j = 5.4e-6f;
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_commissioning_t result;
    pmstep_identify_sums_t sums;
    pmstep_electrical_t model;
    (void)state;
    cfg.motor.inertia_kgm2 = 1.2f * j;
    cfg.motor.friction_Nms_rad = 0.0f;
    cfg.motor.torque_constant_Nm_A = 2.0f * k_m; /* the model's k_M is the one used */
    cfg.timing.period_s = PERIOD_S;
    cfg.commissioning.use_identified_mechanics = true;
    memset(&result, 0, sizeof result);
    /* J = k_M c_a, F = k_M c_w, into the model. */
    sums = synthetic(16000u, 0.05f, j / k_m, 1e-4f / k_m, 0.0f);
    model = pmstep_configured_electrical(&cfg);
    model.torque_constant_Nm_A = k_m;
    assert_true(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_DONE);
    assert_float_equal(result.inertia_kgm2, j, j * 1e-3f);
    assert_float_equal(result.friction_Nms_rad, 1e-4f, 1e-4f * 1e-2f);
    assert_true(model.inertia_kgm2 == result.inertia_kgm2 && model.friction_Nms_rad == result.friction_Nms_rad);
    /* Identified but not to be used. */
    cfg.commissioning.use_identified_mechanics = false;
    assert_false(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_DONE);
    cfg.commissioning.use_identified_mechanics = true;
    /* Negative friction: reported as such; the model gets none. */
    sums = synthetic(16000u, 0.05f, j / k_m, -1e-5f / k_m, 0.0f);
    assert_true(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_FRICTION_NEGATIVE);
    assert_true(result.friction_Nms_rad < 0.0f && model.friction_Nms_rad == 0.0f);
    /* J four times the configured one (a load of three rotors): plausible, used. */
    model = pmstep_configured_electrical(&cfg);
    model.torque_constant_Nm_A = k_m;
    sums = synthetic(16000u, 0.05f, 4.0f * 1.2f * j / k_m, 1e-4f / k_m, 0.0f);
    assert_true(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_DONE);
    assert_float_equal(model.inertia_kgm2, 4.8f * j, 4.8f * j * 1e-3f);
    /* J beyond PMSTEP_IDENTIFICATION_INERTIA_RANGE either way of the configured one: implausible,
     * reported, not used. */
    model = pmstep_configured_electrical(&cfg);
    model.torque_constant_Nm_A = k_m;
    sums = synthetic(16000u, 0.05f, 11.0f * 1.2f * j / k_m, 1e-4f / k_m, 0.0f);
    assert_false(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_IMPLAUSIBLE);
    assert_float_equal(result.inertia_kgm2, 13.2f * j, 13.2f * j * 1e-3f);
    assert_true(model.inertia_kgm2 == cfg.motor.inertia_kgm2);
    sums = synthetic(16000u, 0.05f, 0.09f * 1.2f * j / k_m, 1e-4f / k_m, 0.0f);
    assert_false(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_IMPLAUSIBLE);
    assert_true(model.inertia_kgm2 == cfg.motor.inertia_kgm2);
    /* F/J at the control rate, and a sum that is not finite: implausible. */
    sums = synthetic(16000u, 0.05f, j / k_m, j / PERIOD_S / k_m, 0.0f);
    assert_false(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_IMPLAUSIBLE);
    sums = synthetic(16000u, 0.05f, j / k_m, 1e-4f / k_m, 0.0f);
    sums.ay = INFINITY;
    assert_false(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_IMPLAUSIBLE);
    /* No excitation. */
    memset(&result, 0, sizeof result);
    pmstep_identify_clear(&sums);
    assert_false(pmstep_identify_finish(&sums, &cfg, &model, &result));
    assert_int_equal(result.identification, PMSTEP_IDENT_POOR_EXCITATION);
    assert_true(result.inertia_kgm2 == 0.0f);
}

static void config_checks_have_named_errors(void **state)
{
    pmstep_config_t cfg = pmstep_paper_config();
    (void)state;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
    cfg.commissioning.identification_time_s = 0.5f;
    cfg.commissioning.identification_min_speed_rad_s = 2.0f;
    cfg.commissioning.use_identified_mechanics = true;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
    cfg.commissioning.identification_time_s = -0.1f;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_ERR_IDENTIFICATION_WINDOW);
    cfg.commissioning.identification_time_s = 2.0f * PMSTEP_MAX_DURATION_PERIODS * cfg.timing.period_s;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_ERR_IDENTIFICATION_WINDOW);
    cfg.commissioning.identification_time_s = NAN;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_ERR_NONFINITE_PARAMETER);
    cfg.commissioning.identification_time_s = 0.0f;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_ERR_MECHANICS_UNIDENTIFIED);
    cfg.commissioning.use_identified_mechanics = false;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
    cfg.commissioning.identification_min_speed_rad_s = -1.0f;
    assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_ERR_IDENTIFICATION_SPEED);
}

static void identified_model_sets_the_mechanical_coefficients(void **state)
{
    const pmstep_config_t cfg = pmstep_paper_config();
    pmstep_electrical_t model = pmstep_configured_electrical(&cfg);
    pmstep_law_coeffs_t law;
    pmstep_law_coeffs_t law0;
    pmstep_observer_coeffs_t obs;
    (void)state;
    pmstep_law_coeffs_init(&law0, &cfg, &model);
    model.inertia_kgm2 = 2.0f * cfg.motor.inertia_kgm2;
    model.friction_Nms_rad = 0.01f;
    pmstep_law_coeffs_init(&law, &cfg, &model);
    pmstep_observer_coeffs_init(&obs, &cfg, &model);
    assert_float_equal(law.j_over_km, 2.0f * law0.j_over_km, 1e-9f);
    assert_float_equal(law.f_over_j_per_s, 0.01f / model.inertia_kgm2, 1e-6f);
    /* The speed correction's torque bound J k_w kappa stays the configured one. */
    assert_float_equal(law.kappa_rad_s, 0.5f * law0.kappa_rad_s, 1e-6f);
    assert_float_equal(obs.inv_j, 1.0f / model.inertia_kgm2, 1e-3f);
    assert_float_equal(obs.f_over_j_per_s, 0.01f / model.inertia_kgm2, 1e-6f);
    /* The configured model keeps kappa bit for bit. */
    assert_true(law0.kappa_rad_s == cfg.gains.sat_kappa_rad_s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(solver_recovers_known_coefficients),
        cmocka_unit_test(solver_averages_noise),
        cmocka_unit_test(solver_refuses_poor_excitation),
        cmocka_unit_test(solver_threshold_is_the_normalised_determinant),
        cmocka_unit_test(sample_skips_low_speeds_and_closes_the_window),
        cmocka_unit_test(finish_judges_the_result),
        cmocka_unit_test(config_checks_have_named_errors),
        cmocka_unit_test(identified_model_sets_the_mechanical_coefficients),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
