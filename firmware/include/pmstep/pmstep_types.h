/**
 * @file pmstep_types.h
 * @brief Shared plain types of the PM stepper control core: configuration,
 *        measurements, outputs, status and fault codes.
 *
 * Units: rad, rad/s, A, V, Nm, s, kg m^2, Ohm, H. "Electrical" angles are p*theta.
 */
#ifndef PMSTEP_TYPES_H
#define PMSTEP_TYPES_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Status of a fallible call: 0 = ok, negative = one named cause. */
typedef enum {
    PMSTEP_OK = 0,
    PMSTEP_ERR_NULL_ARGUMENT = -1,
    PMSTEP_ERR_NONFINITE_PARAMETER = -2,
    PMSTEP_ERR_RESISTANCE = -3,            /**< R <= 0 */
    PMSTEP_ERR_INDUCTANCE = -4,            /**< L <= 0 */
    PMSTEP_ERR_INERTIA = -5,               /**< J <= 0 */
    PMSTEP_ERR_TORQUE_CONSTANT = -6,       /**< k_M <= 0 */
    PMSTEP_ERR_FRICTION = -7,              /**< F < 0 */
    PMSTEP_ERR_POLE_PAIRS = -8,            /**< p < 1 */
    PMSTEP_ERR_PERIOD = -9,                /**< T_s <= 0 */
    PMSTEP_ERR_GAIN = -10,                 /**< a gain (k_w, K_e, K_i, gamma, lambda, r, kappa) <= 0 */
    PMSTEP_ERR_PERIOD_TOO_LONG = -11,      /**< (R/L + K_e) T_s >= 0.5 or (R/L + K_i) T_s >= 0.5 */
    PMSTEP_ERR_ALIGNMENT_CONDITION = -12,  /**< condition (4) violated */
    PMSTEP_ERR_ALIGNMENT_VOLTAGE = -13,    /**< u_cs or u_cc <= 0, or above the minimum bus voltage */
    PMSTEP_ERR_ALIGNMENT_TIME = -14,       /**< t_s <= 0 or t_c <= t_s, or not at least one period each */
    PMSTEP_ERR_REFERENCE_BANDWIDTH = -15,  /**< varpi_0 <= 0 or varpi_0 T_s > 0.5 */
    PMSTEP_ERR_LIMITS = -16,               /**< current or bus limits not positive / not ordered */
    PMSTEP_ERR_DELAY = -17,                /**< computational delay not 0 or 1 period */
    PMSTEP_ERR_BAD_MODE = -18,             /**< command not allowed in the present mode */
    PMSTEP_ERR_BAD_COMMAND_VALUE = -19,    /**< non-finite target, or ramp rate <= 0 */
    PMSTEP_ERR_ALIGNMENT_CURRENT = -20,    /**< alignment current u/R at or above max_phase_current_a */
    PMSTEP_ERR_CALIBRATION = -21,          /**< calibration/commissioning windows negative or not inside their phase,
                                                dead-time band not > 0, correction gain < 0 or too high for T_s */
    PMSTEP_ERR_DETECTION = -22,            /**< a detection bound < 0, or detection time shorter than 4 periods or
                                                longer than PMSTEP_MAX_DURATION_PERIODS periods */
    PMSTEP_ERR_DERIVED_NONFINITE = -23     /**< a coefficient derived from the settings (an observer injection gain,
                                                1/J, k_M/L, ...) overflows or is not a number in float32 */
} pmstep_status_t;

/** Shortest and longest control period accepted (s): 1 MHz down to 100 Hz. */
#define PMSTEP_MIN_PERIOD_S 1e-6f
#define PMSTEP_MAX_PERIOD_S 1e-2f
/** Longest duration accepted for any time setting, in control periods: counts stay exact in
 *  float32 (2^24) and far from wrapping a uint32_t step counter. */
#define PMSTEP_MAX_DURATION_PERIODS 16777216.0f
/** Narrowest dead-time compensation band (A): keeps 1/band finite and its product with a
 *  current sample far from overflow. */
#define PMSTEP_MIN_CURRENT_BAND_A 1e-4f

/** Operating mode of the strategy (Section III.A). */
typedef enum {
    PMSTEP_MODE_IDLE = 0,    /**< bridge off, zero voltage */
    PMSTEP_MODE_S_ALIGN = 1, /**< u_a = 0, u_b = u_cs   (3), Theorem 1 */
    PMSTEP_MODE_C_ALIGN = 2, /**< u_a = u_cc, u_b = 0   (5), Theorem 2 */
    PMSTEP_MODE_RUN = 3,     /**< adaptive controller (6), or (13) with known load */
    PMSTEP_MODE_FAULT = 4,   /**< latched: bridge off until pmstep_clear_fault() */
    PMSTEP_MODE_OFFSET_CAL = 5 /**< Remark 2: bridge off before s-alignment, current-sensor offsets averaged */
} pmstep_mode_t;

