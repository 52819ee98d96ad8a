/* Motion profile (pmstep_motion.c): ends exactly at the target, keeps its limits, its speed,
 * acceleration and jerk are the derivatives of its position, re-targets while moving, stops. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pmstep/pmstep_motion.h"

#define PERIOD_S 5e-5f
#define MAX_PERIODS 4000000L

/* What a run of the profile to its end showed. */
typedef struct {
    long periods;           /* until finished */
    double max_speed;       /* max |v| */
    double max_accel;       /* max |a| */
    double max_jerk;        /* max |j| */
    double max_overshoot;   /* largest excursion beyond the target, away from the start */
    double max_rate_error;  /* max of |p[k+1]-p[k] - T (v[k]+v[k+1])/2| over its bound (below) */
    double max_accel_error; /* same for v and a */
    double last_position;   /* the sample before the end */
    float final_position;   /* the first finished sample */
    double final_speed;
} run_t;

/* Runs @p m to its end from the sample @p first (already taken), checking as it goes. */
/* One float32 ulp at |x|. */
static double ulp(double x)
{
    const float f = (float)fabs(x);
    return (double)(nextafterf(f, INFINITY) - f);
}

/* The trapezoid rule's error over one period (below j T^3/6 for the position, j T^2 for the
 * speed at a change of jerk) and float32 resolution: four ulps of each value (the sample's own
 * rounding and the segment start's, carried from the previous segment) and the rate times four
 * ulps of the time t of the sample (t and t - t_start, float32). Position, speed and acceleration
 * are then derivatives of one another to float32 resolution. */
static double rule_ratio(double step, double mean_rate, double x0, double x1, double rule_error, double t_s)
{
    const double bound = rule_error + 4.0 * (ulp(x0) + ulp(x1)) + 4.0 * PERIOD_S * ulp(mean_rate)
                         + 4.0 * fabs(mean_rate) * ulp(t_s) + 1e-30;
    return fabs(step - PERIOD_S * mean_rate) / bound;
}

static run_t run_to_end(pmstep_motion_t *m, pmstep_motion_sample_t first, double start)
{
    run_t r = {0};
    pmstep_motion_sample_t prev = first;
    const double target = (double)m->target;
    const double direction = target >= start ? 1.0 : -1.0;
    r.max_speed = fabs((double)first.speed);
    r.max_accel = fabs((double)first.accel);
    r.max_jerk = fabs((double)first.jerk);
    while (!pmstep_motion_finished(m) && r.periods < MAX_PERIODS) {
        const pmstep_motion_sample_t s = pmstep_motion_next(m);
        const double mean_speed = 0.5 * ((double)prev.speed + (double)s.speed);
        const double mean_accel = 0.5 * ((double)prev.accel + (double)s.accel);
        const double t_s = (double)(r.periods + 1) * PERIOD_S;
        r.max_speed = fmax(r.max_speed, fabs((double)s.speed));
        r.max_accel = fmax(r.max_accel, fabs((double)s.accel));
        r.max_jerk = fmax(r.max_jerk, fabs((double)s.jerk));
        r.max_overshoot = fmax(r.max_overshoot, direction * ((double)s.position - target));
        if (pmstep_motion_finished(m)) {
            break; /* the end: onto the target exactly, checked apart (last_position) */
        }
        r.max_rate_error =
            fmax(r.max_rate_error,
                 rule_ratio((double)s.position - (double)prev.position, mean_speed, (double)prev.position,
                            (double)s.position, (double)m->j_max * PERIOD_S * PERIOD_S * PERIOD_S / 6.0, t_s));
        r.max_accel_error =
            fmax(r.max_accel_error, rule_ratio((double)s.speed - (double)prev.speed, mean_accel, (double)prev.speed,
                                               (double)s.speed, (double)m->j_max * PERIOD_S * PERIOD_S, t_s));
        if (!pmstep_motion_finished(m)) {
            r.last_position = (double)s.position;
        }
        prev = s;
        r.periods++;
    }
    {
        const pmstep_motion_sample_t end = pmstep_motion_next(m);
        r.final_position = end.position;
        r.final_speed = (double)end.speed;
        assert_true(end.accel == 0.0f && end.jerk == 0.0f);
    }
    return r;
}

static uint32_t rng_state = 12345u;
static double uniform(double low, double high)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return low + (high - low) * (double)(rng_state >> 8) / 16777216.0;
}

static void check_limits(const run_t *r, double v_max, double a_max, double j_max)
{
    assert_true(r->max_speed <= v_max * (1.0 + 1e-5));
    assert_true(r->max_accel <= a_max * (1.0 + 1e-5));
    assert_true(r->max_jerk <= j_max * (1.0 + 1e-6));
}

