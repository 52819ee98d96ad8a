/* Scenario files: read and checked whole, parsed by inih, each entry set through
 * sil_scenario_set() (scenario.c); then the checks across keys (sil_scenario_check). */
#include "scenario_keys.h"

#include <ini.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct {
    sil_scenario_t *sc;
    char message[SIL_ERROR_MAX];
    int failed;
    char points_key[160]; /**< the points key being read: its value may continue on indented lines */
    char points_text[4096];
} load_ctx_t;

/* A points value continued on indented lines (inih hands each line over under the same key)
 * is joined with a comma, and the whole list is parsed again. NULL if the joined list does
 * not fit. */
static const char *join_points(load_ctx_t *ctx, const char *key, const char *value)
{
    const size_t used = strlen(ctx->points_text);
    int written;
    if (strcmp(ctx->points_key, key) != 0 || used == 0) {
        snprintf(ctx->points_key, sizeof ctx->points_key, "%s", key);
        written = snprintf(ctx->points_text, sizeof ctx->points_text, "%s", value);
    } else {
        const char *separator = ctx->points_text[used - 1] == ',' ? " " : ", ";
        written = snprintf(ctx->points_text + used, sizeof ctx->points_text - used, "%s%s", separator, value);
        written += (int)used;
    }
    if (written < 0 || (size_t)written >= sizeof ctx->points_text) {
        ctx->points_text[0] = '\0';
        return NULL;
    }
    return ctx->points_text;
}

/* scenario.name names the output folder out/<name>: a plain file name only. */
static int plain_file_name(const char *name)
{
    size_t n;
    if (name[0] == '\0' || name[0] == '.' || strlen(name) >= sizeof((sil_scenario_t *)0)->name) {
        return 0;
    }
    for (n = 0; name[n] != '\0'; ++n) {
        const char c = name[n];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_'
              || c == '-')) {
            return 0;
        }
    }
    return 1;
}

static int on_ini_entry(void *user, const char *section, const char *name, const char *value)
{
    load_ctx_t *ctx = (load_ctx_t *)user;
    char key[160];
    char message[SIL_ERROR_MAX];
    if (ctx->failed) {
        return 0; /* keep the first error */
    }
    if (strcmp(section, "scenario") == 0 && strcmp(name, "name") == 0) {
        if (!plain_file_name(value)) {
            snprintf(ctx->message, sizeof ctx->message,
                     "scenario.name '%.64s' is not a plain file name (1 to %d letters, digits, '.', '_' or '-', not "
                     "starting with '.'): it names the output folder",
                     value, (int)sizeof ctx->sc->name - 1);
            ctx->failed = 1;
            return 0;
        }
        snprintf(ctx->sc->name, sizeof ctx->sc->name, "%s", value);
        return 1;
    }
    if (snprintf(key, sizeof key, "%s.%s", section, name) >= (int)sizeof key) {
        snprintf(ctx->message, sizeof ctx->message, "key '%.40s...' is too long", section);
        ctx->failed = 1;
        return 0;
    }
    if (strcmp(name, "points") == 0) {
        value = join_points(ctx, key, value);
        if (value == NULL) {
            snprintf(ctx->message, sizeof ctx->message, "%s: the joined point list is longer than %d characters", key,
                     (int)sizeof ctx->points_text - 1);
            ctx->failed = 1;
            return 0;
        }
    }
    if (sil_scenario_set(ctx->sc, key, value, message, sizeof message) != 0) {
        snprintf(ctx->message, sizeof ctx->message, "%s", message);
        ctx->failed = 1;
        return 0;
    }
    return 1;
}

/* The whole file, checked before inih sees it: a regular file of at most SIL_SCENARIO_MAX_BYTES,
 * no NUL byte, and no line longer than the INI reader's buffer (which would split it silently).
 * @return the text (caller frees) or NULL with @p err set. */
