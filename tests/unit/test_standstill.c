/* The standstill hold of speed mode (pmstep_hold.h) against the real module on the paper
 * instance put in RUN (k_M = 2 N m/A, J = 0.01 kg m^2, p = 6, 20 kHz) with a hold current of
 * 7.5 A, pmstep_standstill_advance() driven with hand-made period outputs: the engagement at rest,
 * the kept estimate, the settling on the aim, the following of a held rotor that moves, the
 * clearance of the phase axes, the commands that keep or end it, its validation. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_text.h"
#include "../../firmware/src/pmstep_internal.h" /* pmstep_standstill_start, _advance */
#include "paper_in_run.h"

static void fixture_with_standstill(paper_run_t *f)
{
    assert_int_equal(paper_instance_in_run(&f->cfg, &f->inst), PMSTEP_OK);
    f->cfg.standstill.hold_current_A = 7.5f;
    pmstep_standstill_start(&f->inst);
}

/* One period after the control step's: the integrals read @p reading, in whose place the step
 * puts out the kept rotor where the standstill keeps its estimate (pmstep_control.c); the
 * integrals are left at the reading, where the motion sum reads it. */
static void standstill_period(paper_run_t *f, const pmstep_output_t *reading)
{
    pmstep_output_t out = *reading;
    if (f->inst.estimate_kept) {
        pmstep_angle_set(&f->inst.angle, &f->inst.derived.angle_coeffs, reading->cos_hat, reading->sin_hat);
        pmstep_standstill_estimate(&f->inst, &out.cos_hat, &out.sin_hat);
    }
    pmstep_standstill_advance(&f->inst, &out);
}

static pmstep_output_t at_rest_output(float cos_hat, float sin_hat)
{
    pmstep_output_t out = {0};
    out.cos_hat = cos_hat;
    out.sin_hat = sin_hat;
    return out;
}

static void standstill_engages_after_the_engage_time_at_rest(void **state)
{
    paper_run_t f;
    const double w_n = sqrt(6.0 * 2.0 * 7.5 / 0.01);
    pmstep_output_t out = at_rest_output(0.6f, 0.8f);
    uint32_t engage;
    uint32_t n;
    (void)state;
    fixture_with_standstill(&f);
    engage = f.inst.scratch.run.standstill.engage_periods;
    assert_true(f.inst.hold.standstill_armed);
    assert_int_equal(engage, (uint32_t)(2.0f / (f.cfg.gains.speed_gain_per_s * f.cfg.timing.period_s)));
    assert_float_equal(f.inst.scratch.run.standstill.quiet_band_rad_s, 0.05 * w_n / 6.0, 1e-6 * w_n);
    /* a rotor not at rest (|w-hat| over the band) restarts the count */
    for (n = 1; n < engage; ++n) {
        standstill_period(&f, &out);
    }
    out.speed_hat_rad_s = 1.1f * f.inst.scratch.run.standstill.quiet_band_rad_s;
    standstill_period(&f, &out);
    assert_false(f.inst.hold.active);
    out.speed_hat_rad_s = 0.0f;
    for (n = 1; n < engage; ++n) {
        standstill_period(&f, &out);
    }
    assert_false(f.inst.hold.active);
    standstill_period(&f, &out);
    assert_true(f.inst.hold.active && f.inst.hold.standstill_engaged);
    /* aimed at the estimate's direction (T_L-hat 0, no detent torque), at the hold's current */
    assert_float_equal(f.inst.hold.cos_vector, 0.6f, 1e-6f);
    assert_float_equal(f.inst.hold.sin_vector, 0.8f, 1e-6f);
    assert_float_equal(f.inst.hold.current_A, 7.5f, 0.0f);
}

/* The standstill keeps the damping term where the vector hold's rule drops it (w-hat lagging the
 * swing: here the observer's triple pole at w_n / 2, Re(w-hat/w) below 1/2 at w_n): it engages
 * with a step of the vector's current, whose first swing the term shortens (docs/design/12-position-hold.md). */
static void standstill_keeps_its_damping_where_the_estimate_lags(void **state)
{
    paper_run_t f;
    const double w_n = sqrt(6.0 * 2.0 * 7.5 / 0.01);
    const double g = 2.0 * 0.7 * 6.0 / w_n;
    const pmstep_output_t out = at_rest_output(1.0f, 0.0f);
    uint32_t n;
    (void)state;
    fixture_with_standstill(&f);
    (void)paper_observer_at_triple_pole(&f.inst.derived.observer_coeffs, 0.5 * w_n);
    for (n = 0; n < f.inst.scratch.run.standstill.engage_periods; ++n) {
        standstill_period(&f, &out);
    }
    assert_true(f.inst.hold.active && f.inst.hold.standstill_engaged);
    assert_float_equal(f.inst.hold.damping_s, g, 1e-5 * g);
    /* the same aim through pmstep_hold_vector: no damping term */
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
    assert_float_equal(f.inst.hold.damping_s, 0.0f, 0.0f);
}

