/* Gain designer (pmstep_design.h): the rules of docs/design, one function per group. */
#include "pmstep/pmstep_design.h"

#include "pmstep/pmstep.h"
#include "pmstep_design_internal.h"

#include <math.h> /* sqrtf, isfinite: one FPU instruction / a classification macro, no libm call */
#include <stddef.h>

/* Bandwidths as fractions of the control rate 1/T_s (docs/design/02-current-and-speed-loops.md). */
#define CURRENT_BANDWIDTH_X_PERIOD 0.2f /* (R/L + K_i) T_s */
/* The observer's triple pole w_o: at least OBSERVER_BANDWIDTH_X_PERIOD / T_s, raised to
 * OBSERVER_HALF_RESPONSE / t_step, t_step the time the rated torque takes to turn the told rotor by
 * one full step (a triple pole's step response is half way at w_o t = 2.674: half a load step is
 * estimated before it has slipped the rotor a full step; robust mode's transient boost meets that at
 * a third of it), up to MAX_OBSERVER_BANDWIDTH_X_PERIOD / T_s
 * (3 w_o T_s = 0.3 within the forward-Euler observer's 0.5; docs/design/03-observer.md). */
#define OBSERVER_BANDWIDTH_X_PERIOD 0.05f
#define MAX_OBSERVER_BANDWIDTH_X_PERIOD 0.1f
#define OBSERVER_HALF_RESPONSE 2.674f
#define DESIGN_PI 3.14159265f
/* Robust mode's angle smoothing: the reading and the turned previous estimate weighted equally
 * (the samples' noise in the estimate x 0.58; docs/design/16-angle-smoothing.md) */
#define ANGLE_SMOOTHING 0.5f
/* Robust mode's transient observer boost: beyond the residual bound the observer's mechanical injections
 * as at 3 w_o (docs/design/18-transient-observer-boost.md). */
#define TRANSIENT_OBSERVER_BOOST 3.0f
#define SPEED_PER_OBSERVER_BANDWIDTH (1.0f / 3.0f)       /* k_w = w_o / 3 */
#define REFERENCE_PER_SPEED_BANDWIDTH 3.0f               /* varpi_0 = 3 k_w */
#define DRIFT_FREE_PER_OBSERVER_BANDWIDTH (1.0f / 30.0f) /* robust mode's angle correction g = w_o / 30 */
/* Robust mode's back-EMF angle correction: K_theta = 2 w_o, two thirds of the residual's R/L + K_e
 * (damping 0.61; docs/design/15-back-emf-angle-correction.md). */
#define EMF_ANGLE_PER_OBSERVER_BANDWIDTH 2.0f
#define CURRENT_INTEGRAL_PER_BANDWIDTH_SQUARED 0.125f /* K_I = K^2/8, K = R/L + K_i: PI poles 0.15 K, 0.85 K */
#define Q_INTEGRAL_SPEED_DIVISOR 5.0f                 /* K_I,q = K k_w / 5: the q PI's slow pole at k_w / 5 */
#define STILL_ROTOR_SWING_PHASE 0.1f /* RUN takes the measured L, k_M only if w_n x L window is below this */
/* Speed correction k_w kappa at most this fraction of the rated current's acceleration k_M I / J. */
#define KAPPA_CURRENT_FRACTION 0.5f
/* The alignments last until the swing has decayed by e^-13.8 (1e-6), plus 5 L/R of current rise. */
#define SETTLING_DECAY 13.8155f
#define CURRENT_RISE_TIME_CONSTANTS 5.0f
#define TIME_GRANULARITY_S 0.01f
/* Field weakening (docs/design/22-field-weakening.md): at most half the magnet's flux taken off in
 * current, k_M / (2 p L); the loop's rate an eighth of the reference filter's bandwidth. */