static char *read_scenario_text(const char *path, char *err, size_t err_size)
{
    /* inih's buffer holds a line with its "\r\n\0" (ini.h: INI_MAX_LINE must be 3 more than the longest line). */
    const size_t max_line_chars = (size_t)ini_max_line - 3u;
    struct stat info;
    size_t size;
    size_t n;
    size_t line_start = 0;
    int line = 1;
    char *text;
    FILE *file = fopen(path, "rb");
    if (file == NULL) {
        fail(err, err_size, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    if (fstat(fileno(file), &info) != 0 || !S_ISREG(info.st_mode)) {
        fclose(file);
        fail(err, err_size, "%s: not a regular file", path);
        return NULL;
    }
    if (info.st_size > (off_t)SIL_SCENARIO_MAX_BYTES) {
        fclose(file);
        fail(err, err_size, "%s: %lld bytes, more than a scenario file may have (%u)", path, (long long)info.st_size,
             (unsigned)SIL_SCENARIO_MAX_BYTES);
        return NULL;
    }
    size = (size_t)info.st_size;
    text = malloc(size + 1u);
    if (text == NULL) {
        fclose(file);
        fail(err, err_size, "%s: out of memory", path);
        return NULL;
    }
    if (fread(text, 1u, size, file) != size) {
        free(text);
        fclose(file);
        fail(err, err_size, "%s: read error", path);
        return NULL;
    }
    fclose(file);
    text[size] = '\0';
    for (n = 0; n <= size; ++n) {
        if (n < size && text[n] == '\0') {
            free(text);
            fail(err, err_size, "%s:%d: NUL byte in the file", path, line);
            return NULL;
        }
        if (n == size || text[n] == '\n') {
            size_t length = n - line_start;
            if (length > 0u && text[n - 1u] == '\r') {
                --length;
            }
            if (length > max_line_chars) {
                free(text);
                fail(err, err_size,
                     "%s:%d: line of %u characters, longer than the %u the INI reader takes (continue a "
                     "long value on indented lines)",
                     path, line, (unsigned)length, (unsigned)max_line_chars);
                return NULL;
            }
            ++line;
            line_start = n + 1u;
        }
    }
    return text;
}

int sil_scenario_load(sil_scenario_t *sc, const char *path, char *err, size_t err_size)
{
    load_ctx_t ctx;
    int line;
    char *text = read_scenario_text(path, err, err_size);
    if (text == NULL) {
        return -1;
    }
    ctx.sc = sc;
    ctx.message[0] = '\0';
    ctx.failed = 0;
    ctx.points_key[0] = '\0';
    ctx.points_text[0] = '\0';
    line = ini_parse_string(text, on_ini_entry, &ctx);
    free(text);
    if (line == -2) {
        return fail(err, err_size, "%s: out of memory", path);
    }
    if (line != 0) {
        if (ctx.failed) {
            return fail(err, err_size, "%s:%d: %s", path, line, ctx.message);
        }
        return fail(err, err_size, "%s:%d: malformed line (expected [section] or key = value)", path, line);
    }
    return 0;
}

int sil_scenario_check(const sil_scenario_t *sc, char *err, size_t err_size)
{

    if (sc->load.kind == PLANT_LOAD_TABLE && sc->load.table_points == 0) {
        return fail(err, err_size, "load.type = table needs load.points");
    }
    if (sc->speed_points == 0) {
        return fail(err, err_size, "speed.points: no set-point profile");
    }
    if (!(sc->inverter.dead_time_s < 0.25 * (double)sc->controller.timing.period_s)) {
        return fail(err, err_size, "inverter.dead_time_s = %g is not below run.period_s / 4 = %g",
                    sc->inverter.dead_time_s, 0.25 * (double)sc->controller.timing.period_s);
    }
    if (sc->sensors.adc_bits > 0u
        && sc->sensors.current_full_scale_A < (double)sc->controller.limits.max_phase_current_A) {
        return fail(
            err, err_size,
            "sensors.current_full_scale_A = %g is below controller.limits.max_phase_current_A = %g: the ADC would clip "
            "before the trip",
            sc->sensors.current_full_scale_A, (double)sc->controller.limits.max_phase_current_A);
    }
    if (sc->sensors.adc_bits > 0u && sc->sensors.bus_full_scale_V < (double)sc->controller.limits.max_bus_voltage_V) {
        return fail(
            err, err_size,
            "sensors.bus_full_scale_V = %g is below controller.limits.max_bus_voltage_V = %g: the ADC would clip "
            "before the overvoltage trip",
            sc->sensors.bus_full_scale_V, (double)sc->controller.limits.max_bus_voltage_V);
    }
    if (sc->controller.inverter.phase_voltage_sensing && sc->sensors.phase_voltage_bits > 0u
        && sc->sensors.phase_voltage_full_scale_V < (double)sc->controller.limits.max_bus_voltage_V) {
        return fail(err, err_size,
                    "sensors.phase_voltage_full_scale_V = %g is below controller.limits.max_bus_voltage_V = %g: the "
                    "phase-voltage ADC would clip a voltage the bridge can apply",
                    sc->sensors.phase_voltage_full_scale_V, (double)sc->controller.limits.max_bus_voltage_V);
    }
    if (sc->drive == SIL_DRIVE_MICROSTEP
        && !(sc->controller.motor.resistance_Ohm >= 0.0f && sc->controller.motor.inductance_H > 0.0f
             && sc->controller.motor.pole_pairs >= 1)) {
        /* The firmware's init does not see the configuration in microstep mode: the drive's own check. */
        return fail(err, err_size,
                    "run.controller = microstep needs controller.motor.resistance_Ohm >= 0, inductance_H > 0 and "
                    "pole_pairs >= 1 (what the drive is told): got %g Ohm, %g H, %d",
                    (double)sc->controller.motor.resistance_Ohm, (double)sc->controller.motor.inductance_H,
                    (int)sc->controller.motor.pole_pairs);
    }
    if (sc->position_moves > 0) {
        const double run_start_s = (double)sc->controller.commissioning.offset_calibration_time_s
                                   + (double)sc->controller.alignment.c_align_time_s;
        int n;
        if (sc->drive != SIL_DRIVE_PMSTEP && sc->position_source != SIL_SOURCE_STEPDIR) {
            return fail(err, err_size,
                        "position.points: moves need run.controller = pmstep, or position.source = "
                        "stepdir (a step count the microstep baseline follows too)");
        }
        if (sc->position_source == SIL_SOURCE_STEPDIR) {
            /* The port's 16-bit counter is read once a period: it must turn by less than half its range. */
            const double microstep_rad =
                2.0 * PI / (4.0 * (double)sc->motor.pole_pairs * (double)sc->stepdir_microsteps);
            const double per_period = sc->move_speed_rad_s * (double)sc->controller.timing.period_s / microstep_rad;
            if (!(per_period < 32767.0)) {
                return fail(err, err_size,
                            "position.v_max_rad_s = %g with stepdir.microsteps = %u: %.0f microsteps a "
                            "period, more than the 16-bit step counter's half turn (32767)",
                            sc->move_speed_rad_s, (unsigned)sc->stepdir_microsteps, per_period);
            }
        }
        for (n = 0; n < sc->speed_points; ++n) {
            if (sc->speed_value_rad_s[n] != 0.0) {
                return fail(err, err_size,
                            "position.points with a speed profile: set speed.points = 0:0 (a speed command "
                            "would leave position mode)");
            }
        }
        if (sc->move_time_s[0] < run_start_s) {
            return fail(err, err_size, "position.points: the first move at %g s is before RUN starts (%g s)",
                        sc->move_time_s[0], run_start_s);
        }
        for (n = 0; n < sc->position_moves; ++n) {
            if (!(fabs(sc->move_target_rad[n]) * (double)sc->controller.motor.pole_pairs
                  <= (double)PMSTEP_POSITION_MAX_ELECTRICAL_RAD)) {
                return fail(err, err_size, "position.points: move %d: p |theta| above %g electrical rad", n + 1,
                            (double)PMSTEP_POSITION_MAX_ELECTRICAL_RAD);
            }
        }
    }
    if (sc->position_source == SIL_SOURCE_STEPDIR && sc->position_moves == 0) {
        return fail(err, err_size,
                    "position.source = stepdir needs position.points (the moves the step generator plans)");
    }
    if (sc->position_source == SIL_SOURCE_HOMING && sc->position_moves != 1) {
        return fail(err, err_size,
                    "position.source = homing needs one position point t:theta (homing starts at t toward "
                    "theta's sign, |theta| its largest travel); got %d",
                    sc->position_moves);
    }
    if (sc->motor.stop_side != 0) {
        /* the rotor on the stop's spring: sqrt(k_s / J) h within 1 keeps the integrator's step well inside its
         * stability (RK4: 2.8) */
        const double h_s = (double)sc->controller.timing.period_s / (double)sc->substeps;
        const double phase = sqrt(sc->motor.stop_stiffness_Nm_rad / sc->motor.inertia_kgm2) * h_s;
        if (!(sc->motor.stop_stiffness_Nm_rad > 0.0)) {
            return fail(err, err_size, "motor.stop_side = %d needs motor.stop_stiffness_Nm_rad > 0",
                        sc->motor.stop_side);
        }
        if (!((double)sc->motor.stop_side * (sc->theta0_rad - sc->motor.stop_position_rad) < 0.0)) {
            return fail(err, err_size,
                        "motor.stop_position_rad = %g with motor.stop_side = %d: the rotor would start "
                        "at or beyond the stop (run.theta0_deg = %g)",
                        sc->motor.stop_position_rad, sc->motor.stop_side, sc->theta0_rad * 180.0 / PI);
        }
        if (phase > 1.0) {
            return fail(
                err, err_size,
                "motor.stop_stiffness_Nm_rad = %g: sqrt(k_s / J) h = %g with a substep of %g s (at most 1): raise "
                "run.substeps to %.0f",
                sc->motor.stop_stiffness_Nm_rad, phase, h_s, ceil((double)sc->substeps * phase));
        }
    }
    if (sc->load.kind == PLANT_LOAD_PROPORTIONAL && sc->integrator == PLANT_INTEGRATOR_RK4) {
        /* RK4 on w' = -(c/J) w: stable for c h / J within 2.78; 2.5 keeps a margin. The exponential
         * integrator takes the load exactly. */
        const double h_s = (double)sc->controller.timing.period_s / (double)sc->substeps;
        const double stiffness = fabs(sc->load.coefficient_Nms_rad) * h_s / sc->motor.inertia_kgm2;
        if (stiffness > 2.5) {
            return fail(err, err_size,
                        "load.coefficient_Nms_rad = %g: |c| h / J = %g with run.integrator = rk4 and a substep of %g s "
                        "(stable up to 2.5): raise run.substeps to %.0f or use run.integrator = exponential",
                        sc->load.coefficient_Nms_rad, stiffness, h_s, ceil((double)sc->substeps * stiffness / 2.5));
        }
    }
    if ((sc->faults.sensor != SIL_SENSOR_OK) != (sc->faults.sensor_phase != SIL_PHASES_NONE)) {
        return fail(err, err_size,
                    "faults.sensor and faults.sensor_phase go together: a failed sensor needs its phase, "
                    "a phase needs the failure (got %s on %s)",
                    sensor_fault_names[sc->faults.sensor], phases_names[sc->faults.sensor_phase]);
    }
    if (!(sc->bus.ripple_V < sc->bus_voltage_V)) {
        return fail(err, err_size, "bus.ripple_V = %g is not below run.bus_voltage_V = %g: the bus would reach zero",
                    sc->bus.ripple_V, sc->bus_voltage_V);
    }
    return 0;
}