static void standstill_waits_for_the_zero_command_reached(void **state)
{
    paper_run_t f;
    pmstep_output_t out = at_rest_output(1.0f, 0.0f);
    uint32_t n;
    (void)state;
    fixture_with_standstill(&f);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 5.0f, 100.0f), PMSTEP_OK);
    for (n = 0; n < 4u * f.inst.scratch.run.standstill.engage_periods; ++n) {
        standstill_period(&f, &out); /* a non-zero command */
    }
    assert_false(f.inst.hold.active);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 100.0f), PMSTEP_OK);
    out.speed_ref_rad_s = 0.02f * f.inst.scratch.run.standstill.quiet_band_rad_s; /* w* still on its way */
    for (n = 0; n < 4u * f.inst.scratch.run.standstill.engage_periods; ++n) {
        standstill_period(&f, &out);
    }
    assert_false(f.inst.hold.active);
}

/* The hold engaged on an estimate at (1, 0) and settled with the integrals on the aim: the
 * estimate kept there from the settling on; @return the settling periods. */
static uint32_t standstill_settled(paper_run_t *f)
{
    const pmstep_output_t out = at_rest_output(1.0f, 0.0f);
    uint32_t settle;
    uint32_t n;
    fixture_with_standstill(f);
    while (!f->inst.hold.active) {
        standstill_period(f, &out);
    }
    settle = f->inst.hold.settle_periods;
    for (n = 0; n < settle; ++n) {
        standstill_period(f, &out);
    }
    assert_true(f->inst.hold.standstill_settled);
    assert_float_equal(f->inst.scratch.run.standstill.keep_cos, 1.0f, 0.0f);
    assert_float_equal(f->inst.scratch.run.standstill.keep_sin, 0.0f, 0.0f);
    assert_true(f->inst.scratch.run.standstill.rest_periods > settle); /* nothing to take: kept from now */
    return settle;
}

static float estimate_angle(const paper_run_t *f) { return paper_estimate_angle(&f->inst); }

/* Settled, the estimate is put back every period: a drift of the integrals whose rate times the
 * settling time is 0.9 x the motion bound is learnt before the sum reaches the bound (the sum
 * then falls back as the learnt drift is taken off the turns); while the rotor moves (w-hat) the
 * estimate follows the integrals. */
static void standstill_keeps_the_estimate_while_the_rotor_rests(void **state)
{
    paper_run_t f;
    pmstep_output_t out;
    uint32_t settle;
    uint32_t n;
    float drift_rad;
    float largest_sum_rad = 0.0f;
    float c;
    float s;
    (void)state;
    settle = standstill_settled(&f);
    drift_rad = 0.9f * PMSTEP_HOLD_MOTION_BOUND_RAD / (float)(settle + 1u);
    for (n = 0; n < 10u * settle; ++n) {
        out = at_rest_output(cosf(drift_rad), sinf(drift_rad)); /* the kept (1, 0) turned on by the drift */
        standstill_period(&f, &out);
        assert_float_equal(estimate_angle(&f), 0.0f, 1e-6f);
        if (f.inst.scratch.run.standstill.motion_rad > largest_sum_rad) {
            largest_sum_rad = f.inst.scratch.run.standstill.motion_rad;
        }
    }
    assert_true(largest_sum_rad > 0.3f * PMSTEP_HOLD_MOTION_BOUND_RAD); /* it was seen */
    assert_true(largest_sum_rad < PMSTEP_HOLD_MOTION_BOUND_RAD);
    assert_true(f.inst.scratch.run.standstill.motion_rad < 0.2f * PMSTEP_HOLD_MOTION_BOUND_RAD);
    assert_float_equal(f.inst.scratch.run.standstill.drift_rad, drift_rad, 0.1f * drift_rad);
    assert_true(f.inst.scratch.run.standstill.rest_periods > 10u * settle);
    /* moving (|w-hat - w-bar| over the hold's band): the estimate is left to the integrals */
    out = at_rest_output(0.8f, 0.6f);                                      /* the integrals' reading */
    f.inst.observer.speed_hat_rad_s = 2.0f * f.inst.hold.quiet_band_rad_s; /* the observer's, after the period */
    standstill_period(&f, &out);
    pmstep_angle_estimate(&f.inst.angle, &f.inst.derived.angle_coeffs, f.inst.angle.i_a_prev_A, f.inst.angle.i_b_prev_A,
                          &c, &s);
    assert_float_equal(c, 0.8f, 1e-6f);
    assert_float_equal(s, 0.6f, 1e-6f);
    assert_int_equal(f.inst.scratch.run.standstill.rest_periods, 0u);
}

