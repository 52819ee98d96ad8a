/* pmstep-tune's own functions shared between its sources (one per mode: pmstep_tune.c the
 * command line, tune_design.c the design printed and written, tune_identify.c --identify,
 * tune_validate.c the validation profile and --validate). */
#ifndef PMSTEP_TUNE_H
#define PMSTEP_TUNE_H

#include <stdbool.h>

#include "pmstep/pmstep_design.h"
#include "sil/runner.h"

/* ---- tune_validate.c ---- */

/* A speed profile through @p levels (each held PROFILE_HOLD_S), starting 0.1 s after t_c. */
void set_profile(sil_scenario_t *sc, const double *levels, int n_levels);

/* False (and a FAIL line) if the run was refused, faulted, left RUN or saw a non-finite value. */
bool run_ok(const char *what, const sil_summary_t *s, int rc);

/* @p max_inertia_error_pct >= 0: with identification in RUN, the first run must identify J
 * within that many percent of the plant's. @return 0 if every check passed, else 1. */
int validate(const sil_scenario_t *designed, double top_speed_rad_s, double max_inertia_error_pct);

/* ---- tune_design.c ---- */

/* The designer's input for the motor the drive is told: the preset's [motor], J and F overridable. */
void design_input(const sil_scenario_t *sc, bool robust, bool low_speed_drive, pmstep_design_input_t *in);

void print_design(const sil_scenario_t *sc, const pmstep_design_report_t *r, bool robust);

/* The design as a C99 initialiser of pmstep_config_t. @return 0, or -1 after a message. */
int write_c(const char *path, const sil_scenario_t *sc);

/* ---- tune_identify.c ---- */

/* Identification window over the profile +0.8 top, -0.8 top (each held), from t_c. */
void set_identification(sil_scenario_t *sc, double top_speed_rad_s, bool use_in_run);

/* --identify: commissioning and the identification window in the SIL with the first design.
 * @return 0 and the identified J, F in @p result; 1 when the run faulted or identified nothing. */
int identify(const sil_scenario_t *designed, double top_speed_rad_s, pmstep_commissioning_t *result);

#endif /* PMSTEP_TUNE_H */
