/* Actuation stage (pmstep_actuate.h): the delay line carries the dead-time compensation with the
 * voltage, and the voltage the flux integrals take over a period where both samples fix the
 * current's sign is the command less the dead time's loss of that sign. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_actuate.h"

#define BUS_V 24.0f
#define DEAD_TIME_S 1e-6f
#define PERIOD_S 50e-6f
#define INDUCTANCE_H 0.0028f
#define BAND_A 0.005f
/* 2 V t_d / T: the loss of a phase at full current */
#define DEAD_V (2.0f * BUS_V * DEAD_TIME_S / PERIOD_S)
/* V T / (16 L) + 3 bands */
#define THRESHOLD_A (BUS_V * PERIOD_S / (16.0f * INDUCTANCE_H) + 3.0f * BAND_A)

static pmstep_config_t config(unsigned delay_periods)
{
    pmstep_config_t cfg = pmstep_paper_config();
    cfg.timing.period_s = PERIOD_S;
    cfg.timing.computational_delay_periods = delay_periods;
    cfg.motor.inductance_H = INDUCTANCE_H;
    cfg.inverter.dead_time_s = DEAD_TIME_S;
    cfg.inverter.dead_time_current_band_A = BAND_A;
    return cfg;
}

static pmstep_output_t command(float u_a_V, float u_b_V)
{
    pmstep_output_t out = {0};
    out.u_a_V = u_a_V;
    out.u_b_V = u_b_V;
    return out;
}

static pmstep_compensation_input_t signs(float i_a_A, float i_b_A)
{
    pmstep_compensation_input_t in;
    in.sign_current_a_A = i_a_A;
    in.sign_current_b_A = i_b_A;
    in.bias_a_V = 0.0f;
    in.bias_b_V = 0.0f;
    return in;
}

static pmstep_period_currents_t currents(float start_a_A, float end_a_A, float start_b_A, float end_b_A)
{
    pmstep_period_currents_t c;
    c.i_start_a_A = start_a_A;
    c.i_end_a_A = end_a_A;
    c.i_start_b_A = start_b_A;
    c.i_end_b_A = end_b_A;
    c.bias_a_V = 0.0f;
    c.bias_b_V = 0.0f;
    return c;
}

static void delay_line_carries_the_compensation(void **state)
{
    const pmstep_config_t cfg = config(1u);
    pmstep_actuate_coeffs_t coeffs;
    pmstep_actuator_t actuator;
    pmstep_compensation_input_t in = signs(1.0f, -1.0f);
    pmstep_output_t out = command(5.0f, -3.0f);
    (void)state;
    pmstep_actuate_coeffs_init(&coeffs, &cfg);
    pmstep_actuate_reset(&actuator);
    assert_true(pmstep_actuate(&actuator, &coeffs, &in, BUS_V, &out));
    /* One period of delay: nothing of this command is applied yet. */
    assert_float_equal(actuator.compensation_applied_a_V, 0.0f, 0.0f);
    assert_float_equal(out.u_a_V, 5.0f + DEAD_V, 1e-5f);
    in = signs(-1.0f, -1.0f);
    out = command(1.0f, 1.0f);
    assert_true(pmstep_actuate(&actuator, &coeffs, &in, BUS_V, &out));
    assert_float_equal(actuator.u_applied_a_V, 5.0f, 1e-5f);
    assert_float_equal(actuator.compensation_applied_a_V, DEAD_V, 1e-5f);
    assert_float_equal(actuator.u_applied_b_V, -3.0f, 1e-5f);
    assert_float_equal(actuator.compensation_applied_b_V, -DEAD_V, 1e-5f);
}

/* The compensation assumed i > 0 on phase a (reference), the samples say i < 0 throughout:
 * the bridge gained the dead time instead of losing it, 2 x DEAD_V more than assumed. Phase b:
 * the samples agree with the compensation, nothing changes. */
