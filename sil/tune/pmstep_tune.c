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
    fprintf(f,
            "usage: pmstep-tune (--motor FILE | --motor-db FILE --name NAME) [--robust [--low-speed-drive]]\n"
            "                   [--force] [--set section.key=value]...\n"
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

int main(int argc, char **argv)
{
    static sil_scenario_t sc;
    pmstep_design_input_t in;
    pmstep_design_report_t report;
    pmstep_status_t status;
    const char *motor_path = NULL;
    const char *motor_db_path = NULL;
    const char *motor_db_name = NULL;
    bool force = false;
    const char *ini_path = NULL;
    const char *c_path = NULL;
    const char *summary_path = NULL;
    tune_check_t checks[TUNE_CHECKS] = {{0}};
    bool robust = false;
    bool low_speed_drive = false;
    bool run_validation = false;
    bool run_identification = false;
    bool identify_in_run = false;
    bool self_commission = false;
    double detent_per_holding = (double)PMSTEP_CALIBRATE_DETENT_PER_HOLDING;
    static tune_calibration_t calibration;
    double told_inertia = -1.0;
    double told_friction = -1.0;
    double max_inertia_error_pct = -1.0;
    char err[SIL_ERROR_MAX];
    int k;

    sil_scenario_paper(&sc);
    for (k = 1; k < argc; ++k) {
        if (strcmp(argv[k], "--motor") == 0 && k + 1 < argc) {
            motor_path = argv[++k];
            if (sil_scenario_load(&sc, motor_path, err, sizeof err) != 0) {
                fprintf(stderr, "pmstep-tune: %s\n", err);
                return 2;
            }
        } else if (strcmp(argv[k], "--motor-db") == 0 && k + 1 < argc) {
            motor_db_path = argv[++k];
        } else if (strcmp(argv[k], "--name") == 0 && k + 1 < argc) {
            motor_db_name = argv[++k];
            if (motor_db_path == NULL) {
                fprintf(stderr, "pmstep-tune: --name needs --motor-db before it\n");
                return 2;
            }
            if (load_motor_db(&sc, motor_db_path, motor_db_name, err, sizeof err) != 0) {
                fprintf(stderr, "pmstep-tune: %s\n", err);
                return 2;
            }
            motor_path = motor_db_path;
            told_inertia = 0.0; /* the database has none: the designer estimates it */
        } else if (strcmp(argv[k], "--force") == 0) {
            force = true;
        } else if (strcmp(argv[k], "--set") == 0 && k + 1 < argc) {
            if (sil_scenario_set_assignment(&sc, argv[++k], err, sizeof err) != 0) {
                fprintf(stderr, "pmstep-tune: %s\n", err);
                return 2;
            }
        } else if (strcmp(argv[k], "--robust") == 0) {
            robust = true;
        } else if (strcmp(argv[k], "--low-speed-drive") == 0) {
            low_speed_drive = true;
        } else if (strcmp(argv[k], "--write-ini") == 0 && k + 1 < argc) {
            ini_path = argv[++k];
        } else if (strcmp(argv[k], "--write-c") == 0 && k + 1 < argc) {
            c_path = argv[++k];
        } else if (strcmp(argv[k], "--summary") == 0 && k + 1 < argc) {
            summary_path = argv[++k];
        } else if (strcmp(argv[k], "--validate") == 0) {
            run_validation = true;
        } else if (strcmp(argv[k], "--identify") == 0) {
            run_identification = true;
        } else if (strcmp(argv[k], "--identify-in-run") == 0) {
            identify_in_run = true;
        } else if (strcmp(argv[k], "--self-commission") == 0) {
            self_commission = true;
        } else if ((strcmp(argv[k], "--told-inertia") == 0 || strcmp(argv[k], "--told-friction") == 0
                    || strcmp(argv[k], "--max-inertia-error") == 0 || strcmp(argv[k], "--detent-fraction") == 0)
                   && k + 1 < argc) {
            char *end = NULL;
            const char *name = argv[k];
            const double value = strtod(argv[++k], &end);
            if (end == argv[k] || *end != '\0' || !isfinite(value) || value < 0.0) {
                fprintf(stderr, "pmstep-tune: %s needs a finite number >= 0, not '%s'\n", name, argv[k]);
                return 2;
            }
            if (strcmp(name, "--told-inertia") == 0) {
                told_inertia = value;
            } else if (strcmp(name, "--told-friction") == 0) {
                told_friction = value;
            } else if (strcmp(name, "--detent-fraction") == 0) {
                detent_per_holding = value;
            } else {
                max_inertia_error_pct = value;
            }
        } else if (strcmp(argv[k], "--help") == 0) {
            usage(stdout);
            return 0;
        } else {
            usage(stderr);
            return 2;
        }
    }
    if (motor_db_path != NULL && motor_db_name == NULL) {
        fprintf(stderr, "pmstep-tune: --motor-db needs --name NAME (its [motor_constants NAME] section)\n");
        return 2;
    }
    if (motor_path == NULL) {
        usage(stderr);
        return 2;
    }

    /* The drive is told the datasheet's motor: the preset's [motor], J and F as --told-* say. */
    design_input(&sc, robust, low_speed_drive, &in);
    if (told_inertia >= 0.0) {
        in.motor.inertia_kgm2 = (float)told_inertia;
    }
    if (told_friction >= 0.0) {
        in.motor.friction_Nms_rad = (float)told_friction;
    }
    in.accept_implausible = force;
    {
        const pmstep_status_t datasheet = pmstep_design_check_datasheet(&in);
        if (datasheet != PMSTEP_OK && force) {
            fprintf(stderr, "pmstep-tune: %s: warning: %s (%d); designing anyway (--force)\n", motor_path,
                    pmstep_status_str(datasheet), (int)datasheet);
        }
    }
    status = pmstep_design(&in, &sc.controller, &report);
    if (status != PMSTEP_OK) {
        fprintf(stderr, "pmstep-tune: %s: cannot design: %s (%d)\n", motor_path, pmstep_status_str(status),
                (int)status);
        if (summary_path != NULL) {
            (void)write_summary(summary_path, motor_path, robust, status, &report, checks, 0, NULL);
        }
        return 1;
    }
    sc.id_target_A = (double)report.magnetising_current_A;
    if (report.inertia_estimated) {
        printf("pmstep-tune: no rotor inertia given: %.3g kg m^2 estimated from the holding torque; the firmware "
               "identifies J and F in RUN's first window (--identify-in-run)\n",
               (double)report.inertia_kgm2);
        identify_in_run = true;
    }
    (void)pmstep_position_design(&sc.controller, &sc.position); /* position loop (docs/design/11-position-loop.md) */
    {
        const double top = (double)report.top_speed_rad_s;
        const double levels[] = {0.8 * top, -0.8 * top, 0.05 * top, -0.05 * top, 0.0};
        set_profile(&sc, levels, 5);
    }
    sc.load.kind = PLANT_LOAD_NONE;
    print_design(&sc, &report, robust);
    if (run_identification) {
        pmstep_commissioning_t ident;
        const double j_plant = sc.motor.inertia_kgm2;
        const double f_plant = sc.motor.friction_Nms_rad;
        double j_error_pct;
        if (identify(&sc, (double)report.top_speed_rad_s, &ident) != 0) {
            return 1;
        }
        j_error_pct = 100.0 * ((double)ident.inertia_kgm2 / j_plant - 1.0);
        printf("  told:       J %.4g kg m^2 (%+.1f %% off the plant's %.4g), F %.4g N m s/rad (plant %.4g)\n",
               (double)in.motor.inertia_kgm2, 100.0 * ((double)in.motor.inertia_kgm2 / j_plant - 1.0), j_plant,
               (double)in.motor.friction_Nms_rad, f_plant);
        printf("  identified: J %.4g kg m^2 (%+.2f %% off the plant's), F %.4g N m s/rad (%+.3g off the plant's)\n",
               (double)ident.inertia_kgm2, j_error_pct, (double)ident.friction_Nms_rad,
               (double)ident.friction_Nms_rad - f_plant);
        in.motor.inertia_kgm2 = ident.inertia_kgm2;
        in.motor.friction_Nms_rad = ident.friction_Nms_rad > 0.0f ? ident.friction_Nms_rad : 0.0f;
        status = pmstep_design(&in, &sc.controller, &report);
        if (status != PMSTEP_OK) {
            fprintf(stderr, "pmstep-tune: cannot design for the identified J, F: %s (%d)\n",
                    pmstep_status_str(status), (int)status);
            return 1;
        }
        printf("pmstep-tune: design for the identified J and F\n");
        {
            const double top = (double)report.top_speed_rad_s;
            const double levels[] = {0.8 * top, -0.8 * top, 0.05 * top, -0.05 * top, 0.0};
            set_profile(&sc, levels, 5);
        }
        print_design(&sc, &report, robust);
        if (max_inertia_error_pct >= 0.0 && !(fabs(j_error_pct) <= max_inertia_error_pct)) {
            printf("pmstep-tune: identified J %+.2f %% off the plant's: over the %.1f %% bound\n", j_error_pct,
                   max_inertia_error_pct);
            return 1;
        }
    }
    if (identify_in_run) {
        /* The firmware identifies over the window of the ramps to +-0.8 top, and uses J and F. */
        static sil_scenario_t window;
        window = sc;
        set_identification(&window, (double)report.top_speed_rad_s, true);
        sc.controller.commissioning.identification_time_s = window.controller.commissioning.identification_time_s;
        sc.controller.commissioning.identification_min_speed_rad_s =
            window.controller.commissioning.identification_min_speed_rad_s;
        sc.controller.commissioning.use_identified_mechanics = true;
        printf("  identification in RUN: %.3f s from t_c, |w*| >= %.1f rad/s, identified J and F used\n",
               (double)sc.controller.commissioning.identification_time_s,
               (double)sc.controller.commissioning.identification_min_speed_rad_s);
    }
    if (self_commission) {
        /* The drive's own design, from the rated current and p: it replaces the datasheet's. */
        static pmstep_calibrate_t cal;
        static pmstep_config_t drive;
        const int rc = calibrate_on_drive(&sc, robust, detent_per_holding, &cal, &drive, &calibration.simulated_s);
        calibration.ran = true;
        calibration.status = cal.status;
        calibration.fault = (int)cal.fault;
        calibration.runs = cal.runs;
        calibration.datasheet = sc.controller;
        calibration.datasheet_report = report;
        calibration.drive = drive;
        calibration.drive_report = cal.report;
        if (rc != 0) {
            if (summary_path != NULL) {
                (void)write_summary(summary_path, motor_path, robust, status, &report, checks, 0, &calibration);
            }
            return rc;
        }
        print_calibration(&sc, &calibration.datasheet, &calibration.datasheet_report, &drive, &cal.report);
        sc.controller = drive;
        report = cal.report;
        sc.id_target_A = (double)report.magnetising_current_A;
        (void)pmstep_position_design(&sc.controller, &sc.position);
        {
            const double top = (double)report.top_speed_rad_s;
            const double levels[] = {0.8 * top, -0.8 * top, 0.05 * top, -0.05 * top, 0.0};
            set_profile(&sc, levels, 5);
        }
        printf("pmstep-tune: the drive's own design replaces the datasheet's from here on\n");
    }
    printf("  position loop: k_theta %g 1/s, k_I %g 1/s^2; vector hold at %g A\n", (double)sc.position.gain_per_s,
           (double)sc.position.integral_gain_per_s2, (double)sc.position.hold_current_A);
    {
        pmstep_homing_config_t homing;
        (void)pmstep_homing_design(&sc.controller, &homing);
        printf("  homing: %g rad/s (%.0f rpm) at %g rad/s^2, stall current %g A, stall error %g rad\n",
               (double)homing.speed_rad_s, (double)homing.speed_rad_s * 60.0 / (2.0 * 3.14159265358979),
               (double)homing.accel_rad_s2, (double)homing.stall_current_A, (double)homing.stall_error_rad);
    }
    if (ini_path != NULL) {
        FILE *f = fopen(ini_path, "w");
        if (f == NULL) {
            fprintf(stderr, "pmstep-tune: cannot write %s\n", ini_path);
            return 2;
        }
        fprintf(f, "; Designed by pmstep-tune from %s%s (docs/design).\n", motor_path,
                robust ? " --robust" : "");
        sil_scenario_print(&sc, f);
        if (fclose(f) != 0) {
            fprintf(stderr, "pmstep-tune: error writing %s\n", ini_path);
            return 2;
        }
        printf("pmstep-tune: wrote %s\n", ini_path);
    }
    if (c_path != NULL) {
        if (write_c(c_path, &sc) != 0) {
            return 2;
        }
        printf("pmstep-tune: wrote %s\n", c_path);
    }
    if (run_validation) {
        const int rc = validate(&sc, (double)report.top_speed_rad_s, max_inertia_error_pct, checks);
        if (summary_path != NULL && write_summary(summary_path, motor_path, robust, status, &report, checks,
                                                  TUNE_CHECKS, &calibration) != 0) {
            return 2;
        }
        return rc;
    }
    if (summary_path != NULL && write_summary(summary_path, motor_path, robust, status, &report, checks, 0, &calibration) != 0) {
        return 2;
    }
    return 0;
}
