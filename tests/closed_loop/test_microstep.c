/* The open-loop microstepping baseline (run.controller = microstep, sil/microstep.h) on the
 * 17HS4401 preset (argv[1]), set up with the same `section.key=value` overrides as --set:
 * it follows a slow ramp without losing a step, loses synchronism under a load step above
 * its pull-out torque k_M I, and draws the per-phase RMS current of the steady-state phasor
 * analysis below. Also: the pmstep mode reports the same new metrics. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <complex.h>
#include <math.h>

#include "sil/microstep.h"
#include "sil/runner.h"

#define PI 3.14159265358979323846

static const char *preset_ini; /* argv[1]: sil/scenarios/motors/17hs4401.ini */

/* What the drive is told: the preset's motor (the [controller] defaults are the paper's). */
static const char *const drive_keys[] = {
    "run.controller=microstep",
    "controller.motor.resistance_Ohm=1.5",
    "controller.motor.inductance_H=0.0028",
    "controller.motor.pole_pairs=50",
};

static void load_preset(sil_scenario_t *sc, const char *const *sets, size_t n_sets)
{
    char err[SIL_ERROR_MAX];
    size_t k;
    sil_scenario_paper(sc);
    assert_int_equal(sil_scenario_load(sc, preset_ini, err, sizeof err), 0);
    for (k = 0; k < sizeof drive_keys / sizeof drive_keys[0]; ++k) {
        assert_int_equal(sil_scenario_set_assignment(sc, drive_keys[k], err, sizeof err), 0);
    }
    for (k = 0; k < n_sets; ++k) {
        if (sil_scenario_set_assignment(sc, sets[k], err, sizeof err) != 0) {
            fail_msg("%s", err);
        }
    }
    assert_int_equal(sil_scenario_check(sc, err, sizeof err), 0);
}

/* Rotor angle and commanded angle at two instants, and the last sample. */
typedef struct {
    double t1_s, t2_s;
    double theta1_rad, theta2_rad;
    double theta_hold_end_rad; /**< rotor angle when the hold ends */
    double hold_end_s;
    double theta_last_rad, omega_last_rad_s, angle_ref_last_rad;
    bool saw_hold, saw_run, firmware_instance;
} trace_t;

static bool on_sample(const sil_sample_t *x, void *user)
{
    trace_t *tr = (trace_t *)user;
    if (x->inst != NULL) {
        tr->firmware_instance = true;
    }
    if (x->out->mode == PMSTEP_MODE_C_ALIGN) {
        tr->saw_hold = true;
        tr->theta_hold_end_rad = x->theta_rad;
    } else if (x->out->mode == PMSTEP_MODE_RUN) {
        if (!tr->saw_run) {
            tr->hold_end_s = x->t_s;
        }
        tr->saw_run = true;
    }
    if (x->t_s <= tr->t1_s) {
        tr->theta1_rad = x->theta_rad;
    }
    if (x->t_s <= tr->t2_s) {
        tr->theta2_rad = x->theta_rad;
    }
    tr->theta_last_rad = x->theta_rad;
    tr->omega_last_rad_s = x->omega_rad_s;
    tr->angle_ref_last_rad = x->angle_ref_rad;
    return true;
}

static void run(const sil_scenario_t *sc, trace_t *tr, sil_summary_t *s)
{
    assert_int_equal(sil_run(sc, on_sample, tr, false, s), 0);
    assert_false(s->nonfinite_seen);
    assert_int_equal(s->fault, PMSTEP_FAULT_NONE);
}

