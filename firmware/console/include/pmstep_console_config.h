/**
 * @file pmstep_console_config.h
 * @brief The console's configuration table (pmstep_console_config.c): every value of
 *        pmstep_config_t and the STEP/DIR settings by name and id, read and written as floats, and
 *        the application's configuration built from the port's figures. The console's requests
 *        (pmstep_console.h) and the stored record (pmstep_store.h) go through it.
 */
#ifndef PMSTEP_CONSOLE_CONFIG_H
#define PMSTEP_CONSOLE_CONFIG_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_stepdir.h"
#include "pmstep_store.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A configuration value exposed by name and id (pmstep_console_config.c). */
typedef struct {
    const char *name;
    uint8_t type;    /**< PMSTEP_CONSOLE_CFG_F32, _U32, _I32, _BOOL */
    uint8_t flags;   /**< PMSTEP_CONSOLE_CFG_READ_ONLY, PMSTEP_CONSOLE_CFG_STEPDIR */
    uint16_t offset; /**< in pmstep_config_t; with PMSTEP_CONSOLE_CFG_STEPDIR in pmstep_stepdir_settings_t */
} pmstep_console_config_entry_t;

#define PMSTEP_CONSOLE_CFG_F32 0u
#define PMSTEP_CONSOLE_CFG_U32 1u
#define PMSTEP_CONSOLE_CFG_I32 2u
#define PMSTEP_CONSOLE_CFG_BOOL 3u
#define PMSTEP_CONSOLE_CFG_READ_ONLY 1u
#define PMSTEP_CONSOLE_CFG_STEPDIR 2u /**< a STEP/DIR setting (pmstep_stepdir_settings_t), named stepdir.* */

/** The table of configuration values: @p count gets its length. */
const pmstep_console_config_entry_t *pmstep_console_config_table(uint32_t *count);

/** Reads entry @p id of @p cfg or, for a STEP/DIR setting, of @p sd, as a float. @return false if @p id
 *  is out of the table. */
bool pmstep_console_config_get(const pmstep_config_t *cfg, const pmstep_stepdir_settings_t *sd, uint32_t id,
                               float *value);

/**
 * Writes entry @p id of @p cfg or, for a STEP/DIR setting, of @p sd (integers and booleans must be
 * given exactly, e.g. 1.0). Only the type is checked here: the ranges by pmstep_validate_config() and
 * pmstep_console_stepdir_validate().
 * @return 0, or PMSTEP_CONSOLE_ERR_UNKNOWN_CONFIG / _READ_ONLY / _BAD_VALUE.
 */
int pmstep_console_config_set(pmstep_config_t *cfg, pmstep_stepdir_settings_t *sd, uint32_t id, float value);

/** Whether entry @p id is a STEP/DIR setting (false beyond the table). */
bool pmstep_console_config_is_stepdir(uint32_t id);

/** The STEP/DIR settings of a drive that was never given any, a TMC driver's conventions: 16
 *  microsteps, DIR not inverted, EN active low, DIAG active high in level mode, a following-error
 *  limit of one full step (the designer's). */
pmstep_stepdir_settings_t pmstep_console_stepdir_defaults(void);

/**
 * Checks STEP/DIR settings, refused by cause, never clamped:
 * @retval PMSTEP_OK, PMSTEP_ERR_NULL_ARGUMENT
 * @retval PMSTEP_ERR_STEPDIR_MICROSTEPS  microsteps not within 1..PMSTEP_STEPDIR_MAX_MICROSTEPS
 * @retval PMSTEP_ERR_STEPDIR_DIAG_MODE   diag_mode neither PMSTEP_DIAG_LEVEL nor PMSTEP_DIAG_PULSE
 * @retval PMSTEP_ERR_STEPDIR_LIMIT       following_error_limit_full_steps not > 0 (or not finite)
 * @retval PMSTEP_ERR_STEPDIR_STALL_CURRENT  stall_current_A < 0 (or not finite)
 */
pmstep_status_t pmstep_console_stepdir_validate(const pmstep_stepdir_settings_t *sd);

/**
 * The step tracker's settings for the motor of @p cfg from the STEP/DIR settings @p sd: the
 * designer's (pmstep_stepdir_design()) with sd's microsteps, direction, DIAG mode, following-error
 * limit (full steps times pi / (2 p)) and stall current.
 * @return pmstep_console_stepdir_validate()'s or pmstep_stepdir_design()'s status, or
 *         PMSTEP_ERR_STEPDIR_STALL_CURRENT for a stall current not below @p cfg's max_phase_current_A;
 *         @p out written on PMSTEP_OK only.
 */
pmstep_status_t pmstep_console_stepdir_config(const pmstep_config_t *cfg, const pmstep_stepdir_settings_t *sd,
                                              pmstep_stepdir_config_t *out);

/** The application's configuration: the paper's, with the port's period, delay and measurement
 *  ranges (A, V). */
pmstep_config_t pmstep_console_app_config(float period_s, uint32_t computational_delay_periods,
                                          float current_sense_range_A, float bus_sense_range_V);

/** The control period (s) of @p cfg. */
float pmstep_console_config_period_s(const pmstep_config_t *cfg);

/** The computational delay (periods) of @p cfg. */
uint32_t pmstep_console_config_delay_periods(const pmstep_config_t *cfg);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_CONSOLE_CONFIG_H */
