/* Host port: pmstep_hal.h implemented on the plant model of sil/. */
#include "pmstep_hal_host.h"

static pmstep_hal_host_t port;

void pmstep_hal_host_bind(plant_t *plant, double bus_voltage_v, unsigned delay_periods)
{
    port.plant = plant;
    port.bus_voltage_v = bus_voltage_v;
    port.delay_periods = delay_periods;
    port.pending_a_v = 0.0;
    port.pending_b_v = 0.0;
    port.applied_a_v = 0.0;
    port.applied_b_v = 0.0;
    port.inverter_limited_periods = 0;
}

const pmstep_hal_host_t *pmstep_hal_host_state(void)
{
    return &port;
}

void pmstep_hal_read_measurements(pmstep_meas_t *meas)
{
    const plant_t *plant = port.plant;
    meas->i_a_a = (float)plant->x.i_a_a;
    meas->i_b_a = (float)plant->x.i_b_a;
    meas->bus_voltage_v = (float)port.bus_voltage_v;
    meas->load_torque_nm = (float)plant_load_torque(&plant->load, plant->time_s, plant->x.omega_rad_s);
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

void pmstep_hal_apply_output(const pmstep_output_t *out)
{
    const double u_a_v = out->bridge_enable ? (double)out->u_a_v : 0.0;
    const double u_b_v = out->bridge_enable ? (double)out->u_b_v : 0.0;
    double next_a_v = u_a_v;
    double next_b_v = u_b_v;
    int clipped = 0;
    if (port.delay_periods == 1u) {
        next_a_v = port.pending_a_v;
        next_b_v = port.pending_b_v;
        port.pending_a_v = u_a_v;
        port.pending_b_v = u_b_v;
        if (!out->bridge_enable) { /* a disabled bridge stops switching at once */
            next_a_v = 0.0;
            next_b_v = 0.0;
            port.pending_a_v = 0.0;
            port.pending_b_v = 0.0;
        }
    }
    port.applied_a_v = clip(next_a_v, port.bus_voltage_v, &clipped);
    port.applied_b_v = clip(next_b_v, port.bus_voltage_v, &clipped);
    if (clipped) {
        port.inverter_limited_periods++;
    }
}
