/* pmstep-tune: designs every controller setting for a motor preset (pmstep_design()), prints
 * the design, writes it as a scenario INI and as a C initialiser, and validates it in the SIL.
 * This file is the command line; the modes are tune_design.c, tune_identify.c, tune_validate.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pmstep/pmstep_homing.h"
#include "pmstep/pmstep_text.h"
#include "pmstep_tune.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: pmstep-tune (--motor FILE | --motor-db FILE --name NAME) [--robust [--low-speed-drive]]\n"
               "                   [--force] [--no-field-weakening] [--set section.key=value]...\n"
               "                   [--write-ini FILE] [--write-c FILE] [--validate]\n"
               "                   [--told-inertia J] [--told-friction F] [--identify [--max-inertia-error PCT]]\n"
               "                   [--identify-in-run] [--self-commission [--detent-fraction D]] [--summary FILE]\n"
               "  --motor      motor preset (sil/scenarios/motors/*.ini): [datasheet], [motor], run.bus_voltage_V;\n"
               "               run.period_s, run.delay_periods, [inverter] and [sensors] are the drive's\n"
               "  --robust     robust mode: Remark 2 calibration, commissioned R/L/k_M, drift-free angle,\n"
               "               dead-time compensation of inverter.dead_time_s\n"
               "  --motor-db   a motor of a Klipper motor database: its [motor_constants NAME] section (resistance,\n"
               "               inductance, holding_torque, max_current, steps_per_revolution); J and F, which it\n"
               "               does not give, are estimated from the holding torque (and J identified in RUN)\n"
               "  --force      design for data the datasheet check refuses (k_M, L/R or J no stepper has),\n"
               "               with a warning\n"
               "  --low-speed-drive  robust mode without phase-voltage sensing: below 2 V_bus t_d / (T_s k_M)\n"
               "               the standstill hold's vector turns at the reference speed (a load step there is\n"
               "               not learnt)\n"
               "  --no-field-weakening  no field weakening: i_d* stays at its command at every speed\n"
               "  --set        override a key of the preset before designing (e.g. run.period_s=25e-6)\n"
               "  --write-ini  the whole scenario with the designed [controller.*] and a validation profile\n"
               "  --write-c    the design as a C99 initialiser of pmstep_config_t\n"
               "  --validate   run the design in the SIL: speed ramps to +-80 %% and +-5 %% of the top speed,\n"
               "               load steps of half the holding torque at 50 %% and 5 %% of it; exit 1 on a miss\n"
               "  --told-inertia, --told-friction  design for this J (kg m^2) / F (N m s/rad) in place of the\n"
               "               preset's; the plant keeps the preset's (a datasheet that is off)\n"
               "  --identify   run commissioning and the identification window in the SIL (ramps to +-80 %% of the\n"
               "               top speed), design again with the identified J and F, print both designs and the\n"
               "               errors against the plant; --validate then validates the second design\n"
               "  --max-inertia-error  with --identify: exit 1 unless J is identified within PCT %% of the plant's\n"
               "  --identify-in-run  the design asks the firmware to identify J and F in each run's first\n"
               "               window and use them (commissioning.use_identified_mechanics)\n"
               "  --self-commission  run the drive's own calibration (pmstep_calibrate.h) in the SIL on the\n"
               "               preset's plant, told only the rated current and the pole pairs; print its design\n"
               "               beside the datasheet's; --validate, --write-ini, --summary then take its design\n"
               "  --detent-fraction  with --self-commission: the detent torque the user tells, as a fraction of\n"
               "               the holding torque (default 0.05, a hybrid stepper's; 0 for a motor without one)\n"
               "  --summary    the design's status and figures and each validation run's outcome as JSON\n");
}

/* main()'s steps: each returns PROCEED, or the exit status to end with. */
#define PROCEED (-1)

/* What the command line asks. */
typedef struct {
    const char *motor_path;
    const char *motor_db_path;
    const char *motor_db_name;
    const char *ini_path;
    const char *c_path;
    const char *summary_path;
    bool force;
    bool robust;
    bool low_speed_drive;
    bool no_field_weakening;
    bool run_validation;
    bool run_identification;
    bool identify_in_run;
    bool self_commission;
    double detent_per_holding;
    double told_inertia;          /* < 0: the preset's */
    double told_friction;         /* < 0: the preset's */
    double max_inertia_error_pct; /* < 0: no bound */
} request_t;

