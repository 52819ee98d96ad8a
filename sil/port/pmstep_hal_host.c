/* Host port: pmstep_hal.h implemented on the plant model, measurement chain and inverter of sil/. */
#include "pmstep_hal_host.h"

static pmstep_hal_host_t port;

int pmstep_hal_host_bind(plant_t *plant, const pmstep_hal_host_setup_t *setup)
{
    pmstep_hal_host_release();
    port.plant = plant;
    port.faults = setup->faults;
    sil_inverter_init(&port.inverter, &setup->inverter, &setup->bus, setup->bus_voltage_V, setup->delay_periods);
    port.meas.i_a_A = 0.0f;
    port.meas.i_b_A = 0.0f;
    port.meas.bus_voltage_V = (float)setup->bus_voltage_V;
    port.meas.load_torque_Nm = 0.0f;
    port.meas.phase_voltage_a_V = 0.0f;
    port.meas.phase_voltage_b_V = 0.0f;
    port.bus_V = setup->bus_voltage_V;
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

/* An open winding from its time on (sil/faults.h): its current cut to 0 once, then held there by the
 * plant whatever the bridge does. */
static void break_windings(plant_t *plant)
{
    if (port.faults.open_phase == SIL_PHASES_NONE || plant->time_s < port.faults.open_phase_time_s) {
        return;
    }
    if (sil_phases_take(port.faults.open_phase, 0) && !plant->broken_a) {
        plant->broken_a = true;
        plant->x.i_a_A = 0.0;
    }
    if (sil_phases_take(port.faults.open_phase, 1) && !plant->broken_b) {
        plant->broken_b = true;
        plant->x.i_b_A = 0.0;
    }
}

/* A failed current sensor from its time on (sil/faults.h): open, the chain's reading of 0 A; stuck,
 * the last reading before the failure. */
static void sense_currents(const plant_t *plant, float *i_a_A, float *i_b_A)
{
    const bool failed = port.faults.sensor != SIL_SENSOR_OK && plant->time_s >= port.faults.sensor_time_s;
    const bool fail_a = failed && sil_phases_take(port.faults.sensor_phase, 0);
    const bool fail_b = failed && sil_phases_take(port.faults.sensor_phase, 1);
    const bool open = port.faults.sensor == SIL_SENSOR_OPEN;
    double a_A, b_A;
    sil_sensors_currents(&port.sensors, (fail_a && open) ? 0.0 : plant->x.i_a_A,
                         (fail_b && open) ? 0.0 : plant->x.i_b_A, &a_A, &b_A);
    *i_a_A = (fail_a && !open) ? port.meas.i_a_A : (float)a_A;
    *i_b_A = (fail_b && !open) ? port.meas.i_b_A : (float)b_A;
}

/* Sampled at the period boundary: the carrier's valley, where every phase sees zero volts; the
 * phase voltages are the means over the period just ended (what the plant received). */
void pmstep_hal_read_measurements(pmstep_meas_t *meas)
{
    plant_t *plant = port.plant;
    double u_a_V, u_b_V;
    break_windings(plant);
    port.bus_V = sil_inverter_bus_voltage(&port.inverter, plant->time_s);
    sense_currents(plant, &meas->i_a_A, &meas->i_b_A);
    meas->bus_voltage_V = (float)sil_sensors_bus(&port.sensors, port.bus_V);
    meas->load_torque_Nm = (float)plant_load_torque(&plant->load, plant->time_s, plant->x.omega_rad_s);
    sil_sensors_phase_voltages(&port.sensors, port.inverter.applied_a_V, port.inverter.applied_b_V, &u_a_V, &u_b_V);
    meas->phase_voltage_a_V = (float)u_a_V;
    meas->phase_voltage_b_V = (float)u_b_V;
    port.meas = *meas;
}

/* The duty is the command over the bus voltage the core was given in this period. */
void pmstep_hal_apply_output(const pmstep_output_t *out)
{
    sil_inverter_apply(&port.inverter, out, (double)port.meas.bus_voltage_V);
}
