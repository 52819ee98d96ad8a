/**
 * @file pmstep_hal_host.h
 * @brief Host port of the HAL contract: the "hardware" is the plant model of
 *        sil/. Measurements are the plant's currents at the sampling instant and
 *        a fixed bus voltage; the output drives the averaged inverter of
 *        sil/inverter.h (phase voltage held over the period, limited to +/- bus,
 *        bridge off = zero phase voltage).
 *
 * Computational delay: with 1 period, the voltage of the step at sample k is
 * applied during [k+1, k+2], as on an MCU that writes duties for the next
 * carrier period. Set the core's computational_delay_periods to match.
 */
#ifndef PMSTEP_HAL_HOST_H
#define PMSTEP_HAL_HOST_H

#include "pmstep_hal.h"
#include "sil/inverter.h"
#include "sil/plant.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    plant_t *plant;
    sil_inverter_t inverter;
} pmstep_hal_host_t;

/** Binds the port to @p plant; the port state is global, as a real port's registers are. */
void pmstep_hal_host_bind(plant_t *plant, double bus_voltage_v, unsigned delay_periods);

/** The port's state (for the runner and tests). */
const pmstep_hal_host_t *pmstep_hal_host_state(void);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_HAL_HOST_H */
