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

/** Status of a fallible call: 0 = ok, negative = one named cause (pmstep_status_str() gives its text). */
typedef enum {
    PMSTEP_OK = 0,
    /* Arguments and commands. */
    PMSTEP_ERR_NULL_ARGUMENT = -1,          /**< a pointer argument is NULL */
    PMSTEP_ERR_BAD_MODE = -2,               /**< command not allowed in the present mode */
    PMSTEP_ERR_BAD_COMMAND_VALUE = -3,      /**< non-finite target, or ramp rate <= 0 */
    /* Configuration: any group. */
    PMSTEP_ERR_NONFINITE_PARAMETER = -10,   /**< a setting is NaN or Inf */
    PMSTEP_ERR_DERIVED_NONFINITE = -11,     /**< a coefficient derived from the settings (an injection gain of the
                                                 observer, 1/J, k_M/L, ...) overflows or is not a number in float32 */
    /* motor */
    PMSTEP_ERR_RESISTANCE = -20,            /**< R <= 0 */
    PMSTEP_ERR_INDUCTANCE = -21,            /**< L <= 0 */
    PMSTEP_ERR_INERTIA = -22,               /**< J <= 0 */
    PMSTEP_ERR_TORQUE_CONSTANT = -23,       /**< k_M <= 0 */
    PMSTEP_ERR_FRICTION = -24,              /**< F < 0 */
    PMSTEP_ERR_POLE_PAIRS = -25,            /**< p < 1 */
    PMSTEP_ERR_DETENT_TORQUE = -26,         /**< detent torque < 0 */
    /* timing */
    PMSTEP_ERR_PERIOD = -30,                /**< T_s outside [PMSTEP_MIN_PERIOD_S, PMSTEP_MAX_PERIOD_S] */
    PMSTEP_ERR_DELAY = -31,                 /**< computational delay not 0 or 1 period */
    /* gains */
    PMSTEP_ERR_SPEED_GAIN = -40,            /**< k_w <= 0 */
    PMSTEP_ERR_OBSERVER_GAIN = -41,         /**< K_e <= 0 */
    PMSTEP_ERR_CURRENT_GAIN = -42,          /**< K_i <= 0 */
    PMSTEP_ERR_ADAPT_GAMMA = -43,           /**< gamma <= 0 */
    PMSTEP_ERR_ADAPT_LAMBDA = -44,          /**< lambda <= 0 */
    PMSTEP_ERR_ADAPT_R = -45,               /**< r <= 0 */
    PMSTEP_ERR_SAT_KAPPA = -46,             /**< kappa <= 0 */
    PMSTEP_ERR_OBSERVER_GAIN_FOR_PERIOD = -47, /**< (R/L + K_e) T_s >= 0.5: forward-Euler observer too close to unstable */
    PMSTEP_ERR_CURRENT_GAIN_FOR_PERIOD = -48,  /**< (R/L + K_i) T_s >= 0.5: current loop too fast for the period */
    PMSTEP_ERR_REFERENCE_BANDWIDTH = -49,   /**< varpi_0 <= 0 or varpi_0 T_s > 0.5 */
    PMSTEP_ERR_ANGLE_CORRECTION_GAIN = -50, /**< drift-free gain g < 0 or g T_s >= 0.5 */
    PMSTEP_ERR_CURRENT_INTEGRAL_GAIN = -51, /**< current-loop integral gain < 0, or above (R/L + K_i)^2 / 4 (the
                                                 loop's poles would turn complex) */
    PMSTEP_ERR_DETENT_FADE_SPEED = -52,     /**< detent compensation's fade speed < 0 */
    PMSTEP_ERR_EMF_ANGLE_GAIN = -53,        /**< back-EMF angle correction: gain < 0 or not below R/L + K_e, corner
                                                 < 0, or a gain without a corner */
    PMSTEP_ERR_ANGLE_SMOOTHING = -54,       /**< angle smoothing a < 0 or >= 1 */
    PMSTEP_ERR_FIELD_WEAKENING = -56,       /**< field weakening: its max_current_A < 0 or not below
                                                 max_phase_current_A, or > 0 with a modulation outside (0, 1] or a
                                                 gain_A_per_s <= 0 */
    PMSTEP_ERR_OBSERVER_BOOST = -55,        /**< transient observer boost k not 0 and not within [1, 4], or k > 0
                                                 without detection.observer_residual_bound_A */
    /* limits */
    PMSTEP_ERR_MAX_CURRENT = -60,           /**< max_phase_current_A <= 0 */
    PMSTEP_ERR_MIN_BUS = -61,               /**< min_bus_voltage_V <= 0 */
    PMSTEP_ERR_BUS_ORDER = -62,             /**< max_bus_voltage_V <= min_bus_voltage_V */
    PMSTEP_ERR_TRIP_ABOVE_RATED = -63,      /**< max_phase_current_A above PMSTEP_MAX_TRIP_PER_RATED_CURRENT x
                                                 motor.rated_current_A */
    PMSTEP_ERR_TRIP_ABOVE_SENSE_RANGE = -64, /**< max_phase_current_A above PMSTEP_SENSE_RANGE_USABLE_FRACTION x
                                                 limits.current_sense_range_A: a reading saturated at the sensor's
                                                 end would never trip */
    PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE = -65, /**< max_bus_voltage_V above PMSTEP_SENSE_RANGE_USABLE_FRACTION x
                                                 limits.bus_sense_range_V: the overvoltage trip would never fire */
    PMSTEP_ERR_SENSE_RANGE = -66,           /**< current_sense_range_A or bus_sense_range_V <= 0 */
    /* alignment */
    PMSTEP_ERR_ALIGNMENT_VOLTAGE = -70,     /**< u_cs or u_cc <= 0 */
    PMSTEP_ERR_ALIGNMENT_ABOVE_BUS = -71,   /**< u_cs or u_cc above the minimum bus voltage */
    PMSTEP_ERR_ALIGNMENT_CURRENT = -72,     /**< u_cs/R or u_cc/R at or above max_phase_current_A */
    PMSTEP_ERR_S_ALIGN_TIME = -73,          /**< t_s shorter than one period */
    PMSTEP_ERR_C_ALIGN_TIME = -74,          /**< t_c - t_s shorter than one period */
    PMSTEP_ERR_ALIGNMENT_TOO_LONG = -75,    /**< t_c longer than PMSTEP_MAX_DURATION_PERIODS periods */
    PMSTEP_ERR_ALIGNMENT_CONDITION = -76,   /**< condition (4) violated */
    PMSTEP_ERR_S_LEAD_IN_TIME = -77,        /**< s-alignment's lead-in < 0, or not leaving t_s at least one period */
    /* commissioning */
    PMSTEP_ERR_OFFSET_CALIBRATION_TIME = -80, /**< offset calibration time < 0 or longer than PMSTEP_MAX_DURATION_PERIODS */
    PMSTEP_ERR_STEADY_STATE_WINDOW = -81,   /**< steady-state window < 0 or longer than half an alignment */
    PMSTEP_ERR_INDUCTANCE_WINDOW = -82,     /**< current-rise window < 0 or longer than half of s-alignment */
    PMSTEP_ERR_ALIGNMENT_OFFSETS_UNMEASURED = -83, /**< offsets from the alignments without a steady-state window */
    PMSTEP_ERR_RESISTANCE_UNMEASURED = -84, /**< measured R used without a steady-state window */
    PMSTEP_ERR_INDUCTANCE_UNMEASURED = -85, /**< measured L used without a current-rise window or level drops */
    PMSTEP_ERR_TORQUE_CONSTANT_UNMEASURED = -86, /**< measured k_M used without a steady-state window */
    PMSTEP_ERR_VOLTAGE_BIAS_FRACTION = -87, /**< voltage-bias level fraction outside [0, 1) */
    PMSTEP_ERR_VOLTAGE_BIAS_WINDOW = -88,   /**< voltage bias without a window, or a window over a quarter alignment */
    PMSTEP_ERR_VOLTAGE_BIAS_SETTLING = -89, /**< voltage bias: half a window is shorter than 5 L/R of settling */
    /* inverter */
    PMSTEP_ERR_DEAD_TIME = -90,             /**< dead time < 0 or 4 t_d >= T_s */
    PMSTEP_ERR_DEAD_TIME_BAND = -91,        /**< compensation band < 0, or in use and outside
                                                 [PMSTEP_MIN_CURRENT_BAND_A, max_phase_current_A] */
    /* detection */
    PMSTEP_ERR_DETECTION_BOUND = -100,      /**< a detection bound < 0 */
    PMSTEP_ERR_DETECTION_TIME = -101,       /**< persistence not 0 (only with every detector off) or within
                                                 [PMSTEP_DETECTION_DECIMATION periods (one check),
                                                 PMSTEP_MAX_DURATION_PERIODS periods] */
    /* gain designer (pmstep_design.h): motor data it cannot design for */
    PMSTEP_ERR_RATED_CURRENT = -110,        /**< motor.rated_current_A <= 0 */
    PMSTEP_ERR_BUS_BELOW_RATED = -111,      /**< bus voltage <= 0, or R x rated current above the usable bus */
    PMSTEP_ERR_RATE_TOO_SLOW = -112,        /**< control rate too slow for the motor: R/L, or F/J, not well below
                                                 the bandwidths the designer gives the current loop and the observer */
    PMSTEP_ERR_SENSE_RANGE_BELOW_RATED = -113, /**< the drive's current sensing cannot read the trip the motor
                                                 needs (1.25 x its rated current) */
    PMSTEP_ERR_DATASHEET_TORQUE_CONSTANT = -114, /**< k_M outside [1/2, 2] x T_H / (sqrt(2) I): no stepper has it */
    PMSTEP_ERR_DATASHEET_TIME_CONSTANT = -115, /**< L/R outside [0.1, 20] ms: no stepper has it */
    PMSTEP_ERR_DATASHEET_INERTIA = -116,    /**< J outside [1/10, 10] x its estimate from the holding torque */
    PMSTEP_ERR_DATASHEET_FLUX_RATIO = -117, /**< p L I / k_M outside [0.1, 10]: the winding's flux at rated current
                                                 against the magnet's, which no stepper has */
    PMSTEP_ERR_DETENT_ABOVE_ALIGNMENT = -118, /**< the detent torque holds the rotor against the largest
                                                 alignment current condition (4) and the rating allow */
    /* commissioning: identification of J and F at the start of RUN (pmstep_identify.h) */
    PMSTEP_ERR_IDENTIFICATION_WINDOW = -120, /**< identification window < 0 or longer than PMSTEP_MAX_DURATION_PERIODS */
    PMSTEP_ERR_IDENTIFICATION_SPEED = -121,  /**< identification's lowest speed < 0 */
    PMSTEP_ERR_MECHANICS_UNIDENTIFIED = -122, /**< identified J and F used without an identification window */
    PMSTEP_ERR_MEASURE_ONLY_WINDOW = -123,  /**< measure_only without a steady-state window: it would measure nothing */
    /* position control (pmstep_position.h) */
    PMSTEP_ERR_POSITION_GAIN = -130,        /**< position gain k_theta <= 0, or above k_w/2 (the speed loop's) */
    PMSTEP_ERR_POSITION_INTEGRAL_GAIN = -131, /**< position integral gain k_I < 0, or above k_theta^2/4 (the loop's
                                                 poles would turn complex) */
    PMSTEP_ERR_HOLD_CURRENT = -132,         /**< hold current <= 0 or not below max_phase_current_A, or too small
                                                 for the load: |T_L - T_detent| above 0.9 k_M I (pmstep_hold.h);
                                                 the standstill hold's current < 0 or not below max_phase_current_A */
    PMSTEP_ERR_STANDSTILL_KNOWN_LOAD = -133, /**< a standstill hold with known_load_mode (a vector hold needs (6)) */
    PMSTEP_ERR_VECTOR_SPEED = -134,          /**< the standstill's low-speed drive: a speed < 0, stops_only without a
                                                  speed, or > 0 without a
                                                  hold current */
    /* STEP/DIR input (pmstep_stepdir.h) */
    PMSTEP_ERR_STEPDIR_MICROSTEPS = -135,   /**< microsteps per full step not within 1..PMSTEP_STEPDIR_MAX_MICROSTEPS */
    PMSTEP_ERR_STEPDIR_TRACKING = -136,     /**< the step tracker's bandwidth not > 0, or above 4 / (N T_s) */
    PMSTEP_ERR_STEPDIR_LIMIT = -137,        /**< the following-error limit or the stop time not > 0, or a DIAG pulse
                                                 of 0 periods */
    PMSTEP_ERR_STEPDIR_DIAG_MODE = -138,    /**< DIAG's mode neither PMSTEP_DIAG_LEVEL (0) nor PMSTEP_DIAG_PULSE (1) */
    PMSTEP_ERR_STEPDIR_STALL_CURRENT = -129, /**< the STEP/DIR stall current < 0, not finite, or not below
                                                  max_phase_current_A (-140 to -151: pmstep_store_status_t) */
    /* homing (pmstep_homing.h) */
    PMSTEP_ERR_HOMING = -139                /**< a homing speed, acceleration, travel or stall error not > 0, a back-off
                                                 < 0, a stall current not in (0, max_phase_current_A), or a direction
                                                 other than +1 or -1 */
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
/** Identification of J and F: the least-squares fit is refused (PMSTEP_IDENT_POOR_EXCITATION) when the
 *  determinant of its regressors' normalised Gram matrix (cosines between the columns 1, w*', w*:
 *  1 = orthogonal, 0 = collinear) is below this. */
#define PMSTEP_IDENTIFICATION_MIN_DETERMINANT 0.02f
/** Detection runs in RUN every this many periods (supervision at a fraction of the control rate). */
#define PMSTEP_DETECTION_DECIMATION 4u
/** The identification of J and F takes a sample every this many periods of its window, two periods
 *  after each detection check (so that the two never share a step). */
#define PMSTEP_IDENTIFICATION_DECIMATION 4u

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
    PMSTEP_FAULT_MEASUREMENT_NONFINITE = 1, /**< NaN or Inf in a current, bus or load input, or in a sensed
                                                 phase voltage (with phase-voltage sensing) */
    PMSTEP_FAULT_OVERCURRENT = 2,           /**< |i_a| or |i_b| above max_phase_current_A */
    PMSTEP_FAULT_BUS_UNDERVOLTAGE = 3,      /**< bus below min_bus_voltage_V */
    PMSTEP_FAULT_BUS_OVERVOLTAGE = 4,       /**< bus above max_bus_voltage_V */
    PMSTEP_FAULT_STATE_NONFINITE = 5,       /**< an internal estimate became NaN/Inf */
    PMSTEP_FAULT_ANGLE_MAGNITUDE = 6,       /**< |c-hat^2 + s-hat^2 - 1| above angle_magnitude_bound: angle lost */
    PMSTEP_FAULT_SPEED_INCONSISTENT = 7,    /**< speed from the angle estimate's rotation and w-hat disagree */
    PMSTEP_FAULT_STALL = 8,                 /**< |w-hat - w*| above stall_speed_error_rad_s: motor not following */
    PMSTEP_FAULT_COMMISSIONING = 9,         /**< measured R, L or k_M outside [1/2, 2] x the configured value */
    PMSTEP_FAULT_OBSERVER_RESIDUAL = 10,    /**< |i_a - i_a-hat| + |i_b - i_b-hat| low-passed above its bound: the
                                                 observer's model no longer explains the currents */
    PMSTEP_FAULT_PHASE_VOLTAGE_RANGE = 11,  /**< with phase-voltage sensing: a sensed mean phase voltage beyond
                                                 PMSTEP_PHASE_VOLTAGE_RANGE_FACTOR x the measured bus (a mean
                                                 phase voltage cannot exceed the bus: a sensor fault) */
    PMSTEP_FAULT_ALIGNMENT_MOTION = 12,     /**< the rotor still moved in an alignment's steady-state window, in the
                                                 alignments' repeat too (pmstep_commission_finish()) */
    PMSTEP_FAULT_OPEN_PHASE_A = 13,         /**< phase a carries no current where its voltage (alignment) or its
                                                 reference (RUN) says it must: an open winding, connector or
                                                 current sensor (pmstep_continuity.h) */
    PMSTEP_FAULT_OPEN_PHASE_B = 14,         /**< the same for phase b */
    PMSTEP_FAULT_CURRENT_STUCK_A = 15,      /**< phase a's reading does not move while its reference does: a
                                                 stuck current sensor or ADC (pmstep_continuity.h) */
    PMSTEP_FAULT_CURRENT_STUCK_B = 16,      /**< the same for phase b */
    PMSTEP_FAULT_ESTIMATE_RANGE = 17        /**< the observer's speed or load estimate left the range the bus and
                                                 the trip allow (pmstep_observer_coeffs_t): control is lost */
} pmstep_fault_t;

