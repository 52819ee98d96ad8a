/* The motion controller's step generator of a STEP/DIR scenario (step_generator.h): moves planned
 * in double precision, sampled into a step count. */
#include "sil/step_generator.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846
/* Bisection steps of the peak speed of a short move: 2^-80 of v_max, far below a microstep's time. */
#define PEAK_BISECTION_STEPS 80

/* Time of a speed-up from rest to @p speed at acceleration limit @p accel and jerk @p jerk (0: none). */
static double speed_up_s(double speed, double accel, double jerk)
{
    if (!(jerk > 0.0)) {
        return speed / accel;
    }
    if (speed >= accel * accel / jerk) {
        return speed / accel + accel / jerk; /* the acceleration reaches a and is held */
    }
    return 2.0 * sqrt(speed / jerk); /* a triangle of acceleration, peak sqrt(speed jerk) */
}

/* A segment of @p duration_s at constant jerk, appended if it lasts; the next one's state follows. */
static void add_segment(sil_step_move_t *m, double *t_s, double *position, double *speed, double accel, double jerk,
                        double duration_s)
{
    sil_step_segment_t *seg;
    if (!(duration_s > 0.0)) {
        return;
    }
    seg = &m->segment[m->segments++];
    seg->start_s = *t_s;
    seg->end_s = *t_s + duration_s;
    seg->position_rad = *position;
    seg->speed_rad_s = *speed;
    seg->accel_rad_s2 = accel;
    seg->jerk_rad_s3 = jerk;
    *position += duration_s * (*speed + duration_s * (0.5 * accel + duration_s * jerk / 6.0));
    *speed += duration_s * (accel + 0.5 * duration_s * jerk);
    *t_s = seg->end_s;
}

/* Plans @p m from rest at m->from_rad at m->start_s to rest at m->to_rad. */
static void plan_move(sil_step_move_t *m, double v_max, double a_max, double j_max)
{
    const double distance = fabs(m->to_rad - m->from_rad);
    const double dir = m->to_rad >= m->from_rad ? 1.0 : -1.0;
    double peak = v_max;
    double cruise_s = 0.0;
    double t = m->start_s;
    double position = m->from_rad;
    double speed = 0.0;
    m->segments = 0;
    if (distance > 0.0) {
        if (v_max * speed_up_s(v_max, a_max, j_max) <= distance) {
            cruise_s = (distance - v_max * speed_up_s(v_max, a_max, j_max)) / v_max;
        } else {
            double lo = 0.0, hi = v_max;
            int n;
            for (n = 0; n < PEAK_BISECTION_STEPS; ++n) {
                const double mid = 0.5 * (lo + hi);
                if (mid * speed_up_s(mid, a_max, j_max) <= distance) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            peak = lo;
        }
        if (j_max > 0.0) {
            const double accel = fmin(a_max, sqrt(peak * j_max)); /* the acceleration's peak */
            const double jerk_s = accel / j_max;
            const double hold_s = fmax(0.0, peak / accel - jerk_s);
            add_segment(m, &t, &position, &speed, 0.0, dir * j_max, jerk_s);
            add_segment(m, &t, &position, &speed, dir * accel, 0.0, hold_s);
            add_segment(m, &t, &position, &speed, dir * accel, -dir * j_max, jerk_s);
            add_segment(m, &t, &position, &speed, 0.0, 0.0, cruise_s);
            add_segment(m, &t, &position, &speed, 0.0, -dir * j_max, jerk_s);
            add_segment(m, &t, &position, &speed, -dir * accel, 0.0, hold_s);
            add_segment(m, &t, &position, &speed, -dir * accel, dir * j_max, jerk_s);
        } else {
            const double ramp_s = peak / a_max;
            add_segment(m, &t, &position, &speed, dir * a_max, 0.0, ramp_s);
            add_segment(m, &t, &position, &speed, 0.0, 0.0, cruise_s);
            add_segment(m, &t, &position, &speed, -dir * a_max, 0.0, ramp_s);
        }
    }
    m->peak_speed_rad_s = distance > 0.0 ? peak : 0.0;
    m->end_s = t; /* the sum of the segments: at rest on the target from here */
}

void sil_step_generator_plan(sil_step_generator_t *gen, const sil_scenario_t *sc)
{
    double previous_end_s = 0.0;
    double previous_target = 0.0;
    int n;
    memset(gen, 0, sizeof *gen);
    gen->rad_per_microstep = 2.0 * PI / (4.0 * (double)sc->motor.pole_pairs * (double)sc->stepdir_microsteps);
    gen->moves = sc->position_moves;
    for (n = 0; n < sc->position_moves; ++n) {
        sil_step_move_t *m = &gen->move[n];
        m->start_s = fmax(sc->move_time_s[n], previous_end_s); /* queued behind the move before */
        m->from_rad = previous_target;
        m->to_rad = sc->move_target_rad[n];
        plan_move(m, sc->move_speed_rad_s, sc->move_accel_rad_s2, sc->move_jerk_rad_s3);
        previous_end_s = m->end_s;
        previous_target = m->to_rad;
    }
}

sil_step_sample_t sil_step_generator_sample(sil_step_generator_t *gen, double t_s)
{
    sil_step_sample_t out = {0.0, 0.0, 0.0, false};
    const sil_step_move_t *m;
    int k;
    while (gen->current + 1 < gen->moves && t_s >= gen->move[gen->current].end_s) {
        gen->current++;
    }
    if (gen->moves == 0) {
        return out;
    }
    m = &gen->move[gen->current];
    if (t_s < m->start_s) {
        out.position_rad = m->from_rad; /* waiting for it: at rest where the move before ended */
        return out;
    }
    if (t_s >= m->end_s) {
        out.position_rad = m->to_rad; /* ended exactly on its target (no round-off of the segments) */
        return out;
    }
    for (k = 0; k < m->segments; ++k) {
        const sil_step_segment_t *seg = &m->segment[k];
        if (t_s < seg->end_s || k + 1 == m->segments) {
            const double h = t_s - seg->start_s;
            out.position_rad =
                seg->position_rad + h * (seg->speed_rad_s + h * (0.5 * seg->accel_rad_s2 + h * seg->jerk_rad_s3 / 6.0));
            out.speed_rad_s = seg->speed_rad_s + h * (seg->accel_rad_s2 + 0.5 * h * seg->jerk_rad_s3);
            out.accel_rad_s2 = seg->accel_rad_s2 + h * seg->jerk_rad_s3;
            break;
        }
    }
    out.moving = true;
    return out;
}

int32_t sil_step_generator_count(const sil_step_generator_t *gen, double position_rad)
{
    return (int32_t)floor(position_rad / gen->rad_per_microstep);
}

double sil_step_generator_first_start_s(const sil_step_generator_t *gen)
{
    return gen->moves > 0 ? gen->move[0].start_s : 0.0;
}

double sil_step_generator_last_end_s(const sil_step_generator_t *gen)
{
    return gen->moves > 0 ? gen->move[gen->moves - 1].end_s : 0.0;
}
