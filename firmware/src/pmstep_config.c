/* Configuration validation: one status code per cause, group by group. */
#include "pmstep/pmstep.h"
#include "pmstep_internal.h"

#include <math.h> /* isfinite: a classification macro, no libm call */
#include <stddef.h>
#include <string.h> /* memcpy of one float: a load */

/* A duration setting: not negative, and at most PMSTEP_MAX_DURATION_PERIODS periods, so its
 * conversion to a period count (pmstep_periods_in()) is exact and defined. */
static bool duration_ok(float duration_s, float period_s)
{
    return duration_s >= 0.0f && duration_s / period_s <= PMSTEP_MAX_DURATION_PERIODS;
}

/* Every float setting, with the sign it must have and the code of each, group by group. One
 * table instead of a comparison each keeps the core within its flash budget. */
#define SIGN_ANY 0u          /* any finite value */
#define SIGN_NON_NEGATIVE 1u /* >= 0 */
#define SIGN_POSITIVE 2u     /* > 0 */
typedef struct {
    unsigned char offset; /* offsetof the float in pmstep_config_t (below 256: test_core_config.c) */
    unsigned char sign;   /* SIGN_ANY, SIGN_NON_NEGATIVE or SIGN_POSITIVE */
    signed char status;   /* pmstep_status_t when the sign is wrong */
} sign_rule_t;

#define SIGN_RULE(field, sign, status) {(unsigned char)offsetof(pmstep_config_t, field), sign, (signed char)(status)}

/* The float at @p rule's offset. */
static float rule_value(const pmstep_config_t *cfg, const sign_rule_t *rule)
{
    float value;
    memcpy(&value, (const unsigned char *)cfg + rule->offset, sizeof value);
    return value;
}