/* An option that takes a finite number >= 0 (argv[*k], its value at argv[*k + 1]): true where it is
 * one; @p status is 2 for a value that is not such a number. */
static bool number_option(char **argv, int *k, request_t *q, int *status)
{
    const struct {
        const char *name;
        double *value;
    } options[] = {{"--told-inertia", &q->told_inertia},
                   {"--told-friction", &q->told_friction},
                   {"--max-inertia-error", &q->max_inertia_error_pct},
                   {"--detent-fraction", &q->detent_per_holding}};
    size_t n;
    for (n = 0; n < sizeof options / sizeof options[0]; ++n) {
        if (strcmp(argv[*k], options[n].name) == 0) {
            char *end = NULL;
            const double value = strtod(argv[++*k], &end);
            if (end == argv[*k] || *end != '\0' || !isfinite(value) || value < 0.0) {
                fprintf(stderr, "pmstep-tune: %s needs a finite number >= 0, not '%s'\n", options[n].name, argv[*k]);
                *status = 2;
            } else {
                *options[n].value = value;
            }
            return true;
        }
    }
    return false;
}

/* The motor: --motor's preset, or --motor-db's section --name (then J estimated). */
static int motor_option(char **argv, int *k, sil_scenario_t *sc, request_t *q)
{
    char err[SIL_ERROR_MAX];
    if (strcmp(argv[*k], "--motor") == 0) {
        q->motor_path = argv[++*k];
        if (sil_scenario_load(sc, q->motor_path, err, sizeof err) != 0) {
            fprintf(stderr, "pmstep-tune: %s\n", err);
            return 2;
        }
    } else if (strcmp(argv[*k], "--motor-db") == 0) {
        q->motor_db_path = argv[++*k];
    } else {
        q->motor_db_name = argv[++*k];
        if (q->motor_db_path == NULL) {
            fprintf(stderr, "pmstep-tune: --name needs --motor-db before it\n");
            return 2;
        }
        if (load_motor_db(sc, q->motor_db_path, q->motor_db_name, err, sizeof err) != 0) {
            fprintf(stderr, "pmstep-tune: %s\n", err);
            return 2;
        }
        q->motor_path = q->motor_db_path;
        q->told_inertia = 0.0; /* the database has none: the designer estimates it */
    }
    return PROCEED;
}

/* A flag option: true where @p arg is one (and set in @p q). */
static bool flag_option(const char *arg, request_t *q)
{
    const struct {
        const char *name;
        bool *flag;
    } flags[] = {{"--force", &q->force},
                 {"--robust", &q->robust},
                 {"--low-speed-drive", &q->low_speed_drive},
                 {"--no-field-weakening", &q->no_field_weakening},
                 {"--validate", &q->run_validation},
                 {"--identify", &q->run_identification},
                 {"--identify-in-run", &q->identify_in_run},
                 {"--self-commission", &q->self_commission}};
    size_t n;
    for (n = 0; n < sizeof flags / sizeof flags[0]; ++n) {
        if (strcmp(arg, flags[n].name) == 0) {
            *flags[n].flag = true;
            return true;
        }
    }
    return false;
}

/* An option that names a file to write (argv[*k], the name at argv[*k + 1]): true where it is one. */
static bool path_option(char **argv, int *k, request_t *q)
{
    const struct {
        const char *name;
        const char **path;
    } paths[] = {{"--write-ini", &q->ini_path}, {"--write-c", &q->c_path}, {"--summary", &q->summary_path}};
    size_t n;
    for (n = 0; n < sizeof paths / sizeof paths[0]; ++n) {
        if (strcmp(argv[*k], paths[n].name) == 0) {
            *paths[n].path = argv[++*k];
            return true;
        }
    }
    return false;
}

