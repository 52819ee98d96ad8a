/* Private to the scenario reader's sources (scenario*.c): the key table's layout, the value
 * names of the enumerated keys, and the error helper, not part of the API (sil/scenario.h). */
#ifndef SIL_SCENARIO_KEYS_H
#define SIL_SCENARIO_KEYS_H

#include "sil/scenario.h"

#include <stdarg.h>
#include <stdio.h>

#define PI 3.14159265358979323846

typedef enum { KEY_DOUBLE, KEY_FLOAT, KEY_INT, KEY_UINT, KEY_BOOL, KEY_ANGLE_DEG, KEY_SPEED_POINTS,
               KEY_LOAD_POINTS, KEY_LOAD_KIND, KEY_INVERTER_MODEL, KEY_ADC_BITS, KEY_INTEGRATOR,
               KEY_DRIVE, KEY_MOVES, KEY_PHASES, KEY_SENSOR_FAULT, KEY_POSITION_SOURCE,
               KEY_DIAG_MODE } key_type_t;

/* Range of a numeric key: min/max, each inclusive or exclusive. */
typedef struct {
    const char *name;
    key_type_t type;
    size_t offset;
    double min;
    int min_exclusive;
    double max;
    int max_exclusive;
    const char *help;
} key_t_;

/* The keys, in the order --print-scenario writes them (scenario_keys.c). */
extern const key_t_ scenario_keys[];
extern const size_t scenario_key_count;

/* The value names of the enumerated keys, defined here so that the reader (scenario.c) and the
 * printer (scenario_print.c) count them with sizeof. */
static const char *const load_kind_names[] = {"none", "constant", "step", "proportional", "table"};
static const char *const inverter_model_names[] = {"averaged", "switching"};
static const char *const integrator_names[] = {"rk4", "exponential"}; /* in plant_integrator_t order */
static const char *const drive_names[] = {"pmstep", "microstep"};     /* in sil_drive_t order */
static const char *const phases_names[] = {"none", "a", "b", "both"};  /* in sil_phases_t order */
static const char *const sensor_fault_names[] = {"none", "open", "stuck"}; /* in sil_sensor_fault_t order */
static const char *const position_source_names[] = {"move", "stepdir", "homing"}; /* in sil_position_source_t order */
static const char *const diag_mode_names[] = {"level", "pulse"}; /* in pmstep_diag_mode_t order */

/* run.theta0_deg's value as stored (rad): the one conversion the reader applies and the printer
 * inverts (scenario.c). */
double scenario_angle_stored_rad(double degrees);

/* The message into @p err; -1, the readers' error return. */
static inline int fail(char *err, size_t err_size, const char *fmt, ...)
{
    va_list args;
    va_start(args, fmt);
    vsnprintf(err, err_size, fmt, args);
    va_end(args);
    return -1;
}

#endif /* SIL_SCENARIO_KEYS_H */