#define WEAKENING_FLUX_SHARE 0.5f
#define WEAKENING_PER_REFERENCE_BANDWIDTH (1.0f / 8.0f)
#define SQRT2 1.41421356f
/* Protections. */
#define TRIP_CURRENT_PER_RATED 2.0f
#define MIN_BUS_FRACTION 0.625f
#define MAX_BUS_FRACTION 1.25f
/* Detection (docs/design/05-protections-and-detection.md). */
#define ANGLE_MAGNITUDE_BOUND 0.25f
#define STALL_FRACTION_OF_TOP_SPEED 0.2f
#define RESIDUAL_PER_RATED_CURRENT 0.04f
#define PERSISTENCE_S 0.02f
/* Robust mode's commissioning (docs/design/08-robust-mode.md; the windows: docs/design/04-alignment.md). */
#define OFFSET_CALIBRATION_S 0.05f
#define MIN_STEADY_STATE_WINDOW_S 0.01f
#define STEADY_STATE_WINDOW_TIME_CONSTANTS 10.0f /* the core's least (pmstep_validate_config()) */
/* The lower level's step (the voltage bias) decays in the window's first half to the current
 * resolution: e^-n of it, n time constants, between these (12: float32's resolution of the step). */
#define SETTLING_MIN_TIME_CONSTANTS 5.0f
#define SETTLING_MAX_TIME_CONSTANTS 12.0f
#define INDUCTANCE_WINDOW_PER_TIME_CONSTANT 0.25f
#define MIN_INDUCTANCE_WINDOW_PERIODS 4.0f
#define VOLTAGE_BIAS_LEVEL 0.5f
#define MAGNETISING_PER_RATED_CURRENT 0.125f
/* Robust mode, currents sensed only: the magnetising current is this many times the current one
 * period's dead-time volt-seconds move, within [MAGNETISING_PER_RATED_CURRENT,
 * MAX_MAGNETISING_PER_RATED_CURRENT] x I (magnetising_current, docs/design/08-robust-mode.md). */
#define MAGNETISING_PER_DEAD_TIME_CURRENT 25.0f
/* The cap: 0.35 I with K_theta = 2 w_o lost a third of the AS1050's Monte Carlo failures that I/4 had;
 * I/2 gained nothing over I/4 once the detent compensation faded with the speed, and costs copper
 * and the voltage p w L i_d* (docs/design/08-robust-mode.md). */
#define MAX_MAGNETISING_PER_RATED_CURRENT 0.35f
#define MIN_DEAD_TIME_BAND_A 1e-4f
/* Robust mode, currents sensed only: the low-speed drive below the speed whose back EMF is this
 * many times the dead time's loss V_bus t_d / T_s (docs/design/14-low-speed-drive.md). */
#define LOW_SPEED_EMF_PER_DEAD_TIME_LOSS 2.0f
/* ... and where the detent torque's frequency 4 p w is at most this fraction of the held rotor's
 * natural frequency sqrt(p k_M I / J): above, the turning vector drives the rotor near its
 * resonance (docs/design/14-low-speed-drive.md). */
#define LOW_SPEED_DETENT_PER_HELD_NATURAL 0.5f
/* Identification of J and F (pmstep_identify.h): periods with |w*| below this fraction of the top
 * speed stay out of the fit (a hybrid's detent torque does not average out at low speed). */
#define IDENTIFICATION_MIN_SPEED_OF_TOP 0.2f
/* Paper's r: only matters with F > 0 (docs/design/03-observer.md). */
#define ADAPT_R 1.0f
/* The detent torque's compensation fades where its frequency 4 p w-hat is this many current-loop
 * bandwidths (docs/design/02-current-and-speed-loops.md): calibrated on the Monte Carlo. */
#define DETENT_FADE_PER_CURRENT_BANDWIDTH 2.0f

/* @p t_s rounded up to a whole number of TIME_GRANULARITY_S. */
static float round_up_time(float t_s)
{
    const float units = t_s / TIME_GRANULARITY_S;
    uint32_t whole = (uint32_t)units;
    if ((float)whole < units) {
        ++whole;
    }
    return (float)whole * TIME_GRANULARITY_S;
}

