/**
 * @file pmstep_hold.h
 * @brief Standstill hold by a current vector fixed in the stator frame (for position control), and
 *        the low-speed drive that turns it at the reference speed.
 *
 * At zero speed nothing observes the phase of the flux estimate: an estimate hold drifts with
 * the sum of every small voltage error (offsets, R, dead time). A vector hold does not need the
 * estimate: the stator current i = I (cos v, sin v) pulls the rotor to the electrical angle
 * x with k_M I sin(v - x) = T_L - T_detent(x), so a vector aimed at
 *   v = x_rest + delta,   sin delta = (T_L-hat - T_detent(x_rest)) / (k_M I)
 * holds the rotor at x_rest under the estimated load. Linearised about the rest the rotor is a
 * spring, J theta'' = -p k_M I cos(delta) theta, of natural frequency
 *   w_n = sqrt(p k_M I cos(delta) / J);
 * turning the vector back by g (w-hat - w-bar), g = 2 zeta p / w_n, adds the damping 2 zeta w_n
 * where w-hat follows the swing in phase (PMSTEP_HOLD_MIN_IN_PHASE_SHARE; g = 0 where it does
 * not: a rotor light enough that w_n passes the observer's bandwidth, docs/design/12-position-hold.md).
 * The standstill hold of speed mode keeps g whatever the phase: it engages with a step of the
 * vector's current, whose first swing g still shortens (docs/design/12-position-hold.md).
 * w-bar is w-hat low-passed at w_n / PMSTEP_HOLD_BIAS_CORNER_RATIO: the speed estimate's bias
 * at rest, which would otherwise turn the vector off the rest for good (g times the bias).
 * The law's PI current loop (pmstep_law_voltages' at zero speed, written out in pmstep_hold.c)
 * runs in the vector's frame: i_d* = I, i_q* = 0, its integrals on those errors. The observer, the angle integrals
 * and the detection run on as in RUN.
 *
 * Standstill hold in speed mode (cfg->standstill.hold_current_A > 0): when the speed command is
 * 0, the reference has reached it (|w*| below 1 % of the quiet band) and |w-hat| has stayed
 * within the quiet band PMSTEP_HOLD_QUIET_FRACTION w_n / p for PMSTEP_STANDSTILL_ENGAGE_TIME_CONSTANTS
 * of the speed loop (1/k_w), the core holds the rotor with the vector aimed at the estimate,
 * ahead by the load angle of T_L-hat. After the held rotor's settling time, the estimate is
 * kept while the rotor rests (|w-hat - w-bar| within the quiet band; it is taken during the
 * first settling time of each rest and put back every period after) and follows the flux
 * integrals while it moves: the same rule as the position library's hold (pmstep_position.h).
 * Where it is kept (and while the low-speed drive turns it) the period's estimate is the kept
 * rotor itself, not the integrals' reading of it: that reading, a period after the estimate was
 * put back, carries two current samples' noise (L p / k_M per ampere, 0.84 rad/A on the
 * 17HS4401), and goes to the motion sum only.
 * A non-zero speed command releases it (a zero one keeps it), as do leaving RUN and
 * pmstep_leave_speed_mode(), by which the position library takes the reference over.
 * A load step on the held rotor moves it at w_n, above the observer's speed bandwidth on a
 * hybrid stepper, so w-hat misses that motion; the flux integrals do not. While the estimate is
 * kept, each period's turn of the integrals off the kept estimate is summed, leaking over one
 * settling time; a sum beyond PMSTEP_HOLD_MOTION_BOUND_RAD is the rotor's motion (a drift of
 * the integrals sums to its rate times the settling time): the estimate is turned by it,
 * T_L-hat set to the held rotor's balance k_M I sin(v - x-hat) + T_detent(x-hat), and the rest
 * starts again (the estimate follows the integrals for a settling time, then is kept there).
 * That turn is read in the phase with the smaller current, whose dead-time loss is unknown
 * while its current crosses zero: the standstill aims its vector, T_L-hat's load angle ahead
 * of the rest, so that both phase currents stay PMSTEP_HOLD_PHASE_CLEARANCE_BANDS compensation
 * bands clear of zero, and the rest with it (the rotor moves by at most asin(clearance / I) to
 * get there; nothing with a zero band).
 *
 * Low-speed drive (cfg->standstill.vector_speed_rad_s = w_b > 0): below the speed whose back EMF
 * is of the order of the voltage errors (the dead time's loss), the flux integrals' phase is off
 * by tenths of a radian and the law on it loses the rotor. There a command |w_cmd| <= w_b is held
 * the same way, engaged on the same test with the band widened by w_b (|target|, |set-point|
 * and |w*| within w_b, |w-hat - w*| within the quiet band plus w_b), and the vector turns: each
 * period the kept rotor x-hat advances by p w* T_s and the vector is aimed ahead of it,
 *   v = x-hat + delta,   sin delta = (T_L,aim + J w*' + F w* - T_detent(x-hat)) / (k_M I),
 * T_L,aim being T_L-hat at the engagement, then the held rotor's balance each time the estimate
 * is taken or followed. The estimate is x-hat throughout (the integrals are not followed while
 * turning); w-bar is the low-passed w-hat - w*; the voltage adds L I p w_f + k_M w* on q, w_f =
 * w* + (d delta / dt) / p the frame's speed with the detent's rate, and is put out in the frame
 * turned on by p w_f T_s (delay + 1/2). At rest (|w*| below 1 % of the quiet band) on a zero
 * command the vector stops, aimed afresh at its kept rotor clear of the phase axes as an
 * engagement at rest is (it may have stopped with a phase current in the dead-time band), and
 * the standstill's rules above apply from a new settling; a reversal passing w* = 0 turns on.
 * A command beyond w_b releases the vector and the law starts from T_L,aim; so does a load
 * angle beyond PMSTEP_HOLD_MAX_TORQUE_FRACTION.
 *
 * Stops only (cfg->standstill.stops_only): the same drive, engaged only on a zero command while
 * the set-point is on its way to it (the band widens the test only then; at rest the standstill's
 * own test), so that the vector takes the last of a stop, where the law's rotor would come to
 * rest with a phase current in the dead-time band and its integrals drifting. Any other command
 * releases it, T_L-hat left as the observer's, and the law drives every speed.
 */