static void a_sign_fixed_by_the_samples_replaces_the_assumed_one(void **state)
{
    const pmstep_config_t cfg = config(0u);
    pmstep_actuate_coeffs_t coeffs;
    pmstep_actuator_t actuator;
    pmstep_compensation_input_t in = signs(1.0f, 1.0f);
    pmstep_output_t out = command(4.0f, 2.0f);
    pmstep_period_currents_t c = currents(-0.3f, -0.2f, 0.4f, 0.5f);
    float u_a_V;
    float u_b_V;
    (void)state;
    pmstep_actuate_coeffs_init(&coeffs, &cfg);
    pmstep_actuate_reset(&actuator);
    assert_true(pmstep_actuate(&actuator, &coeffs, &in, BUS_V, &out));
    /* No delay: this command's compensation is the one applied. */
    assert_float_equal(actuator.compensation_applied_a_V, DEAD_V, 1e-5f);
    assert_float_equal(actuator.compensation_applied_b_V, DEAD_V, 1e-5f);
    pmstep_actuate_voltage_over_period(&actuator, &coeffs, &c, BUS_V, &u_a_V, &u_b_V);
    assert_float_equal(u_a_V, 4.0f + 2.0f * DEAD_V, 1e-5f);
    assert_float_equal(u_b_V, 2.0f, 1e-5f);
    /* A measured voltage bias adds to the loss of the known sign. */
    c.bias_a_V = 0.1f;
    pmstep_actuate_voltage_over_period(&actuator, &coeffs, &c, BUS_V, &u_a_V, &u_b_V);
    assert_float_equal(u_a_V, 4.0f + DEAD_V + (DEAD_V + 0.1f), 1e-5f);
}

/* Within the threshold at either end, through zero, or a command within the dead time of the
 * bus: the loss is not known, the compensation's assumption (u_applied) stands. */
static void an_unknown_sign_keeps_the_assumed_voltage(void **state)
{
    const pmstep_config_t cfg = config(0u);
    pmstep_actuate_coeffs_t coeffs;
    pmstep_actuator_t actuator;
    pmstep_compensation_input_t in = signs(1.0f, 1.0f);
    pmstep_output_t out = command(4.0f, 2.0f);
    float u_a_V;
    float u_b_V;
    pmstep_period_currents_t c;
    (void)state;
    pmstep_actuate_coeffs_init(&coeffs, &cfg);
    pmstep_actuate_reset(&actuator);
    assert_true(pmstep_actuate(&actuator, &coeffs, &in, BUS_V, &out));
    c = currents(-0.99f * THRESHOLD_A, -0.3f, -0.3f, 0.3f); /* a: start inside; b: through zero */
    pmstep_actuate_voltage_over_period(&actuator, &coeffs, &c, BUS_V, &u_a_V, &u_b_V);
    assert_float_equal(u_a_V, 4.0f, 1e-5f);
    assert_float_equal(u_b_V, 2.0f, 1e-5f);
    c = currents(-1.01f * THRESHOLD_A, -1.01f * THRESHOLD_A, -0.3f, -0.3f); /* just beyond */
    pmstep_actuate_voltage_over_period(&actuator, &coeffs, &c, BUS_V, &u_a_V, &u_b_V);
    assert_float_equal(u_a_V, 4.0f + 2.0f * DEAD_V, 1e-5f);
    assert_float_equal(u_b_V, 2.0f + 2.0f * DEAD_V, 1e-5f);
    /* A command within the dead time of the bus: a leg that hardly switches. */
    in = signs(1.0f, 1.0f);
    out = command(BUS_V - 0.5f * DEAD_V, 2.0f);
    assert_true(pmstep_actuate(&actuator, &coeffs, &in, BUS_V, &out));
    c = currents(-0.3f, -0.3f, -0.3f, -0.3f);
    pmstep_actuate_voltage_over_period(&actuator, &coeffs, &c, BUS_V, &u_a_V, &u_b_V);
    assert_true(out.voltage_limited); /* the compensation took a over the bus: both scaled */
    assert_float_equal(u_a_V, actuator.u_applied_a_V, 0.0f);
    assert_float_equal(u_b_V, actuator.u_applied_b_V + actuator.compensation_applied_b_V + DEAD_V, 1e-5f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(delay_line_carries_the_compensation),
        cmocka_unit_test(a_sign_fixed_by_the_samples_replaces_the_assumed_one),
        cmocka_unit_test(an_unknown_sign_keeps_the_assumed_voltage),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