/** A sensed mean phase voltage above this many times the measured bus latches
 *  PMSTEP_FAULT_PHASE_VOLTAGE_RANGE: the bus bounds the true value, the margin covers the
 *  two sensors' gain errors and noise. */
#define PMSTEP_PHASE_VOLTAGE_RANGE_FACTOR 1.25f

/** Motor model (1), as known to the controller. */
typedef struct {
    float resistance_Ohm;       /**< R */
    float inductance_H;         /**< L */
    float inertia_kgm2;         /**< J */
    float friction_Nms_rad;     /**< F >= 0 */
    float torque_constant_Nm_A; /**< k_M */
    int32_t pole_pairs;         /**< p >= 1 */
    float detent_torque_Nm;     /**< T_d >= 0: detent (cogging) torque -T_d sin(4 p theta) in the model, not in the
                                     paper's (1); the observer and the law compensate it. 0 = none (the paper) */
    float rated_current_A;      /**< rated phase current (amplitude) > 0: bounds the overcurrent trip
                                     (PMSTEP_MAX_TRIP_PER_RATED_CURRENT) */
} pmstep_motor_config_t;

/** Control period and delay of the drive. */
typedef struct {
    float period_s;                       /**< control period T_s */
    uint32_t computational_delay_periods; /**< 0: voltage computed at k applied in [k, k+1]; 1: in [k+1, k+2] */
} pmstep_timing_config_t;

