/*
 * The configuration values the console reads and writes by name or id (the core's configuration
 * and the STEP/DIR settings), the application's configuration, the two values the images read
 * (period, delay), and the STEP/DIR settings' defaults, checks and tracker settings. The only file of
 * the console, the applications and their tests that names fields of pmstep_config_t: a change of
 * the core's configuration layout is an edit of this file alone.
 */
#include <stddef.h>

#include "pmstep_console.h"

#define F32(field) {#field, PMSTEP_CONSOLE_CFG_F32, 0u, (uint16_t)offsetof(pmstep_config_t, field)}
#define U32(field) {#field, PMSTEP_CONSOLE_CFG_U32, 0u, (uint16_t)offsetof(pmstep_config_t, field)}
#define I32(field) {#field, PMSTEP_CONSOLE_CFG_I32, 0u, (uint16_t)offsetof(pmstep_config_t, field)}
#define BOOL(field) {#field, PMSTEP_CONSOLE_CFG_BOOL, 0u, (uint16_t)offsetof(pmstep_config_t, field)}
/* Fixed by the port (the carrier and where the duties load, what its sensors read): never set
 * from the console. */
#define F32_RO(field) {#field, PMSTEP_CONSOLE_CFG_F32, PMSTEP_CONSOLE_CFG_READ_ONLY, (uint16_t)offsetof(pmstep_config_t, field)}
#define U32_RO(field) {#field, PMSTEP_CONSOLE_CFG_U32, PMSTEP_CONSOLE_CFG_READ_ONLY, (uint16_t)offsetof(pmstep_config_t, field)}
/* The STEP/DIR settings (pmstep_stepdir_settings_t), named stepdir.<field>. */
#define SD_F32(field) {"stepdir." #field, PMSTEP_CONSOLE_CFG_F32, PMSTEP_CONSOLE_CFG_STEPDIR, (uint16_t)offsetof(pmstep_stepdir_settings_t, field)}
#define SD_U32(field) {"stepdir." #field, PMSTEP_CONSOLE_CFG_U32, PMSTEP_CONSOLE_CFG_STEPDIR, (uint16_t)offsetof(pmstep_stepdir_settings_t, field)}
#define SD_BOOL(field) {"stepdir." #field, PMSTEP_CONSOLE_CFG_BOOL, PMSTEP_CONSOLE_CFG_STEPDIR, (uint16_t)offsetof(pmstep_stepdir_settings_t, field)}

/* Ids are the positions in this table: append, never reorder. */
static const pmstep_console_config_entry_t table[] = {
    F32(motor.resistance_Ohm),
    F32(motor.inductance_H),
    F32(motor.inertia_kgm2),
    F32(motor.friction_Nms_rad),
    F32(motor.torque_constant_Nm_A),
    I32(motor.pole_pairs),
    F32_RO(timing.period_s),
    U32_RO(timing.computational_delay_periods),
    F32(alignment.s_align_time_s),
    F32(alignment.c_align_time_s),
    F32(alignment.s_align_voltage_V),
    F32(alignment.c_align_voltage_V),
    F32(gains.speed_gain_per_s),
    F32(gains.observer_gain_per_s),
    F32(gains.current_gain_per_s),
    F32(gains.adapt_gamma),
    F32(gains.adapt_lambda),
    F32(gains.adapt_r),
    F32(gains.sat_kappa_rad_s),
    F32(gains.reference_bandwidth_rad_s),
    BOOL(known_load_mode),
    F32(limits.max_phase_current_A),
    F32(limits.min_bus_voltage_V),
    F32(limits.max_bus_voltage_V),
    F32(commissioning.offset_calibration_time_s),
    BOOL(commissioning.alignment_offset_calibration),
    F32(commissioning.steady_state_window_s),
    F32(commissioning.inductance_window_s),
    BOOL(commissioning.use_measured_resistance),
    BOOL(commissioning.use_measured_inductance),
    BOOL(commissioning.use_measured_torque_constant),
    F32(commissioning.voltage_bias_level_fraction),
    F32(inverter.dead_time_s),
    F32(inverter.dead_time_current_band_A),
    F32(gains.angle_correction_gain_per_s),
    F32(detection.angle_magnitude_bound),
    F32(detection.speed_consistency_bound_rad_s),
    F32(detection.stall_speed_error_rad_s),
    F32(detection.observer_residual_bound_A),
    F32(detection.persistence_s),
    U32(detection.max_realignments),
    F32(motor.detent_torque_Nm),
    F32(gains.current_integral_gain_per_s2),
    F32(commissioning.identification_time_s),
    F32(commissioning.identification_min_speed_rad_s),
    BOOL(commissioning.use_identified_mechanics),
    BOOL(inverter.phase_voltage_sensing),
    F32(standstill.hold_current_A),
    F32(standstill.vector_speed_rad_s),
    BOOL(inverter.ripple_dead_zone),
    F32(gains.detent_fade_speed_rad_s),
    F32(alignment.s_lead_in_time_s),
    F32(gains.current_integral_gain_q_per_s2),
    F32(gains.emf_angle_gain_per_s),
    F32(gains.emf_angle_corner_rad_s),
    F32(gains.angle_smoothing),
    BOOL(standstill.stops_only),
    F32(gains.transient_observer_boost),
    F32(motor.rated_current_A),
    F32_RO(limits.current_sense_range_A),
    F32_RO(limits.bus_sense_range_V),
    BOOL(commissioning.measure_only),
    SD_U32(microsteps),
    SD_BOOL(invert_direction),
    SD_BOOL(enable_active_high),
    SD_BOOL(diag_active_high),
    SD_U32(diag_mode),
    SD_F32(following_error_limit_full_steps),
    SD_F32(stall_current_A),
    F32(field_weakening.max_current_A),
    F32(field_weakening.modulation),
    F32(field_weakening.gain_A_per_s),
};

