/**
 * @file stepdir_run.h
 * @brief A STEP/DIR scenario in the runner (issue 53, position.source = stepdir): the step
 *        generator (sil/step_generator.h) puts out the count every period, the drive follows it,
 *        and the run is judged by the following error on the plant's true position
 *        (sil_stepdir_summary_t).
 *
 * The firmware (run.controller = pmstep): its STEP/DIR input (pmstep_stepdir.h) designed for the
 * motor at stepdir.microsteps, DIAG in stepdir.diag_mode; the port's counter starts at
 * SIL_STEPDIR_COUNTER_START (the run crosses the 16-bit wrap within 256 microsteps forward). Each
 * period, around the core's step:
 *   before  the count at t_k from the generator; once the position is tracked and the first move
 *           is due, pmstep_position_follow_steps() (once: count 0 is where the reference then is);
 *   after   pmstep_step(), the counter (its low 16 bits) to pmstep_stepdir_count(), then
 *           pmstep_position_update(), then pmstep_stepdir_diag() with that period's output.
 * The baseline (run.controller = microstep): from the first move's time on, its electrical angle
 * is the count's, n pi / (2 m) (p n q), through sil_microstep_set_angle().
 *
 * The following error's origin is the equilibrium p theta = 0 mod 2 pi the rotor sits at when the
 * count starts to mean something: RUN's first period for the firmware (the c-alignment's, as the
 * position estimate's), the first move's time for the baseline (its hold's).
 */
#ifndef SIL_STEPDIR_RUN_H
#define SIL_STEPDIR_RUN_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep/pmstep_position.h"
#include "pmstep/pmstep_stepdir.h"
#include "sil/metrics.h"
#include "sil/microstep.h"
#include "sil/scenario.h"
#include "sil/step_generator.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The port's step counter at the start of a run: 256 below its 16-bit wrap. */
#define SIL_STEPDIR_COUNTER_START 0xFF00u

typedef struct {
    const sil_scenario_t *sc;
    bool firmware;             /**< the pmstep drive (else the microstep baseline) */
    sil_step_generator_t gen;  /**< the motion controller's plan */
    pmstep_stepdir_t input;    /**< the firmware's STEP/DIR input (firmware only) */
    double pole_pairs;         /**< the plant's p */
    double full_step_rad;      /**< pi / (2 p), mechanical */
    sil_step_sample_t command; /**< the generator at the present period's t_k */
    int32_t count;             /**< its count, microsteps */
    bool following;            /**< the drive has begun following the count */
    bool origin_set;
    double origin_rad;    /**< the plant's theta at the equilibrium count 0 is measured from */
    double sum_sq_all;    /**< sums of the error's square (full steps^2) since following began */
    double sum_sq_moving; /**< the same while a move runs */
    long n_all, n_moving;
    bool diag; /**< DIAG after the present period */
} sil_stepdir_run_t;

/** Plans the moves and, for the firmware (@p firmware), designs and initialises its STEP/DIR input.
 *  @return PMSTEP_OK, or the status pmstep_stepdir_design()/pmstep_stepdir_init() refused with. */
pmstep_status_t sil_stepdir_run_init(sil_stepdir_run_t *run, const sil_scenario_t *sc, bool firmware, sil_summary_t *s);

/** Before the period's step: the generator at @p t_s; the firmware begins following (@p pos) or the
 *  baseline takes the count's angle (@p drive) when due. The other pointer is NULL. */
void sil_stepdir_run_command(sil_stepdir_run_t *run, double t_s, pmstep_position_t *pos, sil_microstep_t *drive,
                             sil_summary_t *s);

/** Firmware, after pmstep_step() and before pmstep_position_update(): the port's counter read. */
void sil_stepdir_run_count(sil_stepdir_run_t *run);

/** Firmware, after pmstep_position_update(): DIAG from the core's @p mode and the position output. */
void sil_stepdir_run_diag(sil_stepdir_run_t *run, pmstep_mode_t mode, const pmstep_position_output_t *pos_out);

/** One period's sample: the following error into @p sample and the summary's sums. */
void sil_stepdir_run_sample(sil_stepdir_run_t *run, sil_sample_t *sample, sil_summary_t *s);

/** The RMS values, the final error and the counts. */
void sil_stepdir_run_finish(const sil_stepdir_run_t *run, sil_summary_t *s);

#ifdef __cplusplus
}
#endif

#endif /* SIL_STEPDIR_RUN_H */
