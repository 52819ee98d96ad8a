/* The standstill's low-speed drive (pmstep_hold.h) against the real module on a paper-configured
 * instance put in RUN (p = 6, k_M = 2 N m/A, 20 kHz) with a hold current of 7.5 A (k_M I =
 * 15 N m) and the drive below 10 rad/s: its validation, the engagement within the band, the
 * vector turning at the reference speed with the estimate on its aim, the voltage in the turning
 * frame, the hand-over to the law beyond the band or beyond the vector's pull, and the stop. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_text.h"
#include "../../firmware/src/pmstep_internal.h" /* pmstep_hold_voltages, the standstill's period */
#include "paper_in_run.h"

#define BAND_RAD_S 10.0f
#define HOLD_A 7.5f
#define SPEED_RAD_S 5.0f
#define LOAD_NM 3.0f /* a load angle of asin(0.2) at k_M I = 15 N m */

static void fixture_with_drive(paper_run_t *f)
{
    assert_int_equal(paper_instance_in_run(&f->cfg, &f->inst), PMSTEP_OK);
    f->cfg.standstill.hold_current_A = HOLD_A;
    f->cfg.standstill.vector_speed_rad_s = BAND_RAD_S;
    pmstep_standstill_start(&f->inst);
}

/* A period's output at the reference speed w* = w-hat = SPEED_RAD_S, the estimate at (1, 0). */
static pmstep_output_t turning_output(void)
{
    pmstep_output_t out = {0};
    out.cos_hat = 1.0f;
    out.sin_hat = 0.0f;
    out.speed_ref_rad_s = SPEED_RAD_S;
    out.speed_hat_rad_s = SPEED_RAD_S;
    return out;
}

static float angle_of(float c, float s) { return atan2f(s, c); }

static float estimate_angle(const paper_run_t *f) { return paper_estimate_angle(&f->inst); }

/* A command of SPEED_RAD_S (within the band) reached: the drive engages after the engage time. */
static void engaged_turning(paper_run_t *f, const pmstep_output_t *out)
{
    uint32_t n;
    fixture_with_drive(f);
    f->inst.observer.load_hat_Nm = LOAD_NM;
    assert_int_equal(pmstep_set_speed_target(&f->inst, SPEED_RAD_S, 100.0f), PMSTEP_OK);
    for (n = 1; n < f->inst.scratch.run.standstill.engage_periods; ++n) {
        pmstep_standstill_advance(&f->inst, out);
    }
    assert_false(f->inst.hold.active);
    pmstep_standstill_advance(&f->inst, out);
    assert_true(f->inst.hold.active && f->inst.hold.standstill_engaged);
}

static void low_speed_drive_validated(void **state)
{
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_t inst;
    (void)state;
    cfg.standstill.hold_current_A = HOLD_A;
    cfg.standstill.vector_speed_rad_s = -1.0f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_VECTOR_SPEED);
    cfg.standstill.vector_speed_rad_s = NAN;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_NONFINITE_PARAMETER);
    cfg.standstill.vector_speed_rad_s = BAND_RAD_S;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    cfg.standstill.hold_current_A = 0.0f; /* the drive turns the hold's vector: none to turn */
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_VECTOR_SPEED);
    assert_string_equal(pmstep_status_str(PMSTEP_ERR_VECTOR_SPEED),
                        "need vector speed >= 0, a hold current where > 0, and > 0 for stops only");
    cfg.standstill.vector_speed_rad_s = 0.0f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    cfg.standstill.stops_only = true; /* stops only, with no band to turn in */
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_VECTOR_SPEED);
}

/* Engaged at w* = 5 rad/s, each period turns the kept rotor by p w* T_s = 1.5e-3 rad and aims the
 * vector ahead of it by the load angle of T_L-hat + J w*' + F w* (paper: F = 0, w*' = 0 here);
 * the estimate is the kept rotor of the period throughout (the integrals are not followed). */
