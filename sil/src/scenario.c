/* Scenario keys: one table gives each key its field, type and range. Files are
 * parsed by inih; this file only converts and checks values. */
#include "sil/scenario.h"

#include <ini.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PI 3.14159265358979323846

typedef enum { KEY_DOUBLE, KEY_FLOAT, KEY_INT, KEY_UINT, KEY_BOOL, KEY_ANGLE_DEG, KEY_SPEED_POINTS,
               KEY_LOAD_POINTS, KEY_LOAD_KIND, KEY_INVERTER_MODEL, KEY_ADC_BITS, KEY_INTEGRATOR,
               KEY_DRIVE, KEY_MOVES } key_type_t;

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

#define OFF(field) offsetof(sil_scenario_t, field)
#define BIG 1e12

static const key_t_ keys[] = {
    {"datasheet.rated_current_A", KEY_DOUBLE, OFF(datasheet.rated_current_A), 0, 1, 1e4, 0, "rated phase current (A)"},
    {"datasheet.holding_torque_Nm", KEY_DOUBLE, OFF(datasheet.holding_torque_Nm), 0, 1, 1e6, 0, "holding torque, both phases at rated current (Nm)"},
    {"datasheet.detent_torque_Nm", KEY_DOUBLE, OFF(datasheet.detent_torque_Nm), 0, 0, 1e6, 0, "unpowered detent torque (Nm); 0 = not given"},

    {"motor.resistance_Ohm", KEY_DOUBLE, OFF(motor.resistance_Ohm), 0, 1, BIG, 0, "plant R (Ohm)"},
    {"motor.inductance_H", KEY_DOUBLE, OFF(motor.inductance_H), 0, 1, BIG, 0, "plant L (H)"},
    {"motor.inertia_kgm2", KEY_DOUBLE, OFF(motor.inertia_kgm2), 0, 1, BIG, 0, "plant J (kg m^2)"},
    {"motor.friction_Nms_rad", KEY_DOUBLE, OFF(motor.friction_Nms_rad), 0, 0, BIG, 0, "plant F (Nm s/rad)"},
    {"motor.torque_constant_Nm_A", KEY_DOUBLE, OFF(motor.torque_constant_Nm_A), 0, 1, BIG, 0, "plant k_M (Nm/A)"},
    {"motor.pole_pairs", KEY_INT, OFF(motor.pole_pairs), 1, 0, 1000, 0, "plant p"},
    {"motor.detent_torque_Nm", KEY_DOUBLE, OFF(motor.detent_torque_Nm), 0, 0, 1e6, 0, "plant detent torque T_d, -T_d sin(4 p theta) (Nm); 0 = none"},

    {"controller.motor.resistance_Ohm", KEY_FLOAT, OFF(controller.motor.resistance_Ohm), -BIG, 0, BIG, 0, "R the firmware assumes (Ohm)"},
    {"controller.motor.inductance_H", KEY_FLOAT, OFF(controller.motor.inductance_H), -BIG, 0, BIG, 0, "L (H)"},
    {"controller.motor.inertia_kgm2", KEY_FLOAT, OFF(controller.motor.inertia_kgm2), -BIG, 0, BIG, 0, "J (kg m^2)"},
    {"controller.motor.friction_Nms_rad", KEY_FLOAT, OFF(controller.motor.friction_Nms_rad), -BIG, 0, BIG, 0, "F (Nm s/rad)"},
    {"controller.motor.torque_constant_Nm_A", KEY_FLOAT, OFF(controller.motor.torque_constant_Nm_A), -BIG, 0, BIG, 0, "k_M (Nm/A)"},
    {"controller.motor.pole_pairs", KEY_INT, OFF(controller.motor.pole_pairs), -1000, 0, 1000, 0, "p"},
    {"controller.motor.detent_torque_Nm", KEY_FLOAT, OFF(controller.motor.detent_torque_Nm), -BIG, 0, BIG, 0, "detent torque T_d the observer and the law compensate (Nm); 0 = none (the paper)"},
    {"controller.alignment.s_align_time_s", KEY_FLOAT, OFF(controller.alignment.s_align_time_s), -BIG, 0, BIG, 0, "t_s (s)"},
    {"controller.alignment.c_align_time_s", KEY_FLOAT, OFF(controller.alignment.c_align_time_s), -BIG, 0, BIG, 0, "t_c (s)"},
    {"controller.alignment.s_align_voltage_V", KEY_FLOAT, OFF(controller.alignment.s_align_voltage_V), -BIG, 0, BIG, 0, "u_cs (V)"},
    {"controller.alignment.c_align_voltage_V", KEY_FLOAT, OFF(controller.alignment.c_align_voltage_V), -BIG, 0, BIG, 0, "u_cc (V)"},
    {"controller.gains.speed_gain_per_s", KEY_FLOAT, OFF(controller.gains.speed_gain_per_s), -BIG, 0, BIG, 0, "k_omega (1/s)"},
    {"controller.gains.observer_gain_per_s", KEY_FLOAT, OFF(controller.gains.observer_gain_per_s), -BIG, 0, BIG, 0, "K_e (1/s)"},
    {"controller.gains.current_gain_per_s", KEY_FLOAT, OFF(controller.gains.current_gain_per_s), -BIG, 0, BIG, 0, "K_i (1/s)"},
    {"controller.gains.adapt_gamma", KEY_FLOAT, OFF(controller.gains.adapt_gamma), -BIG, 0, BIG, 0, "gamma"},
    {"controller.gains.adapt_lambda", KEY_FLOAT, OFF(controller.gains.adapt_lambda), -BIG, 0, BIG, 0, "lambda"},
    {"controller.gains.adapt_r", KEY_FLOAT, OFF(controller.gains.adapt_r), -BIG, 0, BIG, 0, "r"},
    {"controller.gains.sat_kappa_rad_s", KEY_FLOAT, OFF(controller.gains.sat_kappa_rad_s), -BIG, 0, BIG, 0, "kappa (rad/s)"},
    {"controller.gains.reference_bandwidth_rad_s", KEY_FLOAT, OFF(controller.gains.reference_bandwidth_rad_s), -BIG, 0, BIG, 0, "varpi_0 (rad/s)"},
    {"controller.gains.current_integral_gain_per_s2", KEY_FLOAT, OFF(controller.gains.current_integral_gain_per_s2), -BIG, 0, BIG, 0, "K_I: PI current loop, integral of i - i* in the voltage (1/s^2); 0 = the paper's law"},
    {"controller.gains.angle_correction_gain_per_s", KEY_FLOAT, OFF(controller.gains.angle_correction_gain_per_s), -BIG, 0, BIG, 0, "pulls (c-hat, s-hat) onto the unit circle at this rate (1/s); 0 = the paper's open integrals"},
    {"controller.limits.max_phase_current_A", KEY_FLOAT, OFF(controller.limits.max_phase_current_A), -BIG, 0, BIG, 0, "overcurrent trip (A)"},
    {"controller.limits.min_bus_voltage_V", KEY_FLOAT, OFF(controller.limits.min_bus_voltage_V), -BIG, 0, BIG, 0, "undervoltage trip (V)"},
    {"controller.limits.max_bus_voltage_V", KEY_FLOAT, OFF(controller.limits.max_bus_voltage_V), -BIG, 0, BIG, 0, "overvoltage trip (V)"},
    {"controller.commissioning.offset_calibration_time_s", KEY_FLOAT, OFF(controller.commissioning.offset_calibration_time_s), -BIG, 0, BIG, 0, "Remark 2: bridge off this long before s-alignment, current offsets averaged (s); 0 = none"},
    {"controller.commissioning.alignment_offset_calibration", KEY_BOOL, OFF(controller.commissioning.alignment_offset_calibration), 0, 0, 1, 0, "offsets also from the alignment steady states (true/false)"},
    {"controller.commissioning.steady_state_window_s", KEY_FLOAT, OFF(controller.commissioning.steady_state_window_s), -BIG, 0, BIG, 0, "averaging window at the end of each alignment (s); 0 = none"},
    {"controller.commissioning.inductance_window_s", KEY_FLOAT, OFF(controller.commissioning.inductance_window_s), -BIG, 0, BIG, 0, "current-rise window at the start of s-alignment for L (s); 0 = L not measured"},
    {"controller.commissioning.use_measured_resistance", KEY_BOOL, OFF(controller.commissioning.use_measured_resistance), 0, 0, 1, 0, "RUN uses the measured R (true/false)"},
    {"controller.commissioning.use_measured_inductance", KEY_BOOL, OFF(controller.commissioning.use_measured_inductance), 0, 0, 1, 0, "RUN uses the measured L (true/false)"},
    {"controller.commissioning.use_measured_torque_constant", KEY_BOOL, OFF(controller.commissioning.use_measured_torque_constant), 0, 0, 1, 0, "RUN uses the measured k_M (true/false)"},
    {"controller.commissioning.voltage_bias_level_fraction", KEY_FLOAT, OFF(controller.commissioning.voltage_bias_level_fraction), -BIG, 0, BIG, 0, "Remark 2 voltage bias: second alignment level as a fraction of the voltage (0 = off)"},
    {"controller.commissioning.identification_time_s", KEY_FLOAT, OFF(controller.commissioning.identification_time_s), -BIG, 0, BIG, 0, "J and F identified over this long from t_c (s); the speed commands must accelerate in it; 0 = off"},
    {"controller.commissioning.identification_min_speed_rad_s", KEY_FLOAT, OFF(controller.commissioning.identification_min_speed_rad_s), -BIG, 0, BIG, 0, "identification uses only periods with |w*| at least this (rad/s)"},
    {"controller.commissioning.use_identified_mechanics", KEY_BOOL, OFF(controller.commissioning.use_identified_mechanics), 0, 0, 1, 0, "RUN uses the identified J and F from the window's end (true/false)"},
    {"controller.inverter.dead_time_s", KEY_FLOAT, OFF(controller.inverter.dead_time_s), -BIG, 0, BIG, 0, "dead time per half-bridge to compensate (s); 0 = none"},
    {"controller.inverter.dead_time_current_band_A", KEY_FLOAT, OFF(controller.inverter.dead_time_current_band_A), -BIG, 0, BIG, 0, "dead-time compensation linear within +/- this current (A)"},
    {"controller.detection.angle_magnitude_bound", KEY_FLOAT, OFF(controller.detection.angle_magnitude_bound), -BIG, 0, BIG, 0, "|c-hat^2 + s-hat^2 - 1| above -> angle lost; 0 = off"},
    {"controller.detection.speed_consistency_bound_rad_s", KEY_FLOAT, OFF(controller.detection.speed_consistency_bound_rad_s), -BIG, 0, BIG, 0, "|speed from the angle's rotation - omega-hat| above -> inconsistent (rad/s); 0 = off"},
    {"controller.detection.stall_speed_error_rad_s", KEY_FLOAT, OFF(controller.detection.stall_speed_error_rad_s), -BIG, 0, BIG, 0, "|omega-hat - omega*| above -> stall (rad/s); 0 = off"},
    {"controller.detection.observer_residual_bound_A", KEY_FLOAT, OFF(controller.detection.observer_residual_bound_A), -BIG, 0, BIG, 0, "detection: low-passed |i - i-hat| sum above -> OBSERVER_RESIDUAL (A, 0 = off)"},
    {"controller.detection.persistence_s", KEY_FLOAT, OFF(controller.detection.persistence_s), -BIG, 0, BIG, 0, "persistence before a detection acts (s)"},
    {"controller.detection.max_realignments", KEY_UINT, OFF(controller.detection.max_realignments), 0, 0, 4294967295.0, 0, "0: a detection latches its fault; N: re-align up to N times"},
    {"controller.known_load_mode", KEY_BOOL, OFF(controller.known_load_mode), 0, 0, 1, 0, "Remark 1: load torque measured (true/false)"},

    /* 3600 s / 1 us = 3.6e9 periods: the core's uint32 step counter does not wrap. */
    {"run.duration_s", KEY_DOUBLE, OFF(duration_s), 0, 1, 3600, 0, "simulated time (s)"},
    {"run.period_s", KEY_FLOAT, OFF(controller.timing.period_s), 1e-6, 0, 0.01, 0, "control period T_s (s)"},
    {"run.substeps", KEY_INT, OFF(substeps), 1, 0, 10000, 0, "plant integration steps per control period"},
    {"run.integrator", KEY_INTEGRATOR, OFF(integrator), 0, 0, 0, 0, "exponential (R/L exact, fourth order) | rk4 (classical, the reference)"},
    {"run.delay_periods", KEY_UINT, OFF(controller.timing.computational_delay_periods), 0, 0, 1, 0, "computational delay (0 or 1 period)"},
    {"run.bus_voltage_V", KEY_DOUBLE, OFF(bus_voltage_V), 0, 1, 10000, 0, "DC bus (V)"},
    {"run.theta0_deg", KEY_ANGLE_DEG, OFF(theta0_rad), -1e6, 0, 1e6, 0, "initial rotor angle (mechanical deg)"},
    {"run.omega0_rad_s", KEY_DOUBLE, OFF(omega0_rad_s), -1e4, 0, 1e4, 0, "initial speed (rad/s)"},
    {"run.i_a0_A", KEY_DOUBLE, OFF(i_a0_A), -1e4, 0, 1e4, 0, "initial current a (A)"},
    {"run.i_b0_A", KEY_DOUBLE, OFF(i_b0_A), -1e4, 0, 1e4, 0, "initial current b (A)"},
    {"run.decimation", KEY_INT, OFF(decimation), 1, 0, 100000000, 0, "a CSV row every N periods"},
    {"run.transient_window_s", KEY_DOUBLE, OFF(transient_window_s), 0, 0, 3600, 0, "load-transient window after t_c (s)"},
    {"run.seed", KEY_UINT, OFF(seed), 0, 0, 4294967295.0, 0, "seed of every random draw (GSL MT19937; 0 acts as 4357)"},
    {"run.loss_speed_error_rad_s", KEY_DOUBLE, OFF(loss_speed_error_rad_s), 0, 1, BIG, 0, "|omega - omega*| above this in RUN counts as loss of control (rad/s)"},
    {"run.max_csv_MB", KEY_DOUBLE, OFF(max_csv_MB), 0, 1, 1e6, 0, "refuse to start a run whose run.csv would exceed this (MB)"},
    {"run.loss_angle_error_rad", KEY_DOUBLE, OFF(loss_angle_error_rad), 0, 1, BIG, 0, "angle-estimate error above this in RUN counts as loss of control (rad)"},
    {"run.controller", KEY_DRIVE, OFF(drive), 0, 0, 0, 0, "pmstep (the firmware) | microstep (open-loop microstepping at datasheet.rated_current_A, the baseline)"},
    {"run.metrics_start_s", KEY_DOUBLE, OFF(metrics_start_s), -1, 0, 3600, 0, "start of the RMS-current and load-angle window (s); < 0: start of RUN (t_c) or end of the microstep hold"},

    {"speed.points", KEY_SPEED_POINTS, 0, 0, 0, 0, 0, "set-point t:omega pairs (s:rad/s), piecewise linear"},
    {"speed.id_target_A", KEY_DOUBLE, OFF(id_target_A), -1e4, 0, 1e4, 0, "i_d* (A)"},

    {"load.type", KEY_LOAD_KIND, 0, 0, 0, 0, 0, "none | constant | step | proportional | table"},
    {"load.torque_Nm", KEY_DOUBLE, OFF(load.torque_Nm), -1e6, 0, 1e6, 0, "constant / step load (Nm)"},
    {"load.step_time_s", KEY_DOUBLE, OFF(load.step_time_s), 0, 0, 3600, 0, "time of the step (s)"},
    {"load.coefficient_Nms_rad", KEY_DOUBLE, OFF(load.coefficient_Nms_rad), -1e6, 0, 1e6, 0, "proportional load T_L = c omega"},
    {"load.points", KEY_LOAD_POINTS, 0, 0, 0, 0, 0, "table t:T_L pairs (s:Nm), piecewise linear"},

    {"position.points", KEY_MOVES, 0, 0, 0, 0, 0, "moves t:theta (s : mechanical rad from the c-alignment equilibrium); 0:0 alone = a speed scenario"},
    {"position.v_max_rad_s", KEY_DOUBLE, OFF(move_speed_rad_s), 0, 1, 1e6, 0, "speed limit of every move (rad/s)"},
    {"position.a_max_rad_s2", KEY_DOUBLE, OFF(move_accel_rad_s2), 0, 1, 1e9, 0, "acceleration limit (rad/s^2)"},
    {"position.j_max_rad_s3", KEY_DOUBLE, OFF(move_jerk_rad_s3), 0, 0, 1e12, 0, "jerk limit (rad/s^3); 0 = a_max varpi_0"},
    {"position.hold_start_s", KEY_DOUBLE, OFF(hold_start_s), 0, 0, 3600, 0, "start of the hold window of the position metrics (s); 0 = none"},
    {"controller.position.gain_per_s", KEY_FLOAT, OFF(position.gain_per_s), 0, 0, BIG, 0, "k_theta (1/s); 0 = the designer's rule k_w/4 and k_theta^2/8"},
    {"controller.position.integral_gain_per_s2", KEY_FLOAT, OFF(position.integral_gain_per_s2), -BIG, 0, BIG, 0, "k_I of the position loop (1/s^2)"},

    {"sensors.adc_bits", KEY_ADC_BITS, OFF(sensors.adc_bits), 0, 0, 16, 0, "ADC resolution: 0 = ideal (no quantisation), or 8..16 bits"},
    {"sensors.current_full_scale_A", KEY_DOUBLE, OFF(sensors.current_full_scale_A), 0, 1, 1e6, 0, "current ADC span +/- this, mid-tread, clips beyond (A)"},
    {"sensors.offset_a_A", KEY_DOUBLE, OFF(sensors.offset_a_A), -1e6, 0, 1e6, 0, "current-sensor offset, phase a (A)"},
    {"sensors.offset_b_A", KEY_DOUBLE, OFF(sensors.offset_b_A), -1e6, 0, 1e6, 0, "current-sensor offset, phase b (A)"},
    {"sensors.gain_error_a", KEY_DOUBLE, OFF(sensors.gain_error_a), -0.5, 1, 0.5, 1, "current-sensor gain error, phase a (fraction)"},
    {"sensors.gain_error_b", KEY_DOUBLE, OFF(sensors.gain_error_b), -0.5, 1, 0.5, 1, "current-sensor gain error, phase b (fraction)"},
    {"sensors.noise_rms_A", KEY_DOUBLE, OFF(sensors.noise_rms_A), 0, 0, 1e6, 0, "Gaussian current noise per phase per sample (A rms)"},
    {"sensors.bus_full_scale_V", KEY_DOUBLE, OFF(sensors.bus_full_scale_V), 0, 1, 1e6, 0, "bus ADC span [0, this] (V)"},
    {"sensors.bus_noise_rms_V", KEY_DOUBLE, OFF(sensors.bus_noise_rms_V), 0, 0, 1e6, 0, "Gaussian bus-voltage noise per sample (V rms)"},

    {"inverter.model", KEY_INVERTER_MODEL, OFF(inverter.model), 0, 0, 0, 0, "averaged | switching"},
    {"inverter.dead_time_s", KEY_DOUBLE, OFF(inverter.dead_time_s), 0, 0, 0.01, 1, "dead time per half-bridge (s), below run.period_s / 4"},

    {"bus.source_resistance_Ohm", KEY_DOUBLE, OFF(bus.source_resistance_Ohm), 0, 0, 1e6, 0, "sag V_bus = run.bus_voltage_V - R i_bus (Ohm)"},
    {"bus.ripple_V", KEY_DOUBLE, OFF(bus.ripple_V), 0, 0, 1e4, 0, "bus ripple amplitude, ripple_V sin(2 pi ripple_Hz t) (V)"},
    {"bus.ripple_Hz", KEY_DOUBLE, OFF(bus.ripple_Hz), 0, 0, 1e6, 0, "bus ripple frequency (Hz)"},
};

