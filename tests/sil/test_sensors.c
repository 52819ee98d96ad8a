/* Measurement chain (sil/sensors.h): ADC quantisation and clipping, offset and gain,
 * Gaussian noise statistics, reproducibility from the seed, and the ideal chain. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "sil/sensors.h"

static void quantisation_step_and_clipping(void **state)
{
    /* 12 bits over +/- 16.5 A: q = 33/4096 A, codes -2048 q .. 2047 q, 0 is a code (mid-tread). */
    const double fs = 16.5, q = 33.0 / 4096.0;
    double x, max_err = 0.0;
    int clipped;
    (void)state;
    assert_true(sil_adc_quantise(0.0, -fs, fs, 12, &clipped) == 0.0 && !clipped);
    assert_true(sil_adc_quantise(0.49 * q, -fs, fs, 12, &clipped) == 0.0 && !clipped);
    assert_true(sil_adc_quantise(0.51 * q, -fs, fs, 12, &clipped) == q && !clipped);
    assert_true(sil_adc_quantise(-0.51 * q, -fs, fs, 12, &clipped) == -q && !clipped);
    assert_true(sil_adc_quantise(3.0 * q + 0.2 * q, -fs, fs, 12, &clipped) == 3.0 * q);
    /* Ends: the top code is fs - q; what rounds beyond either end code clips to it. */
    assert_true(sil_adc_quantise(fs - 0.6 * q, -fs, fs, 12, &clipped) == fs - q && !clipped);
    assert_true(sil_adc_quantise(fs - 0.4 * q, -fs, fs, 12, &clipped) == fs - q && clipped);
    assert_true(sil_adc_quantise(100.0, -fs, fs, 12, &clipped) == fs - q && clipped);
    assert_true(sil_adc_quantise(-fs, -fs, fs, 12, &clipped) == -fs && !clipped);
    assert_true(sil_adc_quantise(-100.0, -fs, fs, 12, &clipped) == -fs && clipped);
    /* Within the span the error is at most q/2. */
    for (x = -fs + 0.5 * q; x < fs - q; x += 0.0137) {
        max_err = fmax(max_err, fabs(sil_adc_quantise(x, -fs, fs, 12, &clipped) - x));
        assert_true(!clipped);
    }
    print_message("12 bit, +/-16.5 A: q = %.9f A, max |error| in span = %.9f A (q/2 = %.9f)\n", q, max_err, 0.5 * q);
    assert_true(max_err <= 0.5 * q);
    /* Unipolar bus ADC, 8 bits over [0, 80] V: q = 0.3125 V. */
    assert_true(sil_adc_quantise(48.0, 0.0, 80.0, 8, &clipped) == 48.125 && !clipped);
    assert_true(sil_adc_quantise(90.0, 0.0, 80.0, 8, &clipped) == 80.0 - 0.3125 && clipped);
    assert_true(sil_adc_quantise(-1.0, 0.0, 80.0, 8, &clipped) == 0.0 && clipped);
}

static void chain_counts_clipped_samples(void **state)
{
    sil_sensors_t s;
    sil_sensor_config_t cfg = sil_sensors_ideal();
    double a, b;
    (void)state;
    cfg.adc_bits = 12;
    assert_int_equal(sil_sensors_init(&s, &cfg, 1u), 0);
    sil_sensors_currents(&s, 20.0, -20.0, &a, &b);
    assert_true(a == 16.5 - 33.0 / 4096.0 && b == -16.5);
    sil_sensors_currents(&s, 3.0, -3.0, &a, &b);
    assert_true(fabs(a - 3.0) <= 33.0 / 8192.0 && fabs(b + 3.0) <= 33.0 / 8192.0);
    assert_true(s.clipped_current_samples == 2u);
    /* Bus: 12 bits over [0, 80] V, q = 80/4096 V; 48 V = 2457.6 q reads as code 2458. */
    assert_true(sil_sensors_bus(&s, 48.0) == 2458.0 * 80.0 / 4096.0 && s.clipped_bus_samples == 0u);
    assert_true(sil_sensors_bus(&s, 85.0) == 4095.0 * 80.0 / 4096.0 && s.clipped_bus_samples == 1u);
    sil_sensors_release(&s);
}