static void low_speed_drive_turns_the_vector_at_the_reference_speed(void **state)
{
    paper_run_t f;
    const pmstep_output_t out = turning_output();
    const float turn_rad = 6.0f * SPEED_RAD_S * 50e-6f;
    const float load_angle_rad = asinf(LOAD_NM / (2.0f * HOLD_A));
    uint32_t periods;
    uint32_t n;
    (void)state;
    engaged_turning(&f, &out);
    assert_float_equal(f.inst.hold.vector_speed_rad_s, SPEED_RAD_S, 0.0f);
    assert_float_equal(angle_of(f.inst.hold.cos_vector, f.inst.hold.sin_vector), load_angle_rad, 1e-5f);
    periods = f.inst.hold.settle_periods + 100u; /* past the settling time (1805 periods), within pi */
    for (n = 1; n <= periods; ++n) {
        pmstep_standstill_advance(&f.inst, &out);
        assert_float_equal(estimate_angle(&f), (float)(n - 1u) * turn_rad, 2e-5f);
    }
    assert_true(f.inst.hold.standstill_settled);
    assert_float_equal(angle_of(f.inst.scratch.run.standstill.keep_cos, f.inst.scratch.run.standstill.keep_sin),
                       (float)periods * turn_rad, 2e-5f);
    assert_float_equal(angle_of(f.inst.hold.cos_vector, f.inst.hold.sin_vector),
                       (float)periods * turn_rad + load_angle_rad, 2e-5f);
    assert_float_equal(f.inst.scratch.run.standstill.vector_rate_rad_s, SPEED_RAD_S, 0.0f); /* no detent torque */
    /* kept at unit length (the Newton step) */
    assert_float_equal(hypotf(f.inst.scratch.run.standstill.keep_cos, f.inst.scratch.run.standstill.keep_sin), 1.0f,
                       1e-6f);
    assert_float_equal(f.inst.scratch.run.standstill.aim_load_Nm, LOAD_NM, 1e-4f);
}

/* With a detent torque the load angle changes as the rotor turns (sin delta takes -T_detent):
 * the vector's speed handed to the voltage, w* + (d delta / dt) / p, is the speed at which the
 * aimed vector really turns from period to period: within 5e-3 rad/s of the period's mean rate,
 * where the detent's share (4 p T_d w* / (p k_M I cos delta)) swings by up to 2 rad/s. */
static void low_speed_drive_vector_rate_follows_the_detent(void **state)
{
    paper_run_t f;
    const pmstep_output_t out = turning_output();
    const float period_s = 50e-6f;
    float largest_share_rad_s = 0.0f;
    uint32_t n;
    (void)state;
    engaged_turning(&f, &out);
    f.inst.derived.law_coeffs.detent_torque_Nm = 1.5f; /* 10 % of k_M I */
    pmstep_standstill_advance(&f.inst, &out);
    for (n = 0; n < 2000u; ++n) {
        const float before_rad = angle_of(f.inst.hold.cos_vector, f.inst.hold.sin_vector);
        const float rate_rad_s = f.inst.scratch.run.standstill.vector_rate_rad_s;
        float turned_rad;
        pmstep_standstill_advance(&f.inst, &out);
        turned_rad = angle_of(f.inst.hold.cos_vector, f.inst.hold.sin_vector) - before_rad;
        turned_rad = turned_rad > 3.14159265f ? turned_rad - 6.2831853f
                                              : (turned_rad < -3.14159265f ? turned_rad + 6.2831853f : turned_rad);
        /* the mean of the rates at the period's two ends: the rate changes within it */
        {
            const float mean_rate_rad_s = 0.5f * (rate_rad_s + f.inst.scratch.run.standstill.vector_rate_rad_s);
            const float share_rad_s = pmstep_abs(rate_rad_s - SPEED_RAD_S);
            assert_float_equal(turned_rad / (6.0f * period_s), mean_rate_rad_s, 5e-3f);
            largest_share_rad_s = share_rad_s > largest_share_rad_s ? share_rad_s : largest_share_rad_s;
        }
    }
    assert_true(largest_share_rad_s > 0.3f); /* the detent's share was there to follow */
}

/* The vector's voltage turning at w_v: the current loop's at zero errors is R I on d and
 * L I p w_v + k_M w_v on q (the vector's rotation and the back EMF), put out in the frame turned
 * on by p w_v T_s (delay + 1/2), which the dead-time compensation's signs use too. */