/** Alignment (3), (5). */
typedef struct {
    float s_align_time_s;    /**< t_s, measured from the start of s-alignment */
    float s_lead_in_time_s;  /**< s-alignment's first part drives (5)'s u_a = u_cc, u_b = 0 (p theta -> 0), so
                                  that (3) never starts on its unstable equilibrium p theta = -90 deg, where a
                                  detent torque can hold the rotor; 0 = none (the paper's) */
    float c_align_time_s;    /**< t_c, measured from the same start (t_c > t_s) */
    float s_align_voltage_V; /**< u_cs */
    float c_align_voltage_V; /**< u_cc */
} pmstep_alignment_config_t;

/** Gains of controller (6), the reference filter and the drift-free angle option. */
typedef struct {
    float speed_gain_per_s;          /**< k_w */
    float observer_gain_per_s;       /**< K_e */
    float current_gain_per_s;        /**< K_i */
    float adapt_gamma;               /**< gamma (kg m^2 s: g_T = J/gamma with F = 0) */
    float adapt_lambda;              /**< lambda (s: g_w = 2/lambda with F = 0) */
    float adapt_r;                   /**< r (only matters when F > 0) */
    float sat_kappa_rad_s;           /**< kappa of the smooth saturation sat_kappa */
    float reference_bandwidth_rad_s; /**< varpi_0 of H(s) = varpi_0^3/(s+varpi_0)^3 */
    float angle_correction_gain_per_s; /**< drift-free option: pulls (c-hat, s-hat) onto the unit circle at this
                                            rate (flux-magnitude correction); 0 = the paper's open integrals */
    float current_integral_gain_per_s2; /**< K_I: integral of the current error in the law's voltage (a PI current
                                             loop); holds i_q = i_q* against voltage the model does not know, which
                                             (6) otherwise turns into a speed offset. 0 = the paper's law. On the d
                                             axis, and the hold's; the q axis takes the next */
    float current_integral_gain_q_per_s2; /**< K_I,q: the same on the q axis, the speed loop's (0 = none there).
                                               Where its slow pole K_I,q / K meets the speed loop's k_w, a
                                               large dead time's residual can keep a limit cycle going; the
                                               designer puts it at k_w / 5 (K_I,q = K k_w / 5;
                                               docs/design/02-current-and-speed-loops.md) */
    float detent_fade_speed_rad_s; /**< the detent torque's compensation (law and observer) fades with the
                                        estimated speed as w_f^2 / (w_f^2 + w-hat^2); 0 = no fade */
    float emf_angle_gain_per_s; /**< K_theta: turns the flux integrals' estimate toward the back EMF's direction,
                                     read from the observer's d-axis residual, at this rate (1/s), faded in with
                                     the speed as w-hat^2 / (w-hat^2 + w_theta^2) (pmstep_angle.h). Below R/L + K_e;
                                     0 = off (the paper's estimate) */
    float emf_angle_corner_rad_s; /**< w_theta: the speed at which that correction is half on (> 0 with a gain) */
    float angle_smoothing; /**< a in [0, 1): each period's estimate is the previous one turned by p w-hat T_s, plus
                                (1 - a) of the flux integrals' reading's difference from it (the current
                                samples' noise in the estimate times (1 - a) / (1 + a) in power); 0 = the
                                reading itself (the paper's) */
    float transient_observer_boost; /**< k, 0 or in [1, PMSTEP_OBSERVER_BOOST_MAX]: while the observer's q residual
                                         is beyond detection.observer_residual_bound_A (a load step faster than the
                                         observer's bandwidth), its speed injection is k and its load injection
                                         k^2 times the gains' (unknown load only); 0 = off (the paper's observer) */
} pmstep_gains_config_t;

