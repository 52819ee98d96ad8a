/* pmstep-tune's own functions shared between its sources (one per mode: pmstep_tune.c the
 * command line, tune_design.c the design printed and written, tune_identify.c --identify,
 * tune_validate.c the validation profile and --validate). */
#ifndef PMSTEP_TUNE_H
#define PMSTEP_TUNE_H

#include <stdbool.h>

#include "pmstep/pmstep_calibrate.h"
#include "pmstep/pmstep_design.h"
#include "sil/runner.h"

/* ---- tune_validate.c ---- */

/* One run of the validation, for --summary. */
typedef struct {
    const char *check; /* "ramps", "step_50", "step_5" */
    bool ran;          /* init accepted the configuration */
    int fault;         /* pmstep_fault_t latched, 0 none */
    double fault_time_s;
    double angle_error_rad;   /* largest angle-estimate error in RUN after the transients */
    double speed_error_rad_s; /* ramps: after the transients; steps: the dip after the load step */
    double speed_bound_rad_s; /* the tracking bound (2 % of the top speed) */
    bool synchronous;         /* no fault, RUN to the end, angle error below SYNC_ANGLE_BOUND_RAD */
    bool pass;                /* as --validate judges it */
} tune_check_t;

#define TUNE_CHECKS 3

/* A speed profile through @p levels (each held PROFILE_HOLD_S), starting 0.1 s after t_c. */
void set_profile(sil_scenario_t *sc, const double *levels, int n_levels);

/* False (and a FAIL line) if the run was refused, faulted, left RUN or saw a non-finite value. */
bool run_ok(const char *what, const sil_summary_t *s, int rc);

/* @p max_inertia_error_pct >= 0: with identification in RUN, the first run must identify J
 * within that many percent of the plant's. @p checks (TUNE_CHECKS, or NULL) gets each run's outcome.
 * @return 0 if every check passed, else 1. */
int validate(const sil_scenario_t *designed, double top_speed_rad_s, double max_inertia_error_pct,
             tune_check_t *checks);

/* ---- tune_design.c ---- */

/* The designer's input for the motor the drive is told: the preset's [motor], J and F overridable. */
void design_input(const sil_scenario_t *sc, bool robust, bool low_speed_drive, pmstep_design_input_t *in);

void print_design(const sil_scenario_t *sc, const pmstep_design_report_t *r, bool robust);

/* The design as a C99 initialiser of pmstep_config_t. @return 0, or -1 after a message. */
int write_c(const char *path, const sil_scenario_t *sc);

/* ---- tune_motor_db.c ---- */

/* Friction F where the data gives none: 1.5 % of the holding torque at 60 rad/s (N m s/rad per N m). */
#define MOTOR_DB_FRICTION_PER_TORQUE (0.015 / 60.0)

/* The motor of section [motor_constants @p name] of the Klipper motor database @p path into @p sc
 * ([datasheet], [motor] and the name; J and F estimated). @return 0, or -1 with a message in @p err. */
int load_motor_db(sil_scenario_t *sc, const char *path, const char *name, char *err, size_t err_size);

/* ---- tune_calibrate.c ---- */

/* --self-commission's outcome beside the datasheet design, for --summary. */
typedef struct {
    bool ran;
    int32_t status; /* pmstep_calibrate_t::status */
    int fault;      /* the fault that ended the last run */
    unsigned runs;
    double simulated_s;
    pmstep_config_t datasheet; /* the design from the datasheet */
    pmstep_design_report_t datasheet_report;
    pmstep_config_t drive; /* the drive's own design (valid when status is 0) */
    pmstep_design_report_t drive_report;
} tune_calibration_t;

/* Runs the drive's calibration in the SIL on @p sc's plant (no load), told the datasheet's rated
 * current, the pole pairs and the detent torque's fraction of the holding torque; @p cfg gets the configuration in force at its end.
 * @return 0 when it ended DONE, 1 when it failed (a line says why), 2 on a setup error. */
int calibrate_on_drive(const sil_scenario_t *sc, bool robust, double detent_per_holding, pmstep_calibrate_t *cal,
                       pmstep_config_t *cfg, double *simulated_s);

/* A calibration status (pmstep_calibrate_status_t, or a pmstep_status_t) in words. */
const char *calibrate_status_text(int32_t status);

/* The drive's design against the datasheet's (and the plant's truth) as a table. */
void print_calibration(const sil_scenario_t *sc, const pmstep_config_t *datasheet,
                       const pmstep_design_report_t *datasheet_report, const pmstep_config_t *drive,
                       const pmstep_design_report_t *drive_report);

/* ---- tune_summary.c ---- */

/* --summary: the design's status and figures (@p r read only when @p status is PMSTEP_OK), the
 * validation's @p n_checks runs and, with @p cal ran, the self-commissioning's, as JSON at @p path.
 * @return 0, or -1 after a message. */
int write_summary(const char *path, const char *motor_path, bool robust, pmstep_status_t status,
                  const pmstep_design_report_t *r, const tune_check_t *checks, int n_checks,
                  const tune_calibration_t *cal);

/* ---- tune_identify.c ---- */

/* Identification window over the profile +0.8 top, -0.8 top (each held), from t_c. */
void set_identification(sil_scenario_t *sc, double top_speed_rad_s, bool use_in_run);

/* --identify: commissioning and the identification window in the SIL with the first design.
 * @return 0 and the identified J, F in @p result; 1 when the run faulted or identified nothing. */
int identify(const sil_scenario_t *designed, double top_speed_rad_s, pmstep_commissioning_t *result);

#endif /* PMSTEP_TUNE_H */
