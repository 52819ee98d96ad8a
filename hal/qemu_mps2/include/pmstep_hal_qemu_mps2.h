/**
 * @file pmstep_hal_qemu_mps2.h
 * @brief Port of the HAL contract (pmstep_hal.h) to QEMU's mps2-an386 machine
 *        (Cortex-M4 with FPU), for processor-in-the-loop runs.
 *
 * The emulated board has no motor, so the port's "peripherals" are two blocks
 * in RAM that the PIL harness owns, in the roles an MCU's ADC and PWM play:
 * the harness latches a period's samples (SI units) into the sample block and
 * pends the control interrupt, as an ADC end-of-conversion would; the interrupt
 * runs the three steps of every port (pmstep_hal_read_measurements(),
 * pmstep_step(), pmstep_hal_apply_output()); the output block then holds what
 * a PWM driver would turn into duties. The control interrupt is external line
 * MPS2_PIL_CONTROL_IRQ, pended through the NVIC's software trigger register.
 *
 * Around pmstep_step() the interrupt reads the SysTick counter (processor
 * clock) and accumulates, per mode, the ticks spent in the step and in an
 * identical call of an empty function (the bracket's own cost). Under QEMU with
 * `-icount shift=0` one instruction takes 1 ns of virtual time, so ticks convert
 * to instructions exactly on average (see mps2_pil_calibrate()). Outside that
 * bracket it also paints the stack below its stack pointer before the step and
 * finds the deepest word the step wrote: the step's stack use, callees included.
 */
#ifndef PMSTEP_HAL_QEMU_MPS2_H
#define PMSTEP_HAL_QEMU_MPS2_H

#include <stdint.h>

#include "pmstep_hal.h"

#ifdef __cplusplus
extern "C" {
#endif

/** External interrupt lines of the AN386 image (NVIC inputs 0..31). */
#define MPS2_IRQ_COUNT 32

/** Control interrupt: the dual timer's line (the timer is never started, only software pends it). */
#define MPS2_PIL_CONTROL_IRQ 10
#define MPS2_PIL_CONTROL_IRQHandler Irq10_Handler

/** Number of pmstep_mode_t values. */
#define MPS2_PIL_MODES 5

/** Cost of the control step per mode of its output, in SysTick ticks. */
typedef struct {
    uint32_t steps[MPS2_PIL_MODES];
    uint64_t step_ticks[MPS2_PIL_MODES];      /**< reads around pmstep_step() */
    uint64_t empty_ticks[MPS2_PIL_MODES];     /**< the same reads around an empty function, same arguments */
    uint32_t stack_max_bytes[MPS2_PIL_MODES]; /**< deepest stack below the caller's SP during pmstep_step() */
} mps2_pil_cost_t;

/** Bytes painted below the interrupt's stack pointer before each step, to find the step's stack use. */
#define MPS2_PIL_STACK_PAINT_BYTES 1024u

/** Attaches @p inst, starts SysTick (free running, processor clock) and enables the control interrupt. */
void mps2_pil_init(pmstep_t *inst);

/**
 * One control period as an MCU runs it: latches @p samples into the sample
 * block, pends the control interrupt, waits for it, and copies the output block
 * to @p out.
 */
void mps2_pil_control_period(const pmstep_meas_t *samples, pmstep_output_t *out);

/** The cost accumulated since mps2_pil_init(). */
const mps2_pil_cost_t *mps2_pil_cost(void);

/**
 * SysTick ticks taken by a loop of exactly 2 * @p iterations instructions
 * (SUBS + BNE), for the ticks-to-instructions factor.
 */
uint32_t mps2_pil_calibrate(uint32_t iterations);

/** Instructions per tick from a calibration of @p iterations loop turns. */
double mps2_pil_instructions_per_tick(uint32_t iterations);

/** Control interrupt handler (vector MPS2_PIL_CONTROL_IRQ). */
void MPS2_PIL_CONTROL_IRQHandler(void);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_HAL_QEMU_MPS2_H */
