/* Switching model of the bridge (see inverter.h): each leg's edges within the period, the dead time
 * after each edge with the current's sign at that edge, and the plant advanced over the segments
 * between the edges, in one exponential step or in substeps. */
#include <math.h>
#include <stddef.h>

#include "inverter_internal.h"

#define EDGES_MAX 18  /* 0, T and, for each of four legs, its two edges and the ends of their dead times */
#define SIGN_PASSES 3 /* passes over a period at most, until the signs at its edges agree with its currents */

/* A leg's nominal window, centred on mid-period: high from on_s to off_s. A leg that does not
 * switch (width 0 or T) stays at its level all period and has no dead time. */
typedef struct {
    double on_s, off_s;
    bool switches;
    double level_still; /* its level (0 or 1) when it does not switch */
} leg_t;

/* The current's direction out of each leg at its edges, -1, 0 or +1: [phase][leg A, leg B][on, off].
 * Leg A carries +i out to the winding, leg B -i. */
typedef struct {
    int out[2][2][2];
} edge_signs_t;

typedef struct {
    leg_t legs[2][2]; /* [phase][leg A, leg B] */
    int n;            /* segments */
    double start_s[EDGES_MAX], end_s[EDGES_MAX];
    double level[EDGES_MAX][2];   /* phase voltage over V_bus on each segment: -1, 0 or +1 */
    double i_end_A[EDGES_MAX][2]; /* the phase currents at each segment's end, once integrated */
} segments_t;

static leg_t nominal_leg(double width_s, double period_s)
{
    leg_t leg;
    leg.on_s = 0.5 * (period_s - width_s);
    leg.off_s = 0.5 * (period_s + width_s);
    leg.switches = width_s > 0.0 && width_s < period_s;
    leg.level_still = width_s >= period_s ? 1.0 : 0.0;
    return leg;
}

/* Level of a leg at t (1 high, 0 low). For t_d after each edge both its switches are off and the
 * freewheel diode of the current's direction at that edge sets the level: low for a current out
 * of the leg, high for one into it; a zero current leaves the leg at its commanded level. */
static double leg_level(const leg_t *leg, double t_s, double dead_time_s, const int out[2])
{
    if (!leg->switches) {
        return leg->level_still;
    }
    if (t_s >= leg->on_s && t_s < leg->off_s && t_s < leg->on_s + dead_time_s) {
        return out[0] > 0 ? 0.0 : 1.0;
    }
    if (t_s >= leg->off_s && t_s < leg->off_s + dead_time_s) {
        return out[1] < 0 ? 1.0 : 0.0;
    }
    return (t_s >= leg->on_s && t_s < leg->off_s) ? 1.0 : 0.0;
}

/* The period's segments between the sorted edges of both phases (zero-length ones left out),
 * with each phase's level on each. */
static void build_segments(const sil_inv_period_t *p, double period_s, const edge_signs_t *signs, segments_t *seg)
{
    const sil_inverter_t *inv = p->inv;
    const double command_V[2] = {inv->command_a_V, inv->command_b_V};
    const double dead_time_s = inv->cfg.dead_time_s;
    double edges[EDGES_MAX];
    int n_edges = 0;
    int j, k, m;
    edges[n_edges++] = 0.0;
    edges[n_edges++] = period_s;
    for (k = 0; k < 2; ++k) {
        double d = inv->command_bus_V > 0.0 ? command_V[k] / inv->command_bus_V : 0.0;
        d = fmax(-1.0, fmin(1.0, d));
        seg->legs[k][0] = nominal_leg(0.5 * (1.0 + d) * period_s, period_s);
        seg->legs[k][1] = nominal_leg(0.5 * (1.0 - d) * period_s, period_s);
        for (j = 0; j < 2; ++j) {
            const leg_t *leg = &seg->legs[k][j];
            if (leg->switches) {
                edges[n_edges++] = leg->on_s;
                edges[n_edges++] = fmin(leg->on_s + dead_time_s, period_s);
                edges[n_edges++] = leg->off_s;
                edges[n_edges++] = fmin(leg->off_s + dead_time_s, period_s);
            }
        }
    }
    for (j = 1; j < n_edges; ++j) { /* insertion sort */
        const double e = edges[j];
        for (m = j; m > 0 && edges[m - 1] > e; --m) {
            edges[m] = edges[m - 1];
        }
        edges[m] = e;
    }
    seg->n = 0;
    for (j = 0; j + 1 < n_edges; ++j) {
        const double mid_s = 0.5 * (edges[j] + edges[j + 1]);
        if (!(edges[j + 1] > edges[j])) {
            continue;
        }
        seg->start_s[seg->n] = edges[j];
        seg->end_s[seg->n] = edges[j + 1];
        for (k = 0; k < 2; ++k) {
            seg->level[seg->n][k] = leg_level(&seg->legs[k][0], mid_s, dead_time_s, signs->out[k][0])
                                    - leg_level(&seg->legs[k][1], mid_s, dead_time_s, signs->out[k][1]);
        }
        ++seg->n;
    }
}

