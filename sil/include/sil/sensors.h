/**
 * @file sensors.h
 * @brief Measurement chain of the SIL: what the ADC of a drive reports for the phase
 *        currents and the bus voltage, sampled at the carrier centre (the period
 *        boundary, where the PWM applies zero volts to every phase).
 *
 *   current:  x = (1 + gain_error) i + offset + n,   n ~ N(0, noise_rms_A^2) per phase per sample
 *             then an N-bit bipolar mid-tread ADC over [-full scale, +full scale]
 *   bus:      x = V_bus + n,  n ~ N(0, bus_noise_rms_V^2), then an N-bit ADC over [0, bus full scale]
 *   phase voltage (for drives that sense it): the mean voltage across each phase over the
 *             period that ends at the sample (an integrating measurement: the sinc filter of an
 *             isolated sigma-delta modulator over the PWM period, or the bridge outputs' edges
 *             timed by a capture timer),
 *             x = (1 + gain_error) u + offset + n,  n ~ N(0, phase_voltage_noise_rms_V^2) per phase,
 *             then a phase_voltage_bits bipolar mid-tread quantiser over [-full scale, +full scale]
 *             (its own resolution: such a measurement resolves far finer than the current ADC)
 *
 * Every term is skipped when its setting is zero (no RNG call without noise, no
 * quantisation with adc_bits = 0), so the ideal chain returns its input bit for bit.
 * The RNG is GSL's MT19937 seeded with the run's seed; draws per sample in the order
 * i_a, i_b, bus, u_a, u_b (each only when its noise is on), Gaussian by the ziggurat method.
 * Host only (needs GSL); the PIL target never builds it.
 */
#ifndef SIL_SENSORS_H
#define SIL_SENSORS_H

#ifdef __cplusplus
extern "C" {
#endif

/** [sensors] of a scenario. */
typedef struct {
    unsigned adc_bits;           /**< 0 = ideal (no quantisation, no clipping), else 8..16 */
    double current_full_scale_A; /**< bipolar span +/- this (A) */
    double offset_a_A;           /**< current-sensor offset, phase a (A) */
    double offset_b_A;
    double gain_error_a; /**< relative gain error, phase a (0.01 = reads 1 % high) */
    double gain_error_b;
    double noise_rms_A;                /**< Gaussian noise per phase per sample (A rms) */
    double bus_full_scale_V;           /**< unipolar span [0, this] (V) */
    double bus_noise_rms_V;            /**< Gaussian noise on the bus sample (V rms) */
    unsigned phase_voltage_bits;       /**< 0 = no quantisation, else 8..16 */
    double phase_voltage_full_scale_V; /**< phase-voltage span +/- this (V) */
    double phase_voltage_offset_a_V;   /**< phase-voltage sensor offset, phase a (V) */
    double phase_voltage_offset_b_V;
    double phase_voltage_gain_error_a; /**< relative gain error, phase a */
    double phase_voltage_gain_error_b;
    double phase_voltage_noise_rms_V; /**< Gaussian noise per phase per sample (V rms) */
} sil_sensor_config_t;

typedef struct {
    sil_sensor_config_t cfg;
    unsigned long seed;
    void *rng;                             /**< gsl_rng (MT19937), owned */
    unsigned long clipped_current_samples; /**< phase samples the current ADC saturated at an end code */
    unsigned long clipped_bus_samples;     /**< bus samples the bus ADC saturated at an end code */
    unsigned long clipped_voltage_samples; /**< phase-voltage samples the ADC saturated at an end code */
} sil_sensors_t;

/** Ideal chain: 0 bits, no offset, gain error or noise; 16.5 A, 80 V (bus) and +/-80 V (phase) full scale.
 *  Inline, so the paper scenario (also built for the PIL target) needs no GSL. */
static inline sil_sensor_config_t sil_sensors_ideal(void)
{
    sil_sensor_config_t c;
    c.adc_bits = 0u;
    c.current_full_scale_A = 16.5;
    c.offset_a_A = 0.0;
    c.offset_b_A = 0.0;
    c.gain_error_a = 0.0;
    c.gain_error_b = 0.0;
    c.noise_rms_A = 0.0;
    c.bus_full_scale_V = 80.0;
    c.bus_noise_rms_V = 0.0;
    c.phase_voltage_bits = 0u;
    c.phase_voltage_full_scale_V = 80.0;
    c.phase_voltage_offset_a_V = 0.0;
    c.phase_voltage_offset_b_V = 0.0;
    c.phase_voltage_gain_error_a = 0.0;
    c.phase_voltage_gain_error_b = 0.0;
    c.phase_voltage_noise_rms_V = 0.0;
    return c;
}

/** Copies @p cfg, seeds the RNG with @p seed, clears the counters. @return 0, or -1 if out of memory. */
int sil_sensors_init(sil_sensors_t *s, const sil_sensor_config_t *cfg, unsigned long seed);

/** Frees the RNG (the counters stay readable). */
void sil_sensors_release(sil_sensors_t *s);

/** Samples both phase currents (A): what the ADC reports for the plant's @p i_a_A, @p i_b_A. */
void sil_sensors_currents(sil_sensors_t *s, double i_a_A, double i_b_A, double *i_a_meas_A, double *i_b_meas_A);

/** Samples the bus (V): what the ADC reports for the actual @p bus_V. */
double sil_sensors_bus(sil_sensors_t *s, double bus_V);

/** Samples both phase voltages (V): what the sensor reports for the mean voltages @p u_a_V,
 *  @p u_b_V of the period just ended. */
void sil_sensors_phase_voltages(sil_sensors_t *s, double u_a_V, double u_b_V, double *u_a_meas_V, double *u_b_meas_V);

/**
 * Mid-tread ADC over [@p low, @p high] with 2^@p bits codes of width q = (high - low)/2^bits;
 * code k stands for low + k q, k = 0 .. 2^bits - 1 (so 0 is a code when low = -high or low = 0).
 * A value whose nearest code lies outside that range gives the end code and sets @p *clipped
 * to 1 (else 0); NaN gives NaN.
 */
double sil_adc_quantise(double x, double low, double high, unsigned bits, int *clipped);

#ifdef __cplusplus
}
#endif

#endif /* SIL_SENSORS_H */