/* Up to 20 rad/s in 1 s, 1 s there, down in 1 s, at rest 0.3 s: 40 rad in all. */
static void follows_a_slow_ramp(void **state)
{
    static sil_scenario_t sc;
    static const char *const sets[] = {"speed.points=0:0, 0.3:0, 1.3:20, 2.3:20, 3.3:0, 3.6:0", "run.duration_s=3.6",
                                       "load.type=none"};
    const double p = 50.0, distance_rad = 40.0;
    trace_t tr = {1.5, 2.3, 0, 0, 0, 0, 0, 0, 0, false, false, false};
    sil_summary_t s;
    double mean_speed, travel_rad;
    (void)state;
    load_preset(&sc, sets, sizeof sets / sizeof sets[0]);
    run(&sc, &tr, &s);
    mean_speed = (tr.theta2_rad - tr.theta1_rad) / (tr.t2_s - tr.t1_s);
    travel_rad = tr.theta_last_rad - tr.theta_hold_end_rad;
    print_message("  slow ramp: hold until %.5f s, loss of synchronism %d, max load angle %.3f rad, mean speed on "
                  "[%.1f, %.1f] s %.5f rad/s, travel %.6f rad (theta_e*/p %.9f), final speed %.2e rad/s, RMS "
                  "%.4f A, voltage-limited periods %ld\n",
                  tr.hold_end_s, (int)s.loss_of_synchronism, s.max_load_angle_rad, tr.t1_s, tr.t2_s, mean_speed,
                  travel_rad, tr.angle_ref_last_rad / p, tr.omega_last_rad_s, s.rms_phase_current_A,
                  s.voltage_limited_periods);
    assert_true(tr.saw_hold && tr.saw_run);
    assert_false(tr.firmware_instance); /* the firmware is not called */
    assert_true(fabs(tr.hold_end_s - 0.3) < 1e-4);
    assert_false(s.loss_of_synchronism);
    assert_true(s.loss_of_synchronism_time_s < 0.0);
    assert_true(s.max_load_angle_rad < 0.5 * PI);
    /* The commanded angle integrates the ramps exactly: 20 rad/s between the two ramp commands
     * (issued at the first periods at or after 0.3 s and 2.3 s), 40 rad to within a period. */
    {
        const double period_s = (double)sc.controller.timing.period_s;
        const double up_s = ceil(0.3 / period_s - 1e-6) * period_s, down_s = ceil(2.3 / period_s - 1e-6) * period_s;
        assert_true(up_s >= 0.3 && up_s - period_s < 0.3 && down_s >= 2.3 && down_s - period_s < 2.3);
        assert_true(fabs(tr.angle_ref_last_rad / p - 20.0 * (down_s - up_s)) < 1e-9);
        assert_true(fabs(tr.angle_ref_last_rad / p - distance_rad) < 20.0 * period_s);
    }
    /* Synchronous: the mean speed is the command's up to the change of the load angle over the
     * window, |delta(t2) - delta(t1)| / (p (t2 - t1)) <= 2 max |delta| / (p 0.8 s) < 0.04 rad/s. */
    assert_true(fabs(mean_speed - 20.0) <= 2.0 * s.max_load_angle_rad / (p * (tr.t2_s - tr.t1_s)));
    assert_true(fabs(mean_speed - 20.0) < 0.04);
    /* No step lost: the rotor went the commanded 40 rad, to within a full step pi/(2p). */
    assert_true(fabs(travel_rad - distance_rad) < PI / (2.0 * p));
}

/* A load step at 1.6 s on the 20 rad/s plateau: 0.3 k_M I is carried, 1.2 k_M I is not. */
static void load_step(double fraction_of_pull_out, sil_summary_t *s)
{
    static sil_scenario_t sc;
    char torque[64];
    const char *const sets[] = {"speed.points=0:0, 0.3:0, 1.3:20, 2.3:20", "run.duration_s=2.0", "load.type=step",
                                "load.step_time_s=1.6", torque};
    trace_t tr = {1.0, 2.0, 0, 0, 0, 0, 0, 0, 0, false, false, false};
    snprintf(torque, sizeof torque, "load.torque_Nm=%.9g", fraction_of_pull_out * 0.16638 * 1.7);
    load_preset(&sc, sets, sizeof sets / sizeof sets[0]);
    run(&sc, &tr, s);
    print_message(
        "  load step %.2f k_M I = %.4f Nm at 1.6 s: loss of synchronism %d at %.5f s, max load angle %.3g rad\n",
        fraction_of_pull_out, sc.load.torque_Nm, (int)s->loss_of_synchronism, s->loss_of_synchronism_time_s,
        s->max_load_angle_rad);
}

static void loses_synchronism_above_pull_out(void **state)
{
    sil_summary_t s;
    (void)state;
    load_step(0.3, &s);
    assert_false(s.loss_of_synchronism);
    assert_true(s.max_load_angle_rad < 0.5 * PI);
    load_step(1.2, &s);
    assert_true(s.loss_of_synchronism);
    assert_true(s.loss_of_synchronism_time_s >= 1.6 && s.loss_of_synchronism_time_s < 1.7);
    assert_true(s.max_load_angle_rad > PI);
    assert_true(s.loss_of_control_time_s == s.loss_of_synchronism_time_s);
}

/*
 * Per-phase RMS current at a constant speed w, from the steady state of the sampled loop.
 * In complex form i = i_a + j i_b the plant is L i' = -R i - j k_M w e^{j p theta} + u, and
 * everything rotates by z = e^{j w_e T} a period (w_e = p w). Over a period with u held:
 *   i_{k+1} = alpha i_k + beta u_k - e_k (z - alpha)/(R + j w_e L),  alpha = e^{-R T/L}, beta = (1 - alpha)/R,
 * with u_k = z^{-d} [(R + j w_e L + L a) i*_k - L a i_k] (delay d periods). With i*_k = I e^{j theta_e*},
 * p theta = theta_e* - delta, the sampled current is i_k = i*_k (P + Q e^{-j delta}):
 *   D = z - alpha + beta L a z^{-d},  P = beta z^{-d} (R + j w_e L + L a)/D,
 *   Q = -j k_M w (z - alpha) / (I (R + j w_e L) D),
 * the mean torque k_M I Im(P e^{j delta} + Q) balances the friction F w (light load), which gives
 * delta, and the RMS of sqrt((i_a^2 + i_b^2)/2) is I |P e^{j delta} + Q| / sqrt(2). At rest
 * (w = 0, d arbitrary) it is I / sqrt(2). The model leaves out the current ripple within a
 * period and the detent's torque ripple (which makes the load angle oscillate): 1e-3 covers both.
 */
