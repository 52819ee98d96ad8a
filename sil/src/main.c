/* pmstep-sil: runs a scenario through the real control core and the plant model,
 * writes a CSV time series and a JSON summary, prints the summary. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "pmstep_hal_host.h"
#include "sil/runner.h"
#include "summary_json.h"
#include "pmstep/pmstep_text.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: pmstep-sil [--scenario FILE|paper] [--set section.key=value]... [--out DIR]\n"
               "                  [--no-csv] [--quiet] [--print-scenario] [--record FILE]\n"
               "  --scenario   INI scenario file on top of the built-in paper scenario (default: paper)\n"
               "  --set        override one key after the file, e.g. --set run.period_s=25e-6\n"
               "  --out        output folder for run.csv and summary.json (default: out/<scenario name>)\n"
               "  --no-csv     skip the time series (benchmarks)\n"
               "  --quiet      no progress line, no printed summary\n"
               "  --print-scenario  print every key with its value (INI) and exit\n"
               "  --record     write the core's inputs and outputs of every period to FILE (binary,\n"
               "               see sil/include/sil/runner.h), for replay on a target (tests/pil/)\n"
               "exit status: 0 done, 2 bad input or a write error, 3 a fault latched,\n"
               "             4 run.controller = microstep lost synchronism\n");
}

typedef struct {
    FILE *file;
    int decimation;
} csv_ctx_t;

static bool write_row(const sil_sample_t *x, void *user)
{
    csv_ctx_t *csv = (csv_ctx_t *)user;
    const pmstep_output_t *o = x->out;
    const pmstep_hal_host_t *port = pmstep_hal_host_state(); /* its last sample is this period's */
    if (x->step % csv->decimation != 0) {
        return true;
    }
    fprintf(csv->file,
            "%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%d,%.9g,%.9g,%.9g,%.9g",
            x->t_s, x->theta_rad, x->omega_rad_s, (double)o->speed_ref_rad_s, x->i_a_A, x->i_b_A, x->u_a_V, x->u_b_V,
            (double)o->cos_hat, (double)o->sin_hat, x->cos_ptheta, x->sin_ptheta, (double)o->speed_hat_rad_s,
            (double)o->load_hat_Nm, x->load_Nm, (int)o->mode, (int)o->fault, (double)port->meas.i_a_A,
            (double)port->meas.i_b_A, port->bus_V, (double)port->meas.bus_voltage_V);
    if (x->position != NULL) {
        /* A position scenario's row goes on: theta*, theta-hat of the period (0 while not tracked), theta
         * (from the c-alignment equilibrium). */
        fprintf(csv->file, ",%.9g,%.9g,%.9g", x->position_reference_rad, x->position_estimate_rad, x->position_rad);
    }
    if (x->stepdir) {
        /* A STEP/DIR scenario's: the generator's count, the following error (full steps), DIAG. */
        fprintf(csv->file, ",%ld,%.9g,%d", (long)x->step_count, x->step_error_full_steps, x->diag ? 1 : 0);
    }
    fputc('\n', csv->file);
    return true;
}

static int make_dirs(const char *path)
{
    char buf[1024];
    size_t n;
    if (strlen(path) >= sizeof buf) {
        return -1;
    }
    strcpy(buf, path);
    for (n = 1; buf[n] != '\0'; ++n) {
        if (buf[n] == '/') {
            buf[n] = '\0';
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
                return -1;
            }
            buf[n] = '/';
        }
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
        return -1;
    }
    return 0;
}

/* main()'s steps: each returns PROCEED, or the exit status to end with. */
#define PROCEED (-1)

/* The command line's options (the scenario's --set items are applied as they are read). */
typedef struct {
    const char *record_path;
    char out_dir[512];
    bool write_csv;
    bool quiet;
    bool print_only;
} options_t;

/* The scenario: the paper's, then the --scenario file (found first, wherever it stands); --help. */
static int load_scenario(int argc, char **argv, sil_scenario_t *sc)
{
    const char *scenario_file = NULL;
    char err[SIL_ERROR_MAX];
    int i;
    sil_scenario_paper(sc);
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--scenario") == 0 && i + 1 < argc) {
            scenario_file = argv[++i];
        } else if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            usage(stdout);
            return 0;
        }
    }
    if (scenario_file != NULL && strcmp(scenario_file, "paper") != 0) {
        if (sil_scenario_load(sc, scenario_file, err, sizeof err) != 0) {
            fprintf(stderr, "pmstep-sil: %s\n", err);
            return 2;
        }
    }
    return PROCEED;
}