/* Every option in order; the motor loaded and each --set applied as they come. */
static int parse_request(int argc, char **argv, sil_scenario_t *sc, request_t *q)
{
    char err[SIL_ERROR_MAX];
    int status = PROCEED;
    int k;
    for (k = 1; k < argc && status == PROCEED; ++k) {
        const bool has_value = k + 1 < argc;
        if ((strcmp(argv[k], "--motor") == 0 || strcmp(argv[k], "--motor-db") == 0 || strcmp(argv[k], "--name") == 0)
            && has_value) {
            status = motor_option(argv, &k, sc, q);
        } else if (strcmp(argv[k], "--set") == 0 && has_value) {
            if (sil_scenario_set_assignment(sc, argv[++k], err, sizeof err) != 0) {
                fprintf(stderr, "pmstep-tune: %s\n", err);
                status = 2;
            }
        } else if (flag_option(argv[k], q)
                   || (has_value && (path_option(argv, &k, q) || number_option(argv, &k, q, &status)))) {
            /* taken */
        } else if (strcmp(argv[k], "--help") == 0) {
            usage(stdout);
            status = 0;
        } else {
            usage(stderr);
            status = 2;
        }
    }
    if (status == PROCEED && q->motor_db_path != NULL && q->motor_db_name == NULL) {
        fprintf(stderr, "pmstep-tune: --motor-db needs --name NAME (its [motor_constants NAME] section)\n");
        status = 2;
    }
    if (status == PROCEED && q->motor_path == NULL) {
        usage(stderr);
        status = 2;
    }
    return status;
}

/* The validation profile through +-0.8 and +-0.05 of the design's top speed. */
static void validation_profile(sil_scenario_t *sc, const pmstep_design_report_t *report)
{
    const double top = (double)report->top_speed_rad_s;
    const double levels[] = {0.8 * top, -0.8 * top, 0.05 * top, -0.05 * top, 0.0};
    set_profile(sc, levels, 5);
}

/* The design for the datasheet's motor: the preset's [motor], J and F as --told-* say. */
static int design_from_datasheet(sil_scenario_t *sc, request_t *q, pmstep_design_input_t *in,
                                 pmstep_design_report_t *report, pmstep_status_t *status, tune_check_t *checks)
{
    design_input(sc, q->robust, q->low_speed_drive, in);
    in->field_weakening_off = q->no_field_weakening;
    if (q->told_inertia >= 0.0) {
        in->motor.inertia_kgm2 = (float)q->told_inertia;
    }
    if (q->told_friction >= 0.0) {
        in->motor.friction_Nms_rad = (float)q->told_friction;
    }
    in->accept_implausible = q->force;
    {
        const pmstep_status_t datasheet = pmstep_design_check_datasheet(in);
        if (datasheet != PMSTEP_OK && q->force) {
            fprintf(stderr, "pmstep-tune: %s: warning: %s (%d); designing anyway (--force)\n", q->motor_path,
                    pmstep_status_str(datasheet), (int)datasheet);
        }
    }
    *status = pmstep_design(in, &sc->controller, report);
    if (*status != PMSTEP_OK) {
        fprintf(stderr, "pmstep-tune: %s: cannot design: %s (%d)\n", q->motor_path, pmstep_status_str(*status),
                (int)*status);
        if (q->summary_path != NULL) {
            (void)write_summary(q->summary_path, q->motor_path, q->robust, *status, report, checks, 0, NULL);
        }
        return 1;
    }
    sc->id_target_A = (double)report->magnetising_current_A;
    if (report->inertia_estimated) {
        printf("pmstep-tune: no rotor inertia given: %.3g kg m^2 estimated from the holding torque; the firmware "
               "identifies J and F in RUN's first window (--identify-in-run)\n",
               (double)report->inertia_kgm2);
        q->identify_in_run = true;
    }
    (void)pmstep_position_design(&sc->controller, &sc->position); /* position loop (docs/design/11-position-loop.md) */
    validation_profile(sc, report);
    sc->load.kind = PLANT_LOAD_NONE;
    print_design(sc, report, q->robust);
    return PROCEED;
}

/* --identify: commissioning and the identification window in the SIL, then the design again for the
 * identified J and F (exit 1 beyond --max-inertia-error). */