/* Kept, the estimate put out is the kept rotor itself, not the integrals' reading of the period
 * (the current samples' noise, 0.84 rad/A on the 17HS4401, twice over in a reading taken a period
 * after the estimate was put back): the reading goes to the motion sum. Moving, the reading is
 * put out again. */
static void standstill_puts_out_the_kept_rotor(void **state)
{
    paper_run_t f;
    uint32_t n;
    (void)state;
    (void)standstill_settled(&f);
    {
        const pmstep_output_t out = at_rest_output(1.0f, 0.0f); /* the first kept period */
        assert_false(f.inst.estimate_kept);
        standstill_period(&f, &out);
    }
    for (n = 0; n < 6u; ++n) {
        const float noise_rad = 4e-3f; /* the reading 4e-3 rad on, each period */
        float c = cosf(noise_rad);
        float s = sinf(noise_rad);
        pmstep_output_t out;
        assert_true(f.inst.estimate_kept);
        pmstep_angle_set(&f.inst.angle, &f.inst.derived.angle_coeffs, c, s); /* what the integrals read */
        pmstep_standstill_estimate(&f.inst, &c, &s);
        assert_float_equal(c, 1.0f, 0.0f);
        assert_float_equal(s, 0.0f, 0.0f);
        out = at_rest_output(c, s);
        pmstep_standstill_advance(&f.inst, &out);
    }
    /* the readings' turns reached the sum: 6 x 4e-3 rad, less the leak (1/(settle + 1) a period) */
    assert_float_equal(f.inst.scratch.run.standstill.motion_rad, 0.024f, 1e-3f);
    {
        paper_run_t released = f; /* a hold released puts the integrals' estimate out again */
        assert_true(released.inst.estimate_kept);
        pmstep_release_vector(&released.inst);
        assert_false(released.inst.estimate_kept);
    }
    f.inst.observer.speed_hat_rad_s = 2.0f * f.inst.hold.quiet_band_rad_s; /* moving */
    {
        const pmstep_output_t out = at_rest_output(0.8f, 0.6f);
        standstill_period(&f, &out);
    }
    assert_false(f.inst.estimate_kept);
}

/* At the settling the estimate is put where the vector holds the rotor: the aim, T_L-hat's load
 * angle behind the vector, however far the integrals drifted while the current stepped up, as
 * long as that is within the motion bound; beyond it the rotor went elsewhere (a load that
 * T_L-hat did not know), and the integrals' estimate is kept. T_L-hat is the held rotor's balance
 * at the estimate kept. */
static void standstill_settles_on_the_aim(void **state)
{
    static const float drifted_rad[] = {0.04f, -0.04f, 0.08f};
    size_t k;
    (void)state;
    for (k = 0; k < sizeof drifted_rad / sizeof drifted_rad[0]; ++k) {
        paper_run_t f;
        const float aim_rad = 0.3f;
        const float load_Nm = 3.0f; /* k_M I = 15 N m: a load angle of asin(0.2) */
        pmstep_output_t out = at_rest_output(cosf(aim_rad), sinf(aim_rad));
        const float kept_rad =
            pmstep_abs(drifted_rad[k]) > PMSTEP_HOLD_MOTION_BOUND_RAD ? aim_rad + drifted_rad[k] : aim_rad;
        uint32_t n;
        fixture_with_standstill(&f);
        f.inst.observer.load_hat_Nm = load_Nm;
        while (!f.inst.hold.active) {
            standstill_period(&f, &out);
        }
        f.inst.observer.speed_hat_rad_s = 0.3f; /* the observer's transient from the current step */
        assert_float_equal(atan2f(f.inst.hold.sin_vector, f.inst.hold.cos_vector), aim_rad + asinf(0.2f), 1e-5f);
        out = at_rest_output(cosf(aim_rad + drifted_rad[k]), sinf(aim_rad + drifted_rad[k]));
        for (n = 0; n < f.inst.hold.settle_periods; ++n) {
            assert_false(f.inst.hold.standstill_settled);
            standstill_period(&f, &out);
        }
        assert_true(f.inst.hold.standstill_settled);
        assert_float_equal(estimate_angle(&f), kept_rad, 1e-5f);
        assert_float_equal(f.inst.observer.speed_hat_rad_s, f.inst.hold.speed_bias_rad_s, 0.0f);
        assert_float_equal(f.inst.observer.load_hat_Nm, 15.0f * sinf(aim_rad + asinf(0.2f) - kept_rad), 1e-3f);
    }
}