static void offset_and_gain_are_applied(void **state)
{
    sil_sensors_t s;
    sil_sensor_config_t cfg = sil_sensors_ideal();
    double a, b;
    (void)state;
    cfg.offset_a_A = 0.02;
    cfg.offset_b_A = -0.03;
    cfg.gain_error_a = 0.01;
    cfg.gain_error_b = -0.02;
    assert_int_equal(sil_sensors_init(&s, &cfg, 1u), 0);
    sil_sensors_currents(&s, 5.0, -2.0, &a, &b);
    print_message("offset/gain: 5 A -> %.15f A, -2 A -> %.15f A\n", a, b);
    assert_true(fabs(a - (5.0 * 1.01 + 0.02)) < 1e-15);
    assert_true(fabs(b - (-2.0 * 0.98 - 0.03)) < 1e-15);
    sil_sensors_currents(&s, 0.0, 0.0, &a, &b);
    assert_true(a == 0.02 && b == -0.03);
    sil_sensors_release(&s);
}

/* The phase-voltage channel: its own gain, offset, resolution and span, independent of the
 * current ADC's bits; clipped samples counted apart. */
static void phase_voltage_channel(void **state)
{
    sil_sensors_t s;
    sil_sensor_config_t cfg = sil_sensors_ideal();
    double a, b;
    (void)state;
    cfg.adc_bits = 8; /* the current ADC's resolution does not touch the voltages */
    cfg.phase_voltage_offset_a_V = 0.05;
    cfg.phase_voltage_offset_b_V = -0.05;
    cfg.phase_voltage_gain_error_a = 0.005;
    cfg.phase_voltage_gain_error_b = -0.005;
    assert_int_equal(sil_sensors_init(&s, &cfg, 1u), 0);
    sil_sensors_phase_voltages(&s, 12.0, -3.0, &a, &b);
    assert_true(fabs(a - (12.0 * 1.005 + 0.05)) < 1e-14 && fabs(b - (-3.0 * 0.995 - 0.05)) < 1e-14);
    sil_sensors_release(&s);
    /* 14 bits over +-36 V: q = 72/16384 V; 1.0 V = 227.56 q above -36 V's code -> nearest code. */
    cfg = sil_sensors_ideal();
    cfg.phase_voltage_bits = 14;
    cfg.phase_voltage_full_scale_V = 36.0;
    assert_int_equal(sil_sensors_init(&s, &cfg, 1u), 0);
    sil_sensors_phase_voltages(&s, 1.0, 40.0, &a, &b);
    assert_true(fabs(a - 1.0) <= 0.5 * 72.0 / 16384.0 && a != 1.0);
    assert_true(b == 36.0 - 72.0 / 16384.0 && s.clipped_voltage_samples == 1u && s.clipped_current_samples == 0u);
    sil_sensors_release(&s);
}

static void ideal_chain_is_the_identity_and_draws_nothing(void **state)
{
    /* No noise: the RNG is never called, so switching noise on later gives the first draw of the seed. */
    static const double values[] = {0.0, -0.0, 1e-300, -7.25, 15.999999999, 1e9};
    sil_sensors_t ideal, fresh;
    sil_sensor_config_t cfg = sil_sensors_ideal();
    double a, b, a_fresh, b_fresh;
    size_t n;
    (void)state;
    assert_int_equal(sil_sensors_init(&ideal, &cfg, 7u), 0);
    for (n = 0; n < sizeof values / sizeof values[0]; ++n) {
        sil_sensors_currents(&ideal, values[n], -values[n], &a, &b);
        assert_true(memcmp(&a, &values[n], sizeof a) == 0);
        assert_true(b == -values[n] && signbit(b) == signbit(-values[n]));
        assert_true(sil_sensors_bus(&ideal, 48.0 + values[n]) == 48.0 + values[n]);
    }
    ideal.cfg.noise_rms_A = 1.0;
    cfg.noise_rms_A = 1.0;
    assert_int_equal(sil_sensors_init(&fresh, &cfg, 7u), 0);
    sil_sensors_currents(&ideal, 0.0, 0.0, &a, &b);
    sil_sensors_currents(&fresh, 0.0, 0.0, &a_fresh, &b_fresh);
    assert_true(a == a_fresh && b == b_fresh);
    sil_sensors_release(&ideal);
    sil_sensors_release(&fresh);
}

