/* Detection in closed loop: failures provoked on the paper's scenario must be latched
 * as a named fault no later than 50 ms after the loss of control (the SIL's ground
 * truth: |omega - omega*| above 2 rad/s or the angle estimate off by more than 0.5 rad). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include "sil/runner.h"
#include "pmstep/pmstep_text.h"

#define LATENCY_BOUND_S 0.05

/* Runs @p sc and checks the failure was caught in time; returns the fault. */
static pmstep_fault_t run_and_check(const char *what, const sil_scenario_t *sc, sil_sample_fn hook, void *user)
{
    sil_summary_t s;
    assert_int_equal(sil_run(sc, hook, user, false, &s), 0);
    print_message("  %-40s fault %-18s at %.4f s, loss of control at %.4f s, latency %.1f ms\n", what,
                  pmstep_fault_str(s.fault), s.fault_time_s, s.loss_of_control_time_s, 1e3 * s.detection_latency_s);
    assert_int_not_equal(s.fault, PMSTEP_FAULT_NONE);
    assert_false(s.nonfinite_seen);
    if (s.loss_of_control_time_s >= 0.0) {
        assert_true(s.detection_latency_s <= LATENCY_BOUND_S);
    }
    return s.fault;
}

static void resistance_error_in_paper_mode_is_caught(void **state)
{
    /* The paper's open integrals with the plant's R 20 % above the firmware's: the angle is lost. */
    static sil_scenario_t sc;
    (void)state;
    sil_scenario_paper(&sc);
    sc.motor.resistance_Ohm *= 1.2;
    (void)run_and_check("plant R +20 %, paper mode", &sc, NULL, NULL);
}

/* Remark 2 calibration and self-commissioning on (what robust.ini uses). */
static void commissioning_on(sil_scenario_t *sc)
{
    sc->controller.commissioning.steady_state_window_s = 0.05f;
    sc->controller.commissioning.inductance_window_s = 0.0005f;
    sc->controller.commissioning.alignment_offset_calibration = true;
    sc->controller.commissioning.use_measured_resistance = true;
    sc->controller.commissioning.use_measured_inductance = true;
    sc->controller.commissioning.use_measured_torque_constant = true;
}

static void rotor_that_does_not_align_fails_commissioning(void **state)
{
    /* The rotor cannot move (inertia x 1e4): the alignment never happens, the angle is off by
     * pi at t_c. The flux swing of c-alignment measures k_M ~ 0: caught at t_c. */
    static sil_scenario_t sc;
    (void)state;
    sil_scenario_paper(&sc);
    commissioning_on(&sc);
    sc.motor.inertia_kgm2 *= 1e4;
    sc.load.kind = PLANT_LOAD_NONE;
    assert_int_equal(run_and_check("rotor locked (J x 1e4), commissioning", &sc, NULL, NULL),
                     PMSTEP_FAULT_COMMISSIONING);
}

static void rotor_that_does_not_align_stalls_in_paper_mode(void **state)
{
    /* Without commissioning nothing tells the core at t_c; it stalls once w* moves (0.65 s).
     * The loss of control counts from t_c here (angle error pi), so only the fault is checked. */
    static sil_scenario_t sc;
    sil_summary_t s;
    (void)state;
    sil_scenario_paper(&sc);
    sc.motor.inertia_kgm2 *= 1e4;
    sc.load.kind = PLANT_LOAD_NONE;
    assert_int_equal(sil_run(&sc, NULL, NULL, false, &s), 0);
    print_message("  %-40s fault %-18s at %.4f s (w* leaves 0 at 0.65 s)\n", "rotor locked (J x 1e4), paper mode",
                  pmstep_fault_str(s.fault), s.fault_time_s);
    assert_int_equal(s.fault, PMSTEP_FAULT_STALL);
    assert_true(s.fault_time_s < 0.65 + 0.1);
}

static void jammed_load_is_caught(void **state)
{
    /* 40 Nm from 1.0 s, running at 10 rad/s: more than the drive's 15 A x 2 Nm/A. */
    static sil_scenario_t sc;
    (void)state;
    sil_scenario_paper(&sc);
    commissioning_on(&sc);
    sc.load.kind = PLANT_LOAD_STEP;
    sc.load.torque_Nm = 40.0;
    sc.load.step_time_s = 1.0;
    (void)run_and_check("load jams to 40 Nm at 1.0 s", &sc, NULL, NULL);
}

/* Turns the angle estimate by a quarter electrical turn at one instant, keeping it on the unit circle. */
typedef struct {
    double at_s;
    int done;
} kick_t;

static bool quarter_turn(const sil_sample_t *x, void *user)
{
    kick_t *kick = (kick_t *)user;
    if (!kick->done && x->t_s >= kick->at_s && x->out->mode == PMSTEP_MODE_RUN) {
        pmstep_t *inst = x->inst;
        const float k = inst->derived.angle_coeffs.flux_to_angle;
        const float c = x->out->cos_hat;
        const float s = x->out->sin_hat;
        /* c-hat grows by k per unit of phi1, s-hat by k per unit of phi2: (c, s) -> (-s, c). */
        inst->angle.phi_a += (-s - c) / k;
        inst->angle.phi_b += (c - s) / k;
        kick->done = 1;
    }
    return true;
}

static void silent_angle_error_is_caught(void **state)
{
    /* A 90 degree electrical error with |(c-hat, s-hat)| = 1: invisible to the magnitude check. */
    static sil_scenario_t sc;
    kick_t kick = {1.0, 0};
    (void)state;
    sil_scenario_paper(&sc);
    (void)run_and_check("angle estimate turned 90 deg at 1.0 s", &sc, quarter_turn, &kick);
    assert_true(kick.done);
}

static void silent_angle_error_at_standstill_is_caught(void **state)
{
    static sil_scenario_t sc;
    kick_t kick = {2.1, 0}; /* w* = 0 and 2 Nm of load */
    (void)state;
    sil_scenario_paper(&sc);
    (void)run_and_check("angle turned 90 deg at 2.1 s (standstill)", &sc, quarter_turn, &kick);
    assert_true(kick.done);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(resistance_error_in_paper_mode_is_caught),
        cmocka_unit_test(rotor_that_does_not_align_fails_commissioning),
        cmocka_unit_test(rotor_that_does_not_align_stalls_in_paper_mode),
        cmocka_unit_test(jammed_load_is_caught),
        cmocka_unit_test(silent_angle_error_is_caught),
        cmocka_unit_test(silent_angle_error_at_standstill_is_caught),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
