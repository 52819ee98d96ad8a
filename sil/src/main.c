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
#include "sil/microstep.h"
#include "sil/runner.h"
#include "pmstep/pmstep_text.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: pmstep-sil [--scenario FILE|paper] [--set section.key=value]... [--out DIR]\n"
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

/* A position scenario's figures (sil_position_summary_t; electrical rad = p times mechanical). */
static void add_position_json(cJSON *root, const sil_summary_t *s)
{
    const sil_position_summary_t *p = &s->position;
    cJSON *position = cJSON_CreateObject();
    cJSON_AddNumberToObject(position, "moves", p->moves);
    cJSON_AddNumberToObject(position, "rejected_moves", p->rejected_moves);
    cJSON_AddNumberToObject(position, "unfinished_moves", p->unfinished_moves);
    cJSON_AddNumberToObject(position, "max_final_error_electrical_rad", p->max_final_error_rad);
    cJSON_AddNumberToObject(position, "mean_final_error_electrical_rad", p->mean_final_error_rad);
    cJSON_AddNumberToObject(position, "worst_move", p->worst_move);
    cJSON_AddNumberToObject(position, "max_overshoot_fraction", p->max_overshoot_fraction);
    cJSON_AddNumberToObject(position, "max_estimate_error_electrical_rad", p->max_estimate_error_rad);
    cJSON_AddNumberToObject(position, "max_tracking_error_electrical_rad", p->max_tracking_error_rad);
    cJSON_AddNumberToObject(position, "hold_duration_s", p->hold_duration_s);
    cJSON_AddNumberToObject(position, "hold_max_error_electrical_rad", p->hold_max_error_rad);
    cJSON_AddNumberToObject(position, "hold_max_estimate_error_electrical_rad", p->hold_max_estimate_error_rad);
    cJSON_AddNumberToObject(position, "hold_drift_electrical_rad_s", p->hold_drift_rad_s);
    cJSON_AddItemToObject(root, "position", position);
}

/* A STEP/DIR scenario's figures (sil_stepdir_summary_t; errors in full steps, pi / (2 p) mechanical rad). */
static void add_stepdir_json(cJSON *root, const sil_scenario_t *sc, const sil_summary_t *s)
{
    const sil_stepdir_summary_t *d = &s->stepdir;
    cJSON *stepdir = cJSON_CreateObject();
    cJSON_AddNumberToObject(stepdir, "microsteps", (double)d->microsteps);
    cJSON_AddStringToObject(stepdir, "diag_mode", sc->stepdir_diag_mode == PMSTEP_DIAG_PULSE ? "pulse" : "level");
    cJSON_AddNumberToObject(stepdir, "moves", d->moves);
    cJSON_AddNumberToObject(stepdir, "first_move_s", d->first_move_s);
    cJSON_AddNumberToObject(stepdir, "last_move_end_s", d->last_move_end_s);
    cJSON_AddNumberToObject(stepdir, "peak_speed_rad_s", d->peak_speed_rad_s);
    cJSON_AddNumberToObject(stepdir, "following_start_s", d->following_start_s);
    cJSON_AddNumberToObject(stepdir, "following_end_s", d->following_end_s);
    cJSON_AddNumberToObject(stepdir, "generator_steps", (double)d->generator_steps);
    cJSON_AddNumberToObject(stepdir, "drive_steps", (double)d->drive_steps);
    cJSON_AddNumberToObject(stepdir, "max_error_moving_full_steps", d->max_error_moving_full_steps);
    cJSON_AddNumberToObject(stepdir, "rms_error_moving_full_steps", d->rms_error_moving_full_steps);
    cJSON_AddNumberToObject(stepdir, "max_error_full_steps", d->max_error_full_steps);
    cJSON_AddNumberToObject(stepdir, "rms_error_full_steps", d->rms_error_full_steps);
    cJSON_AddNumberToObject(stepdir, "final_error_full_steps", d->final_error_full_steps);
    cJSON_AddNumberToObject(stepdir, "lost_full_steps", (double)d->lost_full_steps);
    cJSON_AddNumberToObject(stepdir, "error_beyond_full_step_s", d->error_beyond_full_step_s);
    cJSON_AddNumberToObject(stepdir, "diag_periods", (double)d->diag_periods);
    cJSON_AddNumberToObject(stepdir, "diag_first_s", d->diag_first_s);
    cJSON_AddItemToObject(root, "stepdir", stepdir);
}