/** The largest transient observer boost init accepts. The boost scales the observer's mechanical
 *  injections as a bandwidth would (k, k^2) but not its current gain: with the designer's triple pole
 *  the observer stays stable for k < 9 (Routh: (R/L + K_e) k g_w > k^2 g_T), and 4 keeps half of that. */
#define PMSTEP_OBSERVER_BOOST_MAX 4.0f

/** The overcurrent trip may be at most this many times the motor's rated current: above, a
 *  winding carries several times its rating (heat, and the magnets' demagnetisation) before the
 *  drive reacts. */
#define PMSTEP_MAX_TRIP_PER_RATED_CURRENT 3.0f
/** A trip must lie within this fraction of its sensor's range: a reading saturated at the
 *  sensor's last code (a shorted winding, a failed sensor) then still trips, with room for the
 *  sensor's gain tolerance and noise. */
#define PMSTEP_SENSE_RANGE_USABLE_FRACTION 0.95f

/** Protections, and the measurement ranges of the drive that bound them (the port's hardware:
 *  set by the port, read-only on the console). */
typedef struct {
    float max_phase_current_A; /**< |i_a|, |i_b| above this -> FAULT_OVERCURRENT */
    float min_bus_voltage_V;   /**< bus below -> FAULT_BUS_UNDERVOLTAGE */
    float max_bus_voltage_V;   /**< bus above -> FAULT_BUS_OVERVOLTAGE */
    float current_sense_range_A; /**< the phase-current measurement reads up to +/- this (its ADC's full scale) */
    float bus_sense_range_V;   /**< the bus measurement reads up to this (its divider's full scale) */
} pmstep_limits_config_t;

