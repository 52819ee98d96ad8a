/**
 * @file scenario.h
 * @brief A SIL scenario: plant, firmware configuration, initial state, speed
 *        set-point profile, load profile, run settings. Read from an INI file
 *        (parsed by inih) and `section.key=value` overrides; every key and
 *        value is checked, and any error names the key (and line).
 */
#ifndef SIL_SCENARIO_H
#define SIL_SCENARIO_H

#include <stddef.h>
#include <stdio.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_stepdir.h"
#include "sil/inverter.h"
#include "sil/plant.h"
#include "sil/faults.h"
#include "sil/sensors.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SIL_SPEED_POINTS_MAX 64
/** Moves of a position scenario at most ([position] points). */
#define SIL_POSITION_MOVES_MAX 128
#define SIL_ERROR_MAX 256
/** Largest scenario file read (bytes). */
#define SIL_SCENARIO_MAX_BYTES (1u << 20)
/** Bytes of one run.csv row at most (21 columns), for the output-size check. */
#define SIL_CSV_ROW_MAX_BYTES 330.0

/** [datasheet]: the motor's ratings, for the gain designer and the baselines (not used by the plant). */
typedef struct {
    double rated_current_A;   /**< datasheet.rated_current_A: rated phase current (A, amplitude of each phase) */
    double holding_torque_Nm; /**< datasheet.holding_torque_Nm: holding torque with both phases at rated current */
    double detent_torque_Nm;  /**< datasheet.detent_torque_Nm: unpowered detent torque (0 = not given) */
} sil_datasheet_t;

/** position.source: what a position scenario's points become. */
typedef enum {
    SIL_SOURCE_MOVE = 0,    /**< each point a pmstep_position_move_to() at its time (the drive plans the move) */
    SIL_SOURCE_STEPDIR = 1, /**< the SIL's step generator (sil/step_generator.h) plans each move as a motion
                                 controller does; the drive follows its STEP/DIR count (pmstep_stepdir.h) */
    SIL_SOURCE_HOMING = 2   /**< the first point starts homing (pmstep_homing.h) toward its sign, its
                                 magnitude the largest travel (sil/homing_run.h) */
} sil_position_source_t;

/** run.controller: what drives the plant. */
typedef enum {
    SIL_DRIVE_PMSTEP = 0,   /**< the firmware: pmstep_step() through the host HAL port */
    SIL_DRIVE_MICROSTEP = 1 /**< open-loop microstepping at rated current (sil/microstep.h); no firmware */
} sil_drive_t;

typedef struct {
    char name[64];
    sil_datasheet_t datasheet;     /**< [datasheet] */
    plant_params_t motor;          /**< [motor]: the plant (may differ from [controller]) */
    plant_load_t load;             /**< [load] */
    pmstep_config_t controller;    /**< [controller]: what the firmware is told */
    double duration_s;             /**< run.duration_s */
    int substeps;                  /**< run.substeps: plant integration steps per control period */
    plant_integrator_t integrator; /**< run.integrator: exponential | rk4 (sil/plant.h) */
    double bus_voltage_V;          /**< run.bus_voltage_V */
    double theta0_rad;             /**< run.theta0_deg (stored in rad) */
    double omega0_rad_s;           /**< run.omega0_rad_s */
    double i_a0_A;                 /**< run.i_a0_A */
    double i_b0_A;                 /**< run.i_b0_A */
    int decimation;                /**< run.decimation: a CSV row every N periods */
    double transient_window_s;     /**< run.transient_window_s: [t_c, t_c + W) is the load transient */
    int speed_points;              /**< [speed] points = t:v, ... (rad/s, piecewise linear) */
    double speed_time_s[SIL_SPEED_POINTS_MAX];
    double speed_value_rad_s[SIL_SPEED_POINTS_MAX];
    double id_target_A;             /**< speed.id_target_A */
    double loss_speed_error_rad_s;  /**< run.loss_speed_error_rad_s: |omega - omega*| above -> loss of control */
    double loss_angle_error_rad;    /**< run.loss_angle_error_rad: angle-estimate error above -> loss of control */
    double loss_position_error_rad; /**< run.loss_position_error_rad: a position scenario in position mode,
                                          |theta* - theta| p above -> loss of control (in place of the speed
                                          error) */
    uint32_t seed;                  /**< run.seed: of every random draw of the run (measurement noise) */
    double max_csv_MB;              /**< run.max_csv_MB: largest run.csv a run may write (MB) */
    sil_sensor_config_t sensors;    /**< [sensors]: measurement chain (ideal by default) */
    sil_fault_config_t faults;      /**< [faults]: an open winding, a failed current sensor (none by default) */
    sil_inverter_config_t inverter; /**< [inverter]: averaged | switching, dead time */
    sil_bus_config_t bus;           /**< [bus]: source resistance and ripple on run.bus_voltage_V */
    sil_drive_t drive;              /**< run.controller: pmstep | microstep */
    double metrics_start_s;         /**< run.metrics_start_s: start of the RMS-current and load-angle window (s);
                                          < 0: the start of RUN (t_c) or the end of the microstep hold */
    /* A position scenario (issue 13): [position] points given. The firmware then runs under
     * pmstep_position_step() and each move is a pmstep_position_move_to() at its time. */
    int position_moves; /**< [position] points = t:theta, ... (s : mechanical rad from the
                                                c-alignment's equilibrium); 0 = a speed scenario */
    double move_time_s[SIL_POSITION_MOVES_MAX];
    double move_target_rad[SIL_POSITION_MOVES_MAX];
    double move_speed_rad_s;           /**< position.v_max_rad_s of every move */
    double move_accel_rad_s2;          /**< position.a_max_rad_s2 */
    double move_jerk_rad_s3;           /**< position.j_max_rad_s3 (source move: 0 = a_max varpi_0; source
                                                stepdir: 0 = no jerk limit, a trapezoid) */
    double hold_start_s;               /**< position.hold_start_s: the hold window's start (0 = none) */
    pmstep_position_config_t position; /**< [controller.position]: gain_per_s 0 = the designer's rule
                                                (pmstep_position_design) for both gains */
    /* A STEP/DIR scenario (issue 53): position.source = stepdir. The points are planned by the SIL's step
     * generator; the firmware follows the count (pmstep_position_follow_steps()), or with run.controller =
     * microstep the open-loop baseline turns its current vector with it. */
    sil_position_source_t position_source;  /**< position.source: move | stepdir */
    uint32_t stepdir_microsteps;            /**< stepdir.microsteps: m per full step, 1 to 256 */
    pmstep_diag_mode_t stepdir_diag_mode;   /**< stepdir.diag_mode: level | pulse */
    float stepdir_tracking_bandwidth_rad_s; /**< stepdir.tracking_bandwidth_rad_s: the step tracker's w_t (0 = the
                                                 designer's, pmstep_stepdir_design()) */
    float stepdir_stall_current_A;          /**< stepdir.stall_current_A: homing on DIAG, the steps toward a block
                                                dropped at this q current (0 = off, the designer's) */
    /* position.source = homing: the designer's settings (pmstep_homing_design()) unless given here. */
    double homing_speed_rad_s;     /**< homing.speed_rad_s (0 = the designer's) */
    double homing_stall_current_A; /**< homing.stall_current_A (0 = the designer's) */
    double homing_back_off_rad;    /**< homing.back_off_rad (< 0 = the designer's) */
} sil_scenario_t;

