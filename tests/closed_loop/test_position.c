/* Sensorless position control in closed loop (issue 13): the paper's motor, ideal chain, the
 * moves of sil/scenarios/position.ini (argv[1]) through pmstep_position_step and the plant.
 * Judged on the plant's true position (sil_position_summary_t) and, per sample, against the
 * position output of the firmware.
 *
 * Bounds, from the run as measured (README, "Sensorless position control"; the loop updated every
 * PMSTEP_POSITION_DECIMATION periods, each move ended in the vector hold): final error after each
 * move 1.2e-5 electrical rad, overshoot 0.49 % of a 0.01 rad move, theta* - theta within 3.0e-4
 * electrical rad while moving, estimate error 2.3e-5 (every period) and the output's at its
 * updates (before the vector hold: 2.3e-5, 0.46 %, 3.1e-4, 2.3e-5). The bounds
 * below, set before the decimation with a factor of about 4-8 over the figures of the loop run
 * every period (1.3e-5, 0.18 %, 2.7e-4, 2.3e-5), are kept: the overshoot's margin is now 2 (and
 * stays well inside the 0.1 electrical rad and 1 %); a regression of the loop, the
 * estimate or the profile shows as
 * orders of magnitude. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "sil/runner.h"

static const char *scenario_ini;

typedef struct {
    long samples_tracked;
    long position_mode_samples;
    long updates;                   /* samples of a position update */
    double max_output_mismatch_rad; /* |theta-hat of the output - theta| p, at each update */
    double pole_pairs;
} trace_t;

static bool on_sample(const sil_sample_t *x, void *user)
{
    trace_t *tr = (trace_t *)user;
    assert_non_null(x->position);
    if (x->position->tracked) {
        tr->samples_tracked++;
        if (x->position_updated) { /* the output's estimate is that of its update's period */
            tr->updates++;
            tr->max_output_mismatch_rad =
                fmax(tr->max_output_mismatch_rad,
                     fabs((double)x->position->position_rad - x->position_rad) * tr->pole_pairs);
        }
    }
    if (x->position->position_mode) {
        tr->position_mode_samples++;
    }
    return true;
}

static void load(sil_scenario_t *sc)
{
    char err[SIL_ERROR_MAX];
    sil_scenario_paper(sc);
    if (sil_scenario_load(sc, scenario_ini, err, sizeof err) != 0 || sil_scenario_check(sc, err, sizeof err) != 0) {
        fail_msg("%s", err);
    }
}

static void paper_motor_moves_end_on_target_without_overshoot(void **state)
{
    static sil_scenario_t sc;
    sil_summary_t s;
    trace_t tr = {0, 0, 0, 0.0, 6.0};
    const sil_position_summary_t *p = &s.position;
    (void)state;
    load(&sc);
    assert_int_equal(sil_run(&sc, on_sample, &tr, false, &s), 0);
    print_message("%d moves: final error max %.3g mean %.3g electrical rad (move %d), overshoot %.3g of the move, "
                  "theta* - theta %.3g, estimate %.3g electrical rad\n",
                  p->moves, p->max_final_error_rad, p->mean_final_error_rad, p->worst_move, p->max_overshoot_fraction,
                  p->max_tracking_error_rad, p->max_estimate_error_rad);
    assert_int_equal(s.fault, PMSTEP_FAULT_NONE);
    assert_int_equal(p->moves, sc.position_moves);
    assert_int_equal(p->rejected_moves, 0);
    assert_int_equal(p->unfinished_moves, 0);
    assert_true(tr.samples_tracked > 0 && tr.position_mode_samples > 0);
    assert_true(tr.updates >= tr.samples_tracked / PMSTEP_POSITION_DECIMATION); /* one in N */
    assert_true(p->max_final_error_rad < 1e-4);
    assert_true(p->max_overshoot_fraction < 0.01);
    assert_true(p->max_tracking_error_rad < 2e-3);
    assert_true(p->max_estimate_error_rad < 1e-4);
    assert_true(tr.max_output_mismatch_rad < 1e-4);
}