/* The speed at which (R i_d - p w L i_q)^2 + (R i_q + (k_M + p L i_d) w)^2 = (0.9 V)^2: the steady
 * state of (2) in the rotor frame with the currents (i_d, i_q) (docs/design/06-top-speed.md; with
 * field weakening, section 22). Written so that i_d = 0 adds exact zeros only. */
static float bus_speed_at(const pmstep_design_input_t *in, float i_d_A, float i_q_A)
{
    const pmstep_motor_config_t *m = &in->motor;
    const float x = (float)m->pole_pairs * m->inductance_H * i_q_A;
    const float flux = m->torque_constant_Nm_A + (float)m->pole_pairs * m->inductance_H * i_d_A;
    const float a = flux * flux + x * x;
    const float b = 2.0f * m->resistance_Ohm * i_q_A * flux - 2.0f * m->resistance_Ohm * i_d_A * x;
    const float usable_V = USABLE_BUS_FRACTION * in->bus_voltage_V;
    const float c = m->resistance_Ohm * i_q_A * m->resistance_Ohm * i_q_A
                    + m->resistance_Ohm * i_d_A * m->resistance_Ohm * i_d_A - usable_V * usable_V;
    return (-b + sqrtf(b * b - 4.0f * a * c)) / (2.0f * a);
}

/* The bus's speed: rated current, i_d = 0. */
static float bus_speed(const pmstep_design_input_t *in)
{
    return bus_speed_at(in, 0.0f, in->motor.rated_current_A);
}

/* The observer's bandwidth from the control rate and the rotor's full-step time under the rated
 * torque, t_step = sqrt(2 (pi / (2 p)) J / (k_M I)) (OBSERVER_HALF_RESPONSE). */
static float observer_bandwidth(const pmstep_design_input_t *in)
{
    const pmstep_motor_config_t *m = &in->motor;
    const float rated_torque_Nm = m->torque_constant_Nm_A * in->motor.rated_current_A;
    const float step_time_s = sqrtf(DESIGN_PI * m->inertia_kgm2 / ((float)m->pole_pairs * rated_torque_Nm));
    const float w_step = OBSERVER_HALF_RESPONSE / step_time_s;
    if (in->self_commissioning) {
        /* Robust mode answers a load step with its transient observer boost, k = 3 times the
         * observer's mechanical bandwidth beyond the residual bound, and aims its standstill hold by
         * T_L-hat, into which a raised observer passes more of the samples' noise: the boosted
         * observer meets the load rule, k w_o >= w_step. */
        return min2(max2(OBSERVER_BANDWIDTH_X_PERIOD, w_step * in->period_s / TRANSIENT_OBSERVER_BOOST),
                    MAX_OBSERVER_BANDWIDTH_X_PERIOD)
               / in->period_s;
    }
    return min2(max2(OBSERVER_BANDWIDTH_X_PERIOD, w_step * in->period_s), MAX_OBSERVER_BANDWIDTH_X_PERIOD)
           / in->period_s;
}

/* Current loop, observer (triple pole at -w_o of s^3 + (a_e + F/J) s^2 + (a_e F/J + g_w b^2) s
 * + g_T b^2 / J, b = k_M/L), speed loop and reference filter (docs/design/02-current-and-speed-loops.md to 03-observer.md). */