/* The argument at argv[*i + 1] of option argv[*i], or NULL (with @p missing said) at the end. */
static const char *option_value(int argc, char **argv, int *i, const char *missing)
{
    if (*i + 1 >= argc) {
        fprintf(stderr, "pmstep-sil: %s %s\n", argv[*i], missing);
        return NULL;
    }
    ++*i;
    return argv[*i];
}

/* Every option in order, each --set applied to @p sc as it comes. */
static int parse_options(int argc, char **argv, sil_scenario_t *sc, options_t *o)
{
    char err[SIL_ERROR_MAX];
    const char *value;
    int i;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--scenario") == 0) {
            if (option_value(argc, argv, &i, "needs a file") == NULL) {
                return 2;
            }
        } else if (strcmp(argv[i], "--set") == 0) {
            value = option_value(argc, argv, &i, "needs section.key=value");
            if (value == NULL) {
                return 2;
            }
            if (sil_scenario_set_assignment(sc, value, err, sizeof err) != 0) {
                fprintf(stderr, "pmstep-sil: --set: %s\n", err);
                return 2;
            }
        } else if (strcmp(argv[i], "--out") == 0) {
            value = option_value(argc, argv, &i, "needs a folder");
            if (value == NULL) {
                return 2;
            }
            if (strlen(value) >= sizeof o->out_dir) {
                fprintf(stderr, "pmstep-sil: --out: a folder name of %u characters, longer than %u\n",
                        (unsigned)strlen(value), (unsigned)sizeof o->out_dir - 1u);
                return 2;
            }
            snprintf(o->out_dir, sizeof o->out_dir, "%s", value);
        } else if (strcmp(argv[i], "--no-csv") == 0) {
            o->write_csv = false;
        } else if (strcmp(argv[i], "--quiet") == 0) {
            o->quiet = true;
        } else if (strcmp(argv[i], "--print-scenario") == 0) {
            o->print_only = true;
        } else if (strcmp(argv[i], "--record") == 0) {
            o->record_path = option_value(argc, argv, &i, "needs a file");
            if (o->record_path == NULL) {
                return 2;
            }
        } else {
            fprintf(stderr, "pmstep-sil: unknown argument '%s'\n", argv[i]);
            usage(stderr);
            return 2;
        }
    }
    return PROCEED;
}

/* What the run asks that cannot be: a record of the baseline, a time series that would fill the disk
 * (refused before the run starts). */
static int check_request(const sil_scenario_t *sc, const options_t *o, bool stepdir)
{
    if (sc->drive == SIL_DRIVE_MICROSTEP && o->record_path != NULL) {
        fprintf(
            stderr,
            "pmstep-sil: --record needs run.controller = pmstep (the microstep baseline has no firmware to replay)\n");
        return 2;
    }
    if (o->write_csv) {
        const double rows = sc->duration_s / (double)sc->controller.timing.period_s / (double)sc->decimation;
        const double csv_MB =
            rows * (SIL_CSV_ROW_MAX_BYTES + (sc->position_moves > 0 ? 48.0 : 0.0) + (stepdir ? 32.0 : 0.0)) / 1e6;
        if (csv_MB > sc->max_csv_MB) {
            fprintf(stderr,
                    "pmstep-sil: run.csv would take up to %.0f MB (%.0f rows), more than run.max_csv_MB = %g: raise "
                    "run.decimation or run.max_csv_MB, or pass --no-csv\n",
                    csv_MB, rows, sc->max_csv_MB);
            return 2;
        }
    }
    return PROCEED;
}

/* Closes run.csv if open (an error path's). */
static void close_csv(csv_ctx_t *csv)
{
    if (csv->file != NULL) {
        fclose(csv->file);
        csv->file = NULL;
    }
}

