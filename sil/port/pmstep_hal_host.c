/* Host port: pmstep_hal.h implemented on the plant model, measurement chain and inverter of sil/. */
#include "pmstep_hal_host.h"

static pmstep_hal_host_t port;

int pmstep_hal_host_bind(plant_t *plant, const pmstep_hal_host_setup_t *setup)
{
    pmstep_hal_host_release();
    port.plant = plant;
    sil_inverter_init(&port.inverter, &setup->inverter, &setup->bus, setup->bus_voltage_v, setup->delay_periods);
    port.meas.i_a_a = 0.0f;
    port.meas.i_b_a = 0.0f;
    port.meas.bus_voltage_v = (float)setup->bus_voltage_v;
    port.meas.load_torque_nm = 0.0f;
    port.bus_v = setup->bus_voltage_v;
    return sil_sensors_init(&port.sensors, &setup->sensors, setup->seed);
}

void pmstep_hal_host_release(void)
{
    sil_sensors_release(&port.sensors);
}

const pmstep_hal_host_t *pmstep_hal_host_state(void)
{
    return &port;
}

sil_inverter_t *pmstep_hal_host_inverter(void)
{
    return &port.inverter;
}

/* Sampled at the period boundary: the carrier's valley, where every phase sees zero volts. */
void pmstep_hal_read_measurements(pmstep_meas_t *meas)
{
    const plant_t *plant = port.plant;
    double i_a_a, i_b_a;
    port.bus_v = sil_inverter_bus_voltage(&port.inverter, plant->time_s);
    sil_sensors_currents(&port.sensors, plant->x.i_a_a, plant->x.i_b_a, &i_a_a, &i_b_a);
    meas->i_a_a = (float)i_a_a;
    meas->i_b_a = (float)i_b_a;
    meas->bus_voltage_v = (float)sil_sensors_bus(&port.sensors, port.bus_v);
    meas->load_torque_nm = (float)plant_load_torque(&plant->load, plant->time_s, plant->x.omega_rad_s);
    port.meas = *meas;
}

/* The duty is the command over the bus voltage the core was given in this period. */
void pmstep_hal_apply_output(const pmstep_output_t *out)
{
    sil_inverter_apply(&port.inverter, out, (double)port.meas.bus_voltage_v);
}