#define HALF_PI 1.5707963f

const pmstep_console_config_entry_t *pmstep_console_config_table(uint32_t *count)
{
    if (count != NULL) {
        *count = (uint32_t)(sizeof table / sizeof table[0]);
    }
    return table;
}

bool pmstep_console_config_is_stepdir(uint32_t id)
{
    return id < sizeof table / sizeof table[0] && (table[id].flags & PMSTEP_CONSOLE_CFG_STEPDIR) != 0u;
}

bool pmstep_console_config_get(const pmstep_config_t *cfg, const pmstep_stepdir_settings_t *sd, uint32_t id,
                               float *value)
{
    const unsigned char *base;
    if (id >= sizeof table / sizeof table[0]) {
        return false;
    }
    base = pmstep_console_config_is_stepdir(id) ? (const unsigned char *)sd : (const unsigned char *)cfg;
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

int pmstep_console_config_set(pmstep_config_t *cfg, pmstep_stepdir_settings_t *sd, uint32_t id, float value)
{
    unsigned char *base;
    if (id >= sizeof table / sizeof table[0]) {
        return PMSTEP_CONSOLE_ERR_UNKNOWN_CONFIG;
    }
    base = pmstep_console_config_is_stepdir(id) ? (unsigned char *)sd : (unsigned char *)cfg;
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

pmstep_config_t pmstep_console_app_config(float period_s, uint32_t computational_delay_periods,
                                          float current_sense_range_A, float bus_sense_range_V)
{
    pmstep_config_t cfg = pmstep_paper_config();
    cfg.timing.period_s = period_s;
    cfg.timing.computational_delay_periods = computational_delay_periods;
    cfg.limits.current_sense_range_A = current_sense_range_A;
    cfg.limits.bus_sense_range_V = bus_sense_range_V;
    return cfg;
}

float pmstep_console_config_period_s(const pmstep_config_t *cfg)
{
    return cfg->timing.period_s;
}

uint32_t pmstep_console_config_delay_periods(const pmstep_config_t *cfg)
{
    return cfg->timing.computational_delay_periods;
}

pmstep_stepdir_settings_t pmstep_console_stepdir_defaults(void)
{
    pmstep_stepdir_settings_t sd;
    sd.microsteps = 16u;
    sd.invert_direction = false;
    sd.enable_active_high = false;
    sd.diag_active_high = true;
    sd.diag_mode = (uint32_t)PMSTEP_DIAG_LEVEL;
    sd.following_error_limit_full_steps = 1.0f;
    sd.stall_current_A = 0.0f;
    return sd;
}

pmstep_status_t pmstep_console_stepdir_validate(const pmstep_stepdir_settings_t *sd)
{
    if (sd == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (sd->microsteps < 1u || sd->microsteps > PMSTEP_STEPDIR_MAX_MICROSTEPS) {
        return PMSTEP_ERR_STEPDIR_MICROSTEPS;
    }
    if (sd->diag_mode != (uint32_t)PMSTEP_DIAG_LEVEL && sd->diag_mode != (uint32_t)PMSTEP_DIAG_PULSE) {
        return PMSTEP_ERR_STEPDIR_DIAG_MODE;
    }
    if (!(sd->following_error_limit_full_steps > 0.0f)
        || (sd->following_error_limit_full_steps - sd->following_error_limit_full_steps) != 0.0f) {
        return PMSTEP_ERR_STEPDIR_LIMIT;
    }
    if (!(sd->stall_current_A >= 0.0f) || (sd->stall_current_A - sd->stall_current_A) != 0.0f) {
        return PMSTEP_ERR_STEPDIR_STALL_CURRENT;
    }
    return PMSTEP_OK;
}

pmstep_status_t pmstep_console_stepdir_config(const pmstep_config_t *cfg, const pmstep_stepdir_settings_t *sd,
                                              pmstep_stepdir_config_t *out)
{
    pmstep_stepdir_config_t c;
    pmstep_status_t st;
    if (cfg == NULL || out == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    st = pmstep_console_stepdir_validate(sd);
    if (st == PMSTEP_OK) {
        st = pmstep_stepdir_design(cfg, sd->microsteps, &c);
    }
    if (st != PMSTEP_OK) {
        return st;
    }
    c.invert_direction = sd->invert_direction;
    c.diag_mode = sd->diag_mode == (uint32_t)PMSTEP_DIAG_PULSE ? PMSTEP_DIAG_PULSE : PMSTEP_DIAG_LEVEL;
    c.following_error_limit_rad = sd->following_error_limit_full_steps * HALF_PI / (float)cfg->motor.pole_pairs;
    if (!(sd->stall_current_A < cfg->limits.max_phase_current_A)) {
        return PMSTEP_ERR_STEPDIR_STALL_CURRENT; /* a stall at or beyond the trip would never be found */
    }
    c.stall_current_A = sd->stall_current_A;
    *out = c;
    return PMSTEP_OK;
}
