/* Texts for status, fault and mode codes: a separate library (pmstep_text), so an image
 * without a console carries none of them. */
#include "pmstep/pmstep_text.h"

const char *pmstep_status_str(pmstep_status_t status)
{
    switch (status) {
    case PMSTEP_OK: return "ok";
    case PMSTEP_ERR_NULL_ARGUMENT: return "null argument";
    case PMSTEP_ERR_BAD_MODE: return "not allowed in this mode";
    case PMSTEP_ERR_BAD_COMMAND_VALUE: return "bad command value";
    case PMSTEP_ERR_NONFINITE_PARAMETER: return "a setting is NaN/Inf";
    case PMSTEP_ERR_DERIVED_NONFINITE: return "a derived gain is not finite";
    case PMSTEP_ERR_RESISTANCE: return "R must be > 0";
    case PMSTEP_ERR_INDUCTANCE: return "L must be > 0";
    case PMSTEP_ERR_INERTIA: return "J must be > 0";
    case PMSTEP_ERR_TORQUE_CONSTANT: return "k_M must be > 0";
    case PMSTEP_ERR_FRICTION: return "F must be >= 0";
    case PMSTEP_ERR_POLE_PAIRS: return "p must be >= 1";
    case PMSTEP_ERR_DETENT_TORQUE: return "detent torque must be >= 0";
    case PMSTEP_ERR_PERIOD: return "need 1 us <= T_s <= 10 ms";
    case PMSTEP_ERR_DELAY: return "delay must be 0 or 1 period";
    case PMSTEP_ERR_SPEED_GAIN: return "k_w must be > 0";
    case PMSTEP_ERR_OBSERVER_GAIN: return "K_e must be > 0";
    case PMSTEP_ERR_CURRENT_GAIN: return "K_i must be > 0";
    case PMSTEP_ERR_ADAPT_GAMMA: return "gamma must be > 0";
    case PMSTEP_ERR_ADAPT_LAMBDA: return "lambda must be > 0";
    case PMSTEP_ERR_ADAPT_R: return "r must be > 0";
    case PMSTEP_ERR_SAT_KAPPA: return "kappa must be > 0";
    case PMSTEP_ERR_OBSERVER_GAIN_FOR_PERIOD: return "need (R/L + K_e) T_s < 0.5";
    case PMSTEP_ERR_CURRENT_GAIN_FOR_PERIOD: return "need (R/L + K_i) T_s < 0.5";
    case PMSTEP_ERR_REFERENCE_BANDWIDTH: return "need 0 < varpi_0 T_s <= 0.5";
    case PMSTEP_ERR_ANGLE_CORRECTION_GAIN: return "need 0 <= g T_s < 0.5";
    case PMSTEP_ERR_CURRENT_INTEGRAL_GAIN: return "need 0 <= K_I <= (R/L + K_i)^2 / 4";
    case PMSTEP_ERR_DETENT_FADE_SPEED: return "detent fade speed < 0";
    case PMSTEP_ERR_ANGLE_SMOOTHING: return "need 0 <= angle smoothing < 1";
    case PMSTEP_ERR_OBSERVER_BOOST: return "need transient observer boost 0, or within [1, 4] with an observer residual bound";
    case PMSTEP_ERR_FIELD_WEAKENING: return "need field weakening current >= 0 below the trip, and if > 0 modulation in (0, 1] and gain > 0";
    case PMSTEP_ERR_EMF_ANGLE_GAIN: return "need 0 <= K_theta < R/L + K_e, w_theta >= 0, and w_theta > 0 with K_theta";
    case PMSTEP_ERR_MAX_CURRENT: return "current limit must be > 0";
    case PMSTEP_ERR_MIN_BUS: return "min bus must be > 0";
    case PMSTEP_ERR_BUS_ORDER: return "need min bus < max bus";
    case PMSTEP_ERR_TRIP_ABOVE_RATED: return "overcurrent trip above 3 x the motor's rated current";
    case PMSTEP_ERR_TRIP_ABOVE_SENSE_RANGE: return "overcurrent trip beyond 95 % of the current sensing's range";
    case PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE: return "overvoltage trip beyond 95 % of the bus sensing's range";
    case PMSTEP_ERR_SENSE_RANGE: return "measurement ranges must be > 0";
    case PMSTEP_ERR_ALIGNMENT_VOLTAGE: return "u_cs, u_cc must be > 0";
    case PMSTEP_ERR_ALIGNMENT_ABOVE_BUS: return "u_cs, u_cc above min bus";
    case PMSTEP_ERR_ALIGNMENT_CURRENT: return "alignment u/R >= current limit";
    case PMSTEP_ERR_S_ALIGN_TIME: return "need t_s >= T_s";
    case PMSTEP_ERR_C_ALIGN_TIME: return "need t_c - t_s >= T_s";
    case PMSTEP_ERR_ALIGNMENT_TOO_LONG: return "t_c over 2^24 periods";
    case PMSTEP_ERR_ALIGNMENT_CONDITION: return "condition (4) violated";
    case PMSTEP_ERR_S_LEAD_IN_TIME: return "need 0 <= lead-in <= t_s - T_s";
    case PMSTEP_ERR_OFFSET_CALIBRATION_TIME: return "offset time < 0 or over 2^24 periods";
    case PMSTEP_ERR_STEADY_STATE_WINDOW: return "window < 0 or over half an alignment";
    case PMSTEP_ERR_INDUCTANCE_WINDOW: return "L window < 0 or over half of t_s";
    case PMSTEP_ERR_ALIGNMENT_OFFSETS_UNMEASURED: return "alignment offsets need a window";
    case PMSTEP_ERR_RESISTANCE_UNMEASURED: return "measured R needs a window";
    case PMSTEP_ERR_INDUCTANCE_UNMEASURED: return "measured L needs an L window or the voltage-bias level";
    case PMSTEP_ERR_TORQUE_CONSTANT_UNMEASURED: return "measured k_M needs a window";
    case PMSTEP_ERR_VOLTAGE_BIAS_FRACTION: return "need 0 <= bias fraction < 1";
    case PMSTEP_ERR_VOLTAGE_BIAS_WINDOW: return "bias needs a window <= 1/4 alignment";
    case PMSTEP_ERR_VOLTAGE_BIAS_SETTLING: return "bias window under 10 L/R";
    case PMSTEP_ERR_DEAD_TIME: return "need 0 <= 4 t_d < T_s";
    case PMSTEP_ERR_DEAD_TIME_BAND: return "band outside [1e-4 A, current limit]";
    case PMSTEP_ERR_DETECTION_BOUND: return "detection bound < 0";
    case PMSTEP_ERR_DETECTION_TIME: return "persistence: 0, or 1 check to 2^24 periods";
    case PMSTEP_ERR_RATED_CURRENT: return "rated current must be > 0";
    case PMSTEP_ERR_BUS_BELOW_RATED: return "bus too low for R x rated current";
    case PMSTEP_ERR_RATE_TOO_SLOW: return "control rate too slow for R/L or F/J";
    case PMSTEP_ERR_SENSE_RANGE_BELOW_RATED: return "current sensing cannot read 1.25 x the rated current";
    case PMSTEP_ERR_DATASHEET_TORQUE_CONSTANT:
        return "k_M far from holding torque / (sqrt(2) rated current): check the units of both";
    case PMSTEP_ERR_DATASHEET_TIME_CONSTANT: return "L/R outside 0.1-20 ms: check the units of R and L";
    case PMSTEP_ERR_DETENT_ABOVE_ALIGNMENT:
        return "detent torque above what the alignment current (condition (4), rating) can pull across";
    case PMSTEP_ERR_DATASHEET_INERTIA: return "rotor inertia far from what the holding torque gives: check its units";
    case PMSTEP_ERR_DATASHEET_FLUX_RATIO:
        return "p L I / k_M outside 0.1-10: the holding torque, the inductance or the current is off";
    case PMSTEP_ERR_IDENTIFICATION_WINDOW: return "identification: 0 to 2^24 periods";
    case PMSTEP_ERR_IDENTIFICATION_SPEED: return "identification speed < 0";
    case PMSTEP_ERR_MECHANICS_UNIDENTIFIED: return "identified J, F used without a window";
    case PMSTEP_ERR_MEASURE_ONLY_WINDOW: return "measure-only commissioning without a steady-state window";
    case PMSTEP_ERR_STEPDIR_MICROSTEPS: return "microsteps per full step not within 1-256";
    case PMSTEP_ERR_STEPDIR_TRACKING: return "step tracker bandwidth not usable";
    case PMSTEP_ERR_STEPDIR_LIMIT: return "following-error limit, stop time or DIAG pulse not > 0";
    case PMSTEP_ERR_STEPDIR_DIAG_MODE: return "DIAG mode neither level nor pulse";
    case PMSTEP_ERR_STEPDIR_STALL_CURRENT: return "STEP/DIR stall current not within 0 to the trip";
    case PMSTEP_ERR_HOMING: return "homing: speed, acceleration, travel, stall error > 0, back-off >= 0, stall current below the trip";
    case PMSTEP_ERR_POSITION_GAIN: return "need 0 < k_theta <= k_w/2";
    case PMSTEP_ERR_POSITION_INTEGRAL_GAIN: return "need 0 <= k_I <= k_theta^2/4";
    case PMSTEP_ERR_HOLD_CURRENT: return "need 0 < hold current < max_phase_current_A and |T_L - T_detent| <= 0.9 k_M I";
    case PMSTEP_ERR_STANDSTILL_KNOWN_LOAD: return "standstill hold not with known_load_mode";
    case PMSTEP_ERR_VECTOR_SPEED: return "need vector speed >= 0, a hold current where > 0, and > 0 for stops only";
    }
    return "unknown status";
}

