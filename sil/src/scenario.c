/* Scenario keys: one table gives each key its field, type and range (scenario_keys.c). Files are
 * parsed by inih (scenario_load.c); this file only converts and checks values. */
#include "scenario_keys.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

double scenario_angle_stored_rad(double degrees)
{
    return degrees * PI / 180.0;
}

/* Whole-string number: no trailing text, finite, 0 or normal. strtod reports a decimal that
 * underflows as ERANGE; an exact subnormal (hex "0x1p-1074") it takes without a word, and the
 * printer's decimal of it would then not read back: refused alike. */
static int parse_number(const char *text, double *value)
{
    char *end;
    errno = 0;
    *value = strtod(text, &end);
    if (end == text || errno == ERANGE || !isfinite(*value) || (*value != 0.0 && fabs(*value) < DBL_MIN)) {
        return -1;
    }
    while (*end == ' ' || *end == '\t') {
        ++end;
    }
    return *end == '\0' ? 0 : -1;
}

/* "t:v, t:v, ..." with strictly increasing t >= 0. */
static int parse_points(const char *key, const char *text, double *times, double *values, int max_points, int *count,
                        char *err, size_t err_size)
{
    char buffer[4096];
    char *cursor;
    int n = 0;
    if (strlen(text) >= sizeof buffer) {
        return fail(err, err_size, "%s: value too long", key);
    }
    strcpy(buffer, text);
    cursor = buffer;
    while (*cursor != '\0') {
        char *comma = strchr(cursor, ',');
        char *colon;
        if (comma != NULL) {
            *comma = '\0';
        }
        colon = strchr(cursor, ':');
        if (colon == NULL) {
            return fail(err, err_size, "%s: point %d '%s' is not time:value", key, n + 1, cursor);
        }
        *colon = '\0';
        if (n >= max_points) {
            return fail(err, err_size, "%s: more than %d points", key, max_points);
        }
        if (parse_number(cursor, &times[n]) != 0 || parse_number(colon + 1, &values[n]) != 0) {
            return fail(err, err_size, "%s: point %d has a malformed number", key, n + 1);
        }
        if (times[n] < 0.0 || (n > 0 && !(times[n] > times[n - 1]))) {
            return fail(err, err_size, "%s: point %d: times must be >= 0 and strictly increasing", key, n + 1);
        }
        ++n;
        if (comma == NULL) {
            break;
        }
        cursor = comma + 1;
    }
    if (n == 0) {
        return fail(err, err_size, "%s: no points", key);
    }
    *count = n;
    return 0;
}

static int in_range(const key_t_ *k, double v)
{
    if (k->min_exclusive ? !(v > k->min) : !(v >= k->min)) {
        return 0;
    }
    if (k->max_exclusive ? !(v < k->max) : !(v <= k->max)) {
        return 0;
    }
    return 1;
}