static const char *homing_state_name(pmstep_homing_state_t state)
{
    static const char *const names[] = {"idle", "seeking", "backing_off", "done", "not_found", "aborted"};
    return (unsigned)state < sizeof names / sizeof names[0] ? names[state] : "unknown";
}

static void add_homing_json(cJSON *root, const sil_summary_t *s)
{
    const sil_homing_summary_t *h = &s->homing;
    cJSON *homing = cJSON_CreateObject();
    cJSON_AddNumberToObject(homing, "speed_rad_s", (double)h->config.speed_rad_s);
    cJSON_AddNumberToObject(homing, "accel_rad_s2", (double)h->config.accel_rad_s2);
    cJSON_AddNumberToObject(homing, "max_travel_rad", (double)h->config.max_travel_rad);
    cJSON_AddNumberToObject(homing, "stall_current_a", (double)h->config.stall_current_A);
    cJSON_AddNumberToObject(homing, "stall_error_rad", (double)h->config.stall_error_rad);
    cJSON_AddNumberToObject(homing, "back_off_rad", (double)h->config.back_off_rad);
    cJSON_AddNumberToObject(homing, "start_status", (double)h->start_status);
    cJSON_AddStringToObject(homing, "state", homing_state_name(h->state));
    cJSON_AddNumberToObject(homing, "start_s", h->start_s);
    cJSON_AddNumberToObject(homing, "contact_s", h->contact_s);
    cJSON_AddNumberToObject(homing, "found_s", h->found_s);
    cJSON_AddNumberToObject(homing, "done_s", h->done_s);
    cJSON_AddStringToObject(homing, "found_by", h->by_current ? "current" : "following_error");
    cJSON_AddNumberToObject(homing, "zero_rad", h->zero_rad);
    cJSON_AddNumberToObject(homing, "stop_error_full_steps", h->stop_error_full_steps);
    cJSON_AddNumberToObject(homing, "contact_peak_current_a", h->contact_peak_current_A);
    cJSON_AddNumberToObject(homing, "seek_peak_stop_torque_nm", h->seek_peak_stop_torque_Nm);
    cJSON_AddNumberToObject(homing, "final_from_stop_full_steps", h->final_from_stop_full_steps);
    cJSON_AddNumberToObject(homing, "final_position_error_full_steps", h->final_position_error_full_steps);
    cJSON_AddItemToObject(root, "homing", homing);
}