/** Fault causes latched by pmstep_step(). */
typedef enum {
    PMSTEP_FAULT_NONE = 0,
    PMSTEP_FAULT_MEASUREMENT_NONFINITE = 1, /**< NaN or Inf in a current, bus or load input */
    PMSTEP_FAULT_OVERCURRENT = 2,           /**< |i_a| or |i_b| above max_phase_current_a */
    PMSTEP_FAULT_BUS_UNDERVOLTAGE = 3,      /**< bus below min_bus_voltage_v */
    PMSTEP_FAULT_BUS_OVERVOLTAGE = 4,       /**< bus above max_bus_voltage_v */
    PMSTEP_FAULT_STATE_NONFINITE = 5,       /**< an internal estimate became NaN/Inf */
    PMSTEP_FAULT_ANGLE_MAGNITUDE = 6,       /**< |c-hat^2 + s-hat^2 - 1| above angle_magnitude_bound: angle lost */
    PMSTEP_FAULT_SPEED_INCONSISTENT = 7,    /**< speed from the angle estimate's rotation and w-hat disagree */
    PMSTEP_FAULT_STALL = 8,                 /**< |w-hat - w*| above stall_speed_error_rad_s: motor not following */
    PMSTEP_FAULT_COMMISSIONING = 9,         /**< measured R, L or k_M outside [1/2, 2] x the configured value */
    PMSTEP_FAULT_OBSERVER_RESIDUAL = 10     /**< |i_a - i_a-hat| + |i_b - i_b-hat| low-passed above its bound: the
                                                 observer's model no longer explains the currents */
} pmstep_fault_t;

/** Constant configuration: motor model (1), strategy timing, gains of (6), limits. */
typedef struct {
    /* Motor model (1), as known to the controller. */
    float resistance_ohm;          /**< R */
    float inductance_h;            /**< L */
    float inertia_kg_m2;           /**< J */
    float friction_nm_s_per_rad;   /**< F >= 0 */
    float torque_constant_nm_per_a;/**< k_M */
    int32_t pole_pairs;            /**< p >= 1 */

    /* Timing. */
    float period_s;                /**< control period T_s */
    uint32_t computational_delay_periods; /**< 0: voltage computed at k applied in [k, k+1]; 1: in [k+1, k+2] */

    /* Alignment (3), (5). */
    float s_align_time_s;          /**< t_s, measured from start */
    float c_align_time_s;          /**< t_c, measured from start (t_c > t_s) */
    float s_align_voltage_v;       /**< u_cs */
    float c_align_voltage_v;       /**< u_cc */

    /* Controller (6) gains. */
    float speed_gain_per_s;        /**< k_omega */
    float observer_gain_per_s;     /**< K_e */
    float current_gain_per_s;      /**< K_i */
    float adapt_gamma;             /**< gamma */
    float adapt_lambda;            /**< lambda */
    float adapt_r;                 /**< r (only matters when F > 0) */
    float sat_kappa_rad_per_s;     /**< kappa of the smooth saturation sat_kappa */
    float reference_bandwidth_rad_per_s; /**< varpi_0 of H(s) = varpi_0^3/(s+varpi_0)^3 */

    /* Remark 1: load torque known and given each period in pmstep_meas_t. */
    bool known_load_mode;

    /* Protections. */
    float max_phase_current_a;     /**< |i_a|, |i_b| above this -> FAULT_OVERCURRENT */
    float min_bus_voltage_v;       /**< bus below -> FAULT_BUS_UNDERVOLTAGE */
    float max_bus_voltage_v;       /**< bus above -> FAULT_BUS_OVERVOLTAGE */

    /* Remark 2 calibration and self-commissioning (all off in the paper's configuration). */
    float offset_calibration_time_s;   /**< bridge off this long before s-alignment; the current samples are averaged
                                            as sensor offsets. 0 = none (alignment starts at once) */
    bool alignment_offset_calibration; /**< also take offsets from the alignment steady states: i_a -> 0 at the end of
                                            s-alignment, i_b -> 0 at the end of c-alignment */
    float steady_state_window_s;       /**< averaging window at the end of each alignment (offsets, R); 0 = none */
    float inductance_window_s;         /**< current-rise window at the start of s-alignment for L; 0 = L not measured */
    bool use_commissioned_resistance;  /**< RUN uses the measured R in place of resistance_ohm */
    bool use_commissioned_inductance;  /**< RUN uses the measured L in place of inductance_h */
    bool use_commissioned_torque_constant; /**< RUN uses k_M measured from the c-alignment swing */
    float voltage_bias_level_fraction; /**< Remark 2 voltage bias: 0 = off; else the last steady_state_window_s of
                                            each alignment runs at this fraction of its voltage, and the two steady
                                            states give R and the bias (the part of the dead time the compensation
                                            misses), which is then compensated too */
    float dead_time_s;                 /**< dead time of each half-bridge to compensate (2 per phase); 0 = none */
    float dead_time_current_band_a;    /**< compensation is linear in i within +/- this band, full outside */

    /* Angle. */
    float angle_correction_gain_per_s; /**< drift-free option: pulls (c-hat, s-hat) onto the unit circle at this
                                            rate (flux-magnitude correction); 0 = the paper's open integrals */

    /* Detection (each 0 = off), checked every 4th period in RUN. Persisting detection_time_s -> fault,
     * or re-alignment (max_realignments). */
    float angle_magnitude_bound;       /**< |c-hat^2 + s-hat^2 - 1| -> FAULT_ANGLE_MAGNITUDE */
    float speed_consistency_bound_rad_s; /**< |w from the angle's rotation - w-hat|, both low-passed -> FAULT_SPEED_INCONSISTENT */
    float stall_speed_error_rad_s;     /**< |w-hat - w*| -> FAULT_STALL */
    float observer_residual_bound_a;   /**< |i_a - i_a-hat| + |i_b - i_b-hat|, low-passed -> FAULT_OBSERVER_RESIDUAL */
    float detection_time_s;            /**< persistence before acting; low-pass time constant is a quarter of it */
    uint32_t max_realignments;         /**< 0: a detection latches its fault; N: re-align (bridge on) up to N times */
} pmstep_config_t;