static void random_moves_from_rest_end_exactly_within_limits_without_overshoot(void **state)
{
    pmstep_motion_t m;
    double worst_overshoot = 0.0;
    double worst_jump = 0.0;
    double worst_rate = 0.0;
    double worst_accel = 0.0;
    double position = 0.0;
    int n;
    (void)state;
    pmstep_motion_reset(&m, 0.0f, PERIOD_S);
    for (n = 0; n < 200; ++n) {
        const float target = (float)uniform(-62.8, 62.8); /* +-10 revolutions */
        const double v_max = uniform(1.0, 60.0);
        const double a_max = uniform(10.0, 3000.0);
        const double j_max = a_max * uniform(20.0, 300.0);
        pmstep_motion_sample_t first;
        run_t r;
        pmstep_motion_plan(&m, (float)position, 0.0f, 0.0f, target, (float)v_max, (float)a_max, (float)j_max);
        first = pmstep_motion_next(&m);
        assert_float_equal(first.position, (float)position, 0.0f);
        r = run_to_end(&m, first, position);
        assert_true(r.periods < MAX_PERIODS);
        assert_true(r.final_position == target); /* exactly */
        assert_true(r.final_speed == 0.0);
        check_limits(&r, v_max, a_max, j_max);
        /* in ulps of the move's largest position */
        worst_overshoot = fmax(worst_overshoot, r.max_overshoot / ulp(fmax(fabs((double)target), fabs(position))));
        worst_jump = fmax(worst_jump, fabs(r.last_position - (double)target));
        worst_rate = fmax(worst_rate, r.max_rate_error);
        worst_accel = fmax(worst_accel, r.max_accel_error);
        position = (double)target;
    }
    print_message("200 random moves: overshoot %.3g ulp of the target, last step onto the target %.3g rad, "
                  "speed vs position %.3g and accel vs speed %.3g of their bounds\n",
                  worst_overshoot, worst_jump, worst_rate, worst_accel);
    assert_true(worst_overshoot <= 4.0); /* none beyond float32 resolution */
    /* the last period before the end is within one period's travel at the final approach (a jerk
     * ramp: j T^3/6, far below a microradian) plus float round-off of a 60 rad position (4e-6) */
    assert_true(worst_jump < 2e-5);
    assert_true(worst_rate <= 1.0);
    assert_true(worst_accel <= 1.0);
}

static void long_move_takes_the_analytic_time(void **state)
{
    /* d = 10, v = 2, a = 20, j = 2000: T = d/v + v/a + a/j = 5 + 0.1 + 0.01 s. */
    pmstep_motion_t m;
    run_t r;
    (void)state;
    pmstep_motion_reset(&m, 0.0f, PERIOD_S);
    pmstep_motion_plan(&m, 0.0f, 0.0f, 0.0f, 10.0f, 2.0f, 20.0f, 2000.0f);
    r = run_to_end(&m, pmstep_motion_next(&m), 0.0);
    assert_in_range(r.periods, (long)(5.11 / PERIOD_S) - 2, (long)(5.11 / PERIOD_S) + 2);
    assert_float_equal(r.max_speed, 2.0, 1e-5);
    assert_float_equal(r.max_accel, 20.0, 1e-4);
}

static void short_move_does_not_reach_the_speed_limit(void **state)
{
    pmstep_motion_t m;
    run_t r;
    (void)state;
    pmstep_motion_reset(&m, 1.0f, PERIOD_S);
    pmstep_motion_plan(&m, 1.0f, 0.0f, 0.0f, 0.99f, 10.0f, 100.0f, 1e4f);
    r = run_to_end(&m, pmstep_motion_next(&m), 1.0);
    assert_true(r.final_position == 0.99f);
    assert_true(r.max_speed < 10.0);
    assert_true(r.max_overshoot <= 2.0 * ulp(0.99));
    check_limits(&r, 10.0, 100.0, 1e4);
}

/* Re-targets at a random instant of a random move; the profile must continue from the sample it
 * would have given next, end exactly at the new target and keep the limits. */
static void retarget_mid_move_is_continuous_and_ends_exactly(void **state)
{
    pmstep_motion_t m;
    double worst_step = 0.0;
    int n;
    (void)state;
    for (n = 0; n < 300; ++n) {
        const float first_target = (float)uniform(-30.0, 30.0);
        const float second_target = (n % 3 == 0) ? first_target * 0.5f : (float)uniform(-30.0, 30.0);
        const double v_max = uniform(2.0, 40.0);
        const double a_max = uniform(20.0, 2000.0);
        const double j_max = a_max * uniform(20.0, 300.0);
        const double v2 = (n % 4 == 1) ? v_max * 0.3 : v_max; /* sometimes lower limits on the re-target */
        const double a2 = (n % 4 == 1) ? a_max * 0.5 : a_max;
        long until;
        long k;
        pmstep_motion_sample_t last;
        pmstep_motion_sample_t next;
        pmstep_motion_sample_t first;
        run_t r;
        pmstep_motion_reset(&m, 0.0f, PERIOD_S);
        pmstep_motion_plan(&m, 0.0f, 0.0f, 0.0f, first_target, (float)v_max, (float)a_max, (float)j_max);
        until = (long)uniform(1.0, 20000.0);
        last = pmstep_motion_next(&m);
        for (k = 0; k < until && !pmstep_motion_finished(&m); ++k) {
            last = pmstep_motion_next(&m);
        }
        next = pmstep_motion_peek(&m);
        pmstep_motion_plan(&m, next.position, next.speed, next.accel, second_target, (float)v2, (float)a2,
                           (float)j_max);
        first = pmstep_motion_next(&m);
        assert_true(first.position == next.position && first.speed == next.speed && first.accel == next.accel);
        worst_step = fmax(worst_step, fabs((double)first.position - (double)last.position));
        r = run_to_end(&m, first, (double)next.position);
        assert_true(r.final_position == second_target);
        /* the speed and acceleration of the moment of the re-target may exceed lower new limits;
         * from there the acceleration only comes down, at j_max, and the speed goes on at most to where
         * that leaves it (|v| + a^2/(2 j)) */
        check_limits(&r, fmax(v2, fabs((double)next.speed) + (double)next.accel * (double)next.accel / (2.0 * j_max)),
                     fmax(a2, fabs((double)next.accel)), j_max);
        assert_true(r.max_rate_error <= 1.0);
        assert_true(r.max_accel_error <= 1.0);
    }
    print_message("300 re-targets: largest position step at the re-target %.3g rad\n", worst_step);
    assert_true(worst_step < 40.0 * 5e-5 * 1.01); /* one period at the largest speed */
}