/** Remark 2 calibration and self-commissioning (all off in the paper's configuration). */
typedef struct {
    float offset_calibration_time_s;   /**< bridge off this long before s-alignment; the current samples are averaged
                                            as sensor offsets. 0 = none (alignment starts at once) */
    bool alignment_offset_calibration; /**< also take offsets from the alignment steady states: i_a -> 0 at the end of
                                            s-alignment, i_b -> 0 at the end of c-alignment */
    float steady_state_window_s;       /**< averaging window at the end of each alignment (offsets, R); 0 = none */
    float inductance_window_s;         /**< current-rise window at the start of s-alignment for L; 0 = L not measured */
    bool use_measured_resistance;      /**< RUN uses the measured R in place of motor.resistance_Ohm */
    bool use_measured_inductance;      /**< RUN uses the measured L in place of motor.inductance_H */
    bool use_measured_torque_constant; /**< RUN uses k_M measured from the c-alignment swing */
    float voltage_bias_level_fraction; /**< Remark 2 voltage bias: 0 = off; else the last steady_state_window_s of
                                            each alignment runs at this fraction of its voltage, and the two steady
                                            states give R and the bias (the part of the dead time the compensation
                                            misses), which is then compensated too */
    float identification_time_s;       /**< J and F identified over this long from t_c (pmstep_identify.h): the speed
                                            commands in it must accelerate the motor; 0 = not identified */
    float identification_min_speed_rad_s; /**< only periods with |w*| at least this enter the fit (the detent torque
                                            and the low-speed transients do not average out below it); 0 = all */
    bool use_identified_mechanics;     /**< at the end of the window RUN uses the identified J and F (the observer's
                                            and the law's coefficients; kappa scaled by J/J-identified) */
    bool measure_only;                 /**< at t_c, once the offsets, R, L and k_M are taken, the bridge goes off and
                                            the motor IDLE instead of RUN, the results kept until the next start: a
                                            drive measuring a motor it has no gains for yet (pmstep_calibrate.h) */
} pmstep_commissioning_config_t;