static int design_from_identification(sil_scenario_t *sc, const request_t *q, pmstep_design_input_t *in,
                                      pmstep_design_report_t *report, pmstep_status_t *status)
{
    pmstep_commissioning_t ident;
    const double j_plant = sc->motor.inertia_kgm2;
    const double f_plant = sc->motor.friction_Nms_rad;
    double j_error_pct;
    if (identify(sc, (double)report->top_speed_rad_s, &ident) != 0) {
        return 1;
    }
    j_error_pct = 100.0 * ((double)ident.inertia_kgm2 / j_plant - 1.0);
    printf("  told:       J %.4g kg m^2 (%+.1f %% off the plant's %.4g), F %.4g N m s/rad (plant %.4g)\n",
           (double)in->motor.inertia_kgm2, 100.0 * ((double)in->motor.inertia_kgm2 / j_plant - 1.0), j_plant,
           (double)in->motor.friction_Nms_rad, f_plant);
    printf("  identified: J %.4g kg m^2 (%+.2f %% off the plant's), F %.4g N m s/rad (%+.3g off the plant's)\n",
           (double)ident.inertia_kgm2, j_error_pct, (double)ident.friction_Nms_rad,
           (double)ident.friction_Nms_rad - f_plant);
    in->motor.inertia_kgm2 = ident.inertia_kgm2;
    in->motor.friction_Nms_rad = ident.friction_Nms_rad > 0.0f ? ident.friction_Nms_rad : 0.0f;
    *status = pmstep_design(in, &sc->controller, report);
    if (*status != PMSTEP_OK) {
        fprintf(stderr, "pmstep-tune: cannot design for the identified J, F: %s (%d)\n", pmstep_status_str(*status),
                (int)*status);
        return 1;
    }
    printf("pmstep-tune: design for the identified J and F\n");
    validation_profile(sc, report);
    print_design(sc, report, q->robust);
    if (q->max_inertia_error_pct >= 0.0 && !(fabs(j_error_pct) <= q->max_inertia_error_pct)) {
        printf("pmstep-tune: identified J %+.2f %% off the plant's: over the %.1f %% bound\n", j_error_pct,
               q->max_inertia_error_pct);
        return 1;
    }
    return PROCEED;
}

/* The firmware identifies J and F over the window of the ramps to +-0.8 top, and uses them. */
static void identification_in_run(sil_scenario_t *sc, const pmstep_design_report_t *report)
{
    static sil_scenario_t window;
    window = *sc;
    set_identification(&window, (double)report->top_speed_rad_s, true);
    sc->controller.commissioning.identification_time_s = window.controller.commissioning.identification_time_s;
    sc->controller.commissioning.identification_min_speed_rad_s =
        window.controller.commissioning.identification_min_speed_rad_s;
    sc->controller.commissioning.use_identified_mechanics = true;
    printf("  identification in RUN: %.3f s from t_c, |w*| >= %.1f rad/s, identified J and F used\n",
           (double)sc->controller.commissioning.identification_time_s,
           (double)sc->controller.commissioning.identification_min_speed_rad_s);
}

/* --self-commission: the drive's own design, from the rated current and p, replaces the datasheet's. */
static int design_on_drive(sil_scenario_t *sc, const request_t *q, pmstep_design_report_t *report,
                           pmstep_status_t status, tune_check_t *checks, tune_calibration_t *calibration)
{
    static pmstep_calibrate_t cal;
    static pmstep_config_t drive;
    const int rc = calibrate_on_drive(sc, q->robust, q->detent_per_holding, &cal, &drive, &calibration->simulated_s);
    calibration->ran = true;
    calibration->status = cal.status;
    calibration->fault = (int)cal.fault;
    calibration->runs = cal.runs;
    calibration->datasheet = sc->controller;
    calibration->datasheet_report = *report;
    calibration->drive = drive;
    calibration->drive_report = cal.report;
    if (rc != 0) {
        if (q->summary_path != NULL) {
            (void)write_summary(q->summary_path, q->motor_path, q->robust, status, report, checks, 0, calibration);
        }
        return rc;
    }
    print_calibration(sc, &calibration->datasheet, &calibration->datasheet_report, &drive, &cal.report);
    sc->controller = drive;
    *report = cal.report;
    sc->id_target_A = (double)report->magnetising_current_A;
    (void)pmstep_position_design(&sc->controller, &sc->position);
    validation_profile(sc, report);
    printf("pmstep-tune: the drive's own design replaces the datasheet's from here on\n");
    return PROCEED;
}