/** Electrical model the controller works with: the configured values, or commissioned ones. */
typedef struct {
    float resistance_ohm;           /**< R */
    float inductance_h;             /**< L */
    float torque_constant_nm_per_a; /**< k_M */
} pmstep_electrical_t;

/** Samples taken at the start of a period. */
typedef struct {
    float i_a_a;         /**< phase a current */
    float i_b_a;         /**< phase b current */
    float bus_voltage_v; /**< DC bus voltage */
    float load_torque_nm;/**< known load T_L (used only in known_load_mode) */
} pmstep_meas_t;

/** What one step commands, and what it estimated. */
typedef struct {
    float u_a_v;             /**< phase a voltage to apply (per the configured delay) */
    float u_b_v;             /**< phase b voltage */
    bool bridge_enable;      /**< false: switch the bridge off */
    bool voltage_limited;    /**< the computed voltage exceeded the bus and was scaled down */
    pmstep_mode_t mode;
    pmstep_fault_t fault;
    uint32_t fault_step;     /**< step count (since init/reset) at which the fault latched */
    /* Telemetry (valid in RUN; zero otherwise). */
    float cos_hat;           /**< c-hat, estimate of cos(p theta) */
    float sin_hat;           /**< s-hat, estimate of sin(p theta) */
    float speed_hat_rad_s;   /**< omega-hat */
    float load_hat_nm;       /**< T_L-hat (or the filtered known load T_L* in known_load_mode) */
    float i_a_hat_a;         /**< observer current a */
    float i_b_hat_a;         /**< observer current b */
    float speed_ref_rad_s;   /**< omega* */
    float speed_ref_dot_rad_s2; /**< omega*' */
    float i_d_a;             /**< i_d from (c-hat, s-hat) */
    float i_q_a;             /**< i_q from (c-hat, s-hat) */
    float i_d_ref_a;         /**< i_d* */
    float i_q_ref_a;         /**< i_q* */
} pmstep_output_t;

/** Remark 2 calibration and self-commissioning results (pmstep_get_commissioning()). */
typedef struct {
    float offset_a_a;               /**< current-sensor offset subtracted from every i_a sample (A) */
    float offset_b_a;               /**< same for i_b */
    uint32_t offset_samples;        /**< samples behind the offsets (0: none taken, offsets 0) */
    float resistance_ohm;           /**< R of phase b from its alignment steady state(s) (0: not measured) */
    float current_scale_a;          /**< R_a / R_b: phase a's samples are multiplied by it, so both phases read on
                                         phase b's scale (a sensor gain mismatch); 1 until measured */
    float inductance_h;             /**< L from the current rise at the start of s-alignment (0: not measured) */
    float torque_constant_nm_per_a; /**< k_M from the flux swing of c-alignment (0: not measured) */
    float voltage_bias_a_v;         /**< voltage phase a falls short by at positive current (0: not measured) */
    float voltage_bias_b_v;         /**< same for phase b */
    uint32_t realignments;          /**< re-alignments after a detection since start */
    bool measured;                  /**< alignment finished and the values above were taken */
} pmstep_commissioning_t;

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_TYPES_H */