static void design_gains(const pmstep_design_input_t *in, pmstep_gains_config_t *gains, pmstep_design_report_t *report)
{
    const pmstep_motor_config_t *m = &in->motor;
    const float r_over_l = m->resistance_Ohm / m->inductance_H;
    const float f_over_j = m->friction_Nms_rad / m->inertia_kgm2;
    const float b = m->torque_constant_Nm_A / m->inductance_H;
    const float w_o = max2(observer_bandwidth(in), WINDING_RATE_MARGIN * (r_over_l + f_over_j) / 3.0f);
    const float a_e = 3.0f * w_o - f_over_j;
    const float g_w = (3.0f * w_o * w_o - a_e * f_over_j) / (b * b);
    const float lambda = 2.0f / g_w;
    const float w_slow = w_o - f_over_j; /* > 0: check_input */
    const float speed_gain = SPEED_PER_OBSERVER_BANDWIDTH * w_o;
    const float current_bandwidth = max2(CURRENT_BANDWIDTH_X_PERIOD / in->period_s, WINDING_RATE_MARGIN * r_over_l);

    gains->current_gain_per_s = current_bandwidth - r_over_l;
    gains->current_integral_gain_per_s2 =
        CURRENT_INTEGRAL_PER_BANDWIDTH_SQUARED * current_bandwidth * current_bandwidth;
    /* The q axis's slow pole K_I,q / K a fifth of the speed loop's k_w: at K^2/8 it sat on k_w (a
     * limit cycle on the AS1050) or, at this K, upset the position loop's moves (docs/design/02-current-and-speed-loops.md). */
    gains->current_integral_gain_q_per_s2 = current_bandwidth * speed_gain / Q_INTEGRAL_SPEED_DIVISOR;
    gains->observer_gain_per_s = a_e - r_over_l;
    gains->adapt_lambda = lambda;
    /* With r F small against gamma: g_w = 2/lambda and g_T = 2F/lambda + J/gamma = J w_o^3 / b^2,
     * so J/gamma = J (w_o - F/J)^3 / b^2. */
    gains->adapt_gamma = b * b / (w_slow * w_slow * w_slow);
    gains->adapt_r = ADAPT_R;
    gains->speed_gain_per_s = speed_gain;
    gains->sat_kappa_rad_s =
        KAPPA_CURRENT_FRACTION * in->motor.rated_current_A * m->torque_constant_Nm_A / (m->inertia_kgm2 * speed_gain);
    gains->reference_bandwidth_rad_s = REFERENCE_PER_SPEED_BANDWIDTH * speed_gain;
    gains->angle_correction_gain_per_s = in->self_commissioning ? DRIFT_FREE_PER_OBSERVER_BANDWIDTH * w_o : 0.0f;
    if (in->self_commissioning) {
        /* Half on where the back EMF equals the voltage the model knows least: the resistive drop at
         * rated current and the dead time's full loss 2 V_bus t_d / T_s. */
        const float uncertain_V =
            m->resistance_Ohm * in->motor.rated_current_A + 2.0f * in->bus_voltage_V * in->dead_time_s / in->period_s;
        gains->emf_angle_gain_per_s = EMF_ANGLE_PER_OBSERVER_BANDWIDTH * w_o;
        gains->emf_angle_corner_rad_s = uncertain_V / m->torque_constant_Nm_A;
        gains->angle_smoothing = ANGLE_SMOOTHING;
        gains->transient_observer_boost = TRANSIENT_OBSERVER_BOOST;
    } else {
        gains->emf_angle_gain_per_s = 0.0f;
        gains->emf_angle_corner_rad_s = 0.0f;
        gains->angle_smoothing = 0.0f;
        gains->transient_observer_boost = 0.0f;
    }
    gains->detent_fade_speed_rad_s = m->detent_torque_Nm > 0.0f ? DETENT_FADE_PER_CURRENT_BANDWIDTH * current_bandwidth
                                                                      / (4.0f * (float)m->pole_pairs)
                                                                : 0.0f;

    report->current_bandwidth_rad_s = current_bandwidth;
    report->observer_bandwidth_rad_s = w_o;
    report->speed_bandwidth_rad_s = speed_gain;
}

/* Alignment voltages from condition (4) and the rated current; times from the swing's decay, and
 * s-alignment's lead-in where a detent torque can hold the rotor on (3)'s unstable equilibrium
 * (docs/design/04-alignment.md). Returns the steady-state window the robust mode uses (0 in paper mode). */
