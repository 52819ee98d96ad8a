/* Plant model (1) and its integrators (RK4, exponential time-differencing RK4) against
 * analytic cases and against finer steps. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "sil/plant.h"

static plant_t paper_plant(void)
{
    plant_t plant;
    memset(&plant, 0, sizeof plant);
    plant.params = plant_paper_params();
    plant.load.kind = PLANT_LOAD_NONE;
    return plant;
}

static void locked_rotor_rl_step_response(void **state)
{
    /* At p theta = 0 a phase-a current makes no torque (-k_M i_a sin 0 = 0): the rotor stays
     * locked and i_a(t) = (u/R)(1 - e^{-R t/L}). */
    plant_t plant = paper_plant();
    const double u = 12.0, period = 50e-6;
    double max_err = 0.0;
    int k;
    (void)state;
    for (k = 1; k <= 400; ++k) { /* 20 ms = 10 L/R */
        plant_advance(&plant, u, 0.0, period, 10);
        max_err = fmax(max_err, fabs(plant.x.i_a_A - u / 3.0 * (1.0 - exp(-500.0 * k * period))));
    }
    print_message("locked rotor: max |i_a - analytic| = %.3g A; theta = %g, i_b = %g\n", max_err,
                  plant.x.theta_rad, plant.x.i_b_A);
    assert_true(max_err < 1e-9);
    assert_true(plant.x.theta_rad == 0.0 && plant.x.omega_rad_s == 0.0 && plant.x.i_b_A == 0.0);
}

static void free_rotor_with_zero_current(void **state)
{
    /* No excitation and no magnet flux (k_M = 0): currents stay zero, the rotor coasts
     * against friction and a constant load: omega' = -(F/J) omega - T_L/J. */
    plant_t plant = paper_plant();
    const double w0 = 20.0, f = 0.05, j = 0.01, t_load = 0.1, a = f / j, period = 50e-6;
    double max_w_err = 0.0, max_theta_err = 0.0;
    int k;
    (void)state;
    plant.params.torque_constant_Nm_A = 0.0;
    plant.params.friction_Nms_rad = f;
    plant.load.kind = PLANT_LOAD_CONSTANT;
    plant.load.torque_Nm = t_load;
    plant.x.omega_rad_s = w0;
    for (k = 1; k <= 2000; ++k) { /* 0.1 s */
        const double t = k * period;
        const double w_inf = -t_load / f;
        const double w = w_inf + (w0 - w_inf) * exp(-a * t);
        const double theta = w_inf * t + (w0 - w_inf) * (1.0 - exp(-a * t)) / a;
        plant_advance(&plant, 0.0, 0.0, period, 10);
        max_w_err = fmax(max_w_err, fabs(plant.x.omega_rad_s - w));
        max_theta_err = fmax(max_theta_err, fabs(plant.x.theta_rad - theta));
        assert_true(plant.x.i_a_A == 0.0 && plant.x.i_b_A == 0.0);
    }
    print_message("free rotor: max |omega err| = %.3g rad/s, max |theta err| = %.3g rad\n", max_w_err, max_theta_err);
    assert_true(max_w_err < 1e-10);
    assert_true(max_theta_err < 1e-10);
}

static void exponential_locked_rotor_is_exact_in_one_step(void **state)
{
    /* The R/L rise under a held voltage has no truncation error in the exponential method:
     * one step per period (and one step of 5 ms) matches the analytic response to round-off. */
    plant_t plant = paper_plant();
    const double u = 12.0, period = 50e-6;
    double max_err = 0.0;
    int k;
    (void)state;
    plant.integrator = PLANT_INTEGRATOR_EXPONENTIAL;
    for (k = 1; k <= 400; ++k) {
        plant_advance(&plant, u, 0.0, period, 1);
        max_err = fmax(max_err, fabs(plant.x.i_a_A - u / 3.0 * (1.0 - exp(-500.0 * k * period))));
    }
    plant_advance(&plant, 0.0, 0.0, 5e-3, 1); /* ten time constants in one step: decays exactly */
    max_err = fmax(max_err, fabs(plant.x.i_a_A - u / 3.0 * (1.0 - exp(-500.0 * 0.02)) * exp(-500.0 * 5e-3)));
    print_message("exponential, locked rotor, one step a period: max |i_a - analytic| = %.3g A\n", max_err);
    assert_true(max_err < 1e-13);
    assert_true(plant.x.theta_rad == 0.0 && plant.x.omega_rad_s == 0.0 && plant.x.i_b_A == 0.0);
}

/* A coupled run: rotating voltage drags the rotor, with a load step inside the interval. */
static plant_state_t coupled_run_with(plant_integrator_t method, int substeps, plant_load_kind_t load_kind)
{
    plant_t plant = paper_plant();
    const double period = 200e-6; /* long steps: the RK4 error stays far above round-off */
    int k;
    plant.integrator = method;
    plant.x.theta_rad = 0.3;
    plant.load.kind = load_kind;
    plant.load.coefficient_Nms_rad = 0.05;
    plant.load.torque_Nm = 0.5;
    plant.load.step_time_s = 0.0101234; /* inside a period and inside its substeps */
    for (k = 0; k < 100; ++k) {
        const double t = k * period;
        const double angle = 6.0 * 30.0 * t * t;
        plant.time_s = t;
        plant_advance(&plant, 20.0 * cos(angle), 20.0 * sin(angle), period, substeps);
    }
    return plant.x;
}

