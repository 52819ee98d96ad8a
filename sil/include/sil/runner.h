/**
 * @file runner.h
 * @brief Runs a scenario: the real control core (pmstep_step through the host
 *        HAL port) in closed loop with the plant model, one control period at a
 *        time, and gathers the metrics of the run. With run.controller = microstep
 *        the open-loop microstepping drive of sil/microstep.h takes the core's place
 *        (same period, measurement chain, inverter and bus; the core is not called).
 */
#ifndef SIL_RUNNER_H
#define SIL_RUNNER_H

#include <stdbool.h>
#include <stdio.h>

#include "sil/metrics.h"
#include "sil/plant.h"
#include "sil/record.h"
#include "sil/scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * @p plant at @p sc's initial state, and the host port (pmstep_hal_host.h) bound to it with @p sc's
 * bridge, bus, measurement chain and faults, as sil_run() does before its first period; the load is
 * @p sc's (a caller may change it before the first period). @return 0, or -3 when the measurement
 * chain's random number generator could not be allocated (the port released).
 */
int sil_bind_plant(const sil_scenario_t *sc, plant_t *plant);

/**
 * Runs @p sc. @p on_sample may be NULL. @p progress prints a progress line to
 * stderr. @return 0, -1 when pmstep_init rejected the configuration
 * (summary->init_status says why), or -3 when the measurement chain's random
 * number generator could not be allocated. The host port's state
 * (pmstep_hal_host_state(): ADC clip counts, last sample) stays readable after the run.
 */
int sil_run(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress, sil_summary_t *summary);

/**
 * sil_run() that also writes the record of sil/record.h to @p record (binary
 * stream; NULL records nothing; microstep mode records nothing: there is no core). @return 0, -1 when pmstep_init rejected the
 * configuration, -2 when writing the record failed, -3 as sil_run().
 */
int sil_run_record(const sil_scenario_t *sc, sil_sample_fn on_sample, void *user, bool progress, sil_summary_t *summary,
                   FILE *record);

#ifdef __cplusplus
}
#endif

#endif /* SIL_RUNNER_H */