static float design_alignment(const pmstep_design_input_t *in, pmstep_config_t *cfg, pmstep_design_report_t *report)
{
    const pmstep_motor_config_t *m = &in->motor;
    const float p = (float)m->pole_pairs;
    const float r = m->resistance_Ohm;
    const float l_over_r = m->inductance_H / r;
    const float condition_limit_A = m->torque_constant_Nm_A / (p * m->inductance_H);
    const float current_A = pmstep_design_alignment_current(in);
    const float stiffness = p * m->torque_constant_Nm_A * current_A;
    const float natural = sqrtf(stiffness / m->inertia_kgm2);
    const float lag = natural * l_over_r;
    const float electrical_damping = m->torque_constant_Nm_A * m->torque_constant_Nm_A / r / (1.0f + lag * lag);
    const float zeta = (electrical_damping + m->friction_Nms_rad) / (2.0f * sqrtf(stiffness * m->inertia_kgm2));
    /* Slowest mode's decay rate: zeta w_n if under-damped, w_n (zeta - sqrt(zeta^2 - 1)) if not. */
    const float decay = zeta < 1.0f ? zeta * natural : natural * (zeta - sqrtf(zeta * zeta - 1.0f));
    const float settle_s = SETTLING_DECAY / decay + CURRENT_RISE_TIME_CONSTANTS * l_over_r;
    float window_s = 0.0f;
    float align_s = settle_s;
    /* Detent stiffness 4 T_d against the alignment's -k_M I there: it slows the rotor's escape, and
     * at 4 T_d >= k_M I (the 17HS4401 at its voltage-bias level) holds it. */
    const float lead_in_s = m->detent_torque_Nm > 0.0f ? round_up_time(settle_s) : 0.0f;

    if (in->self_commissioning) {
        /* Half a window settles the drop to the lower level, (1 - level) I, to the current resolution:
         * n time constants with e^-n at or below resolution / step (counted without a logarithm). */
        const float step_A = (1.0f - VOLTAGE_BIAS_LEVEL) * current_A;
        float n = SETTLING_MIN_TIME_CONSTANTS;
        float decay_left = 148.41316f; /* e^5 */
        while (n < SETTLING_MAX_TIME_CONSTANTS && decay_left * in->current_resolution_A < step_A) {
            n += 1.0f;
            decay_left *= 2.7182818f;
        }
        window_s = round_up_time(
            max2(MIN_STEADY_STATE_WINDOW_S, max2(STEADY_STATE_WINDOW_TIME_CONSTANTS, 2.0f * n) * l_over_r));
        align_s = max2(settle_s + 2.0f * window_s, 4.0f * window_s);
    }
    align_s = round_up_time(align_s);
    cfg->alignment.s_align_voltage_V = r * current_A;
    cfg->alignment.c_align_voltage_V = r * current_A;
    cfg->alignment.s_lead_in_time_s = lead_in_s;
    cfg->alignment.s_align_time_s = lead_in_s + align_s;
    cfg->alignment.c_align_time_s = lead_in_s + 2.0f * align_s;

    report->alignment_current_A = current_A;
    report->alignment_frequency_rad_s = natural;
    report->alignment_damping = zeta;
    /* (4) with u_cs = u_cc = R I: k_M I/(p L) > I^2, i.e. condition_limit_A / I > 1. */
    report->condition_4_margin = condition_limit_A / current_A;
    /* k_M I over the least it needs to pass the detent's barrier (0: no detent). */
    report->detent_margin = m->detent_torque_Nm > 0.0f
                                ? DETENT_BARRIER_RATIO * m->torque_constant_Nm_A * current_A / m->detent_torque_Nm
                                : 0.0f;
    return window_s;
}

/* i_d* of robust mode: I/8, or more where the flux integrals take the compensation's figure for
 * the dead time's loss (no phase-voltage sensing): MAGNETISING_PER_DEAD_TIME_CURRENT times the
 * current one period's dead-time volt-seconds move, 2 V_bus t_d / L, at most 0.35 I (docs/design
 * section 8). The faster a light-load phase current passes zero, the fewer periods the integrals
 * take on the compensation's word for the sign of its loss. */
static float magnetising_current(const pmstep_design_input_t *in)
{
    const float floor_A = MAGNETISING_PER_RATED_CURRENT * in->motor.rated_current_A;
    const float dead_time_current_A = 2.0f * in->bus_voltage_V * in->dead_time_s / in->motor.inductance_H;
    if (in->phase_voltage_sensing) {
        return floor_A;
    }
    return min2(max2(MAGNETISING_PER_DEAD_TIME_CURRENT * dead_time_current_A, floor_A),
                MAX_MAGNETISING_PER_RATED_CURRENT * in->motor.rated_current_A);
}

