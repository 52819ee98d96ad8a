/* The DC bus voltage (sag, ripple) and one substep of the plant within a control period with
 * its sums (see inverter_internal.h): shared by the averaged model and bridge-off freewheeling
 * (inverter.c) and the switching model (inverter_switching.c), which call in here and never
 * back. */
#include "inverter_internal.h"

#include <math.h>

#define PI 3.14159265358979323846

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

int sil_inv_sign_of(double x)
{
    return (x > 0.0) - (x < 0.0);
}

double *sil_inv_phase_current(plant_t *plant, int k)
{
    return k == 0 ? &plant->x.i_a_A : &plant->x.i_b_A;
}

bool *sil_inv_phase_open(plant_t *plant, int k)
{
    return k == 0 ? &plant->open_a : &plant->open_b;
}

/* Bus voltage held over the substep [t, t + h]: at its midpoint when there is ripple. */
double sil_inv_substep_bus_V(sil_inv_period_t *p, double t_s, double h_s)
{
    return p->inv->bus.ripple_V > 0.0 ? sil_inverter_bus_voltage(p->inv, t_s + 0.5 * h_s) : p->bus_V;
}

/* One step of the plant's integrator with u held. bus_fraction[k] = u_k / V_bus (for i_bus). A non-zero
 * diode_sign[k] marks a phase conducting through the freewheel diodes: if its current
 * reaches or crosses zero within the substep it is set to exactly 0 and the phase opens. */
void sil_inv_substep(sil_inv_period_t *p, double t_s, double h_s, const double u_V[2], const double bus_fraction[2],
                     const int diode_sign[2])
{
    plant_t *plant = p->plant;
    double q_c[2];
    int k;
    plant_substep(plant, t_s, h_s, u_V[0], u_V[1], &q_c[0], &q_c[1]);
    for (k = 0; k < 2; ++k) {
        double *i_a = sil_inv_phase_current(plant, k);
        if (diode_sign[k] != 0 && sil_inv_sign_of(*i_a) != diode_sign[k]) {
            *i_a = 0.0;
            *sil_inv_phase_open(plant, k) = true;
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
