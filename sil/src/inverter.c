/* Inverter (see inverter.h): the MCU's duty, the bridge's phase voltages in the averaged model
 * (the switching model is in inverter_switching.c), dead time, freewheeling with the bridge off,
 * and the plant advanced over one control period (the bus voltage and the substep's bookkeeping
 * are in inverter_period.c). */
#include "inverter_internal.h"

#include <math.h>
#include <stddef.h>

sil_inverter_config_t sil_inverter_ideal_config(void)
{
    sil_inverter_config_t c;
    c.model = SIL_INVERTER_AVERAGED;
    c.dead_time_s = 0.0;
    return c;
}

sil_bus_config_t sil_bus_ideal_config(void)
{
    sil_bus_config_t b;
    b.source_resistance_Ohm = 0.0;
    b.ripple_V = 0.0;
    b.ripple_Hz = 100.0;
    return b;
}

void sil_inverter_init(sil_inverter_t *inv, const sil_inverter_config_t *cfg, const sil_bus_config_t *bus,
                       double bus_voltage_V, unsigned delay_periods)
{
    int k;
    inv->cfg = *cfg;
    inv->bus = *bus;
    inv->nominal_bus_voltage_V = bus_voltage_V;
    inv->delay_periods = delay_periods;
    inv->pending_a_V = 0.0;
    inv->pending_b_V = 0.0;
    inv->pending_bus_V = bus_voltage_V;
    inv->pending_clipped = false;
    inv->bridge_enable = true;
    inv->command_a_V = 0.0;
    inv->command_b_V = 0.0;
    inv->command_bus_V = bus_voltage_V;
    inv->applied_a_V = 0.0;
    inv->applied_b_V = 0.0;
    for (k = 0; k < 2; ++k) {
        inv->mean_current_A[k] = 0.0;
        inv->min_current_A[k] = 0.0;
        inv->max_current_A[k] = 0.0;
    }
    inv->mean_bus_current_A = 0.0;
    inv->limited_periods = 0;
    for (k = 0; k < 2; ++k) {
        inv->ripple_memo_t_s[k] = 0.0;
        inv->ripple_memo_hz[k] = 0.0;
        inv->ripple_memo_sin[k] = 0.0; /* sin(2 pi 0 0) */
    }
    inv->ripple_memo_next = 0u;
}

double sil_inverter_clip(double u_V, double limit_V, bool *clipped)
{
    if (u_V > limit_V) {
        *clipped = true;
        return limit_V;
    }
    if (u_V < -limit_V) {
        *clipped = true;
        return -limit_V;
    }
    return u_V;
}

void sil_inverter_apply(sil_inverter_t *inv, const pmstep_output_t *out, double measured_bus_V)
{
    const bool enable = out->bridge_enable;
    /* The MCU's duty is u / V_bus,measured within [-1, 1]; no usable bus reading gives zero duty. */
    const bool bus_ok = measured_bus_V > 0.0 && isfinite(measured_bus_V);
    double u_a_V = 0.0, u_b_V = 0.0, bus_V = measured_bus_V;
    double next_a_V, next_b_V;
    bool clipped = false, next_clipped;
    if (enable && bus_ok) {
        u_a_V = sil_inverter_clip((double)out->u_a_V, measured_bus_V, &clipped);
        u_b_V = sil_inverter_clip((double)out->u_b_V, measured_bus_V, &clipped);
    }
    if (inv->delay_periods == 1u) {
        /* A disabled bridge stops switching at once: nothing stays pending. */
        next_a_V = enable ? inv->pending_a_V : 0.0;
        next_b_V = enable ? inv->pending_b_V : 0.0;
        next_clipped = enable && inv->pending_clipped;
        bus_V = inv->pending_bus_V;
        inv->pending_a_V = u_a_V;
        inv->pending_b_V = u_b_V;
        inv->pending_bus_V = measured_bus_V;
        inv->pending_clipped = clipped;
    } else {
        next_a_V = u_a_V;
        next_b_V = u_b_V;
        next_clipped = clipped;
    }
    if (next_clipped) {
        inv->limited_periods++;
    }
    inv->bridge_enable = enable;
    inv->command_a_V = next_a_V;
    inv->command_b_V = next_b_V;
    inv->command_bus_V = bus_V;
    inv->applied_a_V = next_a_V;
    inv->applied_b_V = next_b_V;
}