/* Every float setting of the configuration with its sign and the code of a wrong one. */
static const sign_rule_t sign_rules[] = {
    SIGN_RULE(motor.resistance_Ohm, SIGN_POSITIVE, PMSTEP_ERR_RESISTANCE),
    SIGN_RULE(motor.inductance_H, SIGN_POSITIVE, PMSTEP_ERR_INDUCTANCE),
    SIGN_RULE(motor.inertia_kgm2, SIGN_POSITIVE, PMSTEP_ERR_INERTIA),
    SIGN_RULE(motor.torque_constant_Nm_A, SIGN_POSITIVE, PMSTEP_ERR_TORQUE_CONSTANT),
    SIGN_RULE(motor.friction_Nms_rad, SIGN_NON_NEGATIVE, PMSTEP_ERR_FRICTION),
    SIGN_RULE(motor.detent_torque_Nm, SIGN_NON_NEGATIVE, PMSTEP_ERR_DETENT_TORQUE),
    SIGN_RULE(motor.rated_current_A, SIGN_POSITIVE, PMSTEP_ERR_RATED_CURRENT),
    SIGN_RULE(gains.speed_gain_per_s, SIGN_POSITIVE, PMSTEP_ERR_SPEED_GAIN),
    SIGN_RULE(gains.observer_gain_per_s, SIGN_POSITIVE, PMSTEP_ERR_OBSERVER_GAIN),
    SIGN_RULE(gains.current_gain_per_s, SIGN_POSITIVE, PMSTEP_ERR_CURRENT_GAIN),
    SIGN_RULE(gains.adapt_gamma, SIGN_POSITIVE, PMSTEP_ERR_ADAPT_GAMMA),
    SIGN_RULE(gains.adapt_lambda, SIGN_POSITIVE, PMSTEP_ERR_ADAPT_LAMBDA),
    SIGN_RULE(gains.adapt_r, SIGN_POSITIVE, PMSTEP_ERR_ADAPT_R),
    SIGN_RULE(gains.sat_kappa_rad_s, SIGN_POSITIVE, PMSTEP_ERR_SAT_KAPPA),
    SIGN_RULE(gains.reference_bandwidth_rad_s, SIGN_POSITIVE, PMSTEP_ERR_REFERENCE_BANDWIDTH),
    SIGN_RULE(gains.angle_correction_gain_per_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_ANGLE_CORRECTION_GAIN),
    SIGN_RULE(gains.current_integral_gain_per_s2, SIGN_NON_NEGATIVE, PMSTEP_ERR_CURRENT_INTEGRAL_GAIN),
    SIGN_RULE(gains.current_integral_gain_q_per_s2, SIGN_NON_NEGATIVE, PMSTEP_ERR_CURRENT_INTEGRAL_GAIN),
    SIGN_RULE(gains.detent_fade_speed_rad_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_DETENT_FADE_SPEED),
    SIGN_RULE(gains.emf_angle_gain_per_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_EMF_ANGLE_GAIN),
    SIGN_RULE(gains.emf_angle_corner_rad_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_EMF_ANGLE_GAIN),
    SIGN_RULE(gains.angle_smoothing, SIGN_NON_NEGATIVE, PMSTEP_ERR_ANGLE_SMOOTHING),
    SIGN_RULE(gains.transient_observer_boost, SIGN_NON_NEGATIVE, PMSTEP_ERR_OBSERVER_BOOST),
    SIGN_RULE(limits.max_phase_current_A, SIGN_POSITIVE, PMSTEP_ERR_MAX_CURRENT),
    SIGN_RULE(limits.min_bus_voltage_V, SIGN_POSITIVE, PMSTEP_ERR_MIN_BUS),
    SIGN_RULE(limits.current_sense_range_A, SIGN_POSITIVE, PMSTEP_ERR_SENSE_RANGE),
    SIGN_RULE(limits.bus_sense_range_V, SIGN_POSITIVE, PMSTEP_ERR_SENSE_RANGE),
    SIGN_RULE(alignment.s_align_voltage_V, SIGN_POSITIVE, PMSTEP_ERR_ALIGNMENT_VOLTAGE),
    SIGN_RULE(alignment.c_align_voltage_V, SIGN_POSITIVE, PMSTEP_ERR_ALIGNMENT_VOLTAGE),
    SIGN_RULE(alignment.s_lead_in_time_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_S_LEAD_IN_TIME),
    SIGN_RULE(commissioning.offset_calibration_time_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_OFFSET_CALIBRATION_TIME),
    SIGN_RULE(commissioning.steady_state_window_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_STEADY_STATE_WINDOW),
    SIGN_RULE(commissioning.inductance_window_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_INDUCTANCE_WINDOW),
    SIGN_RULE(commissioning.voltage_bias_level_fraction, SIGN_NON_NEGATIVE, PMSTEP_ERR_VOLTAGE_BIAS_FRACTION),
    SIGN_RULE(commissioning.identification_time_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_IDENTIFICATION_WINDOW),
    SIGN_RULE(commissioning.identification_min_speed_rad_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_IDENTIFICATION_SPEED),
    SIGN_RULE(inverter.dead_time_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_DEAD_TIME),
    SIGN_RULE(inverter.dead_time_current_band_A, SIGN_NON_NEGATIVE, PMSTEP_ERR_DEAD_TIME_BAND),
    SIGN_RULE(detection.angle_magnitude_bound, SIGN_NON_NEGATIVE, PMSTEP_ERR_DETECTION_BOUND),
    SIGN_RULE(detection.speed_consistency_bound_rad_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_DETECTION_BOUND),
    SIGN_RULE(detection.stall_speed_error_rad_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_DETECTION_BOUND),
    SIGN_RULE(detection.observer_residual_bound_A, SIGN_NON_NEGATIVE, PMSTEP_ERR_DETECTION_BOUND),
    SIGN_RULE(detection.persistence_s, SIGN_NON_NEGATIVE, PMSTEP_ERR_DETECTION_TIME),
    SIGN_RULE(field_weakening.max_current_A, SIGN_NON_NEGATIVE, PMSTEP_ERR_FIELD_WEAKENING),
    /* Checked by range below. */
    SIGN_RULE(timing.period_s, SIGN_ANY, PMSTEP_OK),
    SIGN_RULE(alignment.s_align_time_s, SIGN_ANY, PMSTEP_OK),
    SIGN_RULE(alignment.c_align_time_s, SIGN_ANY, PMSTEP_OK),
    SIGN_RULE(limits.max_bus_voltage_V, SIGN_ANY, PMSTEP_OK),
    SIGN_RULE(standstill.hold_current_A, SIGN_ANY, PMSTEP_OK), /* its code is below a signed char's range */
    SIGN_RULE(standstill.vector_speed_rad_s, SIGN_ANY, PMSTEP_OK), /* so is this one's */
    SIGN_RULE(field_weakening.modulation, SIGN_ANY, PMSTEP_OK),
    SIGN_RULE(field_weakening.gain_A_per_s, SIGN_ANY, PMSTEP_OK),
};

