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
    print_message("locked rotor: max |i_a - analytic| = %.3g A; theta = %g, i_b = %g\n", max_err, plant.x.theta_rad,
                  plant.x.i_b_A);
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

/* A coupled run: rotating voltage drags the rotor, with a load step inside the interval, and
 * optionally a detent torque. */
static plant_state_t coupled_run_detent(plant_integrator_t method, int substeps, plant_load_kind_t load_kind,
                                        double detent_torque_Nm)
{
    plant_t plant = paper_plant();
    const double period = 200e-6; /* long steps: the RK4 error stays far above round-off */
    int k;
    plant.params.detent_torque_Nm = detent_torque_Nm;
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

static plant_state_t coupled_run_with(plant_integrator_t method, int substeps, plant_load_kind_t load_kind)
{
    return coupled_run_detent(method, substeps, load_kind, 0.0);
}

static plant_state_t coupled_run(int substeps)
{
    return coupled_run_with(PLANT_INTEGRATOR_RK4, substeps, PLANT_LOAD_PROPORTIONAL);
}

static double distance(const plant_state_t *a, const plant_state_t *b)
{
    return fabs(a->theta_rad - b->theta_rad) + fabs(a->omega_rad_s - b->omega_rad_s) + fabs(a->i_a_A - b->i_a_A)
           + fabs(a->i_b_A - b->i_b_A);
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

/* Fourth order for both methods with a detent torque in the coupled run (2 Nm, large beside
 * the paper motor's drive torque, so its error shows). */
static void detent_keeps_both_methods_fourth_order(void **state)
{
    static const plant_integrator_t methods[] = {PLANT_INTEGRATOR_RK4, PLANT_INTEGRATOR_EXPONENTIAL};
    const plant_state_t reference = coupled_run_detent(PLANT_INTEGRATOR_RK4, 512, PLANT_LOAD_PROPORTIONAL, 2.0);
    const plant_state_t without = coupled_run_detent(PLANT_INTEGRATOR_RK4, 512, PLANT_LOAD_PROPORTIONAL, 0.0);
    int m;
    (void)state;
    assert_true(distance(&reference, &without) > 1e-3); /* the detent changes the run */
    for (m = 0; m < 2; ++m) {
        const plant_state_t coarse = coupled_run_detent(methods[m], 1, PLANT_LOAD_PROPORTIONAL, 2.0);
        const plant_state_t medium = coupled_run_detent(methods[m], 2, PLANT_LOAD_PROPORTIONAL, 2.0);
        const plant_state_t fine = coupled_run_detent(methods[m], 4, PLANT_LOAD_PROPORTIONAL, 2.0);
        const double e1 = distance(&coarse, &reference);
        const double e2 = distance(&medium, &reference);
        const double e4 = distance(&fine, &reference);
        print_message("%s with detent: error at 200, 100, 50 us: %.3g, %.3g, %.3g; ratios %.2f, %.2f\n",
                      m == 0 ? "rk4" : "exponential", e1, e2, e4, e1 / e2, e2 / e4);
        assert_true(e1 / e2 > 12.0 && e1 / e2 < 20.0);
        assert_true(e2 / e4 > 12.0 && e2 / e4 < 20.0);
    }
}

/* The 17HS4401 preset's rotor (J = 5.4e-6 kg m^2, p = 50, T_d = 0.022 Nm) with k_M = 0 and F = 0:
 * no current and no drag, the detent alone. */
static plant_t detent_plant(plant_integrator_t method)
{
    plant_t plant = paper_plant();
    plant.params.inertia_kgm2 = 5.4e-6;
    plant.params.pole_pairs = 50;
    plant.params.torque_constant_Nm_A = 0.0;
    plant.params.friction_Nms_rad = 0.0;
    plant.params.detent_torque_Nm = 0.022;
    plant.integrator = method;
    return plant;
}

static void detent_static_torque(void **state)
{
    /* At rest the acceleration is the static torque over J: -T_d sin(4 p theta), plus the
     * current's torque when there is current. From plant_derivative() at angles across a full
     * step, and from one short step of each integrator (omega(h)/h = omega'(0) + O(h^2): the
     * jerk is zero at rest). */
    static const plant_integrator_t methods[] = {PLANT_INTEGRATOR_RK4, PLANT_INTEGRATOR_EXPONENTIAL};
    const double j = 5.4e-6, p = 50.0, t_d = 0.022, k_m = 0.16638, h = 1e-8;
    double max_rel = 0.0, max_rel_step = 0.0;
    int n, m;
    (void)state;
    for (n = 0; n <= 32; ++n) {
        const double theta = (double)n / 32.0 * (3.14159265358979323846 / 2.0) / p + 1e-4; /* a full step */
        for (m = 0; m < 3; ++m) {
            plant_t plant = detent_plant(m < 2 ? methods[m] : PLANT_INTEGRATOR_RK4);
            plant_state_t dx;
            const double i_a = m == 2 ? 0.7 : 0.0, i_b = m == 2 ? -0.4 : 0.0;
            const double expected =
                (k_m * (-i_a * sin(p * theta) + i_b * cos(p * theta)) - t_d * sin(4.0 * p * theta)) / j;
            plant.params.torque_constant_Nm_A = m == 2 ? k_m : 0.0;
            plant.x.theta_rad = theta;
            plant.x.i_a_A = i_a;
            plant.x.i_b_A = i_b;
            plant_derivative(&plant.params, &plant.load, 0.0, &plant.x, 0.0, 0.0, &dx);
            max_rel = fmax(max_rel, fabs(dx.omega_rad_s - expected) / (t_d / j));
            if (m < 2) {
                plant_advance(&plant, 0.0, 0.0, h, 1);
                max_rel_step = fmax(max_rel_step, fabs(plant.x.omega_rad_s / h - expected) / (t_d / j));
            }
        }
    }
    print_message("detent static torque: max |J omega' + T_d sin 4p theta| / T_d = %.3g (derivative), %.3g (one "
                  "%.0e s step)\n",
                  max_rel, max_rel_step, h);
    assert_true(max_rel < 1e-12);
    assert_true(max_rel_step < 1e-9);
}

/* Time in [0, h] where the cubic Hermite interpolant through (y0, v0) and (y1, v1) crosses zero. */
static double hermite_zero(double y0, double v0, double y1, double v1, double h)
{
    double lo = 0.0, hi = 1.0;
    int n;
    for (n = 0; n < 60; ++n) {
        const double s = 0.5 * (lo + hi);
        const double h00 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s), h10 = s * (1.0 - s) * (1.0 - s);
        const double h01 = s * s * (3.0 - 2.0 * s), h11 = s * s * (s - 1.0);
        const double y = h00 * y0 + h10 * h * v0 + h01 * y1 + h11 * h * v1;
        if ((y < 0.0) == (y0 < 0.0)) {
            lo = s;
        } else {
            hi = s;
        }
    }
    return 0.5 * (lo + hi) * h;
}

/* Period (s) of the detent pendulum started at rest at 4 p theta = phi0, measured over 20
 * periods from the upward zero crossings of theta, one step of h per control period. */
static double detent_pendulum_period(plant_integrator_t method, double phi0, double h)
{
    plant_t plant = detent_plant(method);
    double first = -1.0, last = -1.0;
    int crossings = 0;
    long k;
    plant.x.theta_rad = phi0 / (4.0 * 50.0);
    for (k = 0; crossings < 21 && k < 1000000; ++k) {
        const plant_state_t x0 = plant.x;
        plant.time_s = (double)k * h;
        plant_advance(&plant, 0.0, 0.0, h, 1);
        if (x0.theta_rad < 0.0 && plant.x.theta_rad >= 0.0) {
            const double t =
                (double)k * h + hermite_zero(x0.theta_rad, x0.omega_rad_s, plant.x.theta_rad, plant.x.omega_rad_s, h);
            if (crossings == 0) {
                first = t;
            }
            last = t;
            ++crossings;
        }
        assert_true(plant.x.i_a_A == 0.0 && plant.x.i_b_A == 0.0);
    }
    assert_int_equal(crossings, 21);
    return (last - first) / 20.0;
}

/* Complete elliptic integral of the first kind K(k) = pi / (2 AGM(1, sqrt(1 - k^2))). */
static double elliptic_k(double k)
{
    double a = 1.0, b = sqrt(1.0 - k * k);
    int n;
    for (n = 0; n < 30; ++n) {
        const double an = 0.5 * (a + b);
        b = sqrt(a * b);
        a = an;
    }
    return 3.14159265358979323846 / (2.0 * a);
}

static void detent_pendulum(void **state)
{
    /* With no current the detent alone makes a pendulum in phi = 4 p theta:
     * phi'' = -(4 p T_d / J) sin phi. Small swings have the angular frequency
     * Omega = sqrt(4 p T_d / J) (903 rad/s here, period 6.96 ms); a swing of amplitude phi0 has
     * the period 4 K(sin(phi0/2)) / Omega. Tolerance: the integrators (RK4; the exponential
     * one reduces to RK4 on theta and omega when F = 0) shift the frequency by about
     * (Omega h)^4/120 = 3.4e-8 at h = 50 us; the small-swing formula is off by phi0^2/16 = 6e-8
     * at phi0 = 1e-3; the Hermite interpolation of the crossings adds O(h (Omega h)^4) per crossing.
     * Ten times the first two is 1e-6: a detent with a wrong harmonic or amplitude is off by
     * tens of percent. */
    static const plant_integrator_t methods[] = {PLANT_INTEGRATOR_RK4, PLANT_INTEGRATOR_EXPONENTIAL};
    const double omega_n = sqrt(4.0 * 50.0 * 0.022 / 5.4e-6), h = 50e-6, pi = 3.14159265358979323846;
    const double integrator_error = pow(omega_n * h, 4.0) / 120.0;
    int m;
    (void)state;
    for (m = 0; m < 2; ++m) {
        const double phi_small = 1e-3, phi_large = 2.0;
        const double t_small = detent_pendulum_period(methods[m], phi_small, h);
        const double t_large = detent_pendulum_period(methods[m], phi_large, h);
        const double expected_small = 2.0 * pi / omega_n;
        const double expected_large = 4.0 * elliptic_k(sin(0.5 * phi_large)) / omega_n;
        const double err_small = fabs(t_small / expected_small - 1.0);
        const double err_large = fabs(t_large / expected_large - 1.0);
        const double tol_small = 10.0 * (integrator_error + phi_small * phi_small / 16.0);
        const double tol_large = 10.0 * integrator_error;
        print_message("%s detent pendulum: period %.9g s vs 2 pi / Omega %.9g s (rel. err %.2e, tol %.1e); swing "
                      "of 2 rad: %.9g s vs 4 K / Omega %.9g s (rel. err %.2e, tol %.1e)\n",
                      m == 0 ? "rk4" : "exponential", t_small, expected_small, err_small, tol_small, t_large,
                      expected_large, err_large, tol_large);
        assert_true(err_small < tol_small);
        assert_true(err_large < tol_large);
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
    load.table_time_s[0] = 1.0;
    load.table_torque_Nm[0] = 0.0;
    load.table_time_s[1] = 2.0;
    load.table_torque_Nm[1] = 1.0;
    load.table_time_s[2] = 3.0;
    load.table_torque_Nm[2] = -1.0;
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
        cmocka_unit_test(detent_keeps_both_methods_fourth_order),
        cmocka_unit_test(detent_static_torque),
        cmocka_unit_test(detent_pendulum),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