/* Every edge with the current's sign at the period start. */
static void signs_at_start(plant_t *plant, edge_signs_t *signs)
{
    int k, e;
    for (k = 0; k < 2; ++k) {
        const int s = sil_inv_sign_of(*sil_inv_phase_current(plant, k));
        for (e = 0; e < 2; ++e) {
            signs->out[k][0][e] = s;
            signs->out[k][1][e] = -s;
        }
    }
}

/* The current at a switching edge: every one ends a segment (it is in the sorted edge list, after
 * 0, and the segment before it has a length), so the loop finds it. */
static double current_at(const segments_t *seg, int k, double t_s)
{
    int j;
    for (j = 0; j < seg->n; ++j) {
        if (seg->end_s[j] == t_s) {
            return seg->i_end_A[j][k];
        }
    }
    return seg->i_end_A[seg->n - 1][k];
}

/* The signs at the edges from the currents a pass integrated; true if any changed. With
 * @p last_pass, a sign that changed again is taken as zero: that edge's current turns with
 * the dead time's own sign, so it sits at zero there. */
static bool signs_at_edges(const segments_t *seg, edge_signs_t *signs, bool last_pass)
{
    bool changed = false;
    int k, j, e;
    for (k = 0; k < 2; ++k) {
        for (j = 0; j < 2; ++j) {
            const leg_t *leg = &seg->legs[k][j];
            if (!leg->switches) {
                continue;
            }
            for (e = 0; e < 2; ++e) {
                const int s = sil_inv_sign_of(current_at(seg, k, e == 0 ? leg->on_s : leg->off_s));
                const int out = j == 0 ? s : -s;
                if (signs->out[k][j][e] != out) {
                    signs->out[k][j][e] = last_pass ? 0 : out;
                    changed = true;
                }
            }
        }
    }
    return changed;
}