/* The [sensors], [inverter] and [bus] settings and what the ADC clipped. */
static cJSON *measurement_chain_json(const sil_scenario_t *sc)
{
    const pmstep_hal_host_t *port = pmstep_hal_host_state();
    cJSON *chain = cJSON_CreateObject();
    cJSON *sensors = cJSON_CreateObject();
    cJSON *inverter = cJSON_CreateObject();
    cJSON *bus = cJSON_CreateObject();
    cJSON_AddNumberToObject(sensors, "adc_bits", sc->sensors.adc_bits);
    cJSON_AddNumberToObject(sensors, "current_full_scale_A", sc->sensors.current_full_scale_A);
    cJSON_AddNumberToObject(sensors, "offset_a_A", sc->sensors.offset_a_A);
    cJSON_AddNumberToObject(sensors, "offset_b_A", sc->sensors.offset_b_A);
    cJSON_AddNumberToObject(sensors, "gain_error_a", sc->sensors.gain_error_a);
    cJSON_AddNumberToObject(sensors, "gain_error_b", sc->sensors.gain_error_b);
    cJSON_AddNumberToObject(sensors, "noise_rms_A", sc->sensors.noise_rms_A);
    cJSON_AddNumberToObject(sensors, "bus_full_scale_V", sc->sensors.bus_full_scale_V);
    cJSON_AddNumberToObject(sensors, "bus_noise_rms_V", sc->sensors.bus_noise_rms_V);
    cJSON_AddNumberToObject(sensors, "phase_voltage_bits", sc->sensors.phase_voltage_bits);
    cJSON_AddNumberToObject(sensors, "phase_voltage_full_scale_V", sc->sensors.phase_voltage_full_scale_V);
    cJSON_AddNumberToObject(sensors, "phase_voltage_offset_a_V", sc->sensors.phase_voltage_offset_a_V);
    cJSON_AddNumberToObject(sensors, "phase_voltage_offset_b_V", sc->sensors.phase_voltage_offset_b_V);
    cJSON_AddNumberToObject(sensors, "phase_voltage_gain_error_a", sc->sensors.phase_voltage_gain_error_a);
    cJSON_AddNumberToObject(sensors, "phase_voltage_gain_error_b", sc->sensors.phase_voltage_gain_error_b);
    cJSON_AddNumberToObject(sensors, "phase_voltage_noise_rms_V", sc->sensors.phase_voltage_noise_rms_V);
    cJSON_AddBoolToObject(sensors, "phase_voltage_sensing", sc->controller.inverter.phase_voltage_sensing);
    cJSON_AddItemToObject(chain, "sensors", sensors);
    cJSON_AddStringToObject(inverter, "model", sc->inverter.model == SIL_INVERTER_SWITCHING ? "switching" : "averaged");
    cJSON_AddNumberToObject(inverter, "dead_time_s", sc->inverter.dead_time_s);
    cJSON_AddItemToObject(chain, "inverter", inverter);
    cJSON_AddNumberToObject(bus, "voltage_V", sc->bus_voltage_V);
    cJSON_AddNumberToObject(bus, "source_resistance_Ohm", sc->bus.source_resistance_Ohm);
    cJSON_AddNumberToObject(bus, "ripple_V", sc->bus.ripple_V);
    cJSON_AddNumberToObject(bus, "ripple_Hz", sc->bus.ripple_Hz);
    cJSON_AddItemToObject(chain, "bus", bus);
    /* Phase samples (two per period) and bus samples at an end code of the ADC. */
    cJSON_AddNumberToObject(chain, "adc_clipped_current_samples", (double)port->sensors.clipped_current_samples);
    cJSON_AddNumberToObject(chain, "adc_clipped_bus_samples", (double)port->sensors.clipped_bus_samples);
    cJSON_AddNumberToObject(chain, "adc_clipped_phase_voltage_samples", (double)port->sensors.clipped_voltage_samples);
    return chain;
}

/* Ground truth against what the core reported, and what its commissioning measured. */
static void add_robustness_json(cJSON *root, const sil_summary_t *s)
{
    cJSON *robust = cJSON_CreateObject();
    cJSON *comm = cJSON_CreateObject();
    const pmstep_commissioning_t *c = &s->commissioning;
    cJSON_AddNumberToObject(robust, "run_start_time_s", s->run_start_time_s);
    cJSON_AddNumberToObject(robust, "settle_time_s", s->settle_time_s);
    cJSON_AddNumberToObject(robust, "max_angle_error_rad", s->max_angle_error_rad);
    cJSON_AddNumberToObject(robust, "max_angle_error_time_s", s->max_angle_error_time_s);
    cJSON_AddNumberToObject(robust, "final_angle_error_rad", s->final_angle_error_rad);
    cJSON_AddNumberToObject(robust, "max_speed_error_rad_s", s->max_speed_error_after_settle_rad_s);
    cJSON_AddNumberToObject(robust, "max_speed_error_time_s", s->max_speed_error_time_s);
    cJSON_AddNumberToObject(robust, "loss_of_control_time_s", s->loss_of_control_time_s);
    if (isnan(s->detection_latency_s)) {
        cJSON_AddNullToObject(robust, "detection_latency_s");
    } else {
        cJSON_AddNumberToObject(robust, "detection_latency_s", s->detection_latency_s);
    }
    cJSON_AddBoolToObject(robust, "nonfinite_seen", s->nonfinite_seen);
    cJSON_AddItemToObject(root, "robustness", robust);
    cJSON_AddNumberToObject(comm, "offset_a_A", (double)c->offset_a_A);
    cJSON_AddNumberToObject(comm, "offset_b_A", (double)c->offset_b_A);
    cJSON_AddNumberToObject(comm, "offset_samples", (double)c->offset_samples);
    cJSON_AddNumberToObject(comm, "resistance_Ohm", (double)c->resistance_Ohm);
    cJSON_AddNumberToObject(comm, "inductance_H", (double)c->inductance_H);
    cJSON_AddNumberToObject(comm, "torque_constant_Nm_A", (double)c->torque_constant_Nm_A);
    cJSON_AddNumberToObject(comm, "equilibrium_cos", (double)c->equilibrium_cos);
    cJSON_AddNumberToObject(comm, "equilibrium_sin", (double)c->equilibrium_sin);
    cJSON_AddNumberToObject(comm, "voltage_bias_a_V", (double)c->voltage_bias_a_V);
    cJSON_AddNumberToObject(comm, "voltage_bias_b_V", (double)c->voltage_bias_b_V);
    cJSON_AddNumberToObject(comm, "inertia_kgm2", (double)c->inertia_kgm2);
    cJSON_AddNumberToObject(comm, "friction_Nms_rad", (double)c->friction_Nms_rad);
    cJSON_AddStringToObject(comm, "identification", pmstep_identification_str(c->identification));
    cJSON_AddNumberToObject(comm, "realignments", (double)c->realignments);
    cJSON_AddNumberToObject(comm, "alignment_repeats", (double)c->alignment_repeats);
    cJSON_AddBoolToObject(comm, "measured", c->measured);
    cJSON_AddItemToObject(root, "commissioning", comm);
}