/* Bridge off: freewheel diodes while a phase carries current, open once it is zero. */
static void freewheel(sil_inv_period_t *p, double period_s, int substeps)
{
    const double h = period_s / (double)substeps;
    int n, k;
    for (n = 0; n < substeps; ++n) {
        const double t = p->t0_s + (double)n * h;
        const double bus_V = sil_inv_substep_bus_V(p, t, h);
        double u_V[2], fraction[2];
        int diode[2];
        for (k = 0; k < 2; ++k) {
            bool *open = sil_inv_phase_open(p->plant, k);
            const int s = *open ? 0 : sil_inv_sign_of(*sil_inv_phase_current(p->plant, k));
            if (s == 0) {
                *open = true;
            }
            u_V[k] = s == 0 ? 0.0 : -(double)s * bus_V; /* +0 for an open phase, as the bridge-off voltage was */
            fraction[k] = s == 0 ? 0.0 : -(double)s;
            diode[k] = s;
        }
        sil_inv_substep(p, t, h, u_V, fraction, diode);
    }
}

/* The dead-time branch of a phase at the present state: +1 or -1 with the current's sign;
 * at zero current the branch the current leaves into, or 0 (held at zero) when neither
 * branch drives it away: with u0 the duty's voltage and dead_v = 2 V_bus t_d / T, the
 * positive branch has L di/dt = e + u0 - dead_v at i = 0 and the negative e + u0 + dead_v
 * (e the back EMF). */
static int dead_time_branch(const plant_t *plant, int k, double u0_v, double dead_v)
{
    const double i_a = k == 0 ? plant->x.i_a_A : plant->x.i_b_A;
    double s, c, emf_v;
    if (i_a != 0.0) {
        return sil_inv_sign_of(i_a);
    }
    s = sin((double)plant->params.pole_pairs * plant->x.theta_rad);
    c = cos((double)plant->params.pole_pairs * plant->x.theta_rad);
    emf_v = plant->params.torque_constant_Nm_A * plant->x.omega_rad_s * (k == 0 ? s : -c);
    if (emf_v + u0_v - dead_v > 0.0) {
        return 1;
    }
    if (emf_v + u0_v + dead_v < 0.0) {
        return -1;
    }
    return 0;
}

#define DEAD_TIME_EVENTS_MAX 8 /* zero crossings located per substep */
#define CROSSING_REFINEMENTS 3 /* regula falsi steps on the crossing time */

/* Averaged bridge: u = d V_bus - 2 sign(i) V_bus t_d / T. With dead time the voltage jumps
 * where a current crosses zero: the substep is cut at the crossing (located by regula falsi
 * on re-integrations from the substep's start), the current set to exactly 0 there, and the
 * rest integrated on the branch it leaves into. A current that neither branch drives away
 * from zero stays at zero (the dead time's zero-current clamp): the phase is held open
 * until a later substep finds a branch. */
