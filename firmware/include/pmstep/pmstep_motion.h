/**
 * @file pmstep_motion.h
 * @brief Jerk-limited motion profile: position, speed, acceleration and jerk at every control
 *        period, from any present state (p, v, a) to a target at rest, within |v| <= v_max,
 *        |a| <= a_max, |jerk| <= j_max, ending exactly at the target.
 *
 * A plan is a list of segments of constant jerk. From (p, v, a):
 *  1. a != 0: jerk -sign(a) j_max until a = 0;
 *  2. if the target cannot be reached without overshoot (it lies behind, or nearer than the
 *     stopping distance), a stop to v = 0 first (the move then comes back);
 *  3. a change of speed to the peak v_p, a cruise at v_p, a change of speed to 0; each change of
 *     speed by dv is jerk-limited: (+j, 0, -j) for 3 segments when dv >= a_max^2/j_max, else two
 *     segments of peak acceleration sqrt(dv j_max); its distance is (v_start + v_end)/2 times its
 *     time. v_p = v_max with a cruise if the distance allows, else the v_p whose distance is the
 *     remaining one (bisection, then a cruise of the bisection's rest).
 * Limits hold from the instant the plan starts, except an |a| or |v| already above them (a
 * re-target with lower limits): step 1 and the changes of speed bring them down at j_max.
 * At most PMSTEP_MOTION_SEGMENTS segments. Planning (pmstep_motion_plan) is for command time;
 * pmstep_motion_next() is the per-period part: a few multiply-adds, no division.
 */
#ifndef PMSTEP_MOTION_H
#define PMSTEP_MOTION_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Segments of the longest plan: 1 (acceleration to 0) + 3 (stop) + 3 + 1 + 3. */
#define PMSTEP_MOTION_SEGMENTS 11u

/** One segment of constant jerk. */
typedef struct {
    float end_s;     /**< end time, from the plan's start (s) */
    float jerk;      /**< jerk over the segment (unit/s^3) */
    float end_speed; /**< speed and acceleration at the end, as planned (a change of speed ends at exactly */
    float end_accel; /**< its speed and a = 0: no round-off left to integrate over a long cruise) */
} pmstep_motion_segment_t;

/** Position, speed, acceleration and jerk at one instant. */
typedef struct {
    float position;
    float speed;
    float accel;
    float jerk;
} pmstep_motion_sample_t;

/** Where the profile is in its plan: the present segment, its start and the state there. */
typedef struct {
    uint32_t index; /**< present segment (the plan's count: finished, at the target) */
    float start_s;  /**< start of the present segment (s from the plan's start) */
    float position; /**< state at the start of the present segment */
    float speed;
    float accel;
} pmstep_motion_cursor_t;

/** A plan and where the profile is in it. */
typedef struct {
    pmstep_motion_segment_t segment[PMSTEP_MOTION_SEGMENTS];
    uint32_t count;   /**< segments in the plan */
    uint32_t periods; /**< periods since the plan started */
    float period_s;   /**< T_s */
    pmstep_motion_cursor_t cursor;
    float target; /**< where the plan ends, at rest */
    float v_max;  /**< the plan's limits (kept for a stop) */
    float a_max;
    float j_max;
} pmstep_motion_t;

/** At rest at @p position (finished), period @p period_s. */
void pmstep_motion_reset(pmstep_motion_t *m, float position, float period_s);

/**
 * Plans from the state (@p position, @p speed, @p accel) to @p target at rest; the next
 * pmstep_motion_next() returns that state. Limits must be > 0 and every value finite (the
 * caller checks).
 */
void pmstep_motion_plan(pmstep_motion_t *m, float position, float speed, float accel, float target, float v_max,
                        float a_max, float j_max);

/** Plans a stop from the state of @p now with the plan's limits; the target becomes where it ends. */
void pmstep_motion_stop(pmstep_motion_t *m, const pmstep_motion_sample_t *now);

/** The profile at the present period, then one period on. Finished: the target exactly, at rest. */
pmstep_motion_sample_t pmstep_motion_next(pmstep_motion_t *m);

/** The profile at the present period without advancing. */
pmstep_motion_sample_t pmstep_motion_peek(const pmstep_motion_t *m);

/** True once the plan has ended (the profile is at the target, at rest). */
static inline bool pmstep_motion_finished(const pmstep_motion_t *m)
{
    return m->cursor.index >= m->count;
}

/** Adds @p offset to every position of the plan (a new zero). */
void pmstep_motion_shift(pmstep_motion_t *m, float offset);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_MOTION_H */