/** What the controller knows of its inverter: dead-time compensation. */
typedef struct {
    float dead_time_s;              /**< dead time of each half-bridge to compensate (2 per phase); 0 = none */
    float dead_time_current_band_A; /**< compensation is linear in i within +/- this band, full outside */
    bool phase_voltage_sensing;     /**< the drive measures each phase's mean voltage over every period
                                         (pmstep_meas_t phase_voltage_a_V, _b_V): RUN's flux integrals take it
                                         in place of the command less the dead time's estimated loss, it
                                         corrects the observer's last current prediction, and the Remark 2
                                         steady states take it for R (so R is as that sensor sees it, and the
                                         voltage bias only what it leaves unexplained); its offsets come from
                                         the offset calibration. false = not measured (fields unread) */
    bool ripple_dead_zone;          /**< the bridge's PWM ripple is taken into RUN's compensation: no loss
                                         where it straddles zero (pmstep_actuate_mean_loss_current; the
                                         legs' windows centred, as the ports drive them). false = a bridge
                                         without ripple (the SIL's averaged inverter): the sweep's mean only */
} pmstep_inverter_config_t;

/** Detection in RUN, every PMSTEP_DETECTION_DECIMATION periods; a bound of 0 switches its detector off.
 *  A condition persisting persistence_s latches its fault, or re-aligns (max_realignments). */
