/* Field weakening (pmstep_weakening.h) against the real module: the weakening current's integration of
 * the voltage's excess over the bus share, its bounds, the command it is added to, an excess a weaker
 * field cannot lower, the test of that, a non-finite input;
 * the configuration's checks; and, on a paper-configured instance put in RUN, i_d*'s target taken
 * below the command by the supervise stage where the law's voltage exceeds the bus share, and left
 * at it where it does not. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_text.h"
#include "pmstep/pmstep_weakening.h"
#include "paper_in_run.h"

#define STEP_A 0.01f
#define MAX_A 0.05f
#define BUS_V 20.0f

static pmstep_weakening_coeffs_t coeffs(void)
{
    pmstep_weakening_coeffs_t c;
    c.modulation_squared = 0.81f; /* m = 0.9: 18 V of the 20 V bus */
    c.step_A = STEP_A;
    c.max_current_A = MAX_A;
    return c;
}

/* Within the bus share the error is positive: i_w stays at 0, the target is the command. */
static void within_the_bus_nothing_is_taken(void **state)
{
    const pmstep_weakening_coeffs_t c = coeffs();
    pmstep_weakening_t w = {0.3f, 0.0f};
    (void)state;
    assert_float_equal(pmstep_weakening_update(&w, &c, 10.0f, 5.0f, BUS_V, true), 0.3f, 0.0f);
    assert_float_equal(w.weakening_A, 0.0f, 0.0f);
}

/* |u| = 2 x 18 V: e = (18^2 - 36^2) / 36^2 = -0.75, one check takes 0.75 g T_c; the target is the
 * command plus i_w; checks on stop at -I_w. */
static void an_excess_is_integrated_to_its_bound(void **state)
{
    const pmstep_weakening_coeffs_t c = coeffs();
    pmstep_weakening_t w = {0.3f, 0.0f};
    int n;
    (void)state;
    assert_float_equal(pmstep_weakening_update(&w, &c, 36.0f, 0.0f, BUS_V, true), 0.3f - 0.75f * STEP_A, 1e-7f);
    assert_float_equal(w.weakening_A, -0.75f * STEP_A, 1e-7f);
    for (n = 0; n < 20; ++n) {
        (void)pmstep_weakening_update(&w, &c, 0.0f, -36.0f, BUS_V, true);
    }
    assert_float_equal(w.weakening_A, -MAX_A, 0.0f);
    /* the voltage back within the share: i_w returns toward 0, and no further */
    assert_float_equal(pmstep_weakening_update(&w, &c, 9.0f, 0.0f, BUS_V, true), 0.3f - MAX_A + 0.75f * STEP_A, 1e-6f);
    for (n = 0; n < 20; ++n) {
        (void)pmstep_weakening_update(&w, &c, 9.0f, 0.0f, BUS_V, true);
    }
    assert_float_equal(w.weakening_A, 0.0f, 0.0f);
}

/* An excess a weaker field would not lower (the winding's drop at low speed) takes i_w back toward 0. */
static void an_excess_it_cannot_lower_takes_it_back(void **state)
{
    const pmstep_weakening_coeffs_t c = coeffs();
    pmstep_weakening_t w = {0.3f, -0.03f};
    int n;
    (void)state;
    assert_float_equal(pmstep_weakening_update(&w, &c, 36.0f, 0.0f, BUS_V, false), 0.3f - 0.03f + 0.75f * STEP_A,
                       1e-6f);
    for (n = 0; n < 4; ++n) {
        (void)pmstep_weakening_update(&w, &c, 36.0f, 0.0f, BUS_V, false);
    }
    assert_float_equal(w.weakening_A, 0.0f, 0.0f);
}

/* d|u|^2/di_d = 2 (R u_d + p w L u_q): at rest a lower i_d lowers |u| only while u_d = R i_d > 0, and
 * adds to it below i_d = 0; at speed, u_q the back EMF's sign, it takes off, either way round. */
static void it_helps_where_the_back_emf_dominates(void **state)
{
    (void)state;
    assert_true(pmstep_weakening_helps(500.0f, 6.0f, 0.0f, 30.0f, 20.0f));
    assert_false(pmstep_weakening_helps(500.0f, 6.0f, 0.0f, -30.0f, 20.0f));
    assert_true(pmstep_weakening_helps(500.0f, 6.0f, 20.0f, 1.0f, 40.0f));
    assert_true(pmstep_weakening_helps(500.0f, 6.0f, -20.0f, 1.0f, -40.0f));
    /* a large d voltage against a small speed: R u_d = 500 x -30 outweighs p w u_q = 6 x 1 x 40 */
    assert_false(pmstep_weakening_helps(500.0f, 6.0f, 1.0f, -30.0f, 40.0f));
}