int sil_scenario_set(sil_scenario_t *sc, const char *key, const char *value, char *err, size_t err_size)
{
    size_t n;
    char *base = (char *)sc;
    for (n = 0; n < scenario_key_count; ++n) {
        const key_t_ *k = &scenario_keys[n];
        double v = 0.0;
        if (strcmp(k->name, key) != 0) {
            continue;
        }
        switch (k->type) {
        case KEY_SPEED_POINTS:
            return parse_points(key, value, sc->speed_time_s, sc->speed_value_rad_s, SIL_SPEED_POINTS_MAX,
                                &sc->speed_points, err, err_size);
        case KEY_LOAD_POINTS:
            return parse_points(key, value, sc->load.table_time_s, sc->load.table_torque_Nm, PLANT_LOAD_TABLE_MAX,
                                &sc->load.table_points, err, err_size);
        case KEY_MOVES:
            if (parse_points(key, value, sc->move_time_s, sc->move_target_rad, SIL_POSITION_MOVES_MAX,
                             &sc->position_moves, err, err_size)
                != 0) {
                return -1;
            }
            if (sc->position_moves == 1 && sc->move_time_s[0] == 0.0 && sc->move_target_rad[0] == 0.0) {
                sc->position_moves = 0; /* 0:0 alone: no moves */
            }
            return 0;
        case KEY_LOAD_KIND: {
            size_t j;
            for (j = 0; j < sizeof load_kind_names / sizeof load_kind_names[0]; ++j) {
                if (strcmp(value, load_kind_names[j]) == 0) {
                    sc->load.kind = (plant_load_kind_t)j;
                    return 0;
                }
            }
            return fail(err, err_size, "%s: '%s' is not one of none, constant, step, proportional, table", key, value);
        }
        case KEY_INVERTER_MODEL: {
            size_t j;
            for (j = 0; j < sizeof inverter_model_names / sizeof inverter_model_names[0]; ++j) {
                if (strcmp(value, inverter_model_names[j]) == 0) {
                    *(sil_inverter_model_t *)(base + k->offset) = (sil_inverter_model_t)j;
                    return 0;
                }
            }
            return fail(err, err_size, "%s: '%s' is not one of averaged, switching", key, value);
        }
        case KEY_INTEGRATOR: {
            size_t j;
            for (j = 0; j < sizeof integrator_names / sizeof integrator_names[0]; ++j) {
                if (strcmp(value, integrator_names[j]) == 0) {
                    sc->integrator = (plant_integrator_t)j;
                    return 0;
                }
            }
            return fail(err, err_size, "%s: '%s' is not one of exponential, rk4", key, value);
        }
        case KEY_DRIVE: {
            size_t j;
            for (j = 0; j < sizeof drive_names / sizeof drive_names[0]; ++j) {
                if (strcmp(value, drive_names[j]) == 0) {
                    sc->drive = (sil_drive_t)j;
                    return 0;
                }
            }
            return fail(err, err_size, "%s: '%s' is not one of pmstep, microstep", key, value);
        }
        case KEY_POSITION_SOURCE:
        case KEY_DIAG_MODE: {
            const bool source = k->type == KEY_POSITION_SOURCE;
            const char *const *names = source ? position_source_names : diag_mode_names;
            const size_t count = source ? sizeof position_source_names / sizeof position_source_names[0]
                                        : sizeof diag_mode_names / sizeof diag_mode_names[0];
            size_t j;
            for (j = 0; j < count; ++j) {
                if (strcmp(value, names[j]) == 0) {
                    if (source) {
                        *(sil_position_source_t *)(base + k->offset) = (sil_position_source_t)j;
                    } else {
                        *(pmstep_diag_mode_t *)(base + k->offset) = (pmstep_diag_mode_t)j;
                    }
                    return 0;
                }
            }
            return fail(err, err_size, "%s: '%s' is not one of %s", key, value,
                        source ? "move, stepdir" : "level, pulse");
        }
        case KEY_PHASES:
        case KEY_SENSOR_FAULT: {
            const char *const *names = k->type == KEY_PHASES ? phases_names : sensor_fault_names;
            const size_t count = k->type == KEY_PHASES ? sizeof phases_names / sizeof phases_names[0]
                                                       : sizeof sensor_fault_names / sizeof sensor_fault_names[0];
            size_t j;
            for (j = 0; j < count; ++j) {
                if (strcmp(value, names[j]) == 0) {
                    if (k->type == KEY_PHASES) {
                        *(sil_phases_t *)(base + k->offset) = (sil_phases_t)j;
                    } else {
                        *(sil_sensor_fault_t *)(base + k->offset) = (sil_sensor_fault_t)j;
                    }
                    return 0;
                }
            }
            return fail(err, err_size, "%s: '%s' is not one of %s", key, value,
                        k->type == KEY_PHASES ? "none, a, b, both" : "none, open, stuck");
        }
        case KEY_BOOL:
            if (strcmp(value, "true") == 0 || strcmp(value, "1") == 0) {
                *(bool *)(base + k->offset) = true;
            } else if (strcmp(value, "false") == 0 || strcmp(value, "0") == 0) {
                *(bool *)(base + k->offset) = false;
            } else {
                return fail(err, err_size, "%s: '%s' is not true or false", key, value);
            }
            return 0;
        default: break;
        }
        if (parse_number(value, &v) != 0) {
            return fail(err, err_size, "%s: '%s' is not a finite number (0 or of magnitude %g to %g)", key, value,
                        DBL_MIN, DBL_MAX);
        }
        if (!in_range(k, v)) {
            return fail(err, err_size, "%s = %s is out of range: must be %s %g and %s %g (%s)", key, value,
                        k->min_exclusive ? ">" : ">=", k->min, k->max_exclusive ? "<" : "<=", k->max, k->help);
        }
        if ((k->type == KEY_INT || k->type == KEY_UINT || k->type == KEY_ADC_BITS) && v != floor(v)) {
            return fail(err, err_size, "%s: '%s' is not an integer", key, value);
        }
        if (k->type == KEY_FLOAT && v != 0.0 && !(fabs(v) >= (double)FLT_MIN && fabs(v) <= (double)FLT_MAX)) {
            return fail(err, err_size, "%s = %s is not representable as a normal float32 (the firmware's type)", key,
                        value);
        }
        if (k->type == KEY_ADC_BITS && v > 0.0 && v < 8.0) {
            return fail(err, err_size, "%s = %s is out of range: must be 0 (ideal) or 8 .. 16 (%s)", key, value,
                        k->help);
        }
        switch (k->type) {
        case KEY_DOUBLE: *(double *)(base + k->offset) = v; break;
        case KEY_FLOAT: *(float *)(base + k->offset) = (float)v; break;
        case KEY_INT: *(int32_t *)(base + k->offset) = (int32_t)v; break;
        case KEY_UINT: *(uint32_t *)(base + k->offset) = (uint32_t)v; break;
        case KEY_ADC_BITS: *(unsigned *)(base + k->offset) = (unsigned)v; break;
        case KEY_ANGLE_DEG: *(double *)(base + k->offset) = scenario_angle_stored_rad(v); break;
        default: break;
        }
        sil_scenario_sense_ranges(sc);
        return 0;
    }
    return fail(err, err_size, "unknown key '%s' (run with --print-scenario to list the keys)", key);
}

int sil_scenario_set_assignment(sil_scenario_t *sc, const char *assignment, char *err, size_t err_size)
{
    char key[128];
    const char *eq = strchr(assignment, '=');
    size_t len;
    if (eq == NULL) {
        return fail(err, err_size, "--set '%s': expected section.key=value", assignment);
    }
    len = (size_t)(eq - assignment);
    if (len == 0 || len >= sizeof key) {
        return fail(err, err_size, "--set '%s': bad key", assignment);
    }
    memcpy(key, assignment, len);
    key[len] = '\0';
    return sil_scenario_set(sc, key, eq + 1, err, err_size);
}
