/**
 * @file inverter.h
 * @brief Inverter and DC bus of the SIL, and the function that advances the plant
 *        over one control period through them. Shared by the host port and the PIL
 *        closed loop on the target, so both drive the plant alike.
 *
 * MCU side (sil_inverter_apply): the step's voltage is clipped to +/- the bus voltage
 * the step was given (the duty d = u / V_bus,measured is kept in [-1, 1]; a clip counts
 * in limited_periods when that command is applied) and applied now, or one period
 * later with a computational delay of one period.
 *
 * Bridge (sil_drive_advance): each phase is an H-bridge of two half-bridges (legs A and
 * B). Leg A carries +i out to the winding, leg B carries -i. The bridge applies the duty
 * to the actual bus, d V_bus:
 *  - averaged model: u = d V_bus - 2 sign(i) V_bus t_d / T (dead time t_d per leg, T the
 *    control period = PWM period). The voltage is constant between zero crossings of the
 *    current: a step in which a current crosses zero is cut where it crosses (located by
 *    regula falsi on re-integrations of the step), the current set to exactly 0 there, and
 *    the rest integrated on the branch the current leaves into. A zero current that neither
 *    branch drives away (|back EMF + d V_bus| <= 2 V_bus t_d / T) stays at zero, the phase
 *    held open (the dead time's zero-current clamp) until a later step finds a branch.
 *  - switching model: centre-aligned carrier, valley at the period boundary (where the
 *    ADC samples). Leg A is high for (1+d)/2 T and leg B for (1-d)/2 T, both windows
 *    centred on mid-period; u = V_bus (s_A - s_B). For t_d after each edge of a leg both
 *    its switches are off and the freewheel diode of the current's direction at that edge
 *    sets the leg: low for a current out of the leg, high for one into it, as commanded
 *    for a zero current. So a turn-on edge is delayed by t_d when the current flows out of
 *    that leg, a turn-off edge when it flows in (a leg at d = +/-1 does not switch and has
 *    no dead time; a dead time is held inside the period). Each edge takes the sign of
 *    the current at that edge: the period is integrated with the signs of its start, and
 *    again (up to three passes) with the signs the last pass found at the edges while any
 *    differ, so a current crossing zero within the period, or rippling across zero, loses
 *    the dead time of each edge with its own sign. Not modelled: a current that reaches
 *    zero inside a dead time stays there until the edge's switch turns on (the zero-current
 *    clamp of the averaged model). With the exponential integrator at one
 *    step a period, the currents are split into the response to the period's mean voltage
 *    (one step, with the back EMF and the mechanics) and the PWM ripple, which solves
 *    r' = -(R/L) r + (u - u_mean)/L, r(0) = 0, exactly between the edges; the ripple's
 *    torque enters the step as its projection onto quadratics over the period (exact
 *    moments of order 0 to 2), and the currents at the end are the sum (a load step inside
 *    the period falls back to the segments). Otherwise the plant is integrated segment by
 *    segment between the sorted edges of both phases, in steps of at most T / substeps;
 *    zero-length segments are skipped.
 *  - bridge off (either model): every switch off. A phase with current conducts
 *    through the freewheel diodes, u = -sign(i) V_bus, sign held over each substep; at
 *    the end of the substep in which the current reaches or crosses zero it is set to
 *    exactly 0 and the phase is open (the plant holds i = 0, whatever the back EMF) until
 *    the bridge is enabled again. A back EMF above the bus, which would make the diodes
 *    conduct again, is not modelled.
 *
 * Bus: V_bus(t) = V0 - R_src i_bus + ripple_V sin(2 pi ripple_Hz t), clamped at >= 0.
 * i_bus = (u_a i_a + u_b i_b)/V_bus is taken as the mean over the previous period
 * (a stiff DC-link capacitor holding the sag of the last period), computed from the
 * integrators' quadrature of the currents; the ripple is evaluated at each substep's midpoint
 * and at the sample.
 *
 * With the defaults (averaged, t_d = 0, R_src = 0, ripple 0) and a constant bus the
 * plant receives exactly the commanded voltage, bit for bit, as with plant_advance().
 */