#ifndef PMSTEP_HOLD_H
#define PMSTEP_HOLD_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** zeta of the held rotor (the vector's lag g = 2 zeta p / w_n). */
#define PMSTEP_HOLD_DAMPING_RATIO 0.7f
/** Smallest in-phase share Re(w-hat/w) of the observer's speed estimate at w_n (the estimate kept,
 *  so the observer's model has no restoring torque) for the damping term: below it w-hat lags
 *  the rotor by so much that g (w-hat - w-bar) would turn the vector with the displacement, not
 *  the speed (the hybrid presets, w_n 1.1 to 1.6 times the observer's w_o: Re 0.37 to -0.06). */
#define PMSTEP_HOLD_MIN_IN_PHASE_SHARE 0.5f
/** |w-hat - w-bar| below this fraction of w_n / p counts as at rest (the position library's test). */
#define PMSTEP_HOLD_QUIET_FRACTION 0.05f
/** Settling time of the held rotor, in time constants 1/(zeta w_n). */
#define PMSTEP_HOLD_SETTLE_TIME_CONSTANTS 6.0f
/** w-bar follows w-hat with the corner frequency w_n divided by this. */
#define PMSTEP_HOLD_BIAS_CORNER_RATIO 20.0f
/** Largest |sin delta| a hold accepts: beyond, the load is too near the vector's pull-out torque. */
#define PMSTEP_HOLD_MAX_TORQUE_FRACTION 0.9f
/** Largest turn of the vector by the damping term (electrical rad). */
#define PMSTEP_HOLD_MAX_DAMPING_TURN 0.5f
/** A summed turn of the flux integrals off the kept estimate beyond this is the rotor's motion
 * (electrical rad; the envelope's angle bound). */
