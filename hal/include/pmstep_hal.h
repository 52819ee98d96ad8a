/**
 * @file pmstep_hal.h
 * @brief The contract between the control core and a port (host SIL, STM32G4,
 *        QEMU Cortex-M4). A port implements these functions; the build links
 *        exactly one port, so the core's calls into it are direct.
 *
 * The control interrupt of every port does the same three things, once per
 * period, in this order (see pmstep_hal_control_period()):
 *   1. pmstep_hal_read_measurements(): phase currents and bus voltage sampled at
 *      the carrier centre (and, with a known load, the load torque);
 *   2. pmstep_step();
 *   3. pmstep_hal_apply_output(): voltages to duties against the measured bus,
 *      bridge enable/disable. Duties written here take effect at the next
 *      carrier period; configure computational_delay_periods accordingly.
 *
 * Optional: work that needs each step's output (position control's
 * pmstep_position_update(), a STEP/DIR input's count and DIAG, a console's
 * homing) may run in the same interrupt once the output is applied. A port
 * may offer it as one hook the application sets before the interrupt starts
 * (the STM32G4 port's pmstep_stm32g4_set_after_step()): the one indirect call
 * of the interrupt, after the bridge has its duties, so it never delays them.
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