/* A load step on the held rotor: the integrals turn the estimate by 0.01 rad a period, which
 * w-hat does not see. Once the summed turn passes the bound the estimate is turned by it,
 * T_L-hat set to the held rotor's balance there, and the rest starts again. */
static void standstill_follows_a_held_rotor_that_moves(void **state)
{
    paper_run_t f;
    pmstep_output_t out;
    float kept_rad;
    float moved_rad = 0.0f;
    float estimate_rad;
    uint32_t periods = 0u;
    (void)state;
    (void)standstill_settled(&f);
    kept_rad = atan2f(f.inst.scratch.run.standstill.keep_sin, f.inst.scratch.run.standstill.keep_cos);
    f.inst.observer.load_hat_Nm = 0.0f;
    while (f.inst.scratch.run.standstill.rest_periods > 0u) {
        /* the kept estimate turned on by this period's 0.01 rad */
        out = at_rest_output(cosf(kept_rad - 0.01f), sinf(kept_rad - 0.01f));
        moved_rad = f.inst.scratch.run.standstill.motion_rad;
        standstill_period(&f, &out);
        assert_true(++periods < 10u);
    }
    /* 6 periods: the sum (leaking by 1/(settle + 1) a period) passes 0.05 rad at the sixth */
    assert_int_equal(periods, 6u);
    assert_true(-moved_rad < PMSTEP_HOLD_MOTION_BOUND_RAD);
    estimate_rad = estimate_angle(&f);
    assert_true(estimate_rad < kept_rad - PMSTEP_HOLD_MOTION_BOUND_RAD);
    assert_true(estimate_rad > kept_rad - 0.06f);
    assert_float_equal(f.inst.scratch.run.standstill.motion_rad, 0.0f, 0.0f);
    /* T_L-hat = k_M I sin(v - x-hat): v the vector aimed at engagement, (1, 0); no detent torque */
    assert_float_equal(f.inst.hold.cos_vector, 1.0f, 0.0f);
    assert_float_equal(f.inst.observer.load_hat_Nm, 2.0f * 7.5f * sinf(-estimate_rad), 1e-3f);
    /* the rest's first settling time again: the estimate taken where the integrals go */
    out = at_rest_output(cosf(estimate_rad - 0.01f), sinf(estimate_rad - 0.01f));
    standstill_period(&f, &out);
    assert_float_equal(f.inst.scratch.run.standstill.keep_cos, cosf(estimate_rad - 0.01f), 1e-6f);
    assert_float_equal(f.inst.scratch.run.standstill.keep_sin, sinf(estimate_rad - 0.01f), 1e-6f);
}

/* With a compensation band the standstill aims its vector so that both phase currents are
 * PMSTEP_HOLD_PHASE_CLEARANCE_BANDS bands clear of zero; without one, at the estimate. The
 * clearance is of the vector, T_L-hat's load angle ahead of the rest: with k_M I = 15 N m and
 * T_L-hat = 3 N m (delta = asin 0.2), an estimate at 0.01 - delta put the vector 0.01 rad off phase
 * a's axis, with phase b's current almost zero; the rest is turned with the vector. */
