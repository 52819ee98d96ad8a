/* A scenario written back as INI (--print-scenario): every key of the table with its help line,
 * in a form that sil_scenario_load() reads back to the same values. */
#include "scenario_keys.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The shortest decimal (9 to 17 significant digits) of @p value that reads back as it: the reader
 * takes every value with strtod, and a value that printed rounded could fall outside its key's
 * range or break a strict order (0.4999999999 as 0.5 against a bound < 0.5). */
static void format_double(char *text, size_t size, double value)
{
    int digits;
    for (digits = 9; digits < 17; ++digits) {
        snprintf(text, size, "%.*g", digits, value);
        if (strtod(text, NULL) == value) {
            return;
        }
    }
    snprintf(text, size, "%.17g", value);
}

static void print_double(FILE *file, double value)
{
    char text[40];
    format_double(text, sizeof text, value);
    fprintf(file, "%s\n", text);
}

/* run.theta0_deg: degrees that the reader's conversion turns into the stored radians again,
 * the shortest decimal of rad * 180 / pi that does; else (rare) a double within a few units in
 * the last place of it, at 17 digits. The stored value came from that conversion, so one exists. */
static void print_angle_deg(FILE *file, double stored_rad)
{
    const double nearest_deg = stored_rad * 180.0 / PI;
    double below = nearest_deg;
    double above = nearest_deg;
    char text[40];
    int digits;
    int step;
    for (digits = 9; digits <= 17; ++digits) {
        snprintf(text, sizeof text, "%.*g", digits, nearest_deg);
        if (scenario_angle_stored_rad(strtod(text, NULL)) == stored_rad) {
            fprintf(file, "%s\n", text);
            return;
        }
    }
    for (step = 0; step < 8; ++step) {
        above = nextafter(above, HUGE_VAL);
        below = nextafter(below, -HUGE_VAL);
        if (scenario_angle_stored_rad(above) == stored_rad || scenario_angle_stored_rad(below) == stored_rad) {
            snprintf(text, sizeof text, "%.17g", scenario_angle_stored_rad(above) == stored_rad ? above : below);
            fprintf(file, "%s\n", text);
            return;
        }
    }
    fprintf(file, "%.17g\n", nearest_deg); /* not a value the reader stored: the nearest */
}

static void print_points(FILE *file, const double *t, const double *v, int n)
{
    int k;
    for (k = 0; k < n; ++k) {
        char time_text[40];
        char value_text[40];
        format_double(time_text, sizeof time_text, t[k]);
        format_double(value_text, sizeof value_text, v[k]);
        /* three points a line, continued on indented lines: inih reads lines of up to 200
         * characters, and a point at 17 digits takes up to 49 */
        fprintf(file, "%s%s:%s", k == 0 ? "" : (k % 3 == 0 ? ",\n    " : ", "), time_text, value_text);
    }
    fputc('\n', file);
}

/* Shortest decimal that reads back as the same float: the reader rounds strtod's double to float,
 * so the test is that same double rounding (strtof may differ from it in the last bit). */
static void print_float(FILE *file, float value)
{
    char text[32];
    int digits;
    for (digits = 6; digits < 9; ++digits) {
        snprintf(text, sizeof text, "%.*g", digits, (double)value);
        if ((float)strtod(text, NULL) == value) {
            break;
        }
    }
    snprintf(text, sizeof text, "%.*g", digits, (double)value);
    fprintf(file, "%s\n", text);
}

void sil_scenario_print(const sil_scenario_t *sc, FILE *file)
{
    const char *section = "";
    size_t n;
    const char *base = (const char *)sc;
    fprintf(file, "[scenario]\nname = %s\n", sc->name);
    for (n = 0; n < scenario_key_count; ++n) {
        const key_t_ *k = &scenario_keys[n];
        const char *dot = strrchr(k->name, '.'); /* [controller.gains] speed_gain_per_s = ... */
        const size_t section_len = (size_t)(dot - k->name);
        if (strncmp(section, k->name, section_len) != 0 || section[section_len] != '\0') {
            static char current[32];
            memcpy(current, k->name, section_len);
            current[section_len] = '\0';
            section = current;
            fprintf(file, "\n[%s]\n", section);
        }
        fprintf(file, "; %s\n%s = ", k->help, dot + 1);
        switch (k->type) {
        case KEY_DOUBLE: print_double(file, *(const double *)(base + k->offset)); break;
        case KEY_FLOAT: print_float(file, *(const float *)(base + k->offset)); break;
        case KEY_INT: fprintf(file, "%d\n", (int)*(const int32_t *)(base + k->offset)); break;
        case KEY_UINT: fprintf(file, "%u\n", (unsigned)*(const uint32_t *)(base + k->offset)); break;
        case KEY_BOOL: fprintf(file, "%s\n", *(const bool *)(base + k->offset) ? "true" : "false"); break;
        case KEY_ANGLE_DEG: print_angle_deg(file, *(const double *)(base + k->offset)); break;
        case KEY_SPEED_POINTS: print_points(file, sc->speed_time_s, sc->speed_value_rad_s, sc->speed_points); break;
        case KEY_LOAD_POINTS:
            if (sc->load.table_points > 0) {
                print_points(file, sc->load.table_time_s, sc->load.table_torque_Nm, sc->load.table_points);
            } else {
                fprintf(file, "0:0\n");
            }
            break;
        case KEY_LOAD_KIND: fprintf(file, "%s\n", load_kind_names[sc->load.kind]); break;
        case KEY_INVERTER_MODEL: fprintf(file, "%s\n", inverter_model_names[sc->inverter.model]); break;
        case KEY_INTEGRATOR: fprintf(file, "%s\n", integrator_names[sc->integrator]); break;
        case KEY_DRIVE: fprintf(file, "%s\n", drive_names[sc->drive]); break;
        case KEY_PHASES: fprintf(file, "%s\n", phases_names[*(const sil_phases_t *)(base + k->offset)]); break;
        case KEY_SENSOR_FAULT:
            fprintf(file, "%s\n", sensor_fault_names[*(const sil_sensor_fault_t *)(base + k->offset)]);
            break;
        case KEY_POSITION_SOURCE:
            fprintf(file, "%s\n", position_source_names[*(const sil_position_source_t *)(base + k->offset)]);
            break;
        case KEY_DIAG_MODE:
            fprintf(file, "%s\n", diag_mode_names[*(const pmstep_diag_mode_t *)(base + k->offset)]);
            break;
        case KEY_MOVES:
            if (sc->position_moves > 0) {
                print_points(file, sc->move_time_s, sc->move_target_rad, sc->position_moves);
            } else {
                fprintf(file, "0:0\n");
            }
            break;
        case KEY_ADC_BITS: fprintf(file, "%u\n", *(const unsigned *)(base + k->offset)); break;
        }
    }
}
