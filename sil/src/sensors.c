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
    s->clipped_voltage_samples = 0;
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

/* A bipolar channel of one phase (current or voltage): gain, offset, noise, ADC over
 * +/- full_scale; each stage only when it is on. */
typedef struct {
    double gain_error;
    double offset;
    double noise_rms;
    double full_scale;
    unsigned bits;
} phase_channel_t;

static double phase_sample(sil_sensors_t *s, double x, const phase_channel_t *ch, unsigned long *clipped_count)
{
    if (ch->gain_error != 0.0) {
        x *= 1.0 + ch->gain_error;
    }
    if (ch->offset != 0.0) {
        x += ch->offset;
    }
    if (ch->noise_rms > 0.0) {
        x += gsl_ran_gaussian_ziggurat((gsl_rng *)s->rng, ch->noise_rms);
    }
    if (ch->bits > 0u) {
        int clipped;
        x = sil_adc_quantise(x, -ch->full_scale, ch->full_scale, ch->bits, &clipped);
        *clipped_count += (unsigned long)clipped;
    }
    return x;
}

void sil_sensors_currents(sil_sensors_t *s, double i_a_A, double i_b_A, double *i_a_meas_A, double *i_b_meas_A)
{
    const sil_sensor_config_t *c = &s->cfg;
    const phase_channel_t a = {c->gain_error_a, c->offset_a_A, c->noise_rms_A, c->current_full_scale_A, c->adc_bits};
    const phase_channel_t b = {c->gain_error_b, c->offset_b_A, c->noise_rms_A, c->current_full_scale_A, c->adc_bits};
    *i_a_meas_A = phase_sample(s, i_a_A, &a, &s->clipped_current_samples);
    *i_b_meas_A = phase_sample(s, i_b_A, &b, &s->clipped_current_samples);
}

void sil_sensors_phase_voltages(sil_sensors_t *s, double u_a_V, double u_b_V, double *u_a_meas_V, double *u_b_meas_V)
{
    const sil_sensor_config_t *c = &s->cfg;
    const phase_channel_t a = {c->phase_voltage_gain_error_a, c->phase_voltage_offset_a_V, c->phase_voltage_noise_rms_V,
                               c->phase_voltage_full_scale_V, c->phase_voltage_bits};
    const phase_channel_t b = {c->phase_voltage_gain_error_b, c->phase_voltage_offset_b_V, c->phase_voltage_noise_rms_V,
                               c->phase_voltage_full_scale_V, c->phase_voltage_bits};
    *u_a_meas_V = phase_sample(s, u_a_V, &a, &s->clipped_voltage_samples);
    *u_b_meas_V = phase_sample(s, u_b_V, &b, &s->clipped_voltage_samples);
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
