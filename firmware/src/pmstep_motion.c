/* Jerk-limited motion profile (pmstep_motion.h). */
#include "pmstep/pmstep_motion.h"

#include <math.h> /* fabsf, sqrtf: single FPU instructions (-fno-math-errno), no libm call */

/* 1/6 of the cubic term, a multiplication (no division in the period's work). */
#define MOTION_SIXTH (1.0f / 6.0f)

/* Bisection steps for the peak speed of a short move: 2^-32 of v_max, below float resolution. */
#define MOTION_BISECTION_STEPS 32

/* State after @p d seconds of constant jerk @p jerk from (p, v, a) in @p c. */
static void advance_state(pmstep_motion_cursor_t *c, float d, float jerk)
{
    c->position += d * (c->speed + d * (0.5f * c->accel + d * (jerk * MOTION_SIXTH)));
    c->speed += d * (c->accel + d * (0.5f * jerk));
    c->accel += d * jerk;
}

/* Moves @p c on to the segment that contains @p t_s (or to the end of the plan). */
static void locate(const pmstep_motion_t *m, pmstep_motion_cursor_t *c, float t_s)
{
    while (c->index < m->count && t_s >= m->segment[c->index].end_s) {
        const pmstep_motion_segment_t *seg = &m->segment[c->index];
        advance_state(c, seg->end_s - c->start_s, seg->jerk);
        c->speed = seg->end_speed;
        c->accel = seg->end_accel;
        c->start_s = seg->end_s;
        c->index++;
    }
}

static pmstep_motion_sample_t sample_at(const pmstep_motion_t *m, const pmstep_motion_cursor_t *c, float t_s)
{
    pmstep_motion_sample_t s;
    if (c->index >= m->count) {
        s.position = m->target; /* exactly, at rest */
        s.speed = 0.0f;
        s.accel = 0.0f;
        s.jerk = 0.0f;
    } else {
        const float jerk = m->segment[c->index].jerk;
        const float d = t_s - c->start_s;
        s.position = c->position + d * (c->speed + d * (0.5f * c->accel + d * (jerk * MOTION_SIXTH)));
        s.speed = c->speed + d * (c->accel + d * (0.5f * jerk));
        s.accel = c->accel + d * jerk;
        s.jerk = jerk;
    }
    return s;
}

void pmstep_motion_reset(pmstep_motion_t *m, float position, float period_s)
{
    m->count = 0u;
    m->periods = 0u;
    m->period_s = period_s;
    m->cursor.index = 0u;
    m->cursor.start_s = 0.0f;
    m->cursor.position = position;
    m->cursor.speed = 0.0f;
    m->cursor.accel = 0.0f;
    m->target = position;
    m->v_max = 0.0f;
    m->a_max = 0.0f;
    m->j_max = 0.0f;
}

pmstep_motion_sample_t pmstep_motion_peek(const pmstep_motion_t *m)
{
    const float t_s = (float)m->periods * m->period_s;
    pmstep_motion_cursor_t c = m->cursor;
    locate(m, &c, t_s);
    return sample_at(m, &c, t_s);
}

pmstep_motion_sample_t pmstep_motion_next(pmstep_motion_t *m)
{
    const float t_s = (float)m->periods * m->period_s;
    locate(m, &m->cursor, t_s);
    if (m->cursor.index < m->count) {
        m->periods++; /* a finished plan stays put: no count to overflow while holding */
    }
    return sample_at(m, &m->cursor, t_s);
}

void pmstep_motion_shift(pmstep_motion_t *m, float offset)
{
    m->cursor.position += offset;
    m->target += offset;
}

/* ---- Planning ---- */

/* Appends segments to a plan, keeping the state at its end. */
typedef struct {
    pmstep_motion_t *m;
    pmstep_motion_cursor_t end; /* start_s: the plan's end time so far */
} builder_t;

static void add_segment(builder_t *b, float duration_s, float jerk)
{
    if (duration_s > 0.0f && b->m->count < PMSTEP_MOTION_SEGMENTS) {
        pmstep_motion_segment_t *seg = &b->m->segment[b->m->count];
        b->m->count++;
        advance_state(&b->end, duration_s, jerk);
        b->end.start_s += duration_s;
        seg->end_s = b->end.start_s;
        seg->jerk = jerk;
        seg->end_speed = b->end.speed;
        seg->end_accel = b->end.accel;
    }
}

/* The planned end state of the last segment (after a change of speed: exactly its speed, a = 0). */
static void settle_last_segment(builder_t *b)
{
    if (b->m->count > 0u) {
        b->m->segment[b->m->count - 1u].end_speed = b->end.speed;
        b->m->segment[b->m->count - 1u].end_accel = b->end.accel;
    }
}

/* Time of a jerk-limited change of speed by @p dv >= 0. */
static float change_time(float dv, float a_max, float j_max)
{
    if (dv >= a_max * a_max / j_max) {
        return dv / a_max + a_max / j_max;
    }
    return 2.0f * sqrtf(dv / j_max);
}

/* Distance of the change of speed from @p v0 to @p v1 (same sign or zero): mean speed times time. */
static float change_distance(float v0, float v1, float a_max, float j_max)
{
    return 0.5f * (v0 + v1) * change_time(fabsf(v1 - v0), a_max, j_max);
}

