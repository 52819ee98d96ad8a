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
}

static double clip(double u_V, double limit_V, bool *clipped)
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
        u_a_V = clip((double)out->u_a_V, measured_bus_V, &clipped);
        u_b_V = clip((double)out->u_b_V, measured_bus_V, &clipped);
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

double sil_inverter_bus_voltage(const sil_inverter_t *inv, double t_s)
{
    double v = inv->nominal_bus_voltage_V;
    if (inv->bus.source_resistance_Ohm > 0.0) {
        v -= inv->bus.source_resistance_Ohm * inv->mean_bus_current_A;
    }
    if (inv->bus.ripple_V > 0.0) {
        v += inv->bus.ripple_V * sin(2.0 * PI * inv->bus.ripple_Hz * t_s);
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
    const sil_inverter_t *inv;
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
static double substep_bus_V(const period_t *p, double t_s, double h_s)
{
    return p->inv->bus.ripple_V > 0.0 ? sil_inverter_bus_voltage(p->inv, t_s + 0.5 * h_s) : p->bus_V;
}

/* One RK4 substep with u held. bus_fraction[k] = u_k / V_bus (for i_bus). A non-zero
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

/* Averaged bridge: u = d V_bus - 2 sign(i) V_bus t_d / T, sign at each substep's start. */
static void averaged(period_t *p, double period_s, int substeps)
{
    static const int no_diode[2] = {0, 0};
    const sil_inverter_t *inv = p->inv;
    const double h = period_s / (double)substeps;
    const double dead_fraction = 2.0 * inv->cfg.dead_time_s / period_s;
    const double command_V[2] = {inv->command_a_V, inv->command_b_V};
    const bool bus_ok = inv->command_bus_V > 0.0;
    int n, k;
    for (n = 0; n < substeps; ++n) {
        const double t = p->t0_s + (double)n * h;
        const double bus_V = substep_bus_V(p, t, h);
        /* d V_bus as u (V_bus / V_measured): exactly the command when the two agree. */
        const double ratio = bus_ok ? bus_V / inv->command_bus_V : 0.0;
        double u_V[2], fraction[2];
        for (k = 0; k < 2; ++k) {
            u_V[k] = command_V[k] * ratio;
            fraction[k] = bus_ok ? command_V[k] / inv->command_bus_V : 0.0;
            if (inv->cfg.dead_time_s > 0.0) {
                const int s = sign_of(*phase_current(p->plant, k));
                if (s != 0) {
                    u_V[k] -= (double)s * bus_V * dead_fraction;
                    fraction[k] -= (double)s * dead_fraction;
                }
            }
        }
        substep(p, t, h, u_V, fraction, no_diode);
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

/* Switching bridge: constant phase voltages between the sorted edges of both phases. */
static void switching(period_t *p, double period_s, int substeps)
{
    static const int no_diode[2] = {0, 0};
    const sil_inverter_t *inv = p->inv;
    const double command_V[2] = {inv->command_a_V, inv->command_b_V};
    const double h_max = period_s / (double)substeps;
    window_t legs[2][2]; /* [phase][leg A, leg B] */
    double edges[EDGES_MAX];
    int n_edges = 0;
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
        const double start_s = edges[j];
        const double length_s = edges[j + 1] - start_s;
        const double mid_s = start_s + 0.5 * length_s;
        double level[2];
        int count;
        double h;
        if (!(length_s > 0.0)) {
            continue;
        }
        for (k = 0; k < 2; ++k) {
            level[k] = (double)(leg_high(&legs[k][0], mid_s) - leg_high(&legs[k][1], mid_s));
        }
        count = (int)ceil(length_s / h_max - 1e-9);
        if (count < 1) {
            count = 1;
        }
        h = length_s / (double)count;
        for (m = 0; m < count; ++m) {
            const double t = p->t0_s + start_s + (double)m * h;
            const double bus_V = substep_bus_V(p, t, h);
            const double u_V[2] = {level[0] * bus_V, level[1] * bus_V};
            substep(p, t, h, u_V, level, no_diode);
        }
    }
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
            switching(&p, period_s, substeps);
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