static plant_state_t coupled_run(int substeps)
{
    return coupled_run_with(PLANT_INTEGRATOR_RK4, substeps, PLANT_LOAD_PROPORTIONAL);
}

static double distance(const plant_state_t *a, const plant_state_t *b)
{
    return fabs(a->theta_rad - b->theta_rad) + fabs(a->omega_rad_s - b->omega_rad_s)
           + fabs(a->i_a_A - b->i_a_A) + fabs(a->i_b_A - b->i_b_A);
}

static void halving_the_substep_cuts_the_error_16_times(void **state)
{
    const plant_state_t reference = coupled_run(512);
    const plant_state_t coarse = coupled_run(1);
    const plant_state_t medium = coupled_run(2);
    const plant_state_t fine = coupled_run(4);
    const double e1 = distance(&coarse, &reference);
    const double e2 = distance(&medium, &reference);
    const double e4 = distance(&fine, &reference);
    (void)state;
    print_message("RK4 error at 200, 100, 50 us: %.3g, %.3g, %.3g; ratios %.2f, %.2f\n", e1, e2, e4, e1 / e2, e2 / e4);
    assert_true(e1 / e2 > 12.0 && e1 / e2 < 20.0);
    assert_true(e2 / e4 > 12.0 && e2 / e4 < 20.0);
}

/* Fourth order for both methods, with a smooth load and with a load step inside a step
 * (the step is split at the jump, so the jump costs no order). */
static void both_methods_are_fourth_order(void **state)
{
    static const plant_integrator_t methods[] = {PLANT_INTEGRATOR_RK4, PLANT_INTEGRATOR_EXPONENTIAL};
    static const plant_load_kind_t loads[] = {PLANT_LOAD_PROPORTIONAL, PLANT_LOAD_STEP};
    int m, l;
    (void)state;
    for (m = 0; m < 2; ++m) {
        for (l = 0; l < 2; ++l) {
            const plant_state_t reference = coupled_run_with(PLANT_INTEGRATOR_RK4, 512, loads[l]);
            const plant_state_t coarse = coupled_run_with(methods[m], 1, loads[l]);
            const plant_state_t medium = coupled_run_with(methods[m], 2, loads[l]);
            const plant_state_t fine = coupled_run_with(methods[m], 4, loads[l]);
            const double e1 = distance(&coarse, &reference);
            const double e2 = distance(&medium, &reference);
            const double e4 = distance(&fine, &reference);
            print_message("%s, %s load: error at 200, 100, 50 us: %.3g, %.3g, %.3g; ratios %.2f, %.2f\n",
                          m == 0 ? "rk4" : "exponential", l == 0 ? "proportional" : "step", e1, e2, e4, e1 / e2,
                          e2 / e4);
            assert_true(e1 / e2 > 12.0 && e1 / e2 < 20.0);
            assert_true(e2 / e4 > 12.0 && e2 / e4 < 20.0);
        }
    }
}

static void load_profiles(void **state)
{
    plant_load_t load;
    (void)state;
    memset(&load, 0, sizeof load);
    load.kind = PLANT_LOAD_STEP;
    load.torque_Nm = 2.0;
    load.step_time_s = 0.63;
    assert_true(plant_load_torque(&load, 0.6299, 5.0) == 0.0);
    assert_true(plant_load_torque(&load, 0.63, 5.0) == 2.0);
    load.kind = PLANT_LOAD_PROPORTIONAL;
    load.coefficient_Nms_rad = 0.1;
    assert_true(fabs(plant_load_torque(&load, 1.0, -5.0) + 0.5) < 1e-15);
    load.kind = PLANT_LOAD_TABLE;
    load.table_points = 3;
    load.table_time_s[0] = 1.0; load.table_torque_Nm[0] = 0.0;
    load.table_time_s[1] = 2.0; load.table_torque_Nm[1] = 1.0;
    load.table_time_s[2] = 3.0; load.table_torque_Nm[2] = -1.0;
    assert_true(plant_load_torque(&load, 0.0, 0.0) == 0.0);
    assert_true(fabs(plant_load_torque(&load, 1.5, 0.0) - 0.5) < 1e-15);
    assert_true(fabs(plant_load_torque(&load, 2.75, 0.0) + 0.5) < 1e-15);
    assert_true(plant_load_torque(&load, 9.0, 0.0) == -1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(locked_rotor_rl_step_response),
        cmocka_unit_test(free_rotor_with_zero_current),
        cmocka_unit_test(halving_the_substep_cuts_the_error_16_times),
        cmocka_unit_test(exponential_locked_rotor_is_exact_in_one_step),
        cmocka_unit_test(both_methods_are_fourth_order),
        cmocka_unit_test(load_profiles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
