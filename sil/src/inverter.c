/* Averaged inverter: held phase voltage, optional one-period delay, +/- bus limit. */
#include "sil/inverter.h"

void sil_inverter_init(sil_inverter_t *inv, double bus_voltage_v, unsigned delay_periods)
{
    inv->bus_voltage_v = bus_voltage_v;
    inv->delay_periods = delay_periods;
    inv->pending_a_v = 0.0;
    inv->pending_b_v = 0.0;
    inv->applied_a_v = 0.0;
    inv->applied_b_v = 0.0;
    inv->limited_periods = 0;
}

static double clip(double u_v, double limit_v, int *clipped)
{
    if (u_v > limit_v) {
        *clipped = 1;
        return limit_v;
    }
    if (u_v < -limit_v) {
        *clipped = 1;
        return -limit_v;
    }
    return u_v;
}

void sil_inverter_apply(sil_inverter_t *inv, const pmstep_output_t *out)
{
    const double u_a_v = out->bridge_enable ? (double)out->u_a_v : 0.0;
    const double u_b_v = out->bridge_enable ? (double)out->u_b_v : 0.0;
    double next_a_v = u_a_v;
    double next_b_v = u_b_v;
    int clipped = 0;
    if (inv->delay_periods == 1u) {
        /* A disabled bridge stops switching at once: nothing stays pending. */
        next_a_v = out->bridge_enable ? inv->pending_a_v : 0.0;
        next_b_v = out->bridge_enable ? inv->pending_b_v : 0.0;
        inv->pending_a_v = u_a_v;
        inv->pending_b_v = u_b_v;
    }
    inv->applied_a_v = clip(next_a_v, inv->bus_voltage_v, &clipped);
    inv->applied_b_v = clip(next_b_v, inv->bus_voltage_v, &clipped);
    if (clipped) {
        inv->limited_periods++;
    }
}