static void hold_under_load_keeps_the_position(void **state)
{
    /* After the moves, 30 % of the rated torque k_M I = 16 Nm (paper: 8 A taken as rated, 2 Nm/A) stepped on
     * at 7 s and held to 12 s. */
    static sil_scenario_t sc;
    sil_summary_t s;
    char err[SIL_ERROR_MAX];
    const sil_position_summary_t *p = &s.position;
    (void)state;
    load(&sc);
    assert_int_equal(sil_scenario_set_assignment(&sc, "load.type=step", err, sizeof err), 0);
    assert_int_equal(sil_scenario_set_assignment(&sc, "load.torque_Nm=4.8", err, sizeof err), 0);
    assert_int_equal(sil_scenario_set_assignment(&sc, "load.step_time_s=7", err, sizeof err), 0);
    assert_int_equal(sil_scenario_set_assignment(&sc, "position.hold_start_s=7", err, sizeof err), 0);
    assert_int_equal(sil_scenario_set_assignment(&sc, "run.duration_s=12", err, sizeof err), 0);
    assert_int_equal(sil_scenario_set_assignment(&sc, "run.loss_speed_error_rad_s=1", err, sizeof err), 0);
    assert_int_equal(sil_run(&sc, NULL, NULL, false, &s), 0);
    print_message("hold 5 s under 4.8 Nm: max error %.3g electrical rad, drift %.3g electrical rad/s\n",
                  p->hold_max_error_rad, p->hold_drift_rad_s);
    assert_int_equal(s.fault, PMSTEP_FAULT_NONE);
    assert_true(p->hold_duration_s > 4.9);
    /* The vector hold (7.5 A, the designer's) gives way by the load angle asin(4.8/(2 x 7.5)) = 0.326
     * electrical rad, plus the damped rotor's overshoot (zeta 0.7): measured 0.337 at the step. */
    assert_true(p->hold_max_error_rad < 0.35);
    /* Loss of control in a position scenario is a lost step, |theta* - theta| p > pi/2
     * (run.loss_position_error_rad), not the speed error: swinging onto the load angle the rotor
     * leaves w* = 0 by 1.85 rad/s here (up to 5 rad/s in the Monte Carlo's cases of lower J)
     * without losing anything; run.loss_speed_error_rad_s is set to 1 rad/s below it. */
    print_message("largest |w - w*| after settling %.3g rad/s; loss of control at %.3g s\n",
                  s.max_speed_error_after_settle_rad_s, s.loss_of_control_time_s);
    assert_true(s.max_speed_error_after_settle_rad_s > sc.loss_speed_error_rad_s);
    assert_true(s.loss_of_control_time_s < 0.0);
    {
        /* With the bound below the give-way the step is a loss of control, within the hold's
         * settling time 6/(zeta w_n) = 0.093 s of the step (w_n = 92.3 rad/s, zeta = 0.7). */
        static sil_scenario_t tight;
        sil_summary_t t;
        tight = sc;
        assert_int_equal(sil_scenario_set_assignment(&tight, "run.loss_position_error_rad=0.3", err, sizeof err), 0);
        assert_int_equal(sil_run(&tight, NULL, NULL, false, &t), 0);
        print_message("bound 0.3 electrical rad: loss of control at %.6f s\n", t.loss_of_control_time_s);
        assert_true(t.loss_of_control_time_s >= 7.0 && t.loss_of_control_time_s < 7.093);
    }
    /* From 0.5 s after the step: the aim corrected by the displacement (re-aimed while more than
     * 0.05 electrical rad off); measured 4.5e-3 at most, drift -1.4e-4 electrical rad/s. */
    assert_int_equal(sil_scenario_set_assignment(&sc, "position.hold_start_s=7.5", err, sizeof err), 0);
    assert_int_equal(sil_run(&sc, NULL, NULL, false, &s), 0);
    print_message("from 0.5 s after the step: max error %.3g electrical rad, drift %.3g electrical rad/s\n",
                  p->hold_max_error_rad, p->hold_drift_rad_s);
    assert_int_equal(s.fault, PMSTEP_FAULT_NONE);
    assert_true(p->hold_max_error_rad < 0.05);
    assert_true(fabs(p->hold_drift_rad_s) < 4e-3);
}

int main(int argc, char **argv)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(paper_motor_moves_end_on_target_without_overshoot),
        cmocka_unit_test(hold_under_load_keeps_the_position),
    };
    if (argc != 2) {
        return 2;
    }
    scenario_ini = argv[1];
    return cmocka_run_group_tests(tests, NULL, NULL);
}