/* Appends the change of speed by @p dv (either sign); the acceleration ends at 0. */
static void add_speed_change(builder_t *b, float dv, float a_max, float j_max)
{
    const float size = fabsf(dv);
    const float jerk = dv >= 0.0f ? j_max : -j_max;
    const float v_end = b->end.speed + dv;
    if (size >= a_max * a_max / j_max) {
        add_segment(b, a_max / j_max, jerk);
        add_segment(b, size / a_max - a_max / j_max, 0.0f);
        add_segment(b, a_max / j_max, -jerk);
    } else if (size > 0.0f) {
        const float ramp_s = sqrtf(size / j_max);
        add_segment(b, ramp_s, jerk);
        add_segment(b, ramp_s, -jerk);
    } else {
        /* no change */
    }
    b->end.speed = v_end; /* the planned values, free of the segments' round-off */
    b->end.accel = 0.0f;
    settle_last_segment(b);
}

/* Appends the change of acceleration to 0 at j_max. */
static void add_accel_to_zero(builder_t *b, float j_max)
{
    const float a = b->end.accel;
    add_segment(b, fabsf(a) / j_max, a > 0.0f ? -j_max : j_max);
    b->end.accel = 0.0f;
    settle_last_segment(b);
}

/* Distance of a move that changes speed from @p v0 to the peak @p vp and then to 0 (no cruise). */
static float peak_distance(float v0, float vp, float a_max, float j_max)
{
    return change_distance(v0, vp, a_max, j_max) + change_distance(vp, 0.0f, a_max, j_max);
}

static void builder_start(builder_t *b, pmstep_motion_t *m, float position, float speed, float accel)
{
    b->m = m;
    b->end.index = 0u;
    b->end.start_s = 0.0f;
    b->end.position = position;
    b->end.speed = speed;
    b->end.accel = accel;
    m->count = 0u;
    m->periods = 0u;
    m->cursor = b->end;
}

/* The peak speed of a move of @p remaining (>= the stopping distance) from speed @p toward, and the
 * time cruised at it: v_max with a cruise where the move is long enough, else the highest peak whose
 * distance is not above the remaining one (by bisection), the rest cruised at it. */
static void peak_and_cruise(float toward, float remaining, float v_max, float a_max, float j_max, float *peak_out,
                            float *cruise_s_out)
{
    float peak = v_max;
    float cruise_s = 0.0f;
    const float full = peak_distance(toward, v_max, a_max, j_max);
    if (full <= remaining) {
        cruise_s = (remaining - full) / v_max;
    } else {
        float low = toward;
        float high = v_max;
        int n;
        for (n = 0; n < MOTION_BISECTION_STEPS; ++n) {
            const float mid = 0.5f * (low + high);
            if (peak_distance(toward, mid, a_max, j_max) <= remaining) {
                low = mid;
            } else {
                high = mid;
            }
        }
        peak = low;
        if (peak > 0.0f) {
            cruise_s = (remaining - peak_distance(toward, peak, a_max, j_max)) / peak;
        }
    }
    *peak_out = peak;
    *cruise_s_out = cruise_s;
}

void pmstep_motion_plan(pmstep_motion_t *m, float position, float speed, float accel, float target, float v_max,
                        float a_max, float j_max)
{
    builder_t b;
    float remaining;
    float direction;
    float toward; /* speed toward the target */
    bool one_go;
    builder_start(&b, m, position, speed, accel);
    m->target = target;
    m->v_max = v_max;
    m->a_max = a_max;
    m->j_max = j_max;

    add_accel_to_zero(&b, j_max);
    remaining = target - b.end.position;
    direction = remaining >= 0.0f ? 1.0f : -1.0f;
    toward = direction * b.end.speed;
    if (toward < 0.0f) {
        one_go = false; /* moving away */
    } else if (toward <= v_max) {
        one_go = change_distance(toward, 0.0f, a_max, j_max) <= direction * remaining;
    } else {
        one_go = peak_distance(toward, v_max, a_max, j_max) <= direction * remaining;
    }
    if (!one_go) {
        add_speed_change(&b, -b.end.speed, a_max, j_max); /* stop, then from rest */
        b.end.speed = 0.0f;
        remaining = target - b.end.position;
        direction = remaining >= 0.0f ? 1.0f : -1.0f;
        toward = 0.0f;
    }
    remaining *= direction; /* >= the stopping distance from here */
    {
        float peak;
        float cruise_s;
        peak_and_cruise(toward, remaining, v_max, a_max, j_max, &peak, &cruise_s);
        add_speed_change(&b, direction * (peak - toward), a_max, j_max);
        add_segment(&b, cruise_s, 0.0f);
        add_speed_change(&b, -direction * peak, a_max, j_max);
    }
}

void pmstep_motion_stop(pmstep_motion_t *m, const pmstep_motion_sample_t *now)
{
    builder_t b;
    builder_start(&b, m, now->position, now->speed, now->accel);
    add_accel_to_zero(&b, m->j_max);
    add_speed_change(&b, -b.end.speed, m->a_max, m->j_max);
    m->target = b.end.position;
}