/* Every float finite first (whatever its place), then the signs in table order. */
static pmstep_status_t validate_signs(const pmstep_config_t *cfg)
{
    size_t n;
    for (n = 0; n < sizeof sign_rules / sizeof sign_rules[0]; ++n) {
        if (!isfinite(rule_value(cfg, &sign_rules[n]))) {
            return PMSTEP_ERR_NONFINITE_PARAMETER;
        }
    }
    for (n = 0; n < sizeof sign_rules / sizeof sign_rules[0]; ++n) {
        const float value = rule_value(cfg, &sign_rules[n]);
        if ((sign_rules[n].sign == SIGN_POSITIVE && !(value > 0.0f))
            || (sign_rules[n].sign == SIGN_NON_NEGATIVE && value < 0.0f)) {
            return (pmstep_status_t)sign_rules[n].status;
        }
    }
    return cfg->motor.pole_pairs < 1 ? PMSTEP_ERR_POLE_PAIRS : PMSTEP_OK;
}

static pmstep_status_t validate_timing(const pmstep_timing_config_t *timing)
{
    if (!(timing->period_s >= PMSTEP_MIN_PERIOD_S && timing->period_s <= PMSTEP_MAX_PERIOD_S)) {
        return PMSTEP_ERR_PERIOD;
    }
    if (timing->computational_delay_periods > 1u) {
        return PMSTEP_ERR_DELAY;
    }
    return PMSTEP_OK;
}

static pmstep_status_t validate_gains(const pmstep_config_t *cfg)
{
    const pmstep_gains_config_t *gains = &cfg->gains;
    const float period_s = cfg->timing.period_s;
    const float r_over_l = cfg->motor.resistance_Ohm / cfg->motor.inductance_H;
    /* Forward-Euler observer and current loop: keep their poles well inside the unit circle. */
    if ((r_over_l + gains->observer_gain_per_s) * period_s >= 0.5f) {
        return PMSTEP_ERR_OBSERVER_GAIN_FOR_PERIOD;
    }
    if ((r_over_l + gains->current_gain_per_s) * period_s >= 0.5f) {
        return PMSTEP_ERR_CURRENT_GAIN_FOR_PERIOD;
    }
    if (gains->reference_bandwidth_rad_s * period_s > 0.5f) {
        return PMSTEP_ERR_REFERENCE_BANDWIDTH;
    }
    if (gains->angle_correction_gain_per_s * period_s >= 0.5f) {
        return PMSTEP_ERR_ANGLE_CORRECTION_GAIN;
    }
    /* The back-EMF correction reads a residual that settles at R/L + K_e: it must be slower. Without a
     * corner its fade-in w-hat / (w-hat^2 + w_theta^2) would be 1 / w-hat, unbounded at rest. */
    if ((gains->emf_angle_gain_per_s >= r_over_l + gains->observer_gain_per_s)
        || ((gains->emf_angle_gain_per_s > 0.0f) && !(gains->emf_angle_corner_rad_s > 0.0f))) {
        return PMSTEP_ERR_EMF_ANGLE_GAIN;
    }
    if (gains->angle_smoothing >= 1.0f) { /* 1 would never read the integrals again */
        return PMSTEP_ERR_ANGLE_SMOOTHING;
    }
    /* A boost below 1 would slow the observer in the transient; it acts only beyond the residual bound. */
    if ((gains->transient_observer_boost > 0.0f)
        && ((gains->transient_observer_boost < 1.0f) || (gains->transient_observer_boost > PMSTEP_OBSERVER_BOOST_MAX)
            || !(cfg->detection.observer_residual_bound_A > 0.0f))) {
        return PMSTEP_ERR_OBSERVER_BOOST;
    }
    {
        /* e'' + K e' + K_I e = 0, K = R/L + K_i: real poles need K_I <= K^2/4. */
        const float loop_per_s = r_over_l + gains->current_gain_per_s;
        const float largest_integral_per_s2 = 0.25f * loop_per_s * loop_per_s;
        if ((gains->current_integral_gain_per_s2 > largest_integral_per_s2)
            || (gains->current_integral_gain_q_per_s2 > largest_integral_per_s2)) {
            return PMSTEP_ERR_CURRENT_INTEGRAL_GAIN;
        }
    }
    return PMSTEP_OK;
}