static void low_speed_drive_voltage_turns_with_the_vector(void **state)
{
    paper_run_t f;
    pmstep_observer_input_t obs_in = {0};
    pmstep_output_t out = {0};
    const float act_rad = 6.0f * SPEED_RAD_S * 50e-6f * 0.5f; /* paper: no computational delay */
    const float u_d_V = 3.0f * HOLD_A;
    const float u_q_V = 0.006f * HOLD_A * 6.0f * SPEED_RAD_S + 2.0f * SPEED_RAD_S;
    (void)state;
    fixture_with_drive(&f);
    assert_int_equal(pmstep_hold_vector(&f.inst, 1.0f, 0.0f, HOLD_A, 0.0f), PMSTEP_OK);
    f.inst.hold.vector_speed_rad_s = SPEED_RAD_S;
    f.inst.scratch.run.standstill.vector_rate_rad_s = SPEED_RAD_S; /* no detent torque: no load-angle rate */
    f.inst.observer.speed_hat_rad_s = SPEED_RAD_S;                 /* no damping turn */
    obs_in.i_a_A = HOLD_A;
    obs_in.i_b_A = 0.0f;
    pmstep_hold_voltages(&f.inst, &obs_in, &out);
    assert_float_equal(obs_in.i_d_err_A, 0.0f, 1e-6f);
    assert_float_equal(obs_in.i_q_err_A, 0.0f, 1e-6f);
    assert_float_equal(out.u_a_V, cosf(act_rad) * u_d_V - sinf(act_rad) * u_q_V, 1e-4f);
    assert_float_equal(out.u_b_V, sinf(act_rad) * u_d_V + cosf(act_rad) * u_q_V, 1e-4f);
    assert_float_equal(angle_of(f.inst.hold.cos_frame, f.inst.hold.sin_frame), act_rad, 1e-6f);
    /* at rest the same hold is the standstill's: no turn, no rotation terms (the paths that stop
     * the vector zero its frame's rate with its speed) */
    f.inst.hold.vector_speed_rad_s = 0.0f;
    f.inst.scratch.run.standstill.vector_rate_rad_s = 0.0f;
    f.inst.observer.speed_hat_rad_s = 0.0f;
    f.inst.hold.speed_bias_rad_s = 0.0f;
    pmstep_hold_voltages(&f.inst, &obs_in, &out);
    assert_float_equal(out.u_a_V, u_d_V, 1e-4f);
    assert_float_equal(out.u_b_V, 0.0f, 1e-6f);
}

/* A command beyond the band releases the vector and starts the law from the load the vector was
 * aimed for (not the observer's own, which ran on while held); a command within it keeps it. A
 * load beyond 0.9 k_M I is beyond the vector's pull: the law takes over. */
static void low_speed_drive_hands_over_to_the_law(void **state)
{
    paper_run_t f;
    const pmstep_output_t out = turning_output();
    uint32_t n;
    (void)state;
    engaged_turning(&f, &out);
    for (n = 0; n < 2u * f.inst.hold.settle_periods; ++n) {
        pmstep_standstill_advance(&f.inst, &out);
    }
    f.inst.observer.load_hat_Nm = -1.0f;
    assert_int_equal(pmstep_set_speed_target(&f.inst, -BAND_RAD_S, 100.0f), PMSTEP_OK); /* within: held on */
    assert_true(f.inst.hold.active && f.inst.hold.standstill_engaged);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 1.01f * BAND_RAD_S, 100.0f), PMSTEP_OK);
    assert_false(f.inst.hold.active || f.inst.hold.standstill_engaged);
    assert_float_equal(f.inst.hold.vector_speed_rad_s, 0.0f, 0.0f);
    assert_float_equal(f.inst.observer.load_hat_Nm, LOAD_NM, 1e-4f);
    assert_true(f.inst.hold.standstill_armed);

    engaged_turning(&f, &out);
    f.inst.scratch.run.standstill.aim_load_Nm = 0.91f * 2.0f * HOLD_A;
    pmstep_standstill_advance(&f.inst, &out);
    assert_false(f.inst.hold.active || f.inst.hold.standstill_engaged);
}

