/* Inverter and DC bus (see inverter.h): the MCU's duty, the bridge's phase voltages in the
 * averaged and switching models, dead time, freewheeling with the bridge off, bus sag and
 * ripple, and the plant advanced over one control period through them. */
#include "sil/inverter.h"

#include <math.h>
#include <stddef.h>

#define PI 3.14159265358979323846
#define EDGES_MAX 10 /* 0, T and two edges per leg, two legs per phase, two phases */

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

/* sin(2 pi f t) of the ripple, from the memo when (t, f) is one of its two entries. */
static double ripple_sin(sil_inverter_t *inv, double t_s)
{
    const double hz = inv->bus.ripple_Hz;
    unsigned k;
    for (k = 0; k < 2u; ++k) {
        if (inv->ripple_memo_t_s[k] == t_s && inv->ripple_memo_hz[k] == hz) {
            return inv->ripple_memo_sin[k];
        }
    }
    k = inv->ripple_memo_next & 1u;
    inv->ripple_memo_next = k ^ 1u;
    inv->ripple_memo_t_s[k] = t_s;
    inv->ripple_memo_hz[k] = hz;
    inv->ripple_memo_sin[k] = sin(2.0 * PI * hz * t_s);
    return inv->ripple_memo_sin[k];
}

double sil_inverter_bus_voltage(sil_inverter_t *inv, double t_s)
{
    double v = inv->nominal_bus_voltage_V;
    if (inv->bus.source_resistance_Ohm > 0.0) {
        v -= inv->bus.source_resistance_Ohm * inv->mean_bus_current_A;
    }
    if (inv->bus.ripple_V > 0.0) {
        v += inv->bus.ripple_V * ripple_sin(inv, t_s);
    }
    return v > 0.0 ? v : 0.0;
}

static int sign_of(double x)
{
    return (x > 0.0) - (x < 0.0);
}

/* Sums over one period. */
typedef struct {
    plant_t *plant;
    sil_inverter_t *inv;
    double t0_s;
    double bus_V;          /* bus voltage at the period start (held over the period without ripple) */
    bool started;
    bool constant_u;       /* every substep had the first substep's voltages */
    double first_u_V[2];
    double volt_s[2];      /* integral of the phase voltages */
    double charge_c[2];    /* integral of the phase currents */
    double bus_charge_c;   /* integral of i_bus */
    double min_a[2], max_a[2];
} period_t;

static double *phase_current(plant_t *plant, int k)
{
    return k == 0 ? &plant->x.i_a_A : &plant->x.i_b_A;
}

static bool *phase_open(plant_t *plant, int k)
{
    return k == 0 ? &plant->open_a : &plant->open_b;
}

/* Bus voltage held over the substep [t, t + h]: at its midpoint when there is ripple. */
static double substep_bus_V(period_t *p, double t_s, double h_s)
{
    return p->inv->bus.ripple_V > 0.0 ? sil_inverter_bus_voltage(p->inv, t_s + 0.5 * h_s) : p->bus_V;
}

/* One step of the plant's integrator with u held. bus_fraction[k] = u_k / V_bus (for i_bus). A non-zero
 * diode_sign[k] marks a phase conducting through the freewheel diodes: if its current
 * reaches or crosses zero within the substep it is set to exactly 0 and the phase opens. */
static void substep(period_t *p, double t_s, double h_s, const double u_V[2], const double bus_fraction[2],
                    const int diode_sign[2])
{
    plant_t *plant = p->plant;
    double q_c[2];
    int k;
    plant_substep(plant, t_s, h_s, u_V[0], u_V[1], &q_c[0], &q_c[1]);
    for (k = 0; k < 2; ++k) {
        double *i_a = phase_current(plant, k);
        if (diode_sign[k] != 0 && sign_of(*i_a) != diode_sign[k]) {
            *i_a = 0.0;
            *phase_open(plant, k) = true;
        }
        p->charge_c[k] += q_c[k];
        p->bus_charge_c += bus_fraction[k] * q_c[k];
        p->volt_s[k] += u_V[k] * h_s;
        if (!p->started) {
            p->first_u_V[k] = u_V[k];
        } else if (u_V[k] != p->first_u_V[k]) {
            p->constant_u = false;
        }
        if (*i_a < p->min_a[k]) {
            p->min_a[k] = *i_a;
        } else if (*i_a > p->max_a[k]) {
            p->max_a[k] = *i_a;
        }
    }
    p->started = true;
}