#ifndef SIL_INVERTER_H
#define SIL_INVERTER_H

#include <stdbool.h>

#include "pmstep/pmstep_types.h"
#include "sil/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    SIL_INVERTER_AVERAGED = 0, /**< duty times bus, dead time as a mean voltage error */
    SIL_INVERTER_SWITCHING = 1 /**< switching edges within the period */
} sil_inverter_model_t;

/** [inverter] of a scenario. */
typedef struct {
    sil_inverter_model_t model;
    double dead_time_s; /**< per half-bridge (>= 0, < period/4) */
} sil_inverter_config_t;

/** [bus] of a scenario (the nominal V0 is run.bus_voltage_V). */
typedef struct {
    double source_resistance_Ohm; /**< R_src */
    double ripple_V;              /**< amplitude of the sine ripple (V) */
    double ripple_Hz;
} sil_bus_config_t;

typedef struct {
    sil_inverter_config_t cfg;
    sil_bus_config_t bus;
    double nominal_bus_voltage_V; /**< V0 */
    unsigned delay_periods;       /**< 0 or 1 */
    /* MCU side: the last step's command, waiting for the next period (delay 1). */
    double pending_a_V; /**< clipped to +/- pending_bus_V */
    double pending_b_V;
    double pending_bus_V; /**< measured bus the step was given */
    bool pending_clipped;
    /* The bridge over the coming period. */
    bool bridge_enable;
    double command_a_V; /**< clipped command; the duty is command / command_bus_V */
    double command_b_V;
    double command_bus_V;
    /* What the plant received over the last period (set by sil_drive_advance). */
    double applied_a_V; /**< mean phase voltage (before the advance: the command) */
    double applied_b_V;
    double mean_current_A[2]; /**< mean current of phase a [0] and b [1] (A) */
    double min_current_A[2];  /**< extremes of the phase currents at the substep ends, start included (A) */
    double max_current_A[2];
    double mean_bus_current_A;     /**< mean i_bus, which sets the sag of the next period */
    unsigned long limited_periods; /**< periods the MCU had to clip its duty to +/- 1 */
    /* The ripple's last two sines, sin(2 pi f t) for (t, f): a period asks for the same instant
     * twice (the measurement at t_k, the period's start), so one sine of three is reused. A
     * zeroed memo holds t = f = 0, whose sine is 0: consistent without an init. */
    double ripple_memo_t_s[2];
    double ripple_memo_hz[2];
    double ripple_memo_sin[2];
    unsigned ripple_memo_next;
} sil_inverter_t;

/** Averaged model, no dead time. */
sil_inverter_config_t sil_inverter_ideal_config(void);

/** Stiff bus: no source resistance, no ripple (ripple_Hz 100). */
sil_bus_config_t sil_bus_ideal_config(void);

/** Zero voltage, nothing pending, bridge enabled, no bus current. */
void sil_inverter_init(sil_inverter_t *inv, const sil_inverter_config_t *cfg, const sil_bus_config_t *bus,
                       double bus_voltage_V, unsigned delay_periods);

/** @p u_V limited to +-@p limit_V (a phase voltage to the bus); sets *@p clipped when it was. */
double sil_inverter_clip(double u_V, double limit_V, bool *clipped);

/** Takes one step's output and the bus voltage the step was given; sets the command of the coming period. */
void sil_inverter_apply(sil_inverter_t *inv, const pmstep_output_t *out, double measured_bus_V);

/** The actual bus voltage at time @p t_s of the coming period (sag of the last period, ripple at t). */
double sil_inverter_bus_voltage(sil_inverter_t *inv, double t_s);

/**
 * Advances @p plant by @p period_s from plant->time_s through the inverter and bus
 * (steps of plant->integrator of at most period_s / @p substeps), sets plant->time_s to the end of
 * the period and the inverter's applied voltages, currents and bus current.
 */
void sil_drive_advance(plant_t *plant, sil_inverter_t *inv, double period_s, int substeps);

#ifdef __cplusplus
}
#endif

#endif /* SIL_INVERTER_H */