#define PMSTEP_HOLD_MOTION_BOUND_RAD 0.05f
/** The integrals' drift at rest (R and voltage errors times the hold current) is learnt at this
 * fraction of the motion sum's leak: over four settling times, slower than a held rotor's move,
 * which the sum is to see. */
#define PMSTEP_HOLD_DRIFT_LEAK_FRACTION 0.25f
/** The standstill aims its vector so that both phase currents are at least this many dead-time
 * compensation bands clear of zero (0.125 A with the designer's 5 mA band; a load step's swing
 * moves the smaller one by about 0.1 A on the 17HS4401). Measured, Monte Carlo of 200 cases per
 * preset: at 0 bands the release after a loaded hold still fails in 13 and 14 cases of the
 * 17HS4401 and BJ42D29, at 25 in 1 and 1; at 50 the paper motor's move (0.07 rad on its
 * 11.7 mA band) breaks its speed bound in 5 cases (README, Monte Carlo). */
#define PMSTEP_HOLD_PHASE_CLEARANCE_BANDS 25.0f
/** Time at rest before the standstill hold, in time constants 1/k_w of the speed loop. */
#define PMSTEP_STANDSTILL_ENGAGE_TIME_CONSTANTS 2.0f
/** |w*| below this fraction of the quiet band counts as the zero command reached. */
#define PMSTEP_STANDSTILL_REFERENCE_FRACTION 0.01f

/** State of a vector hold (part of pmstep_t). */
typedef struct {
    float cos_vector;         /**< cos v of the aimed vector (stator frame) */
    float sin_vector;         /**< sin v */
    float current_A;          /**< I */
    float damping_s;          /**< g = 2 zeta p / w_n, electrical rad per rad/s (0: w-hat lags the swing) */
    float speed_bias_rad_s;   /**< w-bar, the speed estimate at rest (w-hat low-passed) */
    float bias_gain;          /**< w_n T_s / PMSTEP_HOLD_BIAS_CORNER_RATIO, w-bar's filter per period */
    float quiet_band_rad_s;   /**< PMSTEP_HOLD_QUIET_FRACTION w_n / p */
    float vector_speed_rad_s; /**< w_v, the speed the vector turns at (the standstill's low-speed drive; else 0) */
    float cos_frame;          /**< the period's frame: the vector turned by the damping */
    float sin_frame;
    uint32_t settle_periods; /**< PMSTEP_HOLD_SETTLE_TIME_CONSTANTS / (zeta w_n), in periods */
    bool active;
    /* The standstill hold of speed mode (its counts in pmstep_standstill_t): flags kept out of
     * the RUN scratch union, whose bytes are the commissioning sums until t_c. */
    bool standstill_armed;   /**< RUN with a hold current, in speed mode (not the position library's) */
    bool standstill_engaged; /**< this hold is the standstill's */
    bool standstill_settled; /**< the held rotor's settling time has passed */
} pmstep_vector_hold_t;

/** State of the standstill hold in speed mode (part of pmstep_t's RUN scratch). */
typedef struct {
    float quiet_band_rad_s; /**< PMSTEP_HOLD_QUIET_FRACTION w_n / p for the hold's current: at rest below */
    float keep_cos;         /**< the estimate kept while the held rotor rests */
    float keep_sin;
    float motion_rad;        /**< the integrals' turn off the kept estimate, summed with the leak */
    float motion_leak;       /**< 1 / the hold's settling periods: the sum's leak per period */
    float drift_rad;         /**< the integrals' turn per period at rest (R and voltage errors), learnt */
    float aim_load_Nm;       /**< T_L the vector is aimed for (the load angle's), turning or at rest */
    float vector_rate_rad_s; /**< the turning vector's speed, w* + (d delta / dt) / p (rad/s, mechanical) */
    uint32_t engage_periods; /**< PMSTEP_STANDSTILL_ENGAGE_TIME_CONSTANTS / k_w, in periods */
    uint32_t rest_periods;   /**< periods at rest: before the hold, to engage it; in it, since the settling */
} pmstep_standstill_t;

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_HOLD_H */