static void averaged(sil_inv_period_t *p, double period_s, int substeps)
{
    static const int no_diode[2] = {0, 0};
    const sil_inverter_t *inv = p->inv;
    plant_t *plant = p->plant;
    const double h = period_s / (double)substeps;
    const double dead_fraction = 2.0 * inv->cfg.dead_time_s / period_s;
    const bool dead_time = inv->cfg.dead_time_s > 0.0;
    const double command_V[2] = {inv->command_a_V, inv->command_b_V};
    const bool bus_ok = inv->command_bus_V > 0.0;
    int n, k;
    for (n = 0; n < substeps; ++n) {
        const double t = p->t0_s + (double)n * h;
        const double bus_V = sil_inv_substep_bus_V(p, t, h);
        /* d V_bus as u (V_bus / V_measured): exactly the command when the two agree. */
        const double ratio = bus_ok ? bus_V / inv->command_bus_V : 0.0;
        const double dead_v = bus_V * dead_fraction;
        double u0_v[2], fraction0[2];
        double done_s = 0.0;
        int events = 0;
        for (k = 0; k < 2; ++k) {
            u0_v[k] = command_V[k] * ratio;
            fraction0[k] = bus_ok ? command_V[k] / inv->command_bus_V : 0.0;
        }
        if (!dead_time) {
            sil_inv_substep(p, t, h, u0_v, fraction0, no_diode);
            continue;
        }
        while (done_s < h) {
            const double rest_s = h - done_s;
            const plant_state_t start = plant->x;
            double u_V[2], fraction[2];
            int branch[2];
            double cut_s = rest_s;
            int crossing = -1;
            sil_inv_period_t saved;
            for (k = 0; k < 2; ++k) {
                branch[k] = dead_time_branch(plant, k, u0_v[k], dead_v);
                u_V[k] = u0_v[k] - (double)branch[k] * dead_v;
                fraction[k] = fraction0[k] - (double)branch[k] * dead_fraction;
                if (branch[k] == 0) {
                    /* Held at zero: the voltage that holds it there, no bus current. */
                    const double angle = (double)plant->params.pole_pairs * plant->x.theta_rad;
                    u_V[k] = -plant->params.torque_constant_Nm_A * plant->x.omega_rad_s
                             * (k == 0 ? sin(angle) : -cos(angle));
                    fraction[k] = 0.0;
                }
                *sil_inv_phase_open(plant, k) = branch[k] == 0;
            }
            /* The rest of the substep; undone if a current crossed zero within it. */
            saved = *p;
            sil_inv_substep(p, t + done_s, rest_s, u_V, fraction, no_diode);
            if (events < DEAD_TIME_EVENTS_MAX) {
                double lo_s = 0.0, hi_s = rest_s;
                double i_lo[2], i_hi[2];
                for (k = 0; k < 2; ++k) {
                    i_lo[k] = k == 0 ? start.i_a_A : start.i_b_A;
                    i_hi[k] = *sil_inv_phase_current(plant, k);
                    if (branch[k] != 0 && sil_inv_sign_of(i_hi[k]) != branch[k]) {
                        /* The earliest crossing by linear interpolation. */
                        const double f_s = rest_s * i_lo[k] / (i_lo[k] - i_hi[k]);
                        if (crossing < 0 || f_s < cut_s) {
                            crossing = k;
                            cut_s = f_s;
                        }
                    }
                }
                if (crossing >= 0) {
                    int r;
                    double at_lo = i_lo[crossing], at_hi = i_hi[crossing];
                    for (r = 0; r < CROSSING_REFINEMENTS; ++r) {
                        double i_cut;
                        plant->x = start;
                        plant_substep(plant, t + done_s, cut_s, u_V[0], u_V[1], NULL, NULL);
                        i_cut = *sil_inv_phase_current(plant, crossing);
                        if (sil_inv_sign_of(i_cut) == branch[crossing]) {
                            lo_s = cut_s;
                            at_lo = i_cut;
                        } else {
                            hi_s = cut_s;
                            at_hi = i_cut;
                        }
                        if (i_cut == 0.0 || !(hi_s > lo_s)) {
                            break;
                        }
                        cut_s = lo_s + (hi_s - lo_s) * at_lo / (at_lo - at_hi);
                    }
                    cut_s = hi_s; /* end the piece at or just past the crossing */
                    /* Up to the crossing only, the current there exactly zero. */
                    *p = saved;
                    plant->x = start; /* (the open flags are the branches', as before) */
                    sil_inv_substep(p, t + done_s, cut_s, u_V, fraction, no_diode);
                    *sil_inv_phase_current(plant, crossing) = 0.0;
                    ++events;
                }
            }
            done_s = crossing >= 0 ? done_s + cut_s : h;
        }
        plant->open_a = false;
        plant->open_b = false;
    }
}

void sil_drive_advance(plant_t *plant, sil_inverter_t *inv, double period_s, int substeps)
{
    sil_inv_period_t p;
    int k;
    p.plant = plant;
    p.inv = inv;
    p.t0_s = plant->time_s;
    p.bus_V = sil_inverter_bus_voltage(inv, p.t0_s);
    p.started = false;
    p.constant_u = true;
    p.bus_charge_c = 0.0;
    for (k = 0; k < 2; ++k) {
        p.first_u_V[k] = 0.0;
        p.volt_s[k] = 0.0;
        p.charge_c[k] = 0.0;
        p.min_a[k] = *sil_inv_phase_current(plant, k);
        p.max_a[k] = p.min_a[k];
    }
    if (!inv->bridge_enable) {
        freewheel(&p, period_s, substeps);
    } else {
        plant->open_a = false;
        plant->open_b = false;
        if (inv->cfg.model == SIL_INVERTER_SWITCHING) {
            const plant_load_t *load = &plant->load;
            const bool load_step_inside =
                load->kind == PLANT_LOAD_STEP && p.t0_s < load->step_time_s && load->step_time_s <= p.t0_s + period_s;
            sil_inv_switching_period(&p, period_s, substeps,
                                     substeps == 1 && plant->integrator == PLANT_INTEGRATOR_EXPONENTIAL
                                         && !load_step_inside);
        } else {
            averaged(&p, period_s, substeps);
        }
    }
    /* Time from the period count, not accumulated substeps. */
    plant->time_s = p.t0_s + period_s;
    /* A voltage held over the whole period is reported as is, not as a sum of its parts. */
    inv->applied_a_V = p.constant_u ? p.first_u_V[0] : p.volt_s[0] / period_s;
    inv->applied_b_V = p.constant_u ? p.first_u_V[1] : p.volt_s[1] / period_s;
    for (k = 0; k < 2; ++k) {
        inv->mean_current_A[k] = p.charge_c[k] / period_s;
        inv->min_current_A[k] = p.min_a[k];
        inv->max_current_A[k] = p.max_a[k];
    }
    inv->mean_bus_current_A = p.bus_charge_c / period_s;
}