/* The low-speed drive's band: below the speed whose back EMF is LOW_SPEED_EMF_PER_DEAD_TIME_LOSS
 * times the dead time's loss, and whose detent frequency 4 p w is LOW_SPEED_DETENT_PER_HELD_NATURAL
 * of the vector's held natural frequency at rated current (docs/design/14-low-speed-drive.md). */
static float low_speed_band(const pmstep_design_input_t *in)
{
    const pmstep_motor_config_t *m = &in->motor;
    const float pole_pairs = (float)m->pole_pairs;
    const float emf_band_rad_s = LOW_SPEED_EMF_PER_DEAD_TIME_LOSS * in->bus_voltage_V * in->dead_time_s
                                 / (in->period_s * m->torque_constant_Nm_A);
    const float held_natural_rad_s =
        sqrtf(pole_pairs * m->torque_constant_Nm_A * in->motor.rated_current_A / m->inertia_kgm2);
    const float resonance_band_rad_s = LOW_SPEED_DETENT_PER_HELD_NATURAL * held_natural_rad_s / (4.0f * pole_pairs);
    return min2(emf_band_rad_s, resonance_band_rad_s);
}

static void design_commissioning(const pmstep_design_input_t *in, float window_s, pmstep_config_t *cfg,
                                 pmstep_design_report_t *report)
{
    pmstep_commissioning_config_t *c = &cfg->commissioning;
    const float l_over_r = in->motor.inductance_H / in->motor.resistance_Ohm;
    const bool robust = in->self_commissioning;
    bool rotor_still;
    c->offset_calibration_time_s = robust ? OFFSET_CALIBRATION_S : 0.0f;
    c->alignment_offset_calibration = false;
    c->steady_state_window_s = window_s;
    c->inductance_window_s =
        robust ? max2(INDUCTANCE_WINDOW_PER_TIME_CONSTANT * l_over_r, MIN_INDUCTANCE_WINDOW_PERIODS * in->period_s)
               : 0.0f;
    /* L comes from the first current rise of s-alignment, with the rotor taken as still; where
     * the alignment swing's natural frequency turns the rotor within that window (hybrid
     * steppers: w_n ~ 1000 rad/s), its back EMF would enter the measurement: there L comes
     * from the drops to the voltage-bias level instead, where the rotor stays at its
     * equilibrium (no rise window). k_M's flux swing uses that L. */
    rotor_still = report->alignment_frequency_rad_s * c->inductance_window_s < STILL_ROTOR_SWING_PHASE;
    if (!rotor_still) {
        c->inductance_window_s = 0.0f;
    }
    c->use_measured_resistance = robust;
    c->use_measured_inductance = robust;
    c->use_measured_torque_constant = robust;
    c->voltage_bias_level_fraction = robust ? VOLTAGE_BIAS_LEVEL : 0.0f;
    /* The window is the application's: it must hold the speed commands that excite the motor. */
    c->identification_time_s = 0.0f;
    c->identification_min_speed_rad_s = IDENTIFICATION_MIN_SPEED_OF_TOP * report->top_speed_rad_s;
    c->use_identified_mechanics = false;
    c->measure_only = false;
    cfg->inverter.dead_time_s = robust ? in->dead_time_s : 0.0f;
    /* The band of the compensation, which the voltage bias uses too. */
    cfg->inverter.dead_time_current_band_A = robust ? max2(in->current_resolution_A, MIN_DEAD_TIME_BAND_A) : 0.0f;
    cfg->inverter.phase_voltage_sensing = in->phase_voltage_sensing; /* the drive's, not the design's */
    /* The ports' centred PWM has a ripple: no dead-time loss where it straddles zero. Without
     * phase-voltage sensing the flux integrals take the compensation's figure for the bridge's
     * voltage, and that is where it counts (docs/design/08-robust-mode.md); a sensing drive integrates the
     * sensed voltage, and its Monte Carlo gained nothing from it (181 / 194 / 200 / 200 with it,
     * 182 / 195 / 200 / 200 without). */
    cfg->inverter.ripple_dead_zone = robust && !in->phase_voltage_sensing;
    report->magnetising_current_A = robust ? magnetising_current(in) : 0.0f;
    /* Robust mode holds a zero speed command with a vector at rated current (pmstep_hold.h): the
     * estimate would drift there with what is left of the voltage errors. */
    cfg->standstill.hold_current_A = robust ? in->motor.rated_current_A : 0.0f;
    /* Below the speed whose back EMF is of the order of the dead time's loss the flux integrals'
     * phase is off by tenths of a radian: there the hold's vector can turn at the reference speed
     * in place of the law (at every speed in the band where asked for: a load step while it turns
     * is not learnt, docs/design/14-low-speed-drive.md). A drive that senses its phase voltages integrates the
     * bridge's own. */
    cfg->standstill.vector_speed_rad_s = (robust && !in->phase_voltage_sensing) ? low_speed_band(in) : 0.0f;
    /* Not asked for, the vector takes the stops only: there the law's rotor comes to rest with a
     * phase current in the dead-time band often enough to cost the estimate 0.05 rad (section 14). */
    cfg->standstill.stops_only = cfg->standstill.vector_speed_rad_s > 0.0f && !in->low_speed_drive;
}