/* The output folder, run.csv with its header, and the record. */
static int open_outputs(const sil_scenario_t *sc, options_t *o, bool stepdir, csv_ctx_t *csv, FILE **record)
{
    char path[1100];
    if (o->out_dir[0] == '\0') {
        snprintf(o->out_dir, sizeof o->out_dir, "out/%s", sc->name);
    }
    if (make_dirs(o->out_dir) != 0) {
        fprintf(stderr, "pmstep-sil: cannot create folder '%s': %s\n", o->out_dir, strerror(errno));
        return 2;
    }
    if (o->write_csv) {
        snprintf(path, sizeof path, "%s/run.csv", o->out_dir);
        csv->file = fopen(path, "w");
        if (csv->file == NULL) {
            fprintf(stderr, "pmstep-sil: cannot write '%s': %s\n", path, strerror(errno));
            return 2;
        }
        csv->decimation = sc->decimation;
        fprintf(csv->file,
                "t_s,theta_rad,omega_rad_s,omega_ref_rad_s,i_a_A,i_b_A,u_a_V,u_b_V,cos_hat,sin_hat,"
                "cos_ptheta,sin_ptheta,omega_hat_rad_s,load_hat_Nm,load_Nm,mode,fault,"
                "i_a_meas_A,i_b_meas_A,bus_voltage_V,bus_voltage_meas_V%s%s\n",
                sc->position_moves > 0 && sc->drive == SIL_DRIVE_PMSTEP
                    ? ",position_ref_rad,position_hat_rad,position_rad"
                    : "",
                stepdir ? ",step_count,step_error_full_steps,diag" : "");
    }
    if (o->record_path != NULL && sc->position_moves > 0) {
        fprintf(stderr,
                "pmstep-sil: --record replays pmstep_step alone: not for a position scenario (position.points)\n");
        close_csv(csv);
        return 2;
    }
    if (o->record_path != NULL) {
        *record = fopen(o->record_path, "wb");
        if (*record == NULL) {
            fprintf(stderr, "pmstep-sil: cannot write '%s': %s\n", o->record_path, strerror(errno));
            close_csv(csv);
            return 2;
        }
    }
    return PROCEED;
}

/* The run's setting in one line (and the baseline's drive). */
static void announce(const sil_scenario_t *sc)
{
    fprintf(stderr,
            "pmstep-sil: scenario '%s', %.3f s at %.0f Hz, %d %s steps a period, delay %u, %s inverter, seed %lu\n",
            sc->name, sc->duration_s, 1.0 / (double)sc->controller.timing.period_s, sc->substeps,
            sc->integrator == PLANT_INTEGRATOR_RK4 ? "rk4" : "exponential",
            (unsigned)sc->controller.timing.computational_delay_periods,
            sc->inverter.model == SIL_INVERTER_SWITCHING ? "switching" : "averaged", (unsigned long)sc->seed);
    if (sc->drive == SIL_DRIVE_MICROSTEP) {
        fprintf(stderr, "pmstep-sil: microstep baseline at %g A; the drive is told R = %g Ohm, L = %g H, p = %d%s\n",
                sc->datasheet.rated_current_A, (double)sc->controller.motor.resistance_Ohm,
                (double)sc->controller.motor.inductance_H, (int)sc->controller.motor.pole_pairs,
                sc->controller.motor.pole_pairs != sc->motor.pole_pairs
                    ? " (the plant's p differs: set controller.motor.*)"
                    : "");
    }
}

/* The run's own status (sil_run_record()) and run.csv's closing. */
static int check_run(int run_status, const char *record_path, const sil_summary_t *summary, csv_ctx_t *csv)
{
    if (run_status == 0) {
        const bool failed = csv->file != NULL && (ferror(csv->file) != 0) + (fclose(csv->file) != 0) != 0;
        csv->file = NULL;
        if (failed) {
            fprintf(stderr, "pmstep-sil: error writing run.csv\n");
            return 2;
        }
        return PROCEED;
    }
    if (run_status == -2) {
        fprintf(stderr, "pmstep-sil: error writing the record '%s'\n", record_path);
    } else if (run_status == -3) {
        fprintf(stderr, "pmstep-sil: out of memory for the measurement chain's random number generator\n");
    } else {
        fprintf(stderr, "pmstep-sil: the firmware rejected the configuration: %s (status %d)\n",
                pmstep_status_str(summary->init_status), (int)summary->init_status);
    }
    close_csv(csv);
    return 2;
}

