/**
 * @file homing_run.h
 * @brief A homing scenario in the runner (position.source = homing): at the first position point's
 *        time the drive homes (pmstep_homing.h) toward that point's sign, with its magnitude as the
 *        largest travel, against the plant's hard stop (motor.stop_*); judged on the plant's truth
 *        (sil_homing_summary_t): where the drive put the stop against where the rotor meets it, the
 *        current and the push while seeking, where the rotor ends after the back-off.
 */
#ifndef SIL_HOMING_RUN_H
#define SIL_HOMING_RUN_H

#include <stdbool.h>

#include "pmstep/pmstep_homing.h"
#include "sil/metrics.h"
#include "sil/scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    const sil_scenario_t *sc;
    pmstep_homing_t homing;
    double full_step_rad;
    bool started;
    pmstep_homing_state_t last_state;
} sil_homing_run_t;

/** The homing settings the scenario runs with: the designer's (pmstep_homing_design()) with the
 *  scenario's homing.* overrides and its first point's travel. */
pmstep_homing_config_t sil_homing_config(const sil_scenario_t *sc);

void sil_homing_run_init(sil_homing_run_t *run, const sil_scenario_t *sc, sil_summary_t *s);

/** Starts homing at the first point's time (once the position is tracked). */
void sil_homing_run_command(sil_homing_run_t *run, pmstep_position_t *pos, double t_s, sil_summary_t *s);

/** After the period's step: the homing's update. */
void sil_homing_run_update(sil_homing_run_t *run, pmstep_position_t *pos, const pmstep_output_t *out,
                           const pmstep_position_output_t *pos_out);

/** One period's truth (after sil_position_run_sample(), which puts the true position in the sample). */
void sil_homing_run_sample(sil_homing_run_t *run, const sil_sample_t *sample, const plant_params_t *plant,
                           double origin_rad, sil_summary_t *s);

#ifdef __cplusplus
}
#endif

#endif /* SIL_HOMING_RUN_H */