/* Engaged and turned past its settling, then @p target_rad_s commanded and the period's reference
 * at zero: the stop's (target 0) or a reversal's passage through zero. */
static void turned_then_reference_at_zero(paper_run_t *f, pmstep_output_t *out, float target_rad_s)
{
    uint32_t n;
    engaged_turning(f, out);
    for (n = 0; n < 2u * f->inst.hold.settle_periods; ++n) {
        pmstep_standstill_advance(&f->inst, out);
    }
    assert_true(f->inst.hold.standstill_settled);
    assert_int_equal(pmstep_set_speed_target(&f->inst, target_rad_s, 100.0f), PMSTEP_OK); /* within the band */
    assert_true(f->inst.hold.active && f->inst.hold.standstill_engaged);
    out->speed_ref_rad_s = 0.0f;
    out->speed_hat_rad_s = 0.0f;
    f->inst.observer.speed_hat_rad_s = 0.0f;
    f->inst.hold.speed_bias_rad_s = 0.0f;
}

/* One period, the vector's aim before it into (@p c, @p s). */
static void period_after_vector(paper_run_t *f, const pmstep_output_t *out, float *c, float *s)
{
    *c = f->inst.hold.cos_vector;
    *s = f->inst.hold.sin_vector;
    pmstep_standstill_advance(&f->inst, out);
}

/* The reference at rest on a zero command: the vector stops (w_v = 0), aimed afresh at its kept
 * rotor for T_L,aim (no compensation band here: where it stood), and the standstill's rule takes
 * the estimate over from a new settling (the first settling time taken from the integrals, then
 * kept). */
static void low_speed_drive_stops_at_rest(void **state)
{
    paper_run_t f;
    pmstep_output_t out = turning_output();
    float c;
    float s;
    (void)state;
    turned_then_reference_at_zero(&f, &out, 0.0f);
    period_after_vector(&f, &out, &c, &s);
    assert_true(f.inst.hold.active && f.inst.hold.standstill_engaged);
    assert_false(f.inst.hold.standstill_settled);
    assert_int_equal(f.inst.scratch.run.standstill.rest_periods, 0u);
    assert_float_equal(f.inst.hold.vector_speed_rad_s, 0.0f, 0.0f);
    assert_float_equal(f.inst.hold.cos_vector, c, 1e-6f);
    assert_float_equal(f.inst.hold.sin_vector, s, 1e-6f);
    assert_float_equal(f.inst.scratch.run.standstill.aim_load_Nm, LOAD_NM, 1e-4f);
}

/* Stopped with its vector 0.03 rad off phase a's axis (phase b's current 0.2 A, within 25 bands of
 * 0.02 A): the vector is turned to sin v = 25 x 0.02 / 7.5 (as an engagement at rest is,
 * pmstep_hold.h) and its kept rotor with it, so that the motion sum does not read the dead-time
 * band's drift of phase b as motion. */
static void low_speed_drive_stops_clear_of_the_phase_axes(void **state)
{
    paper_run_t f;
    pmstep_output_t out = turning_output();
    const float clear_sin = 25.0f * 0.02f / HOLD_A;
    float vector_rad;
    float rest_rad;
    (void)state;
    turned_then_reference_at_zero(&f, &out, 0.0f);
    f.cfg.inverter.dead_time_current_band_A = 0.02f;
    f.inst.scratch.run.standstill.aim_load_Nm = 0.0f;
    f.inst.scratch.run.standstill.keep_cos = cosf(0.03f);
    f.inst.scratch.run.standstill.keep_sin = sinf(0.03f);
    pmstep_standstill_advance(&f.inst, &out);
    vector_rad = angle_of(f.inst.hold.cos_vector, f.inst.hold.sin_vector);
    rest_rad = angle_of(f.inst.scratch.run.standstill.keep_cos, f.inst.scratch.run.standstill.keep_sin);
    assert_float_equal(vector_rad, asinf(clear_sin), 1e-5f);
    assert_float_equal(rest_rad, vector_rad, 1e-5f); /* no load: the rest under the vector */
    assert_false(f.inst.hold.standstill_settled);
}