/* Bridge off: freewheel diodes while a phase carries current, open once it is zero. */
static void freewheel(period_t *p, double period_s, int substeps)
{
    const double h = period_s / (double)substeps;
    int n, k;
    for (n = 0; n < substeps; ++n) {
        const double t = p->t0_s + (double)n * h;
        const double bus_V = substep_bus_V(p, t, h);
        double u_V[2], fraction[2];
        int diode[2];
        for (k = 0; k < 2; ++k) {
            bool *open = phase_open(p->plant, k);
            const int s = *open ? 0 : sign_of(*phase_current(p->plant, k));
            if (s == 0) {
                *open = true;
            }
            u_V[k] = s == 0 ? 0.0 : -(double)s * bus_V; /* +0 for an open phase, as the bridge-off voltage was */
            fraction[k] = s == 0 ? 0.0 : -(double)s;
            diode[k] = s;
        }
        substep(p, t, h, u_V, fraction, diode);
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
        return sign_of(i_a);
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

#define DEAD_TIME_EVENTS_MAX 8   /* zero crossings located per substep */
#define CROSSING_REFINEMENTS 3   /* regula falsi steps on the crossing time */

/* Averaged bridge: u = d V_bus - 2 sign(i) V_bus t_d / T. With dead time the voltage jumps
 * where a current crosses zero: the substep is cut at the crossing (located by regula falsi
 * on re-integrations from the substep's start), the current set to exactly 0 there, and the
 * rest integrated on the branch it leaves into. A current that neither branch drives away
 * from zero stays at zero (the dead time's zero-current clamp): the phase is held open
 * until a later substep finds a branch. */
static void averaged(period_t *p, double period_s, int substeps)
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
        const double bus_V = substep_bus_V(p, t, h);
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
            substep(p, t, h, u0_v, fraction0, no_diode);
            continue;
        }
        while (done_s < h) {
            const double rest_s = h - done_s;
            const plant_state_t start = plant->x;
            double u_V[2], fraction[2];
            int branch[2];
            double cut_s = rest_s;
            int crossing = -1;
            period_t saved;
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
                *phase_open(plant, k) = branch[k] == 0;
            }
            /* The rest of the substep; undone if a current crossed zero within it. */
            saved = *p;
            substep(p, t + done_s, rest_s, u_V, fraction, no_diode);
            if (events < DEAD_TIME_EVENTS_MAX) {
                double lo_s = 0.0, hi_s = rest_s;
                double i_lo[2], i_hi[2];
                for (k = 0; k < 2; ++k) {
                    i_lo[k] = k == 0 ? start.i_a_A : start.i_b_A;
                    i_hi[k] = *phase_current(plant, k);
                    if (branch[k] != 0 && sign_of(i_hi[k]) != branch[k]) {
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
                        i_cut = *phase_current(plant, crossing);
                        if (sign_of(i_cut) == branch[crossing]) {
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
                    substep(p, t + done_s, cut_s, u_V, fraction, no_diode);
                    *phase_current(plant, crossing) = 0.0;
                    ++events;
                }
            }
            done_s = crossing >= 0 ? done_s + cut_s : h;
        }
        plant->open_a = false;
        plant->open_b = false;
    }
}

/* When a leg is high within the period: (on_s, off_s), empty if on_s >= off_s. */
typedef struct {
    double on_s, off_s;
} window_t;

