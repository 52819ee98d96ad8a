/* A scenario written back as INI (--print-scenario): every key of the table with its help line,
 * in a form that sil_scenario_load() reads back to the same values. */
#include "scenario_keys.h"

#include <stdlib.h>
#include <string.h>

static void print_points(FILE *file, const double *t, const double *v, int n)
{
    int k;
    for (k = 0; k < n; ++k) {
        /* six points a line, continued on indented lines: inih reads lines of up to 200 characters */
        fprintf(file, "%s%.9g:%.9g", k == 0 ? "" : (k % 6 == 0 ? ",\n    " : ", "), t[k], v[k]);
    }
    fputc('\n', file);
}

/* Shortest decimal that reads back as the same float. */
static void print_float(FILE *file, float value)
{
    char text[32];
    int digits;
    for (digits = 6; digits < 9; ++digits) {
        snprintf(text, sizeof text, "%.*g", digits, (double)value);
        if (strtof(text, NULL) == value) {
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
        case KEY_DOUBLE: fprintf(file, "%.9g\n", *(const double *)(base + k->offset)); break;
        case KEY_FLOAT: print_float(file, *(const float *)(base + k->offset)); break;
        case KEY_INT: fprintf(file, "%d\n", (int)*(const int32_t *)(base + k->offset)); break;
        case KEY_UINT: fprintf(file, "%u\n", (unsigned)*(const uint32_t *)(base + k->offset)); break;
        case KEY_BOOL: fprintf(file, "%s\n", *(const bool *)(base + k->offset) ? "true" : "false"); break;
        case KEY_ANGLE_DEG: fprintf(file, "%.9g\n", *(const double *)(base + k->offset) * 180.0 / PI); break;
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