/* A reversal within the band passes w* = 0 with its target beyond it: the vector keeps its aim and
 * its settled state (no stop, no re-aim). */
static void low_speed_drive_passes_through_zero(void **state)
{
    paper_run_t f;
    pmstep_output_t out = turning_output();
    float c;
    float s;
    (void)state;
    turned_then_reference_at_zero(&f, &out, -SPEED_RAD_S);
    period_after_vector(&f, &out, &c, &s);
    assert_true(f.inst.hold.active && f.inst.hold.standstill_settled);
    assert_float_equal(f.inst.hold.cos_vector, c, 0.0f);
    assert_float_equal(f.inst.hold.sin_vector, s, 0.0f);
}

/* A command of SPEED_RAD_S held for four engage times: nothing engages (the law's). */
static void command_stays_with_the_law(paper_run_t *f, const pmstep_output_t *out)
{
    uint32_t n;
    assert_int_equal(pmstep_set_speed_target(&f->inst, SPEED_RAD_S, 100.0f), PMSTEP_OK);
    for (n = 0; n < 4u * f->inst.scratch.run.standstill.engage_periods; ++n) {
        pmstep_standstill_advance(&f->inst, out);
    }
    assert_false(f->inst.hold.active);
}

/* Without the band (0) a command within 10 rad/s is the law's: nothing engages. */
static void low_speed_drive_off_without_a_band(void **state)
{
    paper_run_t f;
    const pmstep_output_t out = turning_output();
    (void)state;
    fixture_with_drive(&f);
    f.cfg.standstill.vector_speed_rad_s = 0.0f;
    command_stays_with_the_law(&f, &out);
}

/* Stops only: a command of 5 rad/s within the band is the law's; a zero command with w* still at
 * 5 rad/s on its way down engages the turning vector; a new non-zero command releases it and
 * leaves T_L-hat as the observer's (the low-speed drive's law starts from the aim's). */
static void stops_only_engages_on_the_way_to_a_zero_command(void **state)
{
    paper_run_t f;
    const pmstep_output_t out = turning_output();
    uint32_t n;
    (void)state;
    fixture_with_drive(&f);
    f.cfg.standstill.stops_only = true;
    f.inst.observer.load_hat_Nm = LOAD_NM;
    command_stays_with_the_law(&f, &out);
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.0f, 100.0f), PMSTEP_OK);
    f.inst.speed_ref.setpoint = 0.5f * SPEED_RAD_S; /* the ramp on its way down (at rest: the standstill's test) */
    for (n = 0; n < f.inst.scratch.run.standstill.engage_periods; ++n) {
        pmstep_standstill_advance(&f.inst, &out);
    }
    assert_true(f.inst.hold.active && f.inst.hold.standstill_engaged);
    assert_float_equal(f.inst.hold.vector_speed_rad_s, SPEED_RAD_S, 0.0f);
    f.inst.observer.load_hat_Nm = -1.0f;
    assert_int_equal(pmstep_set_speed_target(&f.inst, 0.5f * SPEED_RAD_S, 100.0f), PMSTEP_OK);
    assert_false(f.inst.hold.active || f.inst.hold.standstill_engaged);
    assert_float_equal(f.inst.observer.load_hat_Nm, -1.0f, 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(low_speed_drive_validated),
        cmocka_unit_test(low_speed_drive_turns_the_vector_at_the_reference_speed),
        cmocka_unit_test(low_speed_drive_vector_rate_follows_the_detent),
        cmocka_unit_test(low_speed_drive_voltage_turns_with_the_vector),
        cmocka_unit_test(low_speed_drive_hands_over_to_the_law),
        cmocka_unit_test(low_speed_drive_stops_at_rest),
        cmocka_unit_test(low_speed_drive_stops_clear_of_the_phase_axes),
        cmocka_unit_test(low_speed_drive_passes_through_zero),
        cmocka_unit_test(low_speed_drive_off_without_a_band),
        cmocka_unit_test(stops_only_engages_on_the_way_to_a_zero_command),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