/* Leg high for width_s centred on mid-period. current_out: +1 the leg's current flows out
 * of it (turn-on delayed by t_d), -1 into it (turn-off delayed), 0 no current. */
static window_t leg_window(double width_s, double period_s, int current_out, double dead_time_s)
{
    window_t w;
    if (!(width_s > 0.0)) {
        w.on_s = period_s; /* never switched on */
        w.off_s = period_s;
        return w;
    }
    if (width_s >= period_s) {
        w.on_s = 0.0; /* never switched off: no edge, no dead time */
        w.off_s = period_s;
        return w;
    }
    w.on_s = 0.5 * (period_s - width_s);
    w.off_s = 0.5 * (period_s + width_s);
    if (current_out > 0) {
        w.on_s += dead_time_s;
    } else if (current_out < 0) {
        w.off_s += dead_time_s;
    }
    if (w.off_s > period_s) {
        w.off_s = period_s;
    }
    return w;
}

static int leg_high(const window_t *w, double t_s)
{
    return t_s > w->on_s && t_s < w->off_s;
}

/* The period's segments between the sorted edges of both phases: start, length and the level
 * (-1, 0, +1) of each phase on each. Returns their number (zero-length segments left out). */
static int switching_segments(const period_t *p, double period_s, double start_s[EDGES_MAX],
                              double length_s[EDGES_MAX], double level[EDGES_MAX][2])
{
    const sil_inverter_t *inv = p->inv;
    const double command_V[2] = {inv->command_a_V, inv->command_b_V};
    window_t legs[2][2]; /* [phase][leg A, leg B] */
    double edges[EDGES_MAX];
    int n_edges = 0, n = 0;
    int j, k, m;
    edges[n_edges++] = 0.0;
    edges[n_edges++] = period_s;
    for (k = 0; k < 2; ++k) {
        double d = inv->command_bus_V > 0.0 ? command_V[k] / inv->command_bus_V : 0.0;
        const int s = sign_of(*phase_current(p->plant, k)); /* held for the whole period */
        d = fmax(-1.0, fmin(1.0, d));
        legs[k][0] = leg_window(0.5 * (1.0 + d) * period_s, period_s, s, inv->cfg.dead_time_s);  /* carries +i */
        legs[k][1] = leg_window(0.5 * (1.0 - d) * period_s, period_s, -s, inv->cfg.dead_time_s); /* carries -i */
        for (j = 0; j < 2; ++j) {
            edges[n_edges++] = fmin(legs[k][j].on_s, period_s);
            edges[n_edges++] = fmin(legs[k][j].off_s, period_s);
        }
    }
    for (j = 1; j < n_edges; ++j) { /* insertion sort */
        const double e = edges[j];
        for (m = j; m > 0 && edges[m - 1] > e; --m) {
            edges[m] = edges[m - 1];
        }
        edges[m] = e;
    }
    for (j = 0; j + 1 < n_edges; ++j) {
        const double length = edges[j + 1] - edges[j];
        const double mid_s = edges[j] + 0.5 * length;
        if (!(length > 0.0)) {
            continue;
        }
        start_s[n] = edges[j];
        length_s[n] = length;
        for (k = 0; k < 2; ++k) {
            level[n][k] = (double)(leg_high(&legs[k][0], mid_s) - leg_high(&legs[k][1], mid_s));
        }
        ++n;
    }
    return n;
}

/* Switching bridge, segment by segment: constant phase voltages between the edges, in steps of
 * at most T / substeps. */
