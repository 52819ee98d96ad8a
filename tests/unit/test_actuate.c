/* Actuation stage (pmstep_actuate.h): the delay line carries the dead-time compensation with the
 * voltage; the voltage the flux integrals take over a period where both samples fix the
 * current's sign is the command less the dead time's loss of that sign; the compensation's mean
 * loss over a period matches the bridge's switching through the PWM ripple. */
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

/* One PWM period of a phase's current, from the bridge's switching: the legs' windows
 * (1 + d) T / 2 and (1 - d) T / 2 centred on the period (the ports' duty mapping), the current's
 * slope (V_level - u) / L with V_level = (leg A - leg B) V_bus (back EMF + R i = u over the
 * period). Integrated from 0 at t = 0: the current at each leg's edges, and the period's mean. */
typedef struct {
    double at_edge_A[4]; /* leg A on, leg A off, leg B on, leg B off */
    double mean_A;
} pwm_waveform_t;

static pwm_waveform_t pwm_waveform(double u_V)
{
    const double period_s = PERIOD_S;
    const double duty = u_V / BUS_V;
    const double edge_s[4] = {0.25 * (1.0 - duty) * period_s, (0.75 + 0.25 * duty) * period_s,
                              0.25 * (1.0 + duty) * period_s, (0.75 - 0.25 * duty) * period_s};
    const int steps = 20000;
    const double dt_s = period_s / steps;
    double current_A = 0.0;
    double sum_A_s = 0.0;
    pwm_waveform_t w = {{0.0, 0.0, 0.0, 0.0}, 0.0};
    for (int j = 0; j < steps; ++j) {
        const double t0_s = dt_s * j;
        const double mid_s = t0_s + 0.5 * dt_s;
        const double leg_a = (mid_s >= edge_s[0] && mid_s < edge_s[1]) ? 1.0 : 0.0;
        const double leg_b = (mid_s >= edge_s[2] && mid_s < edge_s[3]) ? 1.0 : 0.0;
        const double slope_A_s = ((leg_a - leg_b) * BUS_V - u_V) / INDUCTANCE_H;
        for (int k = 0; k < 4; ++k) {
            if (edge_s[k] >= t0_s && edge_s[k] < t0_s + dt_s) {
                w.at_edge_A[k] = current_A + slope_A_s * (edge_s[k] - t0_s);
            }
        }
        sum_A_s += (current_A + 0.5 * slope_A_s * dt_s) * dt_s;
        current_A += slope_A_s * dt_s;
    }
    w.mean_A = sum_A_s / period_s;
    return w;
}

/* The share of the full loss over a period whose mean current is @p mean_A. Leg A carries +i:
 * it loses t_d where it turns on with i > 0 and gains where it turns off with i < 0; leg B
 * carries -i, so the phase gains where B turns on with i < 0 and loses where B turns off with
 * i > 0. */
static double switching_loss_share(const pwm_waveform_t *w, double mean_A)
{
    const double shift_A = mean_A - w->mean_A;
    double share = 0.0;
    share += (w->at_edge_A[0] + shift_A > 0.0) ? 0.5 : 0.0;
    share -= (w->at_edge_A[1] + shift_A < 0.0) ? 0.5 : 0.0;
    share -= (w->at_edge_A[2] + shift_A < 0.0) ? 0.5 : 0.0;
    share += (w->at_edge_A[3] + shift_A > 0.0) ? 0.5 : 0.0;
    return share;
}

/* Over a period the current sweeps [i - s, i + s]: the mean of the switching share over it
 * (midpoint rule, 4000 points), against the compensation's figure, for the ripple at d = 1/2
 * (its largest, 26.8 mA here) and at d = -0.1, with a sweep below and above the ripple. The
 * share jumps by 1 at +-h, so the midpoint rule errs by at most 1 / 4000 (2 jumps of half a
 * point each): the bound 5e-4 holds the rule and nothing else. */
static void the_mean_loss_follows_the_pwm_ripple(void **state)
{
    const pmstep_config_t cfg = config(0u);
    pmstep_actuate_coeffs_t coeffs;
    const float voltages_V[] = {12.0f, -2.4f};
    const float sweeps_A[] = {0.0f, 0.01f, 0.05f};
    (void)state;
    pmstep_actuate_coeffs_init(&coeffs, &cfg);
    for (unsigned k = 0u; k < 2u; ++k) {
        const pwm_waveform_t w = pwm_waveform(voltages_V[k]);
        for (unsigned m = 0u; m < 3u; ++m) {
            const double range_A = sweeps_A[m] > BAND_A ? sweeps_A[m] : BAND_A;
            for (int n = -40; n <= 40; ++n) {
                const float current_A = 0.002f * (float)n;
                double mean_share = 0.0;
                const int points = 4000;
                for (int j = 0; j < points; ++j) {
                    const double x_A = current_A + range_A * (-1.0 + (2.0 * j + 1.0) / points);
                    mean_share += switching_loss_share(&w, x_A) / points;
                }
                assert_float_equal(
                    pmstep_actuate_mean_loss_current(&coeffs, BAND_A, current_A, sweeps_A[m], voltages_V[k], BUS_V)
                        / BAND_A,
                    mean_share, 5e-4);
            }
        }
    }
    /* Within the ripple and clear of its edge by the range: no loss; at d = 1/2, h = 26.8 mA. */
    assert_float_equal(pmstep_actuate_mean_loss_current(&coeffs, BAND_A, 0.02f, 0.0f, 12.0f, BUS_V), 0.0f, 0.0f);
    assert_float_equal(pmstep_actuate_mean_loss_current(&coeffs, BAND_A, 0.04f, 0.0f, 12.0f, BUS_V), BAND_A, 1e-9f);
}

/* Without ripple (u = 0) the mapping is the band's linear one, widened to the sweep; a command
 * beyond the bus keeps the share within the band. */
static void without_ripple_the_share_is_linear_over_the_sweep(void **state)
{
    const pmstep_config_t cfg = config(0u);
    pmstep_actuate_coeffs_t coeffs;
    (void)state;
    pmstep_actuate_coeffs_init(&coeffs, &cfg);
    assert_float_equal(pmstep_actuate_mean_loss_current(&coeffs, BAND_A, 0.003f, 0.0f, 0.0f, BUS_V), 0.003f, 1e-8f);
    assert_float_equal(pmstep_actuate_mean_loss_current(&coeffs, BAND_A, -0.2f, 0.0f, 0.0f, BUS_V), -BAND_A, 1e-9f);
    /* a sweep of +-0.1 A: i b / s */
    assert_float_equal(pmstep_actuate_mean_loss_current(&coeffs, BAND_A, 0.05f, 0.1f, 0.0f, BUS_V),
                       0.05f * BAND_A / 0.1f, 1e-8f);
    for (int n = -10; n <= 10; ++n) {
        const float share_A =
            pmstep_actuate_mean_loss_current(&coeffs, BAND_A, 0.01f * (float)n, 0.02f, 1.5f * BUS_V, BUS_V);
        assert_true(share_A >= -BAND_A && share_A <= BAND_A);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(delay_line_carries_the_compensation),
        cmocka_unit_test(a_sign_fixed_by_the_samples_replaces_the_assumed_one),
        cmocka_unit_test(an_unknown_sign_keeps_the_assumed_voltage),
        cmocka_unit_test(the_mean_loss_follows_the_pwm_ripple),
        cmocka_unit_test(without_ripple_the_share_is_linear_over_the_sweep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
