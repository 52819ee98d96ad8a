/* Every reference the fuzzers make to a field of pmstep_config_t or of the coefficient
 * structs lives in this file, so a rename of the configuration is an edit here only.
 * The harnesses otherwise treat the configuration as bytes. */
#ifndef PMSTEP_FUZZ_CONFIG_FIELDS_H
#define PMSTEP_FUZZ_CONFIG_FIELDS_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "pmstep/pmstep.h"
#include "pmstep_test_configs.h"

/* Offsets of the bool fields: a fuzzed byte written over one is reduced to 0 or 1 (any other
 * value in a bool is undefined behaviour in the harness, not a finding in the core). */
static const size_t fuzz_bool_fields[] = {
    offsetof(pmstep_config_t, known_load_mode),
    offsetof(pmstep_config_t, commissioning.alignment_offset_calibration),
    offsetof(pmstep_config_t, commissioning.use_measured_resistance),
    offsetof(pmstep_config_t, commissioning.use_measured_inductance),
    offsetof(pmstep_config_t, commissioning.use_measured_torque_constant),
    offsetof(pmstep_config_t, commissioning.use_identified_mechanics),
    offsetof(pmstep_config_t, commissioning.measure_only),
    offsetof(pmstep_config_t, inverter.phase_voltage_sensing),
    offsetof(pmstep_config_t, inverter.ripple_dead_zone),
    offsetof(pmstep_config_t, standstill.stops_only),
};
#define FUZZ_BOOL_FIELDS (sizeof fuzz_bool_fields / sizeof fuzz_bool_fields[0])

/* Base configurations the fuzzer perturbs. 0: the paper's. 1: every optional feature on
 * (offset calibration, alignment windows with the voltage bias, inductance window, commissioned
 * R, L, k_M used, dead-time compensation, drift-free angle, detent compensation, PI current loop, all
 * detectors, re-alignments, the standstill hold).
 * 2: as 1 in known-load mode (no standstill hold). 3: the paper's with short alignments (RUN after 400 periods) and
 * phase-voltage sensing. */
#define FUZZ_BASE_CONFIGS 4u
static inline pmstep_config_t fuzz_base_config(unsigned which)
{
    pmstep_config_t cfg = pmstep_paper_config();
    if (which == 1u || which == 2u) {
        cfg = pmstep_test_features_config(); /* tests/include, shared with the EVA harnesses */
        cfg.known_load_mode = which == 2u;
        if (cfg.known_load_mode) {
            cfg.standstill.hold_current_A = 0.0f;     /* a vector hold needs (6) */
            cfg.standstill.vector_speed_rad_s = 0.0f; /* and the low-speed drive turns it */
        }
    } else if (which == 3u) {
        cfg.alignment.s_align_time_s = 0.01f;
        cfg.alignment.c_align_time_s = 0.02f;
        cfg.inverter.phase_voltage_sensing = true;
    }
    return cfg;
}

/* Control period, for the harness's plant (read from a configuration init accepted). */
static inline float fuzz_period_s(const pmstep_config_t *cfg) { return cfg->timing.period_s; }

/* Protection limits, for measurements on their edges. */
static inline float fuzz_current_limit_a(const pmstep_config_t *cfg) { return cfg->limits.max_phase_current_A; }

static inline float fuzz_min_bus_v(const pmstep_config_t *cfg) { return cfg->limits.min_bus_voltage_V; }

static inline float fuzz_max_bus_v(const pmstep_config_t *cfg) { return cfg->limits.max_bus_voltage_V; }

/* Re-alignments allowed after a detection. */
static inline uint32_t fuzz_max_realignments(const pmstep_config_t *cfg) { return cfg->detection.max_realignments; }

/* A float32 value is finite. */
static inline bool fuzz_finite(float x) { return isfinite(x) != 0; }

/* The first @p count floats of a struct made of floats. */
static inline bool fuzz_floats_finite(const void *first, size_t count)
{
    size_t n;
    for (n = 0; n < count; ++n) {
        float value;
        memcpy(&value, (const unsigned char *)first + n * sizeof value, sizeof value);
        if (!fuzz_finite(value)) {
            return false;
        }
    }
    return true;
}

/* Recomputes, through the blocks' public coefficient functions (not the instance), every
 * coefficient init derives from @p cfg with the configured model, and the core's own derived
 * ratios; true if all are finite. Used after an accepted init: init must refuse a configuration
 * for which this is false. */
static inline bool fuzz_derived_coefficients_finite(const pmstep_config_t *cfg)
{
    const pmstep_electrical_t model = pmstep_configured_electrical(cfg);
    pmstep_ref_coeffs_t ref;
    pmstep_angle_coeffs_t angle;
    pmstep_observer_coeffs_t observer;
    pmstep_law_coeffs_t law;
    pmstep_detect_coeffs_t detect;
    pmstep_actuate_coeffs_t actuate;
    pmstep_ref_coeffs_init(&ref, cfg->gains.reference_bandwidth_rad_s, cfg->timing.period_s);
    pmstep_angle_coeffs_init(&angle, cfg, &model);
    pmstep_observer_coeffs_init(&observer, cfg, &model);
    pmstep_law_coeffs_init(&law, cfg, &model);
    pmstep_detect_coeffs_init(&detect, cfg);
    pmstep_actuate_coeffs_init(&actuate, cfg);
    return fuzz_floats_finite(&ref, sizeof ref / sizeof(float))
           && fuzz_floats_finite(&angle, sizeof angle / sizeof(float))
           && fuzz_floats_finite(&observer, sizeof observer / sizeof(float))
           && fuzz_floats_finite(&law, offsetof(pmstep_law_coeffs_t, linear_speed_term) / sizeof(float))
           && fuzz_finite(detect.alpha) && fuzz_finite(detect.angle_step_per_speed)
           && fuzz_finite(detect.consistency_bound_rad) && fuzz_finite(actuate.dead_time_duty)
           && fuzz_finite(actuate.inv_band_per_A);
}

#endif /* PMSTEP_FUZZ_CONFIG_FIELDS_H */
