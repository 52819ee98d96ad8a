/**
 * @file position_run.h
 * @brief A position scenario in the runner (issue 13): issues the moves of [position] points at
 *        their times (pmstep_position_move_to), and judges the run on the plant's true position
 *        (sil_position_summary_t): each move's final error and overshoot, the estimate's error,
 *        the hold window's error and drift.
 */
#ifndef SIL_POSITION_RUN_H
#define SIL_POSITION_RUN_H

#include <stdbool.h>

#include "pmstep/pmstep_position.h"
#include "sil/metrics.h"
#include "sil/scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    const sil_scenario_t *sc;
    double pole_pairs;
    int next_move; /**< next move to issue */
    bool origin_set;
    double origin_rad;     /**< plant theta of the c-alignment equilibrium RUN began at */
    bool in_move;          /**< a move has been issued */
    double move_start_rad; /**< true position when the present move was issued */
    double move_target_rad;
    double move_overshoot_rad; /**< largest travel beyond the target so far */
    double last_error_rad;     /**< |theta - target| at the last sample (mechanical) */
    double last_theta_rad;     /**< true position at the last sample */
    bool last_moving;
    double final_error_sum;
    long hold_n; /**< least-squares sums of the hold window */
    double hold_st, hold_sy, hold_stt, hold_sty;
} sil_position_run_t;

/** The position configuration the scenario runs with: [controller.position], or the designer's rule. */
pmstep_position_config_t sil_position_config(const sil_scenario_t *sc);

void sil_position_run_init(sil_position_run_t *run, const sil_scenario_t *sc);

/** Issues the moves due at @p t_s (once the position is tracked). */
void sil_position_run_command(sil_position_run_t *run, pmstep_position_t *pos, double t_s, sil_summary_t *s);

/** One period: the true position from the origin, the estimate and theta* of the period (queried from
 *  @p pos: the output holds the last update's) into the sample, and the metrics. */
void sil_position_run_sample(sil_position_run_t *run, const pmstep_position_t *pos, sil_sample_t *sample,
                             sil_summary_t *s);

/** Closes the last move and the hold window. */
void sil_position_run_finish(sil_position_run_t *run, sil_summary_t *s);

#ifdef __cplusplus
}
#endif

#endif /* SIL_POSITION_RUN_H */