/* The protections: ordered, and bounded by the motor's rating and by what the drive can measure,
 * so that no setting switches a trip off. */
static pmstep_status_t validate_limits(const pmstep_config_t *cfg)
{
    const pmstep_limits_config_t *limits = &cfg->limits;
    if (!(limits->max_bus_voltage_V > limits->min_bus_voltage_V)) {
        return PMSTEP_ERR_BUS_ORDER;
    }
    if (limits->max_phase_current_A > (PMSTEP_MAX_TRIP_PER_RATED_CURRENT * cfg->motor.rated_current_A)) {
        return PMSTEP_ERR_TRIP_ABOVE_RATED;
    }
    if (limits->max_phase_current_A > (PMSTEP_SENSE_RANGE_USABLE_FRACTION * limits->current_sense_range_A)) {
        return PMSTEP_ERR_TRIP_ABOVE_SENSE_RANGE;
    }
    if (limits->max_bus_voltage_V > (PMSTEP_SENSE_RANGE_USABLE_FRACTION * limits->bus_sense_range_V)) {
        return PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE;
    }
    return PMSTEP_OK;
}

static pmstep_status_t validate_alignment(const pmstep_config_t *cfg)
{
    const pmstep_alignment_config_t *align = &cfg->alignment;
    const float period_s = cfg->timing.period_s;
    if (align->s_align_voltage_V > cfg->limits.min_bus_voltage_V
        || align->c_align_voltage_V > cfg->limits.min_bus_voltage_V) {
        return PMSTEP_ERR_ALIGNMENT_ABOVE_BUS;
    }
    if (align->s_align_voltage_V >= cfg->limits.max_phase_current_A * cfg->motor.resistance_Ohm
        || align->c_align_voltage_V >= cfg->limits.max_phase_current_A * cfg->motor.resistance_Ohm) {
        return PMSTEP_ERR_ALIGNMENT_CURRENT;
    }
    if (!(align->s_align_time_s >= period_s)) {
        return PMSTEP_ERR_S_ALIGN_TIME;
    }
    if (!(align->c_align_time_s - align->s_align_time_s >= period_s)) {
        return PMSTEP_ERR_C_ALIGN_TIME;
    }
    if (!((align->s_align_time_s - align->s_lead_in_time_s) >= period_s)) {
        return PMSTEP_ERR_S_LEAD_IN_TIME;
    }
    if (!duration_ok(align->c_align_time_s, period_s)) {
        return PMSTEP_ERR_ALIGNMENT_TOO_LONG;
    }
    {
        /* Condition (4): k_M u_cc/(p L R) - (u_cs^2 + u_cc^2)/(2 R^2) > 0. */
        const float r = cfg->motor.resistance_Ohm;
        const float margin = cfg->motor.torque_constant_Nm_A * align->c_align_voltage_V
                                 / ((float)cfg->motor.pole_pairs * cfg->motor.inductance_H * r)
                             - (align->s_align_voltage_V * align->s_align_voltage_V
                                + align->c_align_voltage_V * align->c_align_voltage_V)
                                   / (2.0f * r * r);
        if (!(margin > 0.0f)) {
            return PMSTEP_ERR_ALIGNMENT_CONDITION;
        }
    }
    return PMSTEP_OK;
}

/* Remark 2 calibration and commissioning (alignment times already checked). The windows are
 * compared with the alignments in whole periods, as the commissioning plan counts them
 * (pmstep_periods_in()): a difference of two float times can fall a rounding step short of a
 * window that fits exactly. */
/* What is used must be measured: offsets, R and k_M need the steady-state windows (@p window), L its
 * rise window or the level drops of the voltage-bias option. */
static pmstep_status_t validate_measured_uses(const pmstep_commissioning_config_t *comm, bool window)
{
    pmstep_status_t status = PMSTEP_OK;
    if (comm->alignment_offset_calibration && !window) {
        status = PMSTEP_ERR_ALIGNMENT_OFFSETS_UNMEASURED;
    } else if (comm->use_measured_resistance && !window) {
        status = PMSTEP_ERR_RESISTANCE_UNMEASURED;
    } else if (comm->use_measured_inductance && !(comm->inductance_window_s > 0.0f)
               && !(window && comm->voltage_bias_level_fraction > 0.0f)) {
        status = PMSTEP_ERR_INDUCTANCE_UNMEASURED;
    } else if (comm->use_measured_torque_constant && !window) {
        status = PMSTEP_ERR_TORQUE_CONSTANT_UNMEASURED;
    } else {
        /* every constant used is measured */
    }
    return status;
}

