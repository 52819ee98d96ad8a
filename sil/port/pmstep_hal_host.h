/**
 * @file pmstep_hal_host.h
 * @brief Host port of the HAL contract: the "hardware" is the plant model of
 *        sil/. Measurements are the plant's currents and the actual bus voltage at
 *        the sampling instant (the period boundary, the centre of the PWM carrier's
 *        zero-voltage interval) through the measurement chain of sil/sensors.h; the
 *        output drives the inverter and bus of sil/inverter.h, whose duty is the
 *        command over the bus voltage measured in the same period.
 *
 * Computational delay: with 1 period, the voltage of the step at sample k is
 * applied during [k+1, k+2], as on an MCU that writes duties for the next
 * carrier period. Set the core's computational_delay_periods to match.
 */
#ifndef PMSTEP_HAL_HOST_H
#define PMSTEP_HAL_HOST_H

#include "pmstep_hal.h"
#include "sil/faults.h"
#include "sil/inverter.h"
#include "sil/plant.h"
#include "sil/sensors.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What the port's "hardware" is. */
typedef struct {
    double bus_voltage_V;   /**< nominal bus V0 */
    unsigned delay_periods; /**< computational delay of the duty update (0 or 1) */
    sil_inverter_config_t inverter;
    sil_bus_config_t bus;
    sil_sensor_config_t sensors;
    sil_fault_config_t faults; /**< what fails, and when (sil/faults.h) */
    unsigned long seed;        /**< of the measurement chain's RNG */
} pmstep_hal_host_setup_t;

typedef struct {
    plant_t *plant;
    sil_inverter_t inverter;
    sil_sensors_t sensors;
    sil_fault_config_t faults;
    /* The last sample (start of the present period). */
    pmstep_meas_t meas; /**< what the core was given */
    double bus_V;       /**< actual bus voltage at the sample */
} pmstep_hal_host_t;

/**
 * Binds the port to @p plant with the inverter, bus and sensors of @p setup; the port
 * state is global, as a real port's registers are. @return 0, or -1 if the RNG could
 * not be allocated.
 */
int pmstep_hal_host_bind(plant_t *plant, const pmstep_hal_host_setup_t *setup);

/** Frees what bind allocated; the state (counters, last sample) stays readable. */
void pmstep_hal_host_release(void);

/** The port's state (for the runner and tests). */
const pmstep_hal_host_t *pmstep_hal_host_state(void);

/** The port's inverter, for the runner to advance the plant through it (sil_drive_advance). */
sil_inverter_t *pmstep_hal_host_inverter(void);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_HAL_HOST_H */