/* The figures both drives report, for the comparison with the microstepping baseline. */
static void add_baseline_json(cJSON *root, const sil_scenario_t *sc, const sil_summary_t *s)
{
    cJSON_AddBoolToObject(root, "loss_of_synchronism", s->loss_of_synchronism);
    cJSON_AddNumberToObject(root, "loss_of_synchronism_time_s", s->loss_of_synchronism_time_s);
    cJSON_AddNumberToObject(root, "max_load_angle_rad", s->max_load_angle_rad);
    cJSON_AddNumberToObject(root, "rms_phase_current_A", s->rms_phase_current_A);
    cJSON_AddNumberToObject(root, "metrics_start_s", s->metrics_start_time_s);
    if (sc->drive == SIL_DRIVE_MICROSTEP) {
        cJSON *drive = cJSON_CreateObject();
        cJSON_AddNumberToObject(drive, "current_A", sc->datasheet.rated_current_A);
        cJSON_AddNumberToObject(drive, "current_gain_per_s",
                                SIL_MICROSTEP_GAIN_FRACTION / (double)sc->controller.timing.period_s);
        cJSON_AddNumberToObject(drive, "pull_out_torque_Nm", sc->motor.torque_constant_Nm_A * sc->datasheet.rated_current_A);
        cJSON_AddItemToObject(root, "microstep", drive);
    }
}