static void noise_mean_and_std(void **state)
{
    /* N samples per phase of N(0, sigma^2) on a constant current: the sample mean is within
     * 5 sigma/sqrt(N) of the current, the sample std within 5 sigma/sqrt(2N) of sigma, the
     * a-b correlation within 5/sqrt(N) of 0 (5 standard errors each). */
    enum { N = 200000 };
    const double sigma = 0.005, i0 = 2.0, sigma_v = 0.2;
    sil_sensors_t s;
    sil_sensor_config_t cfg = sil_sensors_ideal();
    double sum_a = 0.0, sum_b = 0.0, sq_a = 0.0, sq_b = 0.0, ab = 0.0, sum_v = 0.0, sq_v = 0.0;
    double mean_a, mean_b, std_a, std_b, corr, mean_v, std_v;
    long k;
    (void)state;
    cfg.noise_rms_A = sigma;
    cfg.bus_noise_rms_V = sigma_v;
    assert_int_equal(sil_sensors_init(&s, &cfg, 12345u), 0);
    for (k = 0; k < N; ++k) {
        double a, b, v;
        sil_sensors_currents(&s, i0, -i0, &a, &b);
        v = sil_sensors_bus(&s, 48.0);
        a -= i0;
        b += i0;
        v -= 48.0;
        sum_a += a;
        sum_b += b;
        sq_a += a * a;
        sq_b += b * b;
        ab += a * b;
        sum_v += v;
        sq_v += v * v;
    }
    mean_a = sum_a / N;
    mean_b = sum_b / N;
    mean_v = sum_v / N;
    std_a = sqrt(sq_a / N - mean_a * mean_a);
    std_b = sqrt(sq_b / N - mean_b * mean_b);
    std_v = sqrt(sq_v / N - mean_v * mean_v);
    corr = (ab / N - mean_a * mean_b) / (std_a * std_b);
    print_message("noise, seed 12345, N = %d: mean a %.3g, b %.3g A (bound %.3g); std a %.6f, b %.6f A (sigma %.3f, "
                  "bound %.3g); corr %.3g (bound %.3g); bus mean %.3g V, std %.5f V\n",
                  N, mean_a, mean_b, 5.0 * sigma / sqrt((double)N), std_a, std_b, sigma, 5.0 * sigma / sqrt(2.0 * N),
                  corr, 5.0 / sqrt((double)N), mean_v, std_v);
    assert_true(fabs(mean_a) < 5.0 * sigma / sqrt((double)N));
    assert_true(fabs(mean_b) < 5.0 * sigma / sqrt((double)N));
    assert_true(fabs(std_a - sigma) < 5.0 * sigma / sqrt(2.0 * N));
    assert_true(fabs(std_b - sigma) < 5.0 * sigma / sqrt(2.0 * N));
    assert_true(fabs(corr) < 5.0 / sqrt((double)N));
    assert_true(fabs(mean_v) < 5.0 * sigma_v / sqrt((double)N));
    assert_true(fabs(std_v - sigma_v) < 5.0 * sigma_v / sqrt(2.0 * N));
    sil_sensors_release(&s);
}

static void seed_fixes_the_sequence(void **state)
{
    sil_sensors_t s1, s2, s3;
    sil_sensor_config_t cfg = sil_sensors_ideal();
    int k, same_as_other_seed = 0;
    (void)state;
    cfg.noise_rms_A = 0.005;
    cfg.bus_noise_rms_V = 0.1;
    cfg.adc_bits = 16;
    assert_int_equal(sil_sensors_init(&s1, &cfg, 42u), 0);
    assert_int_equal(sil_sensors_init(&s2, &cfg, 42u), 0);
    assert_int_equal(sil_sensors_init(&s3, &cfg, 43u), 0);
    for (k = 0; k < 1000; ++k) {
        double a1, b1, a2, b2, a3, b3;
        sil_sensors_currents(&s1, 1.0, 2.0, &a1, &b1);
        sil_sensors_currents(&s2, 1.0, 2.0, &a2, &b2);
        sil_sensors_currents(&s3, 1.0, 2.0, &a3, &b3);
        assert_true(a1 == a2 && b1 == b2);
        assert_true(sil_sensors_bus(&s1, 48.0) == sil_sensors_bus(&s2, 48.0));
        (void)sil_sensors_bus(&s3, 48.0);
        same_as_other_seed += (a1 == a3) + (b1 == b3);
    }
    /* 16 bits: q = 0.5 mA, so two independent samples share a code with probability about
     * q/(2 sqrt(pi) sigma) = 3 % (about 57 of 2000); the same sequence would give 2000. */
    print_message("seeds 42 and 43: %d of 2000 samples on the same code\n", same_as_other_seed);
    assert_true(same_as_other_seed < 400);
    sil_sensors_release(&s1);
    sil_sensors_release(&s2);
    sil_sensors_release(&s3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(quantisation_step_and_clipping),
        cmocka_unit_test(chain_counts_clipped_samples),
        cmocka_unit_test(offset_and_gain_are_applied),
        cmocka_unit_test(phase_voltage_channel),
        cmocka_unit_test(ideal_chain_is_the_identity_and_draws_nothing),
        cmocka_unit_test(noise_mean_and_std),
        cmocka_unit_test(seed_fixes_the_sequence),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