static void switching(period_t *p, double period_s, int substeps)
{
    static const int no_diode[2] = {0, 0};
    const double h_max = period_s / (double)substeps;
    double start[EDGES_MAX], length[EDGES_MAX], level[EDGES_MAX][2];
    const int n = switching_segments(p, period_s, start, length, level);
    int j, m;
    for (j = 0; j < n; ++j) {
        int count = (int)ceil(length[j] / h_max - 1e-9);
        double h;
        if (count < 1) {
            count = 1;
        }
        h = length[j] / (double)count;
        for (m = 0; m < count; ++m) {
            const double t = p->t0_s + start[j] + (double)m * h;
            const double bus_V = substep_bus_V(p, t, h);
            const double u_V[2] = {level[j][0] * bus_V, level[j][1] * bus_V};
            substep(p, t, h, u_V, level[j], no_diode);
        }
    }
}

/* e^x, by its series for the small |x| of a segment (no libm call), else exp(). */
static double exp_small(double x)
{
    if (fabs(x) < 0.05) { /* x^7 / 7! < 2e-16 */
        return 1.0 + x * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x / 720.0)))));
    }
    return exp(x);
}

/* Switching bridge in one exponential step a period. The currents are linear in the voltage,
 * so i = i-bar + r: i-bar under the period's mean voltage u-bar (one step of the exponential
 * integrator, with the back EMF and the mechanics), and the PWM ripple r, r' = -(R/L) r +
 * (u - u-bar)/L, r(0) = 0, solved exactly segment by segment. The ripple's torque enters the
 * step through the projection of r onto quadratics over the period (its exact moments of
 * order 0, 1, 2, by Simpson's rule on each segment), so the torque's integral against the
 * slowly turning sin, cos of p theta is kept. At the end i = i-bar + r(T). The mean currents,
 * the bus current and the currents at the segment ends come from i-bar's quadratic through
 * its start, middle and end, plus r. */
