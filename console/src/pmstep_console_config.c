/*
 * The configuration values the console reads and writes by name or id, the application's
 * configuration, and the two values the images read (period, delay). The only file of the
 * console, the applications and their tests that names fields of pmstep_config_t: a change of
 * the core's configuration layout is an edit of this file alone.
 */
#include <stddef.h>

#include "pmstep_console.h"

#define F32(field) {#field, PMSTEP_CONSOLE_CFG_F32, 0u, (uint16_t)offsetof(pmstep_config_t, field)}
#define U32(field) {#field, PMSTEP_CONSOLE_CFG_U32, 0u, (uint16_t)offsetof(pmstep_config_t, field)}
#define I32(field) {#field, PMSTEP_CONSOLE_CFG_I32, 0u, (uint16_t)offsetof(pmstep_config_t, field)}
#define BOOL(field) {#field, PMSTEP_CONSOLE_CFG_BOOL, 0u, (uint16_t)offsetof(pmstep_config_t, field)}
/* Fixed by the port (the carrier and where the duties load): never set from the console. */
#define F32_RO(field) {#field, PMSTEP_CONSOLE_CFG_F32, PMSTEP_CONSOLE_CFG_READ_ONLY, (uint16_t)offsetof(pmstep_config_t, field)}
#define U32_RO(field) {#field, PMSTEP_CONSOLE_CFG_U32, PMSTEP_CONSOLE_CFG_READ_ONLY, (uint16_t)offsetof(pmstep_config_t, field)}

/* Ids are the positions in this table: append, never reorder. */
static const pmstep_console_config_entry_t table[] = {
    F32(resistance_ohm),
    F32(inductance_h),
    F32(inertia_kg_m2),
    F32(friction_nm_s_per_rad),
    F32(torque_constant_nm_per_a),
    I32(pole_pairs),
    F32_RO(period_s),
    U32_RO(computational_delay_periods),
    F32(s_align_time_s),
    F32(c_align_time_s),
    F32(s_align_voltage_v),
    F32(c_align_voltage_v),
    F32(speed_gain_per_s),
    F32(observer_gain_per_s),
    F32(current_gain_per_s),
    F32(adapt_gamma),
    F32(adapt_lambda),
    F32(adapt_r),
    F32(sat_kappa_rad_per_s),
    F32(reference_bandwidth_rad_per_s),
    BOOL(known_load_mode),
    F32(max_phase_current_a),
    F32(min_bus_voltage_v),
    F32(max_bus_voltage_v),
    F32(offset_calibration_time_s),
    BOOL(alignment_offset_calibration),
    F32(steady_state_window_s),
    F32(inductance_window_s),
    BOOL(use_commissioned_resistance),
    BOOL(use_commissioned_inductance),
    BOOL(use_commissioned_torque_constant),
    F32(voltage_bias_level_fraction),
    F32(dead_time_s),
    F32(dead_time_current_band_a),
    F32(angle_correction_gain_per_s),
    F32(angle_magnitude_bound),
    F32(speed_consistency_bound_rad_s),
    F32(stall_speed_error_rad_s),
    F32(observer_residual_bound_a),
    F32(detection_time_s),
    U32(max_realignments),
};

const pmstep_console_config_entry_t *pmstep_console_config_table(uint32_t *count)
{
    if (count != NULL) {
        *count = (uint32_t)(sizeof table / sizeof table[0]);
    }
    return table;
}

bool pmstep_console_config_get(const pmstep_config_t *cfg, uint32_t id, float *value)
{
    const unsigned char *base = (const unsigned char *)cfg;
    if (id >= sizeof table / sizeof table[0]) {
        return false;
    }
    switch (table[id].type) {
    case PMSTEP_CONSOLE_CFG_F32:
        *value = *(const float *)(const void *)(base + table[id].offset);
        break;
    case PMSTEP_CONSOLE_CFG_U32:
        *value = (float)*(const uint32_t *)(const void *)(base + table[id].offset);
        break;
    case PMSTEP_CONSOLE_CFG_I32:
        *value = (float)*(const int32_t *)(const void *)(base + table[id].offset);
        break;
    default:
        *value = *(const bool *)(const void *)(base + table[id].offset) ? 1.0f : 0.0f;
        break;
    }
    return true;
}

int pmstep_console_config_set(pmstep_config_t *cfg, uint32_t id, float value)
{
    unsigned char *base = (unsigned char *)cfg;
    if (id >= sizeof table / sizeof table[0]) {
        return PMSTEP_CONSOLE_ERR_UNKNOWN_CONFIG;
    }
    if ((table[id].flags & PMSTEP_CONSOLE_CFG_READ_ONLY) != 0u) {
        return PMSTEP_CONSOLE_ERR_READ_ONLY;
    }
    if (!((value - value) == 0.0f)) {
        return PMSTEP_CONSOLE_ERR_BAD_VALUE; /* NaN, Inf */
    }
    switch (table[id].type) {
    case PMSTEP_CONSOLE_CFG_F32:
        *(float *)(void *)(base + table[id].offset) = value;
        return 0;
    case PMSTEP_CONSOLE_CFG_U32:
        /* An integer from 0 to 2^24 (exact in a float), given exactly. */
        if (!(value >= 0.0f && value <= 16777216.0f) || (float)(uint32_t)value != value) {
            return PMSTEP_CONSOLE_ERR_BAD_VALUE;
        }
        *(uint32_t *)(void *)(base + table[id].offset) = (uint32_t)value;
        return 0;
    case PMSTEP_CONSOLE_CFG_I32:
        if (!(value >= -16777216.0f && value <= 16777216.0f) || (float)(int32_t)value != value) {
            return PMSTEP_CONSOLE_ERR_BAD_VALUE;
        }
        *(int32_t *)(void *)(base + table[id].offset) = (int32_t)value;
        return 0;
    default:
        if (value != 0.0f && value != 1.0f) {
            return PMSTEP_CONSOLE_ERR_BAD_VALUE;
        }
        *(bool *)(void *)(base + table[id].offset) = value == 1.0f;
        return 0;
    }
}

pmstep_config_t pmstep_console_app_config(float period_s, uint32_t computational_delay_periods)
{
    pmstep_config_t cfg = pmstep_paper_config();
    cfg.period_s = period_s;
    cfg.computational_delay_periods = computational_delay_periods;
    return cfg;
}

float pmstep_console_config_period_s(const pmstep_config_t *cfg)
{
    return cfg->period_s;
}

uint32_t pmstep_console_config_delay_periods(const pmstep_config_t *cfg)
{
    return cfg->computational_delay_periods;
}