static void standstill_aims_clear_of_the_phase_axes(void **state)
{
    static const struct {
        float cos_hat, sin_hat, band_A, load_Nm, cos_vector, sin_vector;
    } cases[] = {
        /* 25 x 0.01 A of 7.5 A: the smaller component at least 1/30 */
        {1.0f, 0.0f, 0.01f, 0.0f, 0.99944427f, 1.0f / 30.0f},
        {-0.9999f, -0.0141418f, 0.01f, 0.0f, -0.99944427f, -1.0f / 30.0f},
        {0.02f, -0.9998f, 0.01f, 0.0f, 1.0f / 30.0f, -0.99944427f},
        {0.6f, 0.8f, 0.01f, 0.0f, 0.6f, 0.8f},              /* clear already */
        {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f},               /* no band: at the estimate */
        {1.0f, 0.0f, 1.0f, 0.0f, 0.70710678f, 0.70710678f}, /* a clearance beyond the diagonal: the diagonal */
        /* the estimate clear, its vector not: at 0.01 rad from phase a's axis */
        {0.9817469f, -0.1901922f, 0.01f, 3.0f, 0.99944427f, 1.0f / 30.0f},
        {0.9817469f, 0.1901922f, 0.01f, -3.0f, 0.99944427f, -1.0f / 30.0f},
    };
    size_t k;
    (void)state;
    for (k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        paper_run_t f;
        pmstep_output_t out = at_rest_output(cases[k].cos_hat, cases[k].sin_hat);
        const float delta_rad = asinf(cases[k].load_Nm / 15.0f);
        float rest_rad;
        fixture_with_standstill(&f);
        f.cfg.inverter.dead_time_current_band_A = cases[k].band_A;
        f.inst.observer.load_hat_Nm = cases[k].load_Nm;
        while (!f.inst.hold.active) {
            standstill_period(&f, &out);
        }
        assert_float_equal(f.inst.hold.cos_vector, cases[k].cos_vector, 1e-5f);
        assert_float_equal(f.inst.hold.sin_vector, cases[k].sin_vector, 1e-5f);
        /* the rest the vector holds: the load angle behind it */
        rest_rad = atan2f(f.inst.scratch.run.standstill.keep_sin, f.inst.scratch.run.standstill.keep_cos);
        assert_float_equal(rest_rad, atan2f(cases[k].sin_vector, cases[k].cos_vector) - delta_rad, 1e-5f);
    }
}

static void standstill_zero_command_keeps_it_other_commands_end_it(void **state)
{
    paper_run_t f;
    pmstep_output_t out = at_rest_output(1.0f, 0.0f);
    (void)state;
    fixture_with_standstill(&f);
    while (!f.inst.hold.active) {
        standstill_period(&f, &out);
    }
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    assert_true(f.inst.hold.active); /* a repeated zero: held on */
    assert_int_equal(pmstep_set_speed_target(&f.inst, -2.0f, 50.0f), PMSTEP_OK);
    assert_false(f.inst.hold.active || f.inst.hold.standstill_engaged);
    assert_true(f.inst.hold.standstill_armed); /* armed for the next zero */
    /* the position library takes the reference: released, and off until a speed command */
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    while (!f.inst.hold.active) {
        standstill_period(&f, &out);
    }
    pmstep_leave_speed_mode(&f.inst);
    pmstep_leave_speed_mode(NULL);
    assert_false(f.inst.hold.active || f.inst.hold.standstill_armed);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    assert_true(f.inst.hold.standstill_armed);
    /* an application's own hold is not the standstill's: a zero command ends it */
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, 7.5f, 0.0f), PMSTEP_OK);
    standstill_period(&f, &out);
    assert_false(f.inst.hold.standstill_engaged);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    assert_false(f.inst.hold.active);
}

static void standstill_off_without_a_current_and_validated(void **state)
{
    paper_run_t f;
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_t inst;
    (void)state;
    assert_int_equal(paper_instance_in_run(&f.cfg, &f.inst), PMSTEP_OK);
    pmstep_standstill_start(&f.inst); /* paper: hold current 0 */
    assert_false(f.inst.hold.standstill_armed);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 50.0f), PMSTEP_OK);
    assert_false(f.inst.hold.standstill_armed);
    cfg.standstill.hold_current_A = -0.1f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_HOLD_CURRENT);
    cfg.standstill.hold_current_A = cfg.limits.max_phase_current_A; /* the trip itself */
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_HOLD_CURRENT);
    cfg.standstill.hold_current_A = NAN;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_NONFINITE_PARAMETER);
    cfg.standstill.hold_current_A = 7.5f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    cfg.known_load_mode = true;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_STANDSTILL_KNOWN_LOAD);
    assert_string_equal(pmstep_status_str(PMSTEP_ERR_STANDSTILL_KNOWN_LOAD),
                        "standstill hold not with known_load_mode");
    cfg.standstill.hold_current_A = 0.0f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(standstill_engages_after_the_engage_time_at_rest),
        cmocka_unit_test(standstill_keeps_its_damping_where_the_estimate_lags),
        cmocka_unit_test(standstill_waits_for_the_zero_command_reached),
        cmocka_unit_test(standstill_keeps_the_estimate_while_the_rotor_rests),
        cmocka_unit_test(standstill_puts_out_the_kept_rotor),
        cmocka_unit_test(standstill_settles_on_the_aim),
        cmocka_unit_test(standstill_follows_a_held_rotor_that_moves),
        cmocka_unit_test(standstill_aims_clear_of_the_phase_axes),
        cmocka_unit_test(standstill_zero_command_keeps_it_other_commands_end_it),
        cmocka_unit_test(standstill_off_without_a_current_and_validated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