static double rms_analytic(double w_rad_s, unsigned delay, double period_s)
{
    const double i_rated = 1.7, k_m = 0.16638, r = 1.5, l = 0.0028, f = 1e-4, p = 50.0;
    const double la = l * SIL_MICROSTEP_GAIN_FRACTION / period_s, we = p * w_rad_s;
    const double alpha = exp(-r * period_s / l), beta = (1.0 - alpha) / r;
    const double complex z = cexp(I * we * period_s);
    const double complex zd = delay == 1u ? 1.0 / z : 1.0;
    const double complex d = z - alpha + beta * la * zd;
    const double complex pp = beta * zd * (r + I * we * l + la) / d;
    const double complex q = -I * k_m * w_rad_s * (z - alpha) / (i_rated * (r + I * we * l) * d);
    const double delta = asin((f * w_rad_s / (k_m * i_rated) - cimag(q)) / cabs(pp)) - carg(pp);
    return i_rated * cabs(pp * cexp(I * delta) + q) / sqrt(2.0);
}

static void rms_current_matches_the_phasor_analysis(void **state)
{
    static sil_scenario_t sc;
    static const char *const at_rest[] = {"speed.points=0:0, 1:0", "run.duration_s=1.0", "run.theta0_deg=0",
                                          "load.type=none", "run.metrics_start_s=0.5"};
    static const char *const plateau[] = {"speed.points=0:0, 0.3:0, 1.3:20, 3:20", "run.duration_s=3.0",
                                          "load.type=none", "run.metrics_start_s=2.0"};
    trace_t tr = {0, 0, 0, 0, 0, 0, 0, 0, 0, false, false, false};
    sil_summary_t s;
    unsigned delay;
    double expected;
    (void)state;
    load_preset(&sc, at_rest, sizeof at_rest / sizeof at_rest[0]);
    run(&sc, &tr, &s);
    expected = 1.7 / sqrt(2.0);
    print_message("  at rest: RMS %.9f A, I/sqrt(2) = %.9f A (window from %.4f s)\n", s.rms_phase_current_A, expected,
                  s.metrics_start_time_s);
    assert_true(fabs(s.metrics_start_time_s - 0.5) < 1e-4);
    assert_true(fabs(s.rms_phase_current_A / expected - 1.0) < 1e-6); /* DC: the regulator has no error */
    for (delay = 0; delay <= 1u; ++delay) {
        load_preset(&sc, plateau, sizeof plateau / sizeof plateau[0]);
        sc.controller.timing.computational_delay_periods = delay;
        run(&sc, &tr, &s);
        expected = rms_analytic(20.0, delay, (double)sc.controller.timing.period_s);
        print_message("  20 rad/s, delay %u: RMS %.6f A, analytic %.6f A (rel. %.2e; I/sqrt(2) = %.6f A)\n", delay,
                      s.rms_phase_current_A, expected, s.rms_phase_current_A / expected - 1.0, 1.7 / sqrt(2.0));
        assert_false(s.loss_of_synchronism);
        assert_true(fabs(s.rms_phase_current_A / expected - 1.0) < 1e-3);
    }
}

/* The firmware's run reports the same metrics: the angle-estimate error as its "load angle", and
 * a loss of synchronism when that error passes run.loss_angle_error_rad. */
static void pmstep_mode_reports_the_same_metrics(void **state)
{
    static sil_scenario_t sc;
    sil_summary_t s;
    char err[SIL_ERROR_MAX];
    (void)state;
    sil_scenario_paper(&sc);
    sc.duration_s = 1.0;
    assert_int_equal(sil_run(&sc, NULL, NULL, false, &s), 0);
    print_message(
        "  pmstep (paper, 1 s): RMS %.4f A from %.4f s, max load angle %.3g rad (angle error %.3g), loss %d\n",
        s.rms_phase_current_A, s.metrics_start_time_s, s.max_load_angle_rad, s.max_angle_error_rad,
        (int)s.loss_of_synchronism);
    assert_true(s.metrics_start_time_s == s.run_start_time_s);
    assert_true(s.max_load_angle_rad == s.max_angle_error_rad);
    assert_false(s.loss_of_synchronism);
    assert_true(s.rms_phase_current_A > 0.1 && s.rms_phase_current_A < s.max_phase_current_A);
    assert_int_equal(sil_scenario_set_assignment(&sc, "run.loss_angle_error_rad=1e-9", err, sizeof err), 0);
    assert_int_equal(sil_run(&sc, NULL, NULL, false, &s), 0);
    assert_true(s.loss_of_synchronism);
    assert_true(s.loss_of_synchronism_time_s == s.loss_of_control_time_s);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(follows_a_slow_ramp),
        cmocka_unit_test(loses_synchronism_above_pull_out),
        cmocka_unit_test(rms_current_matches_the_phasor_analysis),
        cmocka_unit_test(pmstep_mode_reports_the_same_metrics),
    };
    if (argc < 2) {
        fprintf(stderr, "usage: test_microstep sil/scenarios/motors/17hs4401.ini\n");
        return 2;
    }
    preset_ini = argv[1];
    return cmocka_run_group_tests(tests, NULL, NULL);
}