/* summary.json, printed too unless quiet. */
static int write_summary(const sil_scenario_t *sc, const sil_summary_t *summary, const options_t *o)
{
    char path[1100];
    cJSON *json = sil_summary_json(sc, summary);
    char *text = cJSON_Print(json);
    FILE *f;
    snprintf(path, sizeof path, "%s/summary.json", o->out_dir);
    f = fopen(path, "w");
    if (f == NULL || text == NULL) {
        fprintf(stderr, "pmstep-sil: cannot write '%s'\n", path);
        if (f != NULL) {
            fclose(f);
        }
        return 2;
    }
    if ((fprintf(f, "%s\n", text) < 0) + (fclose(f) != 0) != 0) {
        fprintf(stderr, "pmstep-sil: error writing '%s'\n", path);
        return 2;
    }
    if (!o->quiet) {
        printf("%s\n", text);
        fprintf(stderr, "pmstep-sil: wrote %s%s/summary.json\n", o->write_csv ? "run.csv and " : "", o->out_dir);
    }
    cJSON_free(text);
    cJSON_Delete(json);
    return PROCEED;
}

/* The STEP/DIR line, a loss of synchronism and a fault said; the exit status: 3 a fault latched, 4 the
 * baseline lost synchronism, else 0. */
static int report_outcome(const sil_scenario_t *sc, const sil_summary_t *summary, bool stepdir, bool quiet)
{
    if (stepdir && !quiet) {
        const sil_stepdir_summary_t *d = &summary->stepdir;
        fprintf(stderr,
                "pmstep-sil: STEP/DIR: %ld microsteps put out, %ld counted; following error max %.3f full steps "
                "(%.3f while moving), final %+.3f",
                (long)d->generator_steps, (long)d->drive_steps, d->max_error_full_steps, d->max_error_moving_full_steps,
                d->final_error_full_steps);
        if (d->diag_first_s >= 0.0) {
            fprintf(stderr, "; DIAG asserted at t = %.6f s (%ld periods)\n", d->diag_first_s, d->diag_periods);
        } else {
            fprintf(stderr, "; DIAG %s\n", sc->drive == SIL_DRIVE_MICROSTEP ? "none (open loop)" : "never asserted");
        }
    }
    if (summary->loss_of_synchronism) {
        fprintf(stderr, "pmstep-sil: LOSS OF SYNCHRONISM at t = %.6f s (%s)\n", summary->loss_of_synchronism_time_s,
                sc->drive == SIL_DRIVE_MICROSTEP ? "load angle beyond pi"
                                                 : "angle-estimate error above run.loss_angle_error_rad");
    }
    if (summary->fault != PMSTEP_FAULT_NONE) {
        fprintf(stderr, "pmstep-sil: FAULT latched at t = %.6f s: %s\n", summary->fault_time_s,
                pmstep_fault_str(summary->fault));
        return 3;
    }
    return (summary->loss_of_synchronism && sc->drive == SIL_DRIVE_MICROSTEP) ? 4 : 0;
}

int main(int argc, char **argv)
{
    static sil_scenario_t sc;
    sil_summary_t summary;
    char err[SIL_ERROR_MAX];
    options_t o = {NULL, "", true, false, false};
    FILE *record = NULL;
    csv_ctx_t csv = {NULL, 1};
    bool stepdir; /* a STEP/DIR scenario: its columns, figures and line */
    int status = load_scenario(argc, argv, &sc);
    if (status == PROCEED) {
        status = parse_options(argc, argv, &sc, &o);
    }
    if (status != PROCEED) {
        return status;
    }
    if (o.print_only) {
        sil_scenario_print(&sc, stdout);
        return 0;
    }
    if (sil_scenario_check(&sc, err, sizeof err) != 0) {
        fprintf(stderr, "pmstep-sil: %s\n", err);
        return 2;
    }
    stepdir = sc.position_moves > 0 && sc.position_source == SIL_SOURCE_STEPDIR;
    status = check_request(&sc, &o, stepdir);
    if (status == PROCEED) {
        status = open_outputs(&sc, &o, stepdir, &csv, &record);
    }
    if (status != PROCEED) {
        return status;
    }
    if (!o.quiet) {
        announce(&sc);
    }
    status = sil_run_record(&sc, o.write_csv ? write_row : NULL, &csv, !o.quiet, &summary, record);
    if (record != NULL && fclose(record) != 0 && status == 0) {
        status = -2;
    }
    status = check_run(status, o.record_path, &summary, &csv);
    if (status == PROCEED) {
        status = write_summary(&sc, &summary, &o);
    }
    return status == PROCEED ? report_outcome(&sc, &summary, stepdir, o.quiet) : status;
}