static pmstep_status_t validate_commissioning(const pmstep_config_t *cfg)
{
    const pmstep_commissioning_config_t *comm = &cfg->commissioning;
    const float period_s = cfg->timing.period_s;
    const uint32_t s_align_steps = pmstep_periods_in(cfg->alignment.s_align_time_s, period_s)
                                   - pmstep_periods_in(cfg->alignment.s_lead_in_time_s, period_s); /* (3) proper */
    const uint32_t c_align_steps = pmstep_periods_in(cfg->alignment.c_align_time_s, period_s)
                                   - pmstep_periods_in(cfg->alignment.s_align_time_s, period_s);
    const uint32_t shorter_steps = s_align_steps < c_align_steps ? s_align_steps : c_align_steps;
    const bool window = comm->steady_state_window_s > 0.0f;
    pmstep_status_t status;
    if (!duration_ok(comm->offset_calibration_time_s, cfg->timing.period_s)) {
        return PMSTEP_ERR_OFFSET_CALIBRATION_TIME;
    }
    /* Each window counted in periods only once duration_ok() has bounded it (the conversion of a
     * larger float to uint32_t is undefined). */
    if (!duration_ok(comm->steady_state_window_s, period_s)
        || (2u * pmstep_periods_in(comm->steady_state_window_s, period_s)) > shorter_steps) {
        return PMSTEP_ERR_STEADY_STATE_WINDOW;
    }
    if (!duration_ok(comm->inductance_window_s, period_s)
        || (2u * pmstep_periods_in(comm->inductance_window_s, period_s)) > s_align_steps) {
        return PMSTEP_ERR_INDUCTANCE_WINDOW;
    }
    status = validate_measured_uses(comm, window);
    if (status != PMSTEP_OK) {
        return status;
    }
    if (comm->voltage_bias_level_fraction >= 1.0f) {
        return PMSTEP_ERR_VOLTAGE_BIAS_FRACTION;
    }
    if (comm->voltage_bias_level_fraction > 0.0f) {
        /* Two windows (2 W) in the second half of each alignment, and W/2 of settling at the
         * lower level: at least 5 L/R. */
        if (!window || (4u * pmstep_periods_in(comm->steady_state_window_s, period_s)) > shorter_steps) {
            return PMSTEP_ERR_VOLTAGE_BIAS_WINDOW;
        }
        if (comm->steady_state_window_s * cfg->motor.resistance_Ohm < 10.0f * cfg->motor.inductance_H) {
            return PMSTEP_ERR_VOLTAGE_BIAS_SETTLING;
        }
    }
    /* J and F identified in RUN: a window of whole periods; what is used must be identified. */
    if (!duration_ok(comm->identification_time_s, cfg->timing.period_s)) {
        return PMSTEP_ERR_IDENTIFICATION_WINDOW;
    }
    if (comm->use_identified_mechanics && !(comm->identification_time_s > 0.0f)) {
        return PMSTEP_ERR_MECHANICS_UNIDENTIFIED;
    }
    if (comm->measure_only && !(comm->steady_state_window_s > 0.0f)) {
        return PMSTEP_ERR_MEASURE_ONLY_WINDOW;
    }
    return PMSTEP_OK;
}

static pmstep_status_t validate_inverter(const pmstep_config_t *cfg)
{
    const pmstep_inverter_config_t *inverter = &cfg->inverter;
    const bool compensating = inverter->dead_time_s > 0.0f || cfg->commissioning.voltage_bias_level_fraction > 0.0f;
    if (2.0f * inverter->dead_time_s >= 0.5f * cfg->timing.period_s) {
        return PMSTEP_ERR_DEAD_TIME;
    }
    if (compensating
        && !(inverter->dead_time_current_band_A >= PMSTEP_MIN_CURRENT_BAND_A
             && inverter->dead_time_current_band_A <= cfg->limits.max_phase_current_A)) {
        return PMSTEP_ERR_DEAD_TIME_BAND;
    }
    return PMSTEP_OK;
}

