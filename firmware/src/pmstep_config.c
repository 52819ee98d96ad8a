/* Configuration: validation with one status per cause, texts, the paper's configuration. */
#include "pmstep/pmstep.h"

#include <math.h> /* isfinite: a classification macro, no libm call */
#include <stddef.h>

/* Longest alignment accepted: 2^31 periods keeps step counters far from wrapping. */
#define PMSTEP_MAX_ALIGN_PERIODS 2147483648.0f

pmstep_status_t pmstep_validate_config(const pmstep_config_t *cfg)
{
    if (cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    {
        const float values[] = {
            cfg->resistance_ohm, cfg->inductance_h, cfg->inertia_kg_m2, cfg->friction_nm_s_per_rad,
            cfg->torque_constant_nm_per_a, cfg->period_s, cfg->s_align_time_s, cfg->c_align_time_s,
            cfg->s_align_voltage_v, cfg->c_align_voltage_v, cfg->speed_gain_per_s, cfg->observer_gain_per_s,
            cfg->current_gain_per_s, cfg->adapt_gamma, cfg->adapt_lambda, cfg->adapt_r, cfg->sat_kappa_rad_per_s,
            cfg->reference_bandwidth_rad_per_s, cfg->max_phase_current_a, cfg->min_bus_voltage_v,
            cfg->max_bus_voltage_v};
        size_t n;
        for (n = 0; n < sizeof values / sizeof values[0]; ++n) {
            if (!isfinite(values[n])) {
                return PMSTEP_ERR_NONFINITE_PARAMETER;
            }
        }
    }
    if (!(cfg->resistance_ohm > 0.0f)) {
        return PMSTEP_ERR_RESISTANCE;
    }
    if (!(cfg->inductance_h > 0.0f)) {
        return PMSTEP_ERR_INDUCTANCE;
    }
    if (!(cfg->inertia_kg_m2 > 0.0f)) {
        return PMSTEP_ERR_INERTIA;
    }
    if (!(cfg->torque_constant_nm_per_a > 0.0f)) {
        return PMSTEP_ERR_TORQUE_CONSTANT;
    }
    if (cfg->friction_nm_s_per_rad < 0.0f) {
        return PMSTEP_ERR_FRICTION;
    }
    if (cfg->pole_pairs < 1) {
        return PMSTEP_ERR_POLE_PAIRS;
    }
    if (!(cfg->period_s > 0.0f)) {
        return PMSTEP_ERR_PERIOD;
    }
    if (!(cfg->speed_gain_per_s > 0.0f) || !(cfg->observer_gain_per_s > 0.0f) || !(cfg->current_gain_per_s > 0.0f)
        || !(cfg->adapt_gamma > 0.0f) || !(cfg->adapt_lambda > 0.0f) || !(cfg->adapt_r > 0.0f)
        || !(cfg->sat_kappa_rad_per_s > 0.0f)) {
        return PMSTEP_ERR_GAIN;
    }
    {
        /* Forward-Euler observer and current loop: keep their poles well inside the unit circle. */
        const float r_over_l = cfg->resistance_ohm / cfg->inductance_h;
        if ((r_over_l + cfg->observer_gain_per_s) * cfg->period_s >= 0.5f
            || (r_over_l + cfg->current_gain_per_s) * cfg->period_s >= 0.5f) {
            return PMSTEP_ERR_PERIOD_TOO_LONG;
        }
    }
    if (!(cfg->reference_bandwidth_rad_per_s > 0.0f) || cfg->reference_bandwidth_rad_per_s * cfg->period_s > 0.5f) {
        return PMSTEP_ERR_REFERENCE_BANDWIDTH;
    }
    if (cfg->computational_delay_periods > 1u) {
        return PMSTEP_ERR_DELAY;
    }
    if (!(cfg->max_phase_current_a > 0.0f) || !(cfg->min_bus_voltage_v > 0.0f)
        || !(cfg->max_bus_voltage_v > cfg->min_bus_voltage_v)) {
        return PMSTEP_ERR_LIMITS;
    }
    if (!(cfg->s_align_voltage_v > 0.0f) || !(cfg->c_align_voltage_v > 0.0f)
        || cfg->s_align_voltage_v > cfg->min_bus_voltage_v || cfg->c_align_voltage_v > cfg->min_bus_voltage_v) {
        return PMSTEP_ERR_ALIGNMENT_VOLTAGE;
    }
    if (cfg->s_align_voltage_v >= cfg->max_phase_current_a * cfg->resistance_ohm
        || cfg->c_align_voltage_v >= cfg->max_phase_current_a * cfg->resistance_ohm) {
        return PMSTEP_ERR_ALIGNMENT_CURRENT;
    }
    if (!(cfg->s_align_time_s >= cfg->period_s) || !(cfg->c_align_time_s - cfg->s_align_time_s >= cfg->period_s)
        || cfg->c_align_time_s / cfg->period_s >= PMSTEP_MAX_ALIGN_PERIODS) {
        return PMSTEP_ERR_ALIGNMENT_TIME;
    }
    {
        /* Condition (4): k_M u_cc/(p L R) - (u_cs^2 + u_cc^2)/(2 R^2) > 0. */
        const float r = cfg->resistance_ohm;
        const float margin = cfg->torque_constant_nm_per_a * cfg->c_align_voltage_v
                                 / ((float)cfg->pole_pairs * cfg->inductance_h * r)
                             - (cfg->s_align_voltage_v * cfg->s_align_voltage_v
                                + cfg->c_align_voltage_v * cfg->c_align_voltage_v)
                                   / (2.0f * r * r);
        if (!(margin > 0.0f)) {
            return PMSTEP_ERR_ALIGNMENT_CONDITION;
        }
    }
    return PMSTEP_OK;
}

const char *pmstep_status_str(pmstep_status_t status)
{
    switch (status) {
    case PMSTEP_OK: return "ok";
    case PMSTEP_ERR_NULL_ARGUMENT: return "null argument";
    case PMSTEP_ERR_NONFINITE_PARAMETER: return "a configuration value is NaN or infinite";
    case PMSTEP_ERR_RESISTANCE: return "resistance R must be > 0";
    case PMSTEP_ERR_INDUCTANCE: return "inductance L must be > 0";
    case PMSTEP_ERR_INERTIA: return "inertia J must be > 0";
    case PMSTEP_ERR_TORQUE_CONSTANT: return "torque constant k_M must be > 0";
    case PMSTEP_ERR_FRICTION: return "friction F must be >= 0";
    case PMSTEP_ERR_POLE_PAIRS: return "pole pairs p must be >= 1";
    case PMSTEP_ERR_PERIOD: return "control period must be > 0";
    case PMSTEP_ERR_GAIN: return "gains k_omega, K_e, K_i, gamma, lambda, r, kappa must be > 0";
    case PMSTEP_ERR_PERIOD_TOO_LONG: return "period too long for the loop: (R/L + K_e) T_s and (R/L + K_i) T_s must be < 0.5";
    case PMSTEP_ERR_ALIGNMENT_CONDITION: return "condition (4) violated: k_M u_cc/(p L R) - (u_cs^2 + u_cc^2)/(2 R^2) must be > 0";
    case PMSTEP_ERR_ALIGNMENT_VOLTAGE: return "alignment voltages must be > 0 and not above the minimum bus voltage";
    case PMSTEP_ERR_ALIGNMENT_TIME: return "alignment times must satisfy T_s <= t_s and t_s + T_s <= t_c";
    case PMSTEP_ERR_REFERENCE_BANDWIDTH: return "reference bandwidth varpi_0 must be > 0 with varpi_0 T_s <= 0.5";
    case PMSTEP_ERR_LIMITS: return "limits must satisfy max current > 0 and 0 < min bus < max bus";
    case PMSTEP_ERR_DELAY: return "computational delay must be 0 or 1 period";
    case PMSTEP_ERR_BAD_MODE: return "command not allowed in the present mode";
    case PMSTEP_ERR_BAD_COMMAND_VALUE: return "command value NaN/infinite or ramp rate not > 0";
    case PMSTEP_ERR_ALIGNMENT_CURRENT: return "alignment current u/R must be below the overcurrent limit";
    }
    return "unknown status";
}

const char *pmstep_fault_str(pmstep_fault_t fault)
{
    switch (fault) {
    case PMSTEP_FAULT_NONE: return "none";
    case PMSTEP_FAULT_MEASUREMENT_NONFINITE: return "measurement NaN or infinite";
    case PMSTEP_FAULT_OVERCURRENT: return "phase overcurrent";
    case PMSTEP_FAULT_BUS_UNDERVOLTAGE: return "bus undervoltage";
    case PMSTEP_FAULT_BUS_OVERVOLTAGE: return "bus overvoltage";
    case PMSTEP_FAULT_STATE_NONFINITE: return "internal estimate NaN or infinite";
    }
    return "unknown fault";
}

const char *pmstep_mode_str(pmstep_mode_t mode)
{
    switch (mode) {
    case PMSTEP_MODE_IDLE: return "IDLE";
    case PMSTEP_MODE_S_ALIGN: return "S_ALIGN";
    case PMSTEP_MODE_C_ALIGN: return "C_ALIGN";
    case PMSTEP_MODE_RUN: return "RUN";
    case PMSTEP_MODE_FAULT: return "FAULT";
    }
    return "unknown mode";
}

pmstep_config_t pmstep_paper_config(void)
{
    pmstep_config_t cfg;
    /* Motor of Section III.B. */
    cfg.resistance_ohm = 3.0f;
    cfg.inductance_h = 0.006f;
    cfg.inertia_kg_m2 = 0.01f;
    cfg.friction_nm_s_per_rad = 0.0f;
    cfg.torque_constant_nm_per_a = 2.0f;
    cfg.pole_pairs = 6;
    cfg.period_s = 50e-6f;
    cfg.computational_delay_periods = 0u;
    cfg.s_align_time_s = 0.3f;
    cfg.c_align_time_s = 0.6f;
    cfg.s_align_voltage_v = 24.0f;
    cfg.c_align_voltage_v = 24.0f;
    cfg.speed_gain_per_s = 100.0f;
    cfg.observer_gain_per_s = 100.0f;
    cfg.current_gain_per_s = 20.0f;
    cfg.adapt_gamma = 0.01f / 9.0f;
    cfg.adapt_lambda = 0.2f;
    cfg.adapt_r = 1.0f;
    cfg.sat_kappa_rad_per_s = 9.0f;
    cfg.reference_bandwidth_rad_per_s = 300.0f;
    cfg.known_load_mode = false;
    /* Drive limits (not in the paper): 48 V bus, alignment draws u/R = 8 A. */
    cfg.max_phase_current_a = 15.0f;
    cfg.min_bus_voltage_v = 30.0f;
    cfg.max_bus_voltage_v = 60.0f;
    return cfg;
}
