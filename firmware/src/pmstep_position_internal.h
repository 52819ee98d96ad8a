/* Private to the position library's sources: the vector hold at the end of a move
 * (pmstep_position_hold.c), called from the loop's updates (pmstep_position.c); the loop's reference
 * for the commands (pmstep_position_commands.c); the STEP/DIR tracker's updates. */
#ifndef PMSTEP_POSITION_INTERNAL_H
#define PMSTEP_POSITION_INTERNAL_H

#include "pmstep/pmstep_position.h"

/* pmstep_position_t.hold_stage */
#define POSITION_HOLD_NONE ((int32_t)0)
#define POSITION_HOLD_WAITING ((int32_t)1) /* the move has ended; the loop holds while T_L-hat settles */
#define POSITION_HOLD_SETTLING ((int32_t)2)
#define POSITION_HOLD_ANCHORED ((int32_t)3)
#define POSITION_HOLD_REFUSED ((int32_t)4) /* until the next move: the loop holds on the estimate */
#define POSITION_HOLD_REAIMED ((int32_t)5) /* settling after a re-aim, the estimate kept turned with it */

/* The flux integrals' turn over an update taken for motion in a hold, in quiet bands' turns
 * (pmstep_position_hold.c, reading_at_rest): at rest their noise is a quarter of one (17HS4401,
 * realistic chain, rms), their drift in the dead time's zero zone with the vector on a phase axis
 * 0.7 to 1.1 (AS1050), a load step's swing 4 to 5 (0.11 to 0.16 rad an update on the 17HS4401). */
#define POSITION_READING_MOTION_BANDS 3.0f

/* An update in position mode with the profile ended and no vector yet: the loop holds
 * POSITION_AIM_WAIT_TIME_CONSTANTS / k_theta, then aims the core's vector at the target (or the
 * stage becomes refused). */
void pmstep_position_wait_and_aim(pmstep_position_t *pos, float position_rad);

/* The core's vector holds the rotor (settling, anchored or settling after a re-aim). */
bool pmstep_position_vector_held(const pmstep_position_t *pos);

/* An update while the vector holds. */
void pmstep_position_vector_hold(pmstep_position_t *pos, float position_rad);

/* Ends a vector hold (a move, a stop); the stage returns to none. */
void pmstep_position_release_hold(pmstep_position_t *pos);

/* ---- the loop's reference (pmstep_position.c), for the commands (pmstep_position_commands.c) ---- */

/* Puts the speed reference channel at (w*, w*', w*'') for the coming N periods, its set-point held so
 * that w* ends them at @p end_speed (pmstep_position.c). */
void pmstep_position_put_speed_reference(pmstep_position_t *pos, float speed, float rate, float accel, float end_speed);

/* The loop no longer follows a STEP/DIR input (a move, a stop, a speed command, leaving RUN). */
void pmstep_position_stop_following(pmstep_position_t *pos);

/* ---- STEP/DIR (pmstep_stepdir.c), run from the position loop ---- */
struct pmstep_stepdir;

/* The loop starts following the count at @p start (its reference for the next period): the count's
 * origin is put there, so theta* does not jump. */
void pmstep_stepdir_start(struct pmstep_stepdir *sd, const pmstep_motion_sample_t *start);

/* An update: the tracker predicted over T and corrected by the count; at rest after stop_time_s. */
void pmstep_stepdir_track(struct pmstep_stepdir *sd);

/* An update after the tracker's, with stall_current_A > 0 or while stalled (pmstep_stepdir.h, Stall): the
 * stall test on theta-hat @p position_rad and the q current @p push_A beyond the tracker's acceleration's,
 * the steps toward a block dropped. @return true when a stall was found at this update. */
bool pmstep_stepdir_stall(struct pmstep_stepdir *sd, float position_rad, float push_A);

/* The tracker's state moved on by @p ahead_s at constant acceleration. */
pmstep_motion_sample_t pmstep_stepdir_predict(const struct pmstep_stepdir *sd, float ahead_s);

#endif /* PMSTEP_POSITION_INTERNAL_H */
