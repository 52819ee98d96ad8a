/**
 * @file pmstep_hal.h
 * @brief The contract between the control core and a port (host SIL, STM32G4,
 *        QEMU Cortex-M4). A port implements these functions; the build links
 *        exactly one port. No function pointers in the interrupt path.
 *
 * The control interrupt of every port does the same three things, once per
 * period, in this order (see pmstep_hal_control_period()):
 *   1. pmstep_hal_read_measurements(): phase currents and bus voltage sampled at
 *      the carrier centre (and, with a known load, the load torque);
 *   2. pmstep_step();
 *   3. pmstep_hal_apply_output(): voltages to duties against the measured bus,
 *      bridge enable/disable. Duties written here take effect at the next
 *      carrier period; configure computational_delay_periods accordingly.
 */
#ifndef PMSTEP_HAL_H
#define PMSTEP_HAL_H

#include "pmstep/pmstep.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Fills @p meas with this period's samples, in SI units. */
void pmstep_hal_read_measurements(pmstep_meas_t *meas);

/** Applies the step's output: phase voltages (V) and bridge enable. */
void pmstep_hal_apply_output(const pmstep_output_t *out);

/** One control period: read, step, apply. Called from the port's control interrupt. */
static inline void pmstep_hal_control_period(pmstep_t *inst, pmstep_output_t *out)
{
    pmstep_meas_t meas;
    pmstep_hal_read_measurements(&meas);
    pmstep_step(inst, &meas, out);
    pmstep_hal_apply_output(out);
}

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_HAL_H */