/* Field weakening: I_w within half the magnet's flux in current and the rated current's circle beside
 * the q current of PMSTEP_DESIGN_WEAKENED_TORQUE_SHARE of the holding torque (sqrt(2) k_M I); the
 * bus share of the top speed's definition; the gain g = w_fw m V / (2 p L w_b) sets the loop's rate
 * 2 g p w L / (m V) to w_fw = varpi_0 / 8 where weakening starts, w_b (pmstep_weakening.h). */
static void design_field_weakening(const pmstep_design_input_t *in, pmstep_config_t *cfg,
                                   pmstep_design_report_t *report)
{
    const pmstep_motor_config_t *m = &in->motor;
    const float p_l = (float)m->pole_pairs * m->inductance_H;
    const float rated_A = in->motor.rated_current_A;
    const float q_A = PMSTEP_DESIGN_WEAKENED_TORQUE_SHARE * SQRT2 * rated_A;
    const float flux_A = WEAKENING_FLUX_SHARE * m->torque_constant_Nm_A / p_l;
    const float circle_A = sqrtf(rated_A * rated_A - q_A * q_A);
    const float current_A = in->field_weakening_off ? 0.0f : min2(flux_A, circle_A);
    cfg->field_weakening.max_current_A = current_A;
    cfg->field_weakening.modulation = USABLE_BUS_FRACTION;
    cfg->field_weakening.gain_A_per_s = WEAKENING_PER_REFERENCE_BANDWIDTH * cfg->gains.reference_bandwidth_rad_s
                                        * USABLE_BUS_FRACTION * in->bus_voltage_V
                                        / (2.0f * p_l * report->bus_speed_rad_s);
    report->weakening_current_A = current_A;
    report->weakened_speed_rad_s =
        current_A > 0.0f ? min2(bus_speed_at(in, -current_A, q_A), report->rate_speed_rad_s) : report->top_speed_rad_s;
}