static const char *const load_kind_names[] = {"none", "constant", "step", "proportional", "table"};
static const char *const inverter_model_names[] = {"averaged", "switching"};
static const char *const integrator_names[] = {"rk4", "exponential"}; /* in plant_integrator_t order */
static const char *const drive_names[] = {"pmstep", "microstep"};     /* in sil_drive_t order */

static int fail(char *err, size_t err_size, const char *fmt, ...)
{
    va_list args;
    va_start(args, fmt);
    vsnprintf(err, err_size, fmt, args);
    va_end(args);
    return -1;
}

/* Whole-string number: no trailing text, finite. */
static int parse_number(const char *text, double *value)
{
    char *end;
    errno = 0;
    *value = strtod(text, &end);
    if (end == text || errno == ERANGE || !isfinite(*value)) {
        return -1;
    }
    while (*end == ' ' || *end == '\t') {
        ++end;
    }
    return *end == '\0' ? 0 : -1;
}

/* "t:v, t:v, ..." with strictly increasing t >= 0. */
static int parse_points(const char *key, const char *text, double *times, double *values, int max_points,
                        int *count, char *err, size_t err_size)
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
    for (n = 0; n < sizeof keys / sizeof keys[0]; ++n) {
        const key_t_ *k = &keys[n];
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
                             &sc->position_moves, err, err_size) != 0) {
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
        case KEY_BOOL:
            if (strcmp(value, "true") == 0 || strcmp(value, "1") == 0) {
                *(bool *)(base + k->offset) = true;
            } else if (strcmp(value, "false") == 0 || strcmp(value, "0") == 0) {
                *(bool *)(base + k->offset) = false;
            } else {
                return fail(err, err_size, "%s: '%s' is not true or false", key, value);
            }
            return 0;
        default:
            break;
        }
        if (parse_number(value, &v) != 0) {
            return fail(err, err_size, "%s: '%s' is not a finite number", key, value);
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
            return fail(err, err_size, "%s = %s is out of range: must be 0 (ideal) or 8 .. 16 (%s)", key, value, k->help);
        }
        switch (k->type) {
        case KEY_DOUBLE: *(double *)(base + k->offset) = v; break;
        case KEY_FLOAT: *(float *)(base + k->offset) = (float)v; break;
        case KEY_INT: *(int32_t *)(base + k->offset) = (int32_t)v; break;
        case KEY_UINT: *(uint32_t *)(base + k->offset) = (uint32_t)v; break;
        case KEY_ADC_BITS: *(unsigned *)(base + k->offset) = (unsigned)v; break;
        case KEY_ANGLE_DEG: *(double *)(base + k->offset) = v * PI / 180.0; break;
        default: break;
        }
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