/* A non-finite voltage or bus, or no voltage on no bus: i_w as it was. */
static void a_non_finite_input_leaves_it(void **state)
{
    const pmstep_weakening_coeffs_t c = coeffs();
    pmstep_weakening_t w = {0.0f, -0.02f};
    (void)state;
    (void)pmstep_weakening_update(&w, &c, NAN, 0.0f, BUS_V, true);
    assert_float_equal(w.weakening_A, -0.02f, 0.0f);
    (void)pmstep_weakening_update(&w, &c, 0.0f, INFINITY, BUS_V, true);
    assert_float_equal(w.weakening_A, -0.02f, 0.0f);
    (void)pmstep_weakening_update(&w, &c, 30.0f, 0.0f, NAN, true);
    assert_float_equal(w.weakening_A, -0.02f, 0.0f);
    (void)pmstep_weakening_update(&w, &c, 0.0f, 0.0f, 0.0f, true);
    assert_float_equal(w.weakening_A, -0.02f, 0.0f);
}

static void expect_refused(const pmstep_config_t *cfg)
{
    pmstep_t inst;
    assert_int_equal(pmstep_init(&inst, cfg), PMSTEP_ERR_FIELD_WEAKENING);
}

static void its_settings_are_checked(void **state)
{
    pmstep_config_t cfg = pmstep_paper_config();
    pmstep_t inst;
    (void)state;
    /* off: modulation and gain unread */
    cfg.field_weakening.max_current_A = 0.0f;
    cfg.field_weakening.modulation = 0.0f;
    cfg.field_weakening.gain_A_per_s = 0.0f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    cfg.field_weakening.max_current_A = -0.1f;
    expect_refused(&cfg);
    cfg.field_weakening.max_current_A = cfg.limits.max_phase_current_A;
    expect_refused(&cfg);
    cfg.field_weakening.max_current_A = 1.0f;
    cfg.field_weakening.gain_A_per_s = 100.0f;
    expect_refused(&cfg); /* modulation 0 */
    cfg.field_weakening.modulation = 1.01f;
    expect_refused(&cfg);
    cfg.field_weakening.modulation = 0.9f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    cfg.field_weakening.gain_A_per_s = 0.0f;
    expect_refused(&cfg);
    cfg.field_weakening.gain_A_per_s = NAN;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_NONFINITE_PARAMETER);
    assert_string_equal(
        pmstep_status_str(PMSTEP_ERR_FIELD_WEAKENING),
        "need field weakening current >= 0 below the trip, and if > 0 modulation in (0, 1] and gain > 0");
}

/* The periods of RUN on the paper's motor up to the first supervise stage, w-hat held at
 * @p speed_rad_s (its back EMF k_M w-hat on a 48 V bus, of which 0.9 is the share): i_d*'s target
 * after them. */
static float target_after_a_check(float speed_rad_s)
{
    paper_run_t f;
    pmstep_meas_t meas = {0};
    pmstep_output_t out;
    assert_int_equal(paper_instance_in_run(&f.cfg, &f.inst), PMSTEP_OK);
    /* the fixture inits with the paper's configuration: the weakening's settings (valid ones, as
     * its_settings_are_checked shows) and their coefficients set after it */
    f.cfg.field_weakening.max_current_A = 2.0f;
    f.cfg.field_weakening.modulation = 0.9f;
    f.cfg.field_weakening.gain_A_per_s = 1000.0f;
    pmstep_weakening_coeffs_init(&f.inst.derived.weakening_coeffs, &f.cfg);
    pmstep_continuity_start(&f.inst.scratch.run.continuity); /* RUN's start, which the fixture skips */
    pmstep_detect_start(&f.inst.scratch.run.detector);
    assert_int_equal(pmstep_set_id_target(&f.inst, 0.5f), PMSTEP_OK);
    meas.bus_voltage_V = 48.0f;
    do {
        f.inst.observer.speed_hat_rad_s = speed_rad_s;
        pmstep_step(&f.inst, &meas, &out);
        assert_int_equal(out.fault, PMSTEP_FAULT_NONE);
    } while ((f.inst.step_count % PMSTEP_DETECTION_DECIMATION) != 0u);
    return f.inst.i_d_ref.target;
}

static void run_takes_i_d_below_its_command_beyond_the_bus(void **state)
{
    float target_A;
    (void)state;
    /* k_M w-hat = 2 x 30 = 60 V, beyond 0.9 x 48 V: below the command, within I_w of it */
    target_A = target_after_a_check(30.0f);
    assert_true(target_A < 0.5f);
    assert_true(target_A >= 0.5f - 2.0f);
    /* at rest the law's voltage is far within the share: the command */
    assert_float_equal(target_after_a_check(0.0f), 0.5f, 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(within_the_bus_nothing_is_taken),
        cmocka_unit_test(an_excess_is_integrated_to_its_bound),
        cmocka_unit_test(an_excess_it_cannot_lower_takes_it_back),
        cmocka_unit_test(it_helps_where_the_back_emf_dominates),
        cmocka_unit_test(a_non_finite_input_leaves_it),
        cmocka_unit_test(its_settings_are_checked),
        cmocka_unit_test(run_takes_i_d_below_its_command_beyond_the_bus),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