static void design_protection(const pmstep_design_input_t *in, pmstep_config_t *cfg, float top_speed_rad_s)
{
    const float usable_current_A = PMSTEP_SENSE_RANGE_USABLE_FRACTION * in->current_sense_range_A;
    const float usable_bus_V = PMSTEP_SENSE_RANGE_USABLE_FRACTION * in->bus_sense_range_V;
    cfg->limits.current_sense_range_A = in->current_sense_range_A;
    cfg->limits.bus_sense_range_V = in->bus_sense_range_V;
    cfg->limits.max_phase_current_A = min2(TRIP_CURRENT_PER_RATED * in->motor.rated_current_A, usable_current_A);
    cfg->limits.min_bus_voltage_V = MIN_BUS_FRACTION * in->bus_voltage_V;
    cfg->limits.max_bus_voltage_V = min2(MAX_BUS_FRACTION * in->bus_voltage_V, usable_bus_V);
    cfg->detection.angle_magnitude_bound = ANGLE_MAGNITUDE_BOUND;
    cfg->detection.stall_speed_error_rad_s = STALL_FRACTION_OF_TOP_SPEED * top_speed_rad_s;
    cfg->detection.speed_consistency_bound_rad_s = STALL_FRACTION_OF_TOP_SPEED * top_speed_rad_s;
    /* Plus the dead time's floor: in a period in which a current crosses zero the observer's
     * prediction (the compensated voltage) can be off by twice the loss 2 V_bus t_d / T (the
     * sign taken the wrong way), which moves that period's current by 4 V_bus t_d / L
     * (docs/design/05-protections-and-detection.md). */
    cfg->detection.observer_residual_bound_A =
        RESIDUAL_PER_RATED_CURRENT * in->motor.rated_current_A
        + 4.0f * in->bus_voltage_V * cfg->inverter.dead_time_s / in->motor.inductance_H;
    cfg->detection.persistence_s = PERSISTENCE_S;
    cfg->detection.max_realignments = 0u;
}

pmstep_status_t pmstep_design(const pmstep_design_input_t *given, pmstep_config_t *cfg, pmstep_design_report_t *report)
{
    pmstep_status_t status;
    float window_s;
    pmstep_design_input_t estimated;
    const pmstep_design_input_t *in = given;
    if (given == NULL || cfg == NULL || report == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    report->inertia_estimated = false;
    if (given->motor.inertia_kgm2 == 0.0f && given->holding_torque_Nm > 0.0f) {
        /* No inertia on the datasheet: the frame's, from the holding torque (to be identified in RUN).
         * Paper mode takes the top of the estimate's range (docs/design/10-inertia-and-friction.md). */
        estimated = *given;
        estimated.motor.inertia_kgm2 = (given->self_commissioning ? 1.0f : PMSTEP_DESIGN_INERTIA_ESTIMATE_SPREAD)
                                       * pmstep_design_inertia_estimate(given->holding_torque_Nm);
        report->inertia_estimated = true;
        in = &estimated;
    }
    report->inertia_kgm2 = in->motor.inertia_kgm2;
    /* Data no stepper has first: a unit typed wrong shows there before it fails a rule below. */
    status =
        (!pmstep_design_finite_input(in) || in->accept_implausible) ? PMSTEP_OK : pmstep_design_check_datasheet(in);
    if (status == PMSTEP_OK) {
        status = pmstep_design_check_input(in);
    }
    if (status != PMSTEP_OK) {
        return status;
    }
    cfg->motor = in->motor;
    cfg->timing.period_s = in->period_s;
    cfg->timing.computational_delay_periods = in->computational_delay_periods;
    cfg->known_load_mode = false;
    /* The top speed: the bus's, or the control rate's where the rotor turns more than
     * PMSTEP_DESIGN_MAX_ELECTRICAL_STEP_RAD per period before the bus runs out. */
    report->bus_speed_rad_s = bus_speed(in);
    report->rate_speed_rad_s = PMSTEP_DESIGN_MAX_ELECTRICAL_STEP_RAD / ((float)in->motor.pole_pairs * in->period_s);
    report->top_speed_rad_s = min2(report->bus_speed_rad_s, report->rate_speed_rad_s);
    report->top_electrical_step_rad = (float)in->motor.pole_pairs * report->top_speed_rad_s * in->period_s;
    report->rated_torque_Nm = in->motor.torque_constant_Nm_A * in->motor.rated_current_A;
    design_gains(in, &cfg->gains, report);
    window_s = design_alignment(in, cfg, report);
    design_commissioning(in, window_s, cfg, report);
    design_protection(in, cfg, report->top_speed_rad_s);
    design_field_weakening(in, cfg, report);
    return pmstep_validate_config(cfg);
}