typedef struct {
    sil_scenario_t *sc;
    char message[SIL_ERROR_MAX];
    int failed;
    char points_key[160];  /**< the points key being read: its value may continue on indented lines */
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
    if (name[0] == '\0' || name[0] == '.' || strlen(name) >= sizeof ((sil_scenario_t *)0)->name) {
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
                fail(err, err_size, "%s:%d: line of %u characters, longer than the %u the INI reader takes (continue a "
                     "long value on indented lines)", path, line, (unsigned)length, (unsigned)max_line_chars);
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
        return fail(err, err_size, "inverter.dead_time_s = %g is not below run.period_s / 4 = %g", sc->inverter.dead_time_s,
                    0.25 * (double)sc->controller.timing.period_s);
    }
    if (sc->sensors.adc_bits > 0u && sc->sensors.current_full_scale_A < (double)sc->controller.limits.max_phase_current_A) {
        return fail(err, err_size,
                    "sensors.current_full_scale_A = %g is below controller.limits.max_phase_current_A = %g: the ADC would clip "
                    "before the trip",
                    sc->sensors.current_full_scale_A, (double)sc->controller.limits.max_phase_current_A);
    }
    if (sc->sensors.adc_bits > 0u && sc->sensors.bus_full_scale_V < (double)sc->controller.limits.max_bus_voltage_V) {
        return fail(err, err_size,
                    "sensors.bus_full_scale_V = %g is below controller.limits.max_bus_voltage_V = %g: the ADC would clip "
                    "before the overvoltage trip",
                    sc->sensors.bus_full_scale_V, (double)sc->controller.limits.max_bus_voltage_V);
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
        if (sc->drive != SIL_DRIVE_PMSTEP) {
            return fail(err, err_size, "position.points: moves need run.controller = pmstep");
        }
        for (n = 0; n < sc->speed_points; ++n) {
            if (sc->speed_value_rad_s[n] != 0.0) {
                return fail(err, err_size, "position.points with a speed profile: set speed.points = 0:0 (a speed command "
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
    if (!(sc->bus.ripple_V < sc->bus_voltage_V)) {
        return fail(err, err_size, "bus.ripple_V = %g is not below run.bus_voltage_V = %g: the bus would reach zero",
                    sc->bus.ripple_V, sc->bus_voltage_V);
    }
    return 0;
}

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
    for (n = 0; n < sizeof keys / sizeof keys[0]; ++n) {
        const key_t_ *k = &keys[n];
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
