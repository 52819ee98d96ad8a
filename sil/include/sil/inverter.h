/**
 * @file inverter.h
 * @brief Averaged inverter model of the SIL: the phase voltage commanded by a
 *        step is held over a period (now, or one period later with a
 *        computational delay), limited to +/- the bus voltage; bridge off is
 *        modelled as zero phase voltage. Shared by the host port and the PIL
 *        closed loop on the target, so both drive the plant alike.
 */
#ifndef SIL_INVERTER_H
#define SIL_INVERTER_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    double bus_voltage_v;
    unsigned delay_periods;      /**< 0 or 1 */
    double pending_a_v;          /**< computed, waiting for the next period (delay 1) */
    double pending_b_v;
    double applied_a_v;          /**< voltage the plant sees over the coming period */
    double applied_b_v;
    unsigned long limited_periods; /**< periods the inverter had to clip to +/- bus */
} sil_inverter_t;

/** Zero voltage, nothing pending. */
void sil_inverter_init(sil_inverter_t *inv, double bus_voltage_v, unsigned delay_periods);

/** Takes one step's output; sets applied_a_v, applied_b_v for the coming period. */
void sil_inverter_apply(sil_inverter_t *inv, const pmstep_output_t *out);

#ifdef __cplusplus
}
#endif

#endif /* SIL_INVERTER_H */