static pmstep_status_t validate_detection(const pmstep_config_t *cfg)
{
    const pmstep_detection_config_t *det = &cfg->detection;
    const float period_s = cfg->timing.period_s;
    const bool any_detector = det->angle_magnitude_bound > 0.0f || det->speed_consistency_bound_rad_s > 0.0f
                              || det->stall_speed_error_rad_s > 0.0f || det->observer_residual_bound_A > 0.0f;
    /* The persistence is 0 (only with every detector off) or at least one check. */
    if (!(det->persistence_s >= (float)PMSTEP_DETECTION_DECIMATION * period_s
          || (det->persistence_s == 0.0f && !any_detector))
        || !duration_ok(det->persistence_s, period_s)) {
        return PMSTEP_ERR_DETECTION_TIME;
    }
    return PMSTEP_OK;
}

/* The standstill hold of speed mode (pmstep_hold.h): below the trip current, and a vector hold
 * needs controller (6); its low-speed drive needs the hold. */
static pmstep_status_t validate_standstill(const pmstep_config_t *cfg)
{
    const float current_A = cfg->standstill.hold_current_A;
    const float band_rad_s = cfg->standstill.vector_speed_rad_s;
    if (current_A < 0.0f || (current_A > 0.0f && !(current_A < cfg->limits.max_phase_current_A))) {
        return PMSTEP_ERR_HOLD_CURRENT;
    }
    if (band_rad_s < 0.0f || (band_rad_s > 0.0f && !(current_A > 0.0f))
        || (cfg->standstill.stops_only && !(band_rad_s > 0.0f))) {
        return PMSTEP_ERR_VECTOR_SPEED; /* the low-speed drive turns the hold's vector, in stops or at all */
    }
    return (current_A > 0.0f && cfg->known_load_mode) ? PMSTEP_ERR_STANDSTILL_KNOWN_LOAD : PMSTEP_OK;
}

/* Field weakening (pmstep_weakening.h): within the trip current, and when on, a share of the bus
 * and a rate to reach it. */
static pmstep_status_t validate_field_weakening(const pmstep_field_weakening_config_t *fw, float max_phase_current_A)
{
    if (!(fw->max_current_A < max_phase_current_A)) {
        return PMSTEP_ERR_FIELD_WEAKENING;
    }
    if ((fw->max_current_A > 0.0f)
        && !((fw->modulation > 0.0f) && (fw->modulation <= 1.0f) && (fw->gain_A_per_s > 0.0f))) {
        return PMSTEP_ERR_FIELD_WEAKENING;
    }
    return PMSTEP_OK;
}

pmstep_status_t pmstep_check_settings(const pmstep_config_t *cfg)
{
    pmstep_status_t status;
    if (cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    /* The signs first (sign_rules), then each group in turn; later groups may rely on the
     * earlier ones. */
    status = validate_signs(cfg);
    if (status == PMSTEP_OK) {
        status = validate_timing(&cfg->timing);
    }
    if (status == PMSTEP_OK) {
        status = validate_gains(cfg);
    }
    if (status == PMSTEP_OK) {
        status = validate_limits(cfg);
    }
    if (status == PMSTEP_OK) {
        status = validate_alignment(cfg);
    }
    if (status == PMSTEP_OK) {
        status = validate_commissioning(cfg);
    }
    if (status == PMSTEP_OK) {
        status = validate_inverter(cfg);
    }
    if (status == PMSTEP_OK) {
        status = validate_detection(cfg);
    }
    if (status == PMSTEP_OK) {
        status = validate_standstill(cfg);
    }
    if (status == PMSTEP_OK) {
        status = validate_field_weakening(&cfg->field_weakening, cfg->limits.max_phase_current_A);
    }
    return status;
}

pmstep_status_t pmstep_validate_config(const pmstep_config_t *cfg)
{
    pmstep_derived_t derived; /* what init derives into its instance */
    pmstep_status_t status = pmstep_check_settings(cfg);
    if (status == PMSTEP_OK) {
        pmstep_derive(&derived, cfg);
        if (!pmstep_derived_finite(&derived)) {
            status = PMSTEP_ERR_DERIVED_NONFINITE;
        }
    }
    return status;
}