/* Segment by segment: constant phase voltages between the edges, in steps of at most T / substeps. */
static void segment_steps(sil_inv_period_t *p, double period_s, int substeps, segments_t *seg)
{
    static const int no_diode[2] = {0, 0};
    const double h_max = period_s / (double)substeps;
    int j, m, k;
    for (j = 0; j < seg->n; ++j) {
        const double length = seg->end_s[j] - seg->start_s[j];
        int count = (int)ceil(length / h_max - 1e-9);
        double h;
        if (count < 1) {
            count = 1;
        }
        h = length / (double)count;
        for (m = 0; m < count; ++m) {
            const double t = p->t0_s + seg->start_s[j] + (double)m * h;
            const double bus_V = sil_inv_substep_bus_V(p, t, h);
            const double u_V[2] = {seg->level[j][0] * bus_V, seg->level[j][1] * bus_V};
            sil_inv_substep(p, t, h, u_V, seg->level[j], no_diode);
        }
        for (k = 0; k < 2; ++k) {
            seg->i_end_A[j][k] = *sil_inv_phase_current(p->plant, k);
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
static void one_step(sil_inv_period_t *p, double period_s, segments_t *seg)
{
    plant_t *plant = p->plant;
    const double inv_l = 1.0 / plant->params.inductance_H;
    const double lambda = -plant->params.resistance_Ohm * inv_l;
    const double to_offset = inv_l / lambda; /* voltage to minus the steady ripple current (A/V) */
    const double inv_t = 1.0 / period_s;
    const double t0 = p->t0_s;
    const double bus_V = sil_inv_substep_bus_V(p, t0, period_s);
    const int n = seg->n;
    double seg_r_end[EDGES_MAX][2], seg_r_int[EDGES_MAX][2];
    double u_mean[2] = {0.0, 0.0}, r[2] = {0.0, 0.0}, m0[2] = {0.0, 0.0}, m1[2] = {0.0, 0.0}, m2[2] = {0.0, 0.0};
    double i0[2], q_c[2], i_mid[2], i_end[2];
    bool constant[2] = {true, true};
    int j, k;
    for (j = 0; j < n; ++j) {
        for (k = 0; k < 2; ++k) {
            u_mean[k] += seg->level[j][k] * bus_V * (seg->end_s[j] - seg->start_s[j]) * inv_t;
            if (seg->level[j][k] != seg->level[0][k]) {
                constant[k] = false;
            }
        }
    }
    for (j = 0; j < n; ++j) {
        const double length = seg->end_s[j] - seg->start_s[j];
        const double e_half = exp_small(0.5 * lambda * length);
        const double e_full = e_half * e_half;
        const double ts = seg->start_s[j], tm = ts + 0.5 * length, te = seg->end_s[j];
        for (k = 0; k < 2; ++k) {
            const double offset = (seg->level[j][k] * bus_V - u_mean[k]) * to_offset; /* -steady state */
            const double rs = r[k];
            const double rm = (rs + offset) * e_half - offset;
            const double re = (rs + offset) * e_full - offset;
            const double w = length / 6.0;
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
        i0[k] = *sil_inv_phase_current(plant, k);
    }
    plant_substep(plant, t0, period_s, u_mean[0], u_mean[1], &q_c[0], &q_c[1]);
    for (k = 0; k < 2; ++k) {
        double *extra = k == 0 ? plant->torque_extra_a_a : plant->torque_extra_b_a;
        extra[0] = extra[1] = extra[2] = 0.0;
        i_end[k] = *sil_inv_phase_current(plant, k);
        /* i-bar at mid-period from Simpson's charge: Q = T/6 (i0 + 4 i_mid + i_end). */
        i_mid[k] = 0.25 * (6.0 * q_c[k] * inv_t - i0[k] - i_end[k]);
        *sil_inv_phase_current(plant, k) = i_end[k] + r[k];
    }
    /* Bookkeeping of the period, as substep() keeps it. */
    for (k = 0; k < 2; ++k) {
        /* i-bar(t) = c0 + c1 t + c2 t^2 through (0, i0), (T/2, i_mid), (T, i_end). */
        const double c0 = i0[k];
        const double c2 = 2.0 * (i_end[k] - 2.0 * i_mid[k] + i0[k]) * inv_t * inv_t;
        const double c1 = (i_end[k] - i0[k]) * inv_t - c2 * period_s;
        p->volt_s[k] += u_mean[k] * period_s;
        p->charge_c[k] += q_c[k] + m0[k];
        p->first_u_V[k] = n > 0 ? seg->level[0][k] * bus_V : 0.0;
        for (j = 0; j < n; ++j) {
            const double a = seg->start_s[j], b = seg->end_s[j];
            const double bar_int =
                c0 * (b - a) + 0.5 * c1 * (b * b - a * a) + c2 * (1.0 / 3.0) * (b * b * b - a * a * a);
            const double at_end = c0 + c1 * b + c2 * b * b + seg_r_end[j][k];
            seg->i_end_A[j][k] = at_end;
            p->bus_charge_c += seg->level[j][k] * (bar_int + seg_r_int[j][k]);
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

void sil_inv_switching_period(sil_inv_period_t *p, double period_s, int substeps, bool one_step_period)
{
    const plant_t plant_start = *p->plant;
    const sil_inv_period_t period_start = *p;
    /* Without dead time the signs at the edges set no level: one pass. */
    const int passes = p->inv->cfg.dead_time_s > 0.0 ? SIGN_PASSES : 1;
    segments_t seg;
    edge_signs_t signs;
    int pass;
    signs_at_start(p->plant, &signs);
    for (pass = 1;; ++pass) {
        build_segments(p, period_s, &signs, &seg);
        if (one_step_period) {
            one_step(p, period_s, &seg);
        } else {
            segment_steps(p, period_s, substeps, &seg);
        }
        if (pass == passes || !signs_at_edges(&seg, &signs, pass + 1 == passes)) {
            break;
        }
        /* A current changed sign before an edge: the period again, with the signs this pass found. */
        *p->plant = plant_start;
        *p = period_start;
    }
}