static cJSON *summary_json(const sil_scenario_t *sc, const sil_summary_t *s)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *align = cJSON_CreateObject();
    cJSON *speed = cJSON_CreateObject();
    cJSON *angle = cJSON_CreateObject();
    cJSON *timing = cJSON_CreateObject();
    cJSON *fault = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scenario", sc->name);
    cJSON_AddStringToObject(root, "controller", sc->drive == SIL_DRIVE_MICROSTEP ? "microstep" : "pmstep");
    cJSON_AddNumberToObject(root, "pole_pairs", sc->motor.pole_pairs);
    cJSON_AddNumberToObject(root, "control_period_s", (double)sc->controller.timing.period_s);
    cJSON_AddNumberToObject(root, "substeps", sc->substeps);
    cJSON_AddStringToObject(root, "integrator", sc->integrator == PLANT_INTEGRATOR_RK4 ? "rk4" : "exponential");
    cJSON_AddNumberToObject(root, "delay_periods", sc->controller.timing.computational_delay_periods);
    cJSON_AddNumberToObject(root, "s_align_time_s", (double)sc->controller.alignment.s_align_time_s);
    cJSON_AddNumberToObject(root, "c_align_time_s", (double)sc->controller.alignment.c_align_time_s);
    cJSON_AddNumberToObject(root, "transient_window_s", sc->transient_window_s);
    cJSON_AddNumberToObject(root, "theta0_deg", sc->theta0_rad * 180.0 / 3.14159265358979323846);
    cJSON_AddNumberToObject(root, "seed", (double)sc->seed);
    cJSON_AddItemToObject(root, "measurement_chain", measurement_chain_json(sc));

    cJSON_AddNumberToObject(align, "cos_ptheta_at_ts", s->cos_ptheta_at_ts);
    cJSON_AddNumberToObject(align, "sin_ptheta_at_ts", s->sin_ptheta_at_ts);
    cJSON_AddNumberToObject(align, "i_b_minus_ucs_over_r_at_ts_A", s->i_b_residual_at_ts_A);
    cJSON_AddNumberToObject(align, "cos_ptheta_at_tc", s->cos_ptheta_at_tc);
    cJSON_AddNumberToObject(align, "sin_ptheta_at_tc", s->sin_ptheta_at_tc);
    cJSON_AddNumberToObject(align, "i_a_minus_ucc_over_r_at_tc_A", s->i_a_residual_at_tc_A);
    cJSON_AddItemToObject(root, "alignment", align);

    cJSON_AddNumberToObject(speed, "transient_max_abs_error_rad_s", s->transient_max_speed_error_rad_s);
    cJSON_AddNumberToObject(speed, "transient_rms_error_rad_s", s->transient_rms_speed_error_rad_s);
    cJSON_AddNumberToObject(speed, "tracking_max_abs_error_rad_s", s->tracking_max_speed_error_rad_s);
    cJSON_AddNumberToObject(speed, "tracking_rms_error_rad_s", s->tracking_rms_speed_error_rad_s);
    cJSON_AddItemToObject(root, "speed", speed);

    cJSON_AddNumberToObject(root, "final_load_hat_Nm", s->final_load_hat_Nm);
    cJSON_AddNumberToObject(root, "final_load_Nm", s->final_load_Nm);
    cJSON_AddNumberToObject(root, "final_load_abs_error_Nm", s->final_load_error_Nm);
    cJSON_AddNumberToObject(angle, "max_abs_cos_error", s->max_cos_error);
    cJSON_AddNumberToObject(angle, "max_abs_sin_error", s->max_sin_error);
    cJSON_AddItemToObject(root, "angle_estimate", angle);
    cJSON_AddNumberToObject(root, "max_abs_phase_voltage_V", s->max_phase_voltage_V);
    cJSON_AddNumberToObject(root, "max_abs_phase_current_a", s->max_phase_current_A);
    cJSON_AddNumberToObject(root, "voltage_limited_periods", (double)s->voltage_limited_periods);
    cJSON_AddNumberToObject(root, "inverter_clipped_periods", (double)s->inverter_limited_periods);
    cJSON_AddStringToObject(root, "final_mode", pmstep_mode_str(s->final_mode));
    add_robustness_json(root, s);
    add_baseline_json(root, sc, s);
    if (sc->position_moves > 0 && sc->drive == SIL_DRIVE_PMSTEP) {
        add_position_json(root, s);
    }
    if (sc->position_moves > 0 && sc->position_source == SIL_SOURCE_STEPDIR) {
        add_stepdir_json(root, sc, s);
    }
    if (sc->motor.stop_side != 0) {
        cJSON_AddNumberToObject(root, "stop_contact_s", s->stop_contact_s);
    }
    if (sc->position_moves > 0 && sc->position_source == SIL_SOURCE_HOMING) {
        add_homing_json(root, s);
    }

    cJSON_AddNumberToObject(fault, "code", (double)s->fault);
    cJSON_AddStringToObject(fault, "name", pmstep_fault_str(s->fault));
    cJSON_AddStringToObject(fault, "text", pmstep_fault_str(s->fault));
    cJSON_AddNumberToObject(fault, "step", (double)s->fault_step);
    cJSON_AddNumberToObject(fault, "time_s", s->fault_time_s);
    cJSON_AddItemToObject(root, "fault", fault);

    cJSON_AddNumberToObject(timing, "steps", (double)s->steps);
    cJSON_AddNumberToObject(timing, "simulated_s", s->sim_time_s);
    cJSON_AddNumberToObject(timing, "wall_s", s->wall_time_s);
    cJSON_AddNumberToObject(timing, "cpu_s", s->cpu_time_s);
    cJSON_AddNumberToObject(timing, "plant_wall_s", s->plant_time_s);
    cJSON_AddNumberToObject(timing, "firmware_wall_s", s->firmware_time_s);
    cJSON_AddNumberToObject(timing, "real_time_factor", s->real_time_factor);
    cJSON_AddItemToObject(root, "timing", timing);
    return root;
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
        fprintf(stderr, "pmstep-sil: --record needs run.controller = pmstep (the microstep baseline has no firmware to replay)\n");
        return 2;
    }
    if (o->write_csv) {
        const double rows = sc->duration_s / (double)sc->controller.timing.period_s / (double)sc->decimation;
        const double csv_MB = rows * (SIL_CSV_ROW_MAX_BYTES + (sc->position_moves > 0 ? 48.0 : 0.0)
                                      + (stepdir ? 32.0 : 0.0)) / 1e6;
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
        fprintf(csv->file, "t_s,theta_rad,omega_rad_s,omega_ref_rad_s,i_a_A,i_b_A,u_a_V,u_b_V,cos_hat,sin_hat,"
                           "cos_ptheta,sin_ptheta,omega_hat_rad_s,load_hat_Nm,load_Nm,mode,fault,"
                           "i_a_meas_A,i_b_meas_A,bus_voltage_V,bus_voltage_meas_V%s%s\n",
                sc->position_moves > 0 && sc->drive == SIL_DRIVE_PMSTEP ? ",position_ref_rad,position_hat_rad,position_rad"
                                                                        : "",
                stepdir ? ",step_count,step_error_full_steps,diag" : "");
    }
    if (o->record_path != NULL && sc->position_moves > 0) {
        fprintf(stderr, "pmstep-sil: --record replays pmstep_step alone: not for a position scenario (position.points)\n");
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
    fprintf(stderr, "pmstep-sil: scenario '%s', %.3f s at %.0f Hz, %d %s steps a period, delay %u, %s inverter, seed %lu\n",
            sc->name, sc->duration_s, 1.0 / (double)sc->controller.timing.period_s, sc->substeps,
            sc->integrator == PLANT_INTEGRATOR_RK4 ? "rk4" : "exponential",
            (unsigned)sc->controller.timing.computational_delay_periods,
            sc->inverter.model == SIL_INVERTER_SWITCHING ? "switching" : "averaged", (unsigned long)sc->seed);
    if (sc->drive == SIL_DRIVE_MICROSTEP) {
        fprintf(stderr, "pmstep-sil: microstep baseline at %g A; the drive is told R = %g Ohm, L = %g H, p = %d%s\n",
                sc->datasheet.rated_current_A, (double)sc->controller.motor.resistance_Ohm,
                (double)sc->controller.motor.inductance_H, (int)sc->controller.motor.pole_pairs,
                sc->controller.motor.pole_pairs != sc->motor.pole_pairs ? " (the plant's p differs: set controller.motor.*)"
                                                                        : "");
    }
}

