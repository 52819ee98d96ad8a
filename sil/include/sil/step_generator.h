/**
 * @file step_generator.h
 * @brief The motion controller's side of a STEP/DIR link (position.source = stepdir): what a
 *        printer's firmware (Klipper, Marlin) does with a queue of moves, in the SIL. Not part of
 *        the drive: it plans in double precision with its own planner, not pmstep_motion.
 *
 * Moves: the scenario's position.points t:theta (mechanical rad from the c-alignment's
 * equilibrium, where step count 0 is), each from rest at the previous target (0 for the first) to
 * rest at its own, at position.v_max_rad_s, a_max_rad_s2 and j_max_rad_s3. A move starts at its
 * time, or when the move before it ends if that is later: moves given close together run back to
 * back, as a motion controller's queue runs them.
 *
 * Profile, per move of length D (a symmetric speed-up and slow-down to a peak speed v_p, then a
 * cruise at v_p if D allows it):
 *   j = 0   trapezoid: constant acceleration a for v_p / a, cruise, constant deceleration;
 *   j > 0   S-curve: jerk j up to the acceleration a_p = min(a, sqrt(v_p j)), held, jerk -j down to
 *           0 (the speed-up takes v_p / a_p + a_p / j), cruise, the mirror image.
 * A speed-up from rest to v_p covers v_p T(v_p) / 2 (the speed is point-symmetric about its
 * middle), so the peak is v_max when v_max T(v_max) <= D, else the v_p in (0, v_max) with
 * v_p T(v_p) = D, found by bisection (the left side grows with v_p).
 *
 * Steps: the commanded position theta_cmd(t) sampled once a control period, the count is
 * floor(theta_cmd / q) with q = 2 pi / (4 p m) (one microstep, mechanical rad, the plant's p): the
 * edges a step generator has put out by then, counted up or down by DIR.
 */
#ifndef SIL_STEP_GENERATOR_H
#define SIL_STEP_GENERATOR_H

#include <stdbool.h>
#include <stdint.h>

#include "sil/scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Segments of one move at most: an S-curve's seven (jerk up, hold, jerk down, cruise, and back). */
#define SIL_STEP_SEGMENTS_MAX 7

/** A segment of constant jerk, with the state it starts from (mechanical rad, s). */
typedef struct {
    double end_s;        /**< when it ends (from the start of the run) */
    double start_s;      /**< when it starts */
    double position_rad; /**< at its start */
    double speed_rad_s;
    double accel_rad_s2; /**< at its start (a trapezoid's acceleration steps between segments) */
    double jerk_rad_s3;
} sil_step_segment_t;

/** One planned move. */
typedef struct {
    double start_s;          /**< its start: its point's time, or the end of the move before if later */
    double end_s;            /**< at rest on the target from here on */
    double from_rad;         /**< where it starts (the previous target; 0 for the first) */
    double to_rad;           /**< its target */
    double peak_speed_rad_s; /**< |speed| of the cruise (or the peak when there is none) */
    int segments;
    sil_step_segment_t segment[SIL_STEP_SEGMENTS_MAX];
} sil_step_move_t;

/** The commanded motion at one instant. */
typedef struct {
    double position_rad; /**< theta_cmd, mechanical rad from the count's origin */
    double speed_rad_s;
    double accel_rad_s2;
    bool moving; /**< inside a move (between its start and its end) */
} sil_step_sample_t;

/** The planned moves and where sampling has got to. */
typedef struct {
    int moves;
    sil_step_move_t move[SIL_POSITION_MOVES_MAX];
    double rad_per_microstep; /**< q = 2 pi / (4 p m), mechanical */
    int current;              /**< the move sampled last (sampling goes forward in time) */
} sil_step_generator_t;

/** Plans every move of @p sc (position.points, v/a/j_max, stepdir.microsteps, the plant's p). */
void sil_step_generator_plan(sil_step_generator_t *gen, const sil_scenario_t *sc);

/** The commanded motion at @p t_s; @p t_s must not go back from one call to the next. */
sil_step_sample_t sil_step_generator_sample(sil_step_generator_t *gen, double t_s);

/** The step count at commanded position @p position_rad: floor(theta_cmd / q). */
int32_t sil_step_generator_count(const sil_step_generator_t *gen, double position_rad);

/** The time of the first move's start (the first point's), and of the last move's end. */
double sil_step_generator_first_start_s(const sil_step_generator_t *gen);
double sil_step_generator_last_end_s(const sil_step_generator_t *gen);

#ifdef __cplusplus
}
#endif

#endif /* SIL_STEP_GENERATOR_H */
