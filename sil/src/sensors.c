/* Measurement chain: sensor gain and offset, Gaussian noise, ADC quantisation and clipping. */
#include "sil/sensors.h"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <math.h>
#include <stddef.h>

int sil_sensors_init(sil_sensors_t *s, const sil_sensor_config_t *cfg, unsigned long seed)
{
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    s->cfg = *cfg;
    s->seed = seed;
    s->rng = rng;
    s->clipped_current_samples = 0;
    s->clipped_bus_samples = 0;
    if (rng == NULL) {
        return -1;
    }
    gsl_rng_set(rng, seed);
    return 0;
}

void sil_sensors_release(sil_sensors_t *s)
{
    if (s->rng != NULL) {
        gsl_rng_free((gsl_rng *)s->rng);
        s->rng = NULL;
    }
}

double sil_adc_quantise(double x, double low, double high, unsigned bits, int *clipped)
{
    /* 2^bits: a shift for the ADC's widths (no libm call a sample), ldexp beyond them. */
    const double codes = bits < 31u ? (double)(1UL << bits) : ldexp(1.0, (int)bits);
    const double q = (high - low) / codes;
    double k = floor((x - low) / q + 0.5);
    *clipped = 0;
    if (k < 0.0) {
        k = 0.0;
        *clipped = 1;
    } else if (k > codes - 1.0) {
        k = codes - 1.0;
        *clipped = 1;
    }
    return isnan(x) ? x : low + k * q;
}

/* One phase: gain, offset, noise, ADC; each stage only when it is on. */
static double current_sample(sil_sensors_t *s, double i_a, double gain_error, double offset_a)
{
    const sil_sensor_config_t *c = &s->cfg;
    double x = i_a;
    if (gain_error != 0.0) {
        x *= 1.0 + gain_error;
    }
    if (offset_a != 0.0) {
        x += offset_a;
    }
    if (c->noise_rms_A > 0.0) {
        x += gsl_ran_gaussian_ziggurat((gsl_rng *)s->rng, c->noise_rms_A);
    }
    if (c->adc_bits > 0u) {
        int clipped;
        x = sil_adc_quantise(x, -c->current_full_scale_A, c->current_full_scale_A, c->adc_bits, &clipped);
        s->clipped_current_samples += (unsigned long)clipped;
    }
    return x;
}

void sil_sensors_currents(sil_sensors_t *s, double i_a_A, double i_b_A, double *i_a_meas_A, double *i_b_meas_A)
{
    *i_a_meas_A = current_sample(s, i_a_A, s->cfg.gain_error_a, s->cfg.offset_a_A);
    *i_b_meas_A = current_sample(s, i_b_A, s->cfg.gain_error_b, s->cfg.offset_b_A);
}

double sil_sensors_bus(sil_sensors_t *s, double bus_V)
{
    const sil_sensor_config_t *c = &s->cfg;
    double x = bus_V;
    if (c->bus_noise_rms_V > 0.0) {
        x += gsl_ran_gaussian_ziggurat((gsl_rng *)s->rng, c->bus_noise_rms_V);
    }
    if (c->adc_bits > 0u) {
        int clipped;
        x = sil_adc_quantise(x, 0.0, c->bus_full_scale_V, c->adc_bits, &clipped);
        s->clipped_bus_samples += (unsigned long)clipped;
    }
    return x;
}