static void retarget_behind_reverses_after_a_stop(void **state)
{
    pmstep_motion_t m;
    pmstep_motion_sample_t s;
    pmstep_motion_sample_t next;
    run_t r;
    long k;
    (void)state;
    pmstep_motion_reset(&m, 0.0f, PERIOD_S);
    pmstep_motion_plan(&m, 0.0f, 0.0f, 0.0f, 10.0f, 5.0f, 50.0f, 5000.0f);
    for (k = 0; k < 20000; ++k) { /* 1 s: cruising at 5 rad/s near 4.7 rad */
        s = pmstep_motion_next(&m);
    }
    assert_float_equal(s.speed, 5.0f, 1e-5f);
    next = pmstep_motion_peek(&m);
    pmstep_motion_plan(&m, next.position, next.speed, next.accel, 4.8f, 5.0f, 50.0f,
                       5000.0f); /* nearer than the stop */
    r = run_to_end(&m, pmstep_motion_next(&m), (double)next.position);
    assert_true(r.final_position == 4.8f);
    check_limits(&r, 5.0, 50.0, 5000.0);
}

static void stop_ends_at_rest_where_it_says(void **state)
{
    pmstep_motion_t m;
    pmstep_motion_sample_t s;
    pmstep_motion_sample_t next;
    run_t r;
    long k;
    (void)state;
    pmstep_motion_reset(&m, 0.0f, PERIOD_S);
    pmstep_motion_plan(&m, 0.0f, 0.0f, 0.0f, -10.0f, 5.0f, 50.0f, 5000.0f);
    for (k = 0; k < 1500; ++k) { /* accelerating: a != 0 at the stop */
        s = pmstep_motion_next(&m);
    }
    assert_true(s.accel < -1.0f);
    next = pmstep_motion_peek(&m);
    pmstep_motion_stop(&m, &next);
    r = run_to_end(&m, pmstep_motion_next(&m), (double)next.position);
    check_limits(&r, 5.0, 50.0, 5000.0);
    assert_true(r.final_position == m.target);
    assert_true(m.target < next.position);        /* it went on in its direction ... */
    assert_true(m.target > next.position - 1.0f); /* ... by about v^2/(2a) + the ramps */
    assert_true(fabs(r.last_position - (double)m.target) < 1e-5);
    /* at rest: a later next() stays at the target */
    s = pmstep_motion_next(&m);
    assert_true(s.position == m.target && s.speed == 0.0f);
}

static void zero_length_move_and_shift(void **state)
{
    pmstep_motion_t m;
    pmstep_motion_sample_t s;
    (void)state;
    pmstep_motion_reset(&m, 2.0f, PERIOD_S);
    pmstep_motion_plan(&m, 2.0f, 0.0f, 0.0f, 2.0f, 1.0f, 1.0f, 1.0f);
    assert_true(pmstep_motion_finished(&m));
    s = pmstep_motion_next(&m);
    assert_true(s.position == 2.0f && s.speed == 0.0f);
    pmstep_motion_plan(&m, 2.0f, 0.0f, 0.0f, 3.0f, 1.0f, 10.0f, 100.0f);
    (void)pmstep_motion_next(&m);
    pmstep_motion_shift(&m, -2.0f);
    assert_true(m.target == 1.0f);
    s = pmstep_motion_next(&m);
    assert_true(s.position < 0.01f && s.position > 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(random_moves_from_rest_end_exactly_within_limits_without_overshoot),
        cmocka_unit_test(long_move_takes_the_analytic_time),
        cmocka_unit_test(short_move_does_not_reach_the_speed_limit),
        cmocka_unit_test(retarget_mid_move_is_continuous_and_ends_exactly),
        cmocka_unit_test(retarget_behind_reverses_after_a_stop),
        cmocka_unit_test(stop_ends_at_rest_where_it_says),
        cmocka_unit_test(zero_length_move_and_shift),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