/** The paper's Section III: t_s = 0.3 s, t_c = 0.6 s, 2 Nm at 0.63 s, theta0 = 30 deg, 2.4 s, 20 kHz. */
void sil_scenario_paper(sil_scenario_t *sc);

/** The drive's measurement ranges are its sensors': the firmware's limits.current_sense_range_A and
 *  bus_sense_range_V follow sensors.current_full_scale_A and sensors.bus_full_scale_V (hardware, as
 *  a port sets them; no key of their own). */
static inline void sil_scenario_sense_ranges(sil_scenario_t *sc)
{
    sc->controller.limits.current_sense_range_A = (float)sc->sensors.current_full_scale_A;
    sc->controller.limits.bus_sense_range_V = (float)sc->sensors.bus_full_scale_V;
}

/**
 * The speed command due at @p t_s under the piecewise-linear profile: at the start of
 * each segment that changes the speed, ramp to its end value at its slope. Call every
 * period with the same @p next_segment (start at 0) until it returns 0.
 * @return 1 with the arguments of pmstep_set_speed_target() in the outputs, or 0.
 */
int sil_scenario_speed_command(const sil_scenario_t *sc, double t_s, int *next_segment, float *target_rad_s,
                               float *ramp_rate_rad_s2);

/**
 * End of the hold (s): the start of the first segment of the speed profile that changes the
 * speed, or run.duration_s if the speed never changes; in a STEP/DIR scenario (position.source =
 * stepdir with points) the first point's time, where the microstep drive starts following the count.
 * The microstep drive holds theta_e* = 0 until then.
 */
double sil_scenario_hold_end_s(const sil_scenario_t *sc);

/**
 * Sets `section.key` from text. @return 0, or -1 with a message in @p err
 * naming the key (unknown key, malformed or out-of-range value).
 */
int sil_scenario_set(sil_scenario_t *sc, const char *key, const char *value, char *err, size_t err_size);

/** Applies `section.key=value`. @return 0 or -1 with a message. */
int sil_scenario_set_assignment(sil_scenario_t *sc, const char *assignment, char *err, size_t err_size);

/**
 * Loads an INI file on top of @p sc (start from sil_scenario_paper() for defaults).
 * @return 0, or -1 with "file:line: message" in @p err.
 */
int sil_scenario_load(sil_scenario_t *sc, const char *path, char *err, size_t err_size);

/** Checks relations between keys (after all keys are set). @return 0 or -1 with a message. */
int sil_scenario_check(const sil_scenario_t *sc, char *err, size_t err_size);

/** Writes every key with its present value in INI form (a template users can edit). */
void sil_scenario_print(const sil_scenario_t *sc, FILE *file);

#ifdef __cplusplus
}
#endif

#endif /* SIL_SCENARIO_H */