static void switching_one_step(period_t *p, double period_s)
{
    plant_t *plant = p->plant;
    const double inv_l = 1.0 / plant->params.inductance_H;
    const double lambda = -plant->params.resistance_Ohm * inv_l;
    const double to_offset = inv_l / lambda;  /* voltage to minus the steady ripple current (A/V) */
    const double inv_t = 1.0 / period_s;
    const double t0 = p->t0_s;
    const double bus_V = substep_bus_V(p, t0, period_s);
    double start[EDGES_MAX], length[EDGES_MAX], level[EDGES_MAX][2];
    double seg_r_end[EDGES_MAX][2], seg_r_int[EDGES_MAX][2];
    double u_mean[2] = {0.0, 0.0}, r[2] = {0.0, 0.0}, m0[2] = {0.0, 0.0}, m1[2] = {0.0, 0.0}, m2[2] = {0.0, 0.0};
    double i0[2], q_c[2], i_mid[2], i_end[2];
    bool constant[2] = {true, true};
    const int n = switching_segments(p, period_s, start, length, level);
    int j, k;
    for (j = 0; j < n; ++j) {
        for (k = 0; k < 2; ++k) {
            u_mean[k] += level[j][k] * bus_V * length[j] * inv_t;
            if (level[j][k] != level[0][k]) {
                constant[k] = false;
            }
        }
    }
    for (j = 0; j < n; ++j) {
        const double e_half = exp_small(0.5 * lambda * length[j]);
        const double e_full = e_half * e_half;
        const double ts = start[j], tm = start[j] + 0.5 * length[j], te = start[j] + length[j];
        for (k = 0; k < 2; ++k) {
            const double offset = (level[j][k] * bus_V - u_mean[k]) * to_offset; /* -steady state */
            const double rs = r[k];
            const double rm = (rs + offset) * e_half - offset;
            const double re = (rs + offset) * e_full - offset;
            const double w = length[j] / 6.0;
            seg_r_int[j][k] = w * (rs + 4.0 * rm + re);
            m0[k] += seg_r_int[j][k];
            m1[k] += w * (rs * ts + 4.0 * rm * tm + re * te);
            m2[k] += w * (rs * ts * ts + 4.0 * rm * tm * tm + re * te * te);
            seg_r_end[j][k] = re;
            r[k] = re;
        }
    }
    for (k = 0; k < 2; ++k) {
        /* Legendre coefficients on [0, T], x = 2 t/T - 1: q = a0 + a1 x + a2 (3 x^2 - 1)/2. */
        const double int_x = 2.0 * inv_t * m1[k] - m0[k];
        const double int_x2 = 4.0 * inv_t * inv_t * m2[k] - 4.0 * inv_t * m1[k] + m0[k];
        const double a0 = m0[k] * inv_t;
        const double a1 = 3.0 * int_x * inv_t;
        const double a2 = 2.5 * (3.0 * int_x2 - m0[k]) * inv_t;
        double *extra = k == 0 ? plant->torque_extra_a_a : plant->torque_extra_b_a;
        extra[0] = a0 - a1 + a2;
        extra[1] = a0 - 0.5 * a2;
        extra[2] = a0 + a1 + a2;
        i0[k] = *phase_current(plant, k);
    }
    plant_substep(plant, t0, period_s, u_mean[0], u_mean[1], &q_c[0], &q_c[1]);
    for (k = 0; k < 2; ++k) {
        double *extra = k == 0 ? plant->torque_extra_a_a : plant->torque_extra_b_a;
        extra[0] = extra[1] = extra[2] = 0.0;
        i_end[k] = *phase_current(plant, k);
        /* i-bar at mid-period from Simpson's charge: Q = T/6 (i0 + 4 i_mid + i_end). */
        i_mid[k] = 0.25 * (6.0 * q_c[k] * inv_t - i0[k] - i_end[k]);
        *phase_current(plant, k) = i_end[k] + r[k];
    }
    /* Bookkeeping of the period, as substep() keeps it. */
    for (k = 0; k < 2; ++k) {
        /* i-bar(t) = c0 + c1 t + c2 t^2 through (0, i0), (T/2, i_mid), (T, i_end). */
        const double c0 = i0[k];
        const double c2 = 2.0 * (i_end[k] - 2.0 * i_mid[k] + i0[k]) * inv_t * inv_t;
        const double c1 = (i_end[k] - i0[k]) * inv_t - c2 * period_s;
        p->volt_s[k] += u_mean[k] * period_s;
        p->charge_c[k] += q_c[k] + m0[k];
        p->first_u_V[k] = n > 0 ? level[0][k] * bus_V : 0.0;
        for (j = 0; j < n; ++j) {
            const double a = start[j], b = start[j] + length[j];
            const double bar_int = c0 * (b - a) + 0.5 * c1 * (b * b - a * a) + c2 * (1.0 / 3.0) * (b * b * b - a * a * a);
            const double at_end = c0 + c1 * b + c2 * b * b + seg_r_end[j][k];
            p->bus_charge_c += level[j][k] * (bar_int + seg_r_int[j][k]);
            if (at_end < p->min_a[k]) {
                p->min_a[k] = at_end;
            } else if (at_end > p->max_a[k]) {
                p->max_a[k] = at_end;
            }
        }
        if (!constant[k]) {
            p->constant_u = false;
        }
    }
    p->started = true;
}

void sil_drive_advance(plant_t *plant, sil_inverter_t *inv, double period_s, int substeps)
{
    period_t p;
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
        p.min_a[k] = *phase_current(plant, k);
        p.max_a[k] = p.min_a[k];
    }
    if (!inv->bridge_enable) {
        freewheel(&p, period_s, substeps);
    } else {
        plant->open_a = false;
        plant->open_b = false;
        if (inv->cfg.model == SIL_INVERTER_SWITCHING) {
            const plant_load_t *load = &plant->load;
            const bool load_step_inside = load->kind == PLANT_LOAD_STEP && p.t0_s < load->step_time_s
                                          && load->step_time_s <= p.t0_s + period_s;
            if (substeps == 1 && plant->integrator == PLANT_INTEGRATOR_EXPONENTIAL && !load_step_inside) {
                switching_one_step(&p, period_s);
            } else {
                switching(&p, period_s, substeps);
            }
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