/* The position loop's and the homing's figures. */
static void print_position_and_homing(const sil_scenario_t *sc)
{
    pmstep_homing_config_t homing;
    printf("  position loop: k_theta %g 1/s, k_I %g 1/s^2; vector hold at %g A\n", (double)sc->position.gain_per_s,
           (double)sc->position.integral_gain_per_s2, (double)sc->position.hold_current_A);
    (void)pmstep_homing_design(&sc->controller, &homing);
    printf("  homing: %g rad/s (%.0f rpm) at %g rad/s^2, stall current %g A, stall error %g rad\n",
           (double)homing.speed_rad_s, (double)homing.speed_rad_s * 60.0 / (2.0 * 3.14159265358979),
           (double)homing.accel_rad_s2, (double)homing.stall_current_A, (double)homing.stall_error_rad);
}

/* --write-ini and --write-c. */
static int write_design(const sil_scenario_t *sc, const request_t *q)
{
    if (q->ini_path != NULL) {
        FILE *f = fopen(q->ini_path, "w");
        if (f == NULL) {
            fprintf(stderr, "pmstep-tune: cannot write %s\n", q->ini_path);
            return 2;
        }
        fprintf(f, "; Designed by pmstep-tune from %s%s (docs/design).\n", q->motor_path, q->robust ? " --robust" : "");
        sil_scenario_print(sc, f);
        if (fclose(f) != 0) {
            fprintf(stderr, "pmstep-tune: error writing %s\n", q->ini_path);
            return 2;
        }
        printf("pmstep-tune: wrote %s\n", q->ini_path);
    }
    if (q->c_path != NULL) {
        if (write_c(q->c_path, sc) != 0) {
            return 2;
        }
        printf("pmstep-tune: wrote %s\n", q->c_path);
    }
    return PROCEED;
}

int main(int argc, char **argv)
{
    static sil_scenario_t sc;
    static tune_calibration_t calibration;
    pmstep_design_input_t in;
    pmstep_design_report_t report;
    pmstep_status_t status = PMSTEP_OK;
    tune_check_t checks[TUNE_CHECKS] = {{0}};
    request_t q;
    int rc;
    memset(&q, 0, sizeof q);
    q.detent_per_holding = (double)PMSTEP_CALIBRATE_DETENT_PER_HOLDING;
    q.told_inertia = -1.0;
    q.told_friction = -1.0;
    q.max_inertia_error_pct = -1.0;
    sil_scenario_paper(&sc);
    rc = parse_request(argc, argv, &sc, &q);
    if (rc == PROCEED) {
        rc = design_from_datasheet(&sc, &q, &in, &report, &status, checks);
    }
    if (rc == PROCEED && q.run_identification) {
        rc = design_from_identification(&sc, &q, &in, &report, &status);
    }
    if (rc == PROCEED && q.identify_in_run) {
        identification_in_run(&sc, &report);
    }
    if (rc == PROCEED && q.self_commission) {
        rc = design_on_drive(&sc, &q, &report, status, checks, &calibration);
    }
    if (rc != PROCEED) {
        return rc;
    }
    print_position_and_homing(&sc);
    rc = write_design(&sc, &q);
    if (rc != PROCEED) {
        return rc;
    }
    rc = q.run_validation ? validate(&sc, (double)report.top_speed_rad_s, q.max_inertia_error_pct, checks) : 0;
    if (q.summary_path != NULL
        && write_summary(q.summary_path, q.motor_path, q.robust, status, &report, checks,
                         q.run_validation ? TUNE_CHECKS : 0, &calibration)
               != 0) {
        return 2;
    }
    return rc;
}