/* The run's own status (sil_run_record()) and run.csv's closing. */
static int check_run(int run_status, const char *record_path, const sil_summary_t *summary, csv_ctx_t *csv)
{
    if (run_status == -2) {
        fprintf(stderr, "pmstep-sil: error writing the record '%s'\n", record_path);
    } else if (run_status == -3) {
        fprintf(stderr, "pmstep-sil: out of memory for the measurement chain's random number generator\n");
    } else if (run_status != 0) {
        fprintf(stderr, "pmstep-sil: the firmware rejected the configuration: %s (status %d)\n",
                pmstep_status_str(summary->init_status), (int)summary->init_status);
    } else {
        if (csv->file != NULL && (ferror(csv->file) != 0) + (fclose(csv->file) != 0) != 0) {
            csv->file = NULL;
            fprintf(stderr, "pmstep-sil: error writing run.csv\n");
            return 2;
        }
        csv->file = NULL;
        return PROCEED;
    }
    close_csv(csv);
    return 2;
}

/* summary.json, printed too unless quiet. */
static int write_summary(const sil_scenario_t *sc, const sil_summary_t *summary, const options_t *o)
{
    char path[1100];
    cJSON *json = summary_json(sc, summary);
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
        fprintf(stderr, "pmstep-sil: STEP/DIR: %ld microsteps put out, %ld counted; following error max %.3f full steps "
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
                sc->drive == SIL_DRIVE_MICROSTEP ? "load angle beyond pi" : "angle-estimate error above run.loss_angle_error_rad");
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