const char *pmstep_fault_str(pmstep_fault_t fault)
{
    switch (fault) {
    case PMSTEP_FAULT_NONE: return "NONE";
    case PMSTEP_FAULT_MEASUREMENT_NONFINITE: return "MEASUREMENT_NONFINITE";
    case PMSTEP_FAULT_OVERCURRENT: return "OVERCURRENT";
    case PMSTEP_FAULT_BUS_UNDERVOLTAGE: return "BUS_UNDERVOLTAGE";
    case PMSTEP_FAULT_BUS_OVERVOLTAGE: return "BUS_OVERVOLTAGE";
    case PMSTEP_FAULT_STATE_NONFINITE: return "STATE_NONFINITE";
    case PMSTEP_FAULT_ANGLE_MAGNITUDE: return "ANGLE_MAGNITUDE";
    case PMSTEP_FAULT_SPEED_INCONSISTENT: return "SPEED_INCONSISTENT";
    case PMSTEP_FAULT_STALL: return "STALL";
    case PMSTEP_FAULT_COMMISSIONING: return "COMMISSIONING";
    case PMSTEP_FAULT_OBSERVER_RESIDUAL: return "OBSERVER_RESIDUAL";
    case PMSTEP_FAULT_PHASE_VOLTAGE_RANGE: return "PHASE_VOLTAGE_RANGE";
    case PMSTEP_FAULT_ALIGNMENT_MOTION: return "ALIGNMENT_MOTION";
    case PMSTEP_FAULT_OPEN_PHASE_A: return "OPEN_PHASE_A";
    case PMSTEP_FAULT_OPEN_PHASE_B: return "OPEN_PHASE_B";
    case PMSTEP_FAULT_CURRENT_STUCK_A: return "CURRENT_STUCK_A";
    case PMSTEP_FAULT_CURRENT_STUCK_B: return "CURRENT_STUCK_B";
    case PMSTEP_FAULT_ESTIMATE_RANGE: return "ESTIMATE_RANGE";
    }
    return "UNKNOWN";
}

const char *pmstep_mode_str(pmstep_mode_t mode)
{
    switch (mode) {
    case PMSTEP_MODE_IDLE: return "IDLE";
    case PMSTEP_MODE_S_ALIGN: return "S_ALIGN";
    case PMSTEP_MODE_C_ALIGN: return "C_ALIGN";
    case PMSTEP_MODE_RUN: return "RUN";
    case PMSTEP_MODE_FAULT: return "FAULT";
    case PMSTEP_MODE_OFFSET_CAL: return "OFFSET_CAL";
    }
    return "unknown mode";
}

const char *pmstep_identification_str(pmstep_identification_t identification)
{
    switch (identification) {
    case PMSTEP_IDENT_OFF: return "OFF";
    case PMSTEP_IDENT_RUNNING: return "RUNNING";
    case PMSTEP_IDENT_DONE: return "DONE";
    case PMSTEP_IDENT_FRICTION_NEGATIVE: return "FRICTION_NEGATIVE";
    case PMSTEP_IDENT_POOR_EXCITATION: return "POOR_EXCITATION";
    case PMSTEP_IDENT_IMPLAUSIBLE: return "IMPLAUSIBLE";
    }
    return "UNKNOWN";
}