typedef struct {
    float angle_magnitude_bound;         /**< |c-hat^2 + s-hat^2 - 1| -> FAULT_ANGLE_MAGNITUDE */
    float speed_consistency_bound_rad_s; /**< |w from the angle's rotation - w-hat|, both low-passed
                                              -> FAULT_SPEED_INCONSISTENT */
    float stall_speed_error_rad_s;       /**< |w-hat - w*| -> FAULT_STALL */
    float observer_residual_bound_A;     /**< |i_a - i_a-hat| + |i_b - i_b-hat|, low-passed -> FAULT_OBSERVER_RESIDUAL */
    float persistence_s;                 /**< persistence before acting; low-pass time constant is a quarter of it */
    uint32_t max_realignments;           /**< 0: a detection latches its fault; N: re-align (bridge on) up to N times */
} pmstep_detection_config_t;

/** Standstill hold in speed mode (pmstep_hold.h): a zero speed command, once reached with the
 *  rotor at rest, is held by a current vector fixed in the stator frame and the angle estimate
 *  is kept, so that it does not drift with the voltage errors nothing observes at zero speed. */
typedef struct {
    float hold_current_A; /**< I of the hold, 0 < I < max_phase_current_A; 0 = off (the law holds on the
                               estimate, which drifts). Not with known_load_mode. */
    float vector_speed_rad_s; /**< below this |speed command| (rad/s) the hold's vector turns at the
                                   reference speed in place of the law (pmstep_hold.h); 0 = standstill only */
    bool stops_only;          /**< with vector_speed_rad_s > 0: the vector turns only on the way to a zero
                                   command (the last of a stop), the law drives every other speed; false =
                                   the low-speed drive */
} pmstep_standstill_config_t;

/** Field weakening in RUN (pmstep_weakening.h): i_d* goes below its command where the law's voltage
 *  would take more than a share of the bus. */
typedef struct {
    float max_current_A; /**< I_w: the most the weakening takes off i_d*, 0 <= I_w < max_phase_current_A; 0 = off */
    float modulation;    /**< m in (0, 1]: the share of the measured bus the law's voltage may take */
    float gain_A_per_s;  /**< g > 0: the weakening current's rate per unit of the voltage's relative excess */
} pmstep_field_weakening_config_t;

/** Constant configuration (may live in flash; must outlive the instance). */
typedef struct {
    pmstep_motor_config_t motor;
    pmstep_timing_config_t timing;
    pmstep_alignment_config_t alignment;
    pmstep_gains_config_t gains;
    pmstep_limits_config_t limits;
    pmstep_commissioning_config_t commissioning;
    pmstep_inverter_config_t inverter;
    pmstep_detection_config_t detection;
    pmstep_standstill_config_t standstill;
    pmstep_field_weakening_config_t field_weakening;
    bool known_load_mode; /**< Remark 1: load torque known, given each period in pmstep_meas_t */
} pmstep_config_t;

/** Model the controller works with: the configured values, or commissioned (R, L, k_M at t_c) and
 *  identified (J, F at the end of the identification window) ones. */
typedef struct {
    float resistance_Ohm;           /**< R */
    float inductance_H;             /**< L */
    float torque_constant_Nm_A; /**< k_M */
    float inertia_kgm2;             /**< J */
    float friction_Nms_rad;         /**< F */
} pmstep_electrical_t;

/** The model of the configuration: R, L, k_M, J, F as configured. */
static inline pmstep_electrical_t pmstep_configured_electrical(const pmstep_config_t *cfg)
{
    pmstep_electrical_t model;
    model.resistance_Ohm = cfg->motor.resistance_Ohm;
    model.inductance_H = cfg->motor.inductance_H;
    model.torque_constant_Nm_A = cfg->motor.torque_constant_Nm_A;
    model.inertia_kgm2 = cfg->motor.inertia_kgm2;
    model.friction_Nms_rad = cfg->motor.friction_Nms_rad;
    return model;
}

/** Samples taken at the start of a period. */
typedef struct {
    float i_a_A;         /**< phase a current */
    float i_b_A;         /**< phase b current */
    float bus_voltage_V; /**< DC bus voltage */
    float load_torque_Nm;/**< known load T_L (used only in known_load_mode) */
    float phase_voltage_a_V; /**< mean voltage across phase a over the period that ends at this sample
                                  (used only with inverter.phase_voltage_sensing) */
    float phase_voltage_b_V; /**< same for phase b */
} pmstep_meas_t;

