/* Host port: pmstep_hal.h implemented on the plant model and inverter of sil/. */
#include "pmstep_hal_host.h"

static pmstep_hal_host_t port;

void pmstep_hal_host_bind(plant_t *plant, double bus_voltage_v, unsigned delay_periods)
{
    port.plant = plant;
    sil_inverter_init(&port.inverter, bus_voltage_v, delay_periods);
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
    meas->bus_voltage_v = (float)port.inverter.bus_voltage_v;
    meas->load_torque_nm = (float)plant_load_torque(&plant->load, plant->time_s, plant->x.omega_rad_s);
}

void pmstep_hal_apply_output(const pmstep_output_t *out)
{
    sil_inverter_apply(&port.inverter, out);
}
