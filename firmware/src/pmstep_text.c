/* Texts for status, fault and mode codes: a separate library (pmstep_text), so an image
 * without a console carries none of them. */
#include "pmstep/pmstep_text.h"

const char *pmstep_status_str(pmstep_status_t status)
{
    switch (status) {
    case PMSTEP_OK: return "ok";
    case PMSTEP_ERR_NULL_ARGUMENT: return "null argument";
    case PMSTEP_ERR_NONFINITE_PARAMETER: return "a config value is NaN/Inf";
    case PMSTEP_ERR_RESISTANCE: return "R must be > 0";
    case PMSTEP_ERR_INDUCTANCE: return "L must be > 0";
    case PMSTEP_ERR_INERTIA: return "J must be > 0";
    case PMSTEP_ERR_TORQUE_CONSTANT: return "k_M must be > 0";
    case PMSTEP_ERR_FRICTION: return "F must be >= 0";
    case PMSTEP_ERR_POLE_PAIRS: return "p must be >= 1";
    case PMSTEP_ERR_PERIOD: return "T_s must be > 0";
    case PMSTEP_ERR_GAIN: return "gains must be > 0";
    case PMSTEP_ERR_PERIOD_TOO_LONG: return "T_s too long: (R/L + K) T_s >= 0.5";
    case PMSTEP_ERR_ALIGNMENT_CONDITION: return "condition (4) violated";
    case PMSTEP_ERR_ALIGNMENT_VOLTAGE: return "need 0 < u_cs, u_cc <= min bus";
    case PMSTEP_ERR_ALIGNMENT_TIME: return "need T_s <= t_s <= t_c - T_s";
    case PMSTEP_ERR_REFERENCE_BANDWIDTH: return "need 0 < varpi_0 T_s <= 0.5";
    case PMSTEP_ERR_LIMITS: return "need 0 < min bus < max bus, current > 0";
    case PMSTEP_ERR_DELAY: return "delay must be 0 or 1 period";
    case PMSTEP_ERR_BAD_MODE: return "not allowed in this mode";
    case PMSTEP_ERR_BAD_COMMAND_VALUE: return "bad command value";
    case PMSTEP_ERR_ALIGNMENT_CURRENT: return "alignment u/R >= current limit";
    case PMSTEP_ERR_CALIBRATION: return "calibration settings invalid";
    case PMSTEP_ERR_DETECTION: return "detection settings invalid";
    case PMSTEP_ERR_DERIVED_NONFINITE: return "a derived gain is not finite";
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