/** What one step commands, and what it estimated. */
typedef struct {
    float u_a_V;             /**< phase a voltage to apply (per the configured delay) */
    float u_b_V;             /**< phase b voltage */
    bool bridge_enable;      /**< false: switch the bridge off */
    bool voltage_limited;    /**< the computed voltage exceeded the bus and was scaled down */
    pmstep_mode_t mode;
    pmstep_fault_t fault;
    uint32_t fault_step;     /**< step count (since init/reset) at which the fault latched */
    /* Telemetry (valid in RUN; zero otherwise). */
    float cos_hat;           /**< c-hat, estimate of cos(p theta) */
    float sin_hat;           /**< s-hat, estimate of sin(p theta) */
    float speed_hat_rad_s;   /**< omega-hat */
    float load_hat_Nm;       /**< T_L-hat (or the filtered known load T_L* in known_load_mode) */
    float i_a_hat_A;         /**< observer current a */
    float i_b_hat_A;         /**< observer current b */
    float speed_ref_rad_s;   /**< omega* */
    float speed_ref_rate_rad_s2; /**< omega*' */
    float i_d_A;             /**< i_d from (c-hat, s-hat) */
    float i_q_A;             /**< i_q from (c-hat, s-hat) */
    float i_d_ref_A;         /**< i_d* */
    float i_q_ref_A;         /**< i_q* */
} pmstep_output_t;

/** Outcome of the identification of J and F (pmstep_commissioning_t.identification). */
typedef enum {
    PMSTEP_IDENT_OFF = 0,              /**< not configured (identification_time_s = 0), or t_c not reached */
    PMSTEP_IDENT_RUNNING = 1,          /**< window open: the fit's sums are being taken */
    PMSTEP_IDENT_DONE = 2,             /**< J and F identified (and used, with use_identified_mechanics) */
    PMSTEP_IDENT_FRICTION_NEGATIVE = 3,/**< J identified; F came out < 0 (below what the data resolves): the value is
                                            reported, and F = 0 is what RUN uses with use_identified_mechanics */
    PMSTEP_IDENT_POOR_EXCITATION = 4,  /**< the window held too little acceleration or speed variation (the fit's
                                            determinant below PMSTEP_IDENTIFICATION_MIN_DETERMINANT): nothing
                                            identified, the configured J and F stay */
    PMSTEP_IDENT_IMPLAUSIBLE = 5       /**< J outside [1/10, 10] x the configured one, or |F|/J not below 0.5/T_s
                                            (or either not finite): reported, not used */
} pmstep_identification_t;

/** Remark 2 calibration and self-commissioning results (pmstep_get_commissioning()). */
typedef struct {
    float offset_a_A;               /**< current-sensor offset subtracted from every i_a sample (A) */
    float offset_b_A;               /**< same for i_b */
    uint32_t offset_samples;        /**< samples behind the offsets (0: none taken, offsets 0) */
    float resistance_Ohm;           /**< R of phase b from its alignment steady state(s) (0: not measured) */
    float phase_a_current_scale;          /**< R_a / R_b: phase a's samples are multiplied by it, so both phases read on
                                         phase b's scale (a sensor gain mismatch); 1 until measured */
    float inductance_H;             /**< L from the current rise at the start of s-alignment (0: not measured) */
    float torque_constant_Nm_A; /**< k_M from the flux swing of c-alignment (0: not measured) */
    float equilibrium_cos;          /**< c-alignment's equilibrium, cos(p theta) at t_c: the direction of the current
                                         vector over its last window (the undriven phase carries current where the
                                         dead-time compensation does not match the bridge); 1 until measured */
    float equilibrium_sin;          /**< sin(p theta) at t_c; 0 until measured */
    float voltage_bias_a_V;         /**< voltage phase a falls short by at positive current (0: not measured) */
    float voltage_bias_b_V;         /**< same for phase b */
    float phase_voltage_offset_a_V; /**< phase-voltage sensor offset subtracted from every sample of phase a, from
                                         the offset calibration (0: not measured or no sensing) */
    float phase_voltage_offset_b_V; /**< same for phase b */
    float inertia_kgm2;             /**< J identified in RUN (0: not identified; see identification) */
    float friction_Nms_rad;         /**< F identified in RUN (may be < 0: see identification) */
    pmstep_identification_t identification; /**< state and outcome of the identification of J and F */
    uint32_t realignments;          /**< re-alignments after a detection since start */
    uint32_t alignment_repeats;     /**< repeats of the alignments after one whose steady-state windows saw the
                                         rotor move (PMSTEP_ALIGNMENT_MAX_REPEATS at most) */
    bool measured;                  /**< alignment finished and the values above were taken */
} pmstep_commissioning_t;

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_TYPES_H */
