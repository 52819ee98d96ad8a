/* Inverter and bus (sil/inverter.h) through the plant: dead time, switching against
 * averaged, ripple, freewheeling with the bridge off, bus sag, duty clipping. Most cases
 * use a pure RL load (k_M = 0: no back EMF, no torque), whose currents are analytic. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "sil/inverter.h"

#define PERIOD_S 50e-6
#define BUS_V 48.0
#define R_OHM 3.0
#define L_H 0.006
#define TAU_S (L_H / R_OHM)

static plant_t rl_plant(void)
{
    plant_t plant;
    memset(&plant, 0, sizeof plant);
    plant.params = plant_paper_params();
    plant.params.torque_constant_Nm_A = 0.0;
    plant.load.kind = PLANT_LOAD_NONE;
    return plant;
}

static sil_inverter_t make_inverter(sil_inverter_model_t model, double dead_time_s, double source_resistance_Ohm)
{
    sil_inverter_t inv;
    sil_inverter_config_t cfg = sil_inverter_ideal_config();
    sil_bus_config_t bus = sil_bus_ideal_config();
    cfg.model = model;
    cfg.dead_time_s = dead_time_s;
    bus.source_resistance_Ohm = source_resistance_Ohm;
    sil_inverter_init(&inv, &cfg, &bus, BUS_V, 0u);
    return inv;
}

/* One control period: the MCU takes (u_a, u_b) against the bus it measured, the plant advances. */
static void period(plant_t *plant, sil_inverter_t *inv, double u_a_V, double u_b_V, bool enable, double measured_bus_V)
{
    pmstep_output_t out;
    memset(&out, 0, sizeof out);
    out.u_a_V = (float)u_a_V;
    out.u_b_V = (float)u_b_V;
    out.bridge_enable = enable;
    sil_inverter_apply(inv, &out, measured_bus_V);
    sil_drive_advance(plant, inv, PERIOD_S, 10);
}

static void run(plant_t *plant, sil_inverter_t *inv, double u_a_V, double u_b_V, long periods)
{
    long k;
    for (k = 0; k < periods; ++k) {
        plant->time_s = (double)k * PERIOD_S;
        period(plant, inv, u_a_V, u_b_V, true, BUS_V);
    }
}

static void ideal_averaged_is_plant_advance_bit_for_bit(void **state)
{
    /* The coupled motor (k_M = 2) under changing commands: the defaults change nothing. */
    plant_t a, b;
    sil_inverter_t inv = make_inverter(SIL_INVERTER_AVERAGED, 0.0, 0.0);
    long k;
    (void)state;
    memset(&a, 0, sizeof a);
    a.params = plant_paper_params();
    a.load.kind = PLANT_LOAD_NONE;
    a.x.theta_rad = 0.3;
    b = a;
    for (k = 0; k < 2000; ++k) {
        const float u_a_V = (float)(20.0 * cos(3e-3 * (double)k)), u_b_V = (float)(60.0 * sin(2e-3 * (double)k));
        const double clipped_b_V = fmax(-BUS_V, fmin(BUS_V, (double)u_b_V));
        a.time_s = b.time_s = (double)k * PERIOD_S;
        period(&a, &inv, (double)u_a_V, (double)u_b_V, true, BUS_V);
        plant_advance(&b, (double)u_a_V, clipped_b_V, PERIOD_S, 10);
        assert_true(memcmp(&a.x, &b.x, sizeof a.x) == 0);
        assert_true(inv.applied_a_V == (double)u_a_V && inv.applied_b_V == clipped_b_V);
    }
    print_message("ideal averaged drive = plant_advance bit for bit over 2000 periods; %lu periods clipped\n",
                  inv.limited_periods);
    assert_true(inv.limited_periods > 0);
}

static void averaged_dead_time_shifts_the_steady_current(void **state)
{
    /* 2 legs per phase, each -sign(i) V t_d / T: the steady current moves by -2 sign(i) V t_d / (T R). */
    const double dead_time_s = 1e-6, u_V = 12.0;
    const double error_v = 2.0 * BUS_V * dead_time_s / PERIOD_S; /* 1.92 V */
    plant_t plant = rl_plant();
    sil_inverter_t inv = make_inverter(SIL_INVERTER_AVERAGED, dead_time_s, 0.0);
    (void)state;
    run(&plant, &inv, u_V, -u_V, 2000); /* 0.1 s = 50 L/R */
    print_message("averaged, t_d = 1 us: i_a = %.12f A (expected %.12f), i_b = %.12f A; mean u_a = %.12f V\n",
                  plant.x.i_a_A, (u_V - error_v) / R_OHM, plant.x.i_b_A, inv.applied_a_V);
    assert_true(fabs(plant.x.i_a_A - (u_V - error_v) / R_OHM) < 1e-9);
    assert_true(fabs(plant.x.i_b_A - (-u_V + error_v) / R_OHM) < 1e-9);
    assert_true(fabs(inv.applied_a_V - (u_V - error_v)) < 1e-9);
}

static void averaged_dead_time_clamps_a_small_command_at_zero(void **state)
{
    /* A command below the dead time's voltage error (1.92 V) drives no current: neither
     * branch of the averaged model moves a zero current away from zero (the zero-current
     * clamp), so the current stays exactly 0 and the applied voltage is the one that holds it. */
    const double dead_time_s = 1e-6;
    plant_t plant = rl_plant();
    sil_inverter_t inv = make_inverter(SIL_INVERTER_AVERAGED, dead_time_s, 0.0);
    (void)state;
    run(&plant, &inv, 1.5, -1.0, 400);
    print_message("averaged, t_d = 1 us, commands 1.5 V and -1 V: i_a = %g A, i_b = %g A, mean u_a = %g V\n",
                  plant.x.i_a_A, plant.x.i_b_A, inv.applied_a_V);
    assert_true(plant.x.i_a_A == 0.0 && plant.x.i_b_A == 0.0);
    assert_true(inv.applied_a_V == 0.0 && inv.applied_b_V == 0.0);
    /* Above the error the current rises, on the positive branch. */
    run(&plant, &inv, 3.0, 0.0, 2000);
    assert_true(fabs(plant.x.i_a_A - (3.0 - 2.0 * BUS_V * dead_time_s / PERIOD_S) / R_OHM) < 1e-9);
}

/* The motor (back EMF, k_M = 2) driven by a rotating voltage through the averaged bridge with
 * dead time, whose currents cross zero many times; the state after 0.2 s. */
static plant_state_t dead_time_crossings_run(int substeps, plant_integrator_t method)
{
    plant_t plant;
    sil_inverter_t inv = make_inverter(SIL_INVERTER_AVERAGED, 1e-6, 0.0);
    pmstep_output_t out;
    long k;
    memset(&plant, 0, sizeof plant);
    plant.params = plant_paper_params();
    plant.load.kind = PLANT_LOAD_NONE;
    plant.integrator = method;
    memset(&out, 0, sizeof out);
    out.bridge_enable = true;
    for (k = 0; k < 4000; ++k) {
        const double t = (double)k * PERIOD_S;
        const double angle = 6.0 * 10.0 * t * t * 10.0; /* electrical angle of the command, accelerating */
        plant.time_s = t;
        out.u_a_V = (float)(8.0 * cos(angle));
        out.u_b_V = (float)(8.0 * sin(angle));
        sil_inverter_apply(&inv, &out, BUS_V);
        sil_drive_advance(&plant, &inv, PERIOD_S, substeps);
    }
    return plant.x;
}

static void averaged_dead_time_converges_across_zero_crossings(void **state)
{
    /* Each zero crossing cuts the step where the current crosses: the error against fine
     * steps falls quickly with the step count (held signs per step were first order). */
    static const plant_integrator_t methods[] = {PLANT_INTEGRATOR_RK4, PLANT_INTEGRATOR_EXPONENTIAL};
    int m;
    (void)state;
    for (m = 0; m < 2; ++m) {
        const plant_state_t ref = dead_time_crossings_run(200, PLANT_INTEGRATOR_RK4);
        const plant_state_t s1 = dead_time_crossings_run(1, methods[m]);
        const plant_state_t s4 = dead_time_crossings_run(4, methods[m]);
        const double e1 =
            fabs(s1.i_a_A - ref.i_a_A) + fabs(s1.i_b_A - ref.i_b_A) + fabs(s1.omega_rad_s - ref.omega_rad_s);
        const double e4 =
            fabs(s4.i_a_A - ref.i_a_A) + fabs(s4.i_b_A - ref.i_b_A) + fabs(s4.omega_rad_s - ref.omega_rad_s);
        print_message("%s, dead time across zero crossings: error at 1 and 4 steps a period %.3g, %.3g (ratio %.1f)\n",
                      m == 0 ? "rk4" : "exponential", e1, e4, e1 / e4);
        assert_true(e1 < 1e-5);
        assert_true(e1 / e4 > 8.0); /* better than first order (4) */
    }
}

static void switching_dead_time_shifts_the_mean_current_alike(void **state)
{
    /* The switching model's edge shifts give the same mean voltage error, so the same mean current. */
    const double dead_time_s = 1e-6, u_V = 12.0;
    const double expected_a = (u_V - 2.0 * BUS_V * dead_time_s / PERIOD_S) / R_OHM;
    plant_t plant = rl_plant();
    sil_inverter_t inv = make_inverter(SIL_INVERTER_SWITCHING, dead_time_s, 0.0);
    (void)state;
    run(&plant, &inv, u_V, -u_V, 2000);
    print_message("switching, t_d = 1 us: mean i_a = %.12f A, mean i_b = %.12f A (expected +/-%.12f)\n",
                  inv.mean_current_A[0], inv.mean_current_A[1], expected_a);
    assert_true(fabs(inv.mean_current_A[0] - expected_a) < 1e-9);
    assert_true(fabs(inv.mean_current_A[1] + expected_a) < 1e-9);
}

static void switching_matches_averaged_and_the_rl_ripple(void **state)
{
    /* Unipolar PWM repeats every T/2: on for a = d T/2 at +V, off (0 V) for b = T/2 - a. Steady
     * state of the RL load: i_max = (V/R)(1 - e^{-a/tau})/(1 - e^{-T/(2 tau)}), i_min = i_max e^{-b/tau};
     * the valley sample is mid-off, i_v = i_max e^{-b/(2 tau)}; the period mean is exactly d V/R.
     * Against the averaged model (whose current is the response to the mean voltage) the switching
     * model's period mean differs by the zero-mean ripple's transient, at most |i_v - d V/R| (the
     * ripple's value at the valley, decaying with L/R), and its valley sample by the same. */
    const double d = 0.25, u_V = d * BUS_V;
    const double a_s = d * PERIOD_S / 2.0, b_s = PERIOD_S / 2.0 - a_s;
    const double i_max = BUS_V / R_OHM * (1.0 - exp(-a_s / TAU_S)) / (1.0 - exp(-PERIOD_S / (2.0 * TAU_S)));
    const double i_min = i_max * exp(-b_s / TAU_S);
    const double i_valley = i_max * exp(-b_s / (2.0 * TAU_S));
    const double mean_a = u_V / R_OHM;
    const double bound_a = fabs(i_valley - mean_a) + 1e-9;
    plant_t sw = rl_plant(), av = rl_plant();
    sil_inverter_t inv_sw = make_inverter(SIL_INVERTER_SWITCHING, 0.0, 0.0);
    sil_inverter_t inv_av = make_inverter(SIL_INVERTER_AVERAGED, 0.0, 0.0);
    double max_mean_diff = 0.0, max_valley_diff = 0.0;
    long k;
    (void)state;
    for (k = 0; k < 2000; ++k) {
        sw.time_s = av.time_s = (double)k * PERIOD_S;
        period(&sw, &inv_sw, u_V, 0.0, true, BUS_V);
        period(&av, &inv_av, u_V, 0.0, true, BUS_V);
        max_mean_diff = fmax(max_mean_diff, fabs(inv_sw.mean_current_A[0] - inv_av.mean_current_A[0]));
        max_valley_diff = fmax(max_valley_diff, fabs(sw.x.i_a_A - av.x.i_a_A));
    }
    print_message("switching vs averaged (d = 0.25, 2000 periods): max |period-mean difference| = %.3g A, "
                  "max |valley difference| = %.3g A, bound |i_v - dV/R| = %.3g A\n",
                  max_mean_diff, max_valley_diff, bound_a - 1e-9);
    print_message("steady state: mean %.12f A (dV/R %.12f), valley %.12f A (analytic %.12f), peak-to-peak %.9f A "
                  "(analytic %.9f, linear V d(1-d)T/(2L) = %.9f)\n",
                  inv_sw.mean_current_A[0], mean_a, sw.x.i_a_A, i_valley,
                  inv_sw.max_current_A[0] - inv_sw.min_current_A[0], i_max - i_min,
                  BUS_V * d * (1.0 - d) * PERIOD_S / (2.0 * L_H));
    assert_true(max_mean_diff <= bound_a);
    assert_true(max_valley_diff <= bound_a);
    assert_true(fabs(inv_sw.mean_current_A[0] - mean_a) < 1e-9);
    assert_true(fabs(sw.x.i_a_A - i_valley) < 1e-9);
    assert_true(fabs(inv_sw.max_current_A[0] - i_max) < 1e-9);
    assert_true(fabs(inv_sw.min_current_A[0] - i_min) < 1e-9);
    assert_true(fabs((inv_sw.max_current_A[0] - inv_sw.min_current_A[0]) - (i_max - i_min)) < 1e-9);
    /* Phase b at d = 0: both legs switch together, no voltage, no current. */
    assert_true(sw.x.i_b_A == 0.0 && inv_sw.applied_b_V == 0.0);
}

static void switching_in_one_exponential_step_keeps_the_ripple(void **state)
{
    /* The one-step path (exponential integrator, one step a period): the mean-voltage step plus
     * the exact ripple gives the same steady state as the segment-by-segment integration above. */
    const double d = 0.25, u_V = d * BUS_V;
    const double a_s = d * PERIOD_S / 2.0, b_s = PERIOD_S / 2.0 - a_s;
    const double i_max = BUS_V / R_OHM * (1.0 - exp(-a_s / TAU_S)) / (1.0 - exp(-PERIOD_S / (2.0 * TAU_S)));
    const double i_min = i_max * exp(-b_s / TAU_S);
    const double i_valley = i_max * exp(-b_s / (2.0 * TAU_S));
    plant_t sw = rl_plant();
    sil_inverter_t inv = make_inverter(SIL_INVERTER_SWITCHING, 0.0, 0.0);
    pmstep_output_t out;
    long k;
    (void)state;
    sw.integrator = PLANT_INTEGRATOR_EXPONENTIAL;
    memset(&out, 0, sizeof out);
    out.u_a_V = (float)u_V;
    out.bridge_enable = true;
    for (k = 0; k < 2000; ++k) {
        sw.time_s = (double)k * PERIOD_S;
        sil_inverter_apply(&inv, &out, BUS_V);
        sil_drive_advance(&sw, &inv, PERIOD_S, 1);
    }
    print_message("one step a period: mean %.12f A (dV/R %.12f), valley %.12f A (analytic %.12f), max %.12f "
                  "(%.12f), min %.12f (%.12f)\n",
                  inv.mean_current_A[0], u_V / R_OHM, sw.x.i_a_A, i_valley, inv.max_current_A[0], i_max,
                  inv.min_current_A[0], i_min);
    assert_true(fabs(inv.mean_current_A[0] - u_V / R_OHM) < 1e-9);
    assert_true(fabs(sw.x.i_a_A - i_valley) < 1e-9);
    assert_true(fabs(inv.max_current_A[0] - i_max) < 1e-9);
    assert_true(fabs(inv.min_current_A[0] - i_min) < 1e-9);
    assert_true(sw.x.i_b_A == 0.0 && inv.applied_b_V == 0.0);
}

/* The motor (k_M = 2) under a rotating command through the switching bridge with dead time. */
static plant_state_t switching_motor_run(plant_integrator_t method, int substeps, double *mean_bus_a)
{
    plant_t plant;
    sil_inverter_t inv = make_inverter(SIL_INVERTER_SWITCHING, 1e-6, 0.2);
    pmstep_output_t out;
    long k;
    memset(&plant, 0, sizeof plant);
    plant.params = plant_paper_params();
    plant.load.kind = PLANT_LOAD_PROPORTIONAL;
    plant.load.coefficient_Nms_rad = 0.05;
    plant.integrator = method;
    memset(&out, 0, sizeof out);
    out.bridge_enable = true;
    for (k = 0; k < 4000; ++k) {
        const double t = (double)k * PERIOD_S;
        const double angle = 600.0 * t * t;
        plant.time_s = t;
        out.u_a_V = (float)(20.0 * cos(angle));
        out.u_b_V = (float)(20.0 * sin(angle));
        sil_inverter_apply(&inv, &out, BUS_V);
        sil_drive_advance(&plant, &inv, PERIOD_S, substeps);
    }
    *mean_bus_a = inv.mean_bus_current_A;
    return plant.x;
}

static void switching_one_step_matches_the_segments(void **state)
{
    /* 0.2 s, the rotor dragged up to speed: one exponential step a period against RK4 at
     * 20 steps a period segment by segment. */
    double bus_one, bus_ref;
    const plant_state_t one = switching_motor_run(PLANT_INTEGRATOR_EXPONENTIAL, 1, &bus_one);
    const plant_state_t ref = switching_motor_run(PLANT_INTEGRATOR_RK4, 20, &bus_ref);
    (void)state;
    print_message(
        "switching, one exponential step vs segments: d theta %.3g rad, d omega %.3g rad/s, d i %.3g / %.3g A, "
        "d i_bus %.3g A (omega %.3f rad/s)\n",
        one.theta_rad - ref.theta_rad, one.omega_rad_s - ref.omega_rad_s, one.i_a_A - ref.i_a_A, one.i_b_A - ref.i_b_A,
        bus_one - bus_ref, ref.omega_rad_s);
    assert_true(fabs(ref.omega_rad_s) > 1.0);
    assert_true(fabs(one.theta_rad - ref.theta_rad) < 1e-8);
    assert_true(fabs(one.omega_rad_s - ref.omega_rad_s) < 1e-7);
    assert_true(fabs(one.i_a_A - ref.i_a_A) < 1e-7 && fabs(one.i_b_A - ref.i_b_A) < 1e-7);
    assert_true(fabs(bus_one - bus_ref) < 1e-7);
}

/* Mean phase voltage over one period that starts at i0 under u_a = -0.9 V_bus (leg B on at
 * 0.025 T, leg A on at 0.475 T and off at 0.525 T, leg B off at 0.975 T). */
static double crossing_period_mean_V(plant_integrator_t method, int substeps, double i0_A, double *i_end_A)
{
    plant_t plant = rl_plant();
    sil_inverter_t inv = make_inverter(SIL_INVERTER_SWITCHING, 1e-6, 0.0);
    pmstep_output_t out;
    memset(&out, 0, sizeof out);
    out.u_a_V = (float)(-0.9 * BUS_V);
    out.bridge_enable = true;
    plant.integrator = method;
    plant.x.i_a_A = i0_A;
    sil_inverter_apply(&inv, &out, BUS_V);
    sil_drive_advance(&plant, &inv, PERIOD_S, substeps);
    *i_end_A = plant.x.i_a_A;
    return inv.applied_a_V;
}

static void switching_dead_time_takes_the_sign_at_each_edge(void **state)
{
    /* From 0.22 A the current falls about 0.18 A in each of the two stretches at -V_bus: it is
     * positive at B's turn-on and at A's two edges, negative at B's turn-off. Only A's turn-on
     * loses its dead time (A stays low for t_d): -0.9 V_bus - V_bus t_d / T. B's turn-on and
     * turn-off take their commanded levels through the diodes, A's turn-off too. Held at the
     * start's sign every edge would lose: -0.9 V_bus - 2 V_bus t_d / T. From 2 A (positive at
     * every edge) the full loss. */
    const double one_edge_V = BUS_V * 1e-6 / PERIOD_S;
    const double command_V = (double)(float)(-0.9 * BUS_V); /* as the MCU's float output carries it */
    const double expected_V = command_V - one_edge_V;
    double i_end_one, i_end_seg, i_end_far;
    const double one_V = crossing_period_mean_V(PLANT_INTEGRATOR_EXPONENTIAL, 1, 0.22, &i_end_one);
    const double seg_V = crossing_period_mean_V(PLANT_INTEGRATOR_RK4, 10, 0.22, &i_end_seg);
    const double far_V = crossing_period_mean_V(PLANT_INTEGRATOR_EXPONENTIAL, 1, 2.0, &i_end_far);
    (void)state;
    print_message("crossing period: mean u %.9f V (one step), %.9f V (segments), expected %.9f V; i 0.22 -> %.4f A; "
                  "from 2 A: %.9f V (expected %.9f V)\n",
                  one_V, seg_V, expected_V, i_end_one, far_V, command_V - 2.0 * one_edge_V);
    assert_true(i_end_one < -0.1 && i_end_seg < -0.1 && i_end_far > 1.0);
    assert_true(fabs(one_V - expected_V) < 1e-9);
    assert_true(fabs(seg_V - expected_V) < 1e-9);
    assert_true(fabs(far_V - (command_V - 2.0 * one_edge_V)) < 1e-9);
}

static void bridge_off_freewheels_to_exactly_zero_and_holds(void **state)
{
    /* Diodes: L di/dt = -R i - sign(i) V until i = 0, i.e. zero at tau ln(1 + R |i0| / V); then open. */
    static const sil_inverter_model_t models[] = {SIL_INVERTER_AVERAGED, SIL_INVERTER_SWITCHING};
    size_t m;
    (void)state;
    for (m = 0; m < 2; ++m) {
        const double i_a0 = 5.0, i_b0 = -3.0, h_s = PERIOD_S / 10.0;
        const double t_a_s = TAU_S * log(1.0 + R_OHM * i_a0 / BUS_V), t_b_s = TAU_S * log(1.0 - R_OHM * i_b0 / BUS_V);
        plant_t plant = rl_plant();
        sil_inverter_t inv = make_inverter(models[m], 1e-6, 0.0);
        double zero_a_s = -1.0, zero_b_s = -1.0;
        long k;
        plant.x.i_a_A = i_a0;
        plant.x.i_b_A = i_b0;
        for (k = 0; k < 400; ++k) {
            plant.time_s = (double)k * PERIOD_S;
            period(&plant, &inv, 10.0, 10.0, false, BUS_V);
            if (zero_a_s < 0.0 && plant.x.i_a_A == 0.0) {
                zero_a_s = plant.time_s;
            }
            if (zero_b_s < 0.0 && plant.x.i_b_A == 0.0) {
                zero_b_s = plant.time_s;
            }
            if (zero_a_s >= 0.0) {
                assert_true(plant.x.i_a_A == 0.0 && plant.open_a);
            } else {
                assert_true(plant.x.i_a_A > 0.0);
            }
            if (zero_b_s >= 0.0) {
                assert_true(plant.x.i_b_A == 0.0 && plant.open_b);
            } else {
                assert_true(plant.x.i_b_A < 0.0);
            }
        }
        print_message("%s, bridge off: i_a 5 A -> 0 by %.6f ms (analytic %.6f), i_b -3 A -> 0 by %.6f ms "
                      "(analytic %.6f); held at exactly 0 to 20 ms; bus current %.3g A\n",
                      m == 0 ? "averaged" : "switching", zero_a_s * 1e3, t_a_s * 1e3, zero_b_s * 1e3, t_b_s * 1e3,
                      inv.mean_bus_current_A);
        /* Zero is detected at the end of the period holding the crossing. */
        assert_true(zero_a_s >= t_a_s && zero_a_s < t_a_s + PERIOD_S + h_s);
        assert_true(zero_b_s >= t_b_s && zero_b_s < t_b_s + PERIOD_S + h_s);
        /* Enabling the bridge closes the phases again. */
        period(&plant, &inv, 12.0, 0.0, true, BUS_V);
        assert_true(!plant.open_a && !plant.open_b && plant.x.i_a_A > 0.0);
    }
}

static void open_phase_holds_zero_against_back_emf(void **state)
{
    /* A spinning rotor (back EMF k_M omega = 10 V, below the bus) with the bridge off and no
     * current: the phases are open, the currents stay exactly 0 and the rotor coasts. */
    plant_t plant;
    sil_inverter_t inv = make_inverter(SIL_INVERTER_AVERAGED, 0.0, 0.0);
    long k;
    (void)state;
    memset(&plant, 0, sizeof plant);
    plant.params = plant_paper_params();
    plant.load.kind = PLANT_LOAD_NONE;
    plant.x.omega_rad_s = 5.0;
    for (k = 0; k < 1000; ++k) {
        plant.time_s = (double)k * PERIOD_S;
        period(&plant, &inv, 0.0, 0.0, false, BUS_V);
        assert_true(plant.x.i_a_A == 0.0 && plant.x.i_b_A == 0.0);
    }
    assert_true(plant.x.omega_rad_s == 5.0);
    assert_true(fabs(plant.x.theta_rad - 5.0 * 1000.0 * PERIOD_S) < 1e-12);
}

static void bus_sags_with_the_source_resistance(void **state)
{
    /* Steady state, phase a at duty d: i_a = d V/R, i_bus = d i_a, V = V0 - R_src d^2 V / R, so
     * V = V0 / (1 + R_src d^2 / R) (the previous period's i_bus, exact once steady). */
    const double r_src = 1.0, d = 0.25;
    const double v_expected = BUS_V / (1.0 + r_src * d * d / R_OHM);
    plant_t plant = rl_plant();
    sil_inverter_t inv = make_inverter(SIL_INVERTER_AVERAGED, 0.0, r_src);
    double v;
    (void)state;
    run(&plant, &inv, d * BUS_V, 0.0, 4000);
    v = sil_inverter_bus_voltage(&inv, plant.time_s);
    print_message("bus sag, R_src = 1 Ohm, d = 0.25: V = %.12f V (expected %.12f), i_bus = %.12f A, i_a = %.12f A\n", v,
                  v_expected, inv.mean_bus_current_A, plant.x.i_a_A);
    assert_true(fabs(v - v_expected) < 1e-9);
    assert_true(fabs(plant.x.i_a_A - d * v_expected / R_OHM) < 1e-9);
}

static void bus_ripple_and_duty_clip(void **state)
{
    plant_t plant = rl_plant();
    sil_inverter_t inv;
    sil_inverter_config_t cfg = sil_inverter_ideal_config();
    sil_bus_config_t bus = sil_bus_ideal_config();
    (void)state;
    bus.ripple_V = 2.0;
    bus.ripple_Hz = 100.0;
    sil_inverter_init(&inv, &cfg, &bus, BUS_V, 0u);
    assert_true(fabs(sil_inverter_bus_voltage(&inv, 2.5e-3) - (BUS_V + 2.0)) < 1e-12);
    assert_true(fabs(sil_inverter_bus_voltage(&inv, 7.5e-3) - (BUS_V - 2.0)) < 1e-12);
    /* The duty against a 40 V reading is u / 40, clipped to 1; the bridge applies it to the actual bus. */
    plant.time_s = 2.5e-3 - 0.5 * PERIOD_S;
    period(&plant, &inv, 60.0, -20.0, true, 40.0);
    print_message("command 60 V / -20 V against a 40 V reading, bus ~50 V: mean u = %.6f V, %.6f V; %lu clipped\n",
                  inv.applied_a_V, inv.applied_b_V, inv.limited_periods);
    assert_true(inv.limited_periods == 1u);
    assert_true(fabs(inv.applied_a_V - (BUS_V + 2.0)) < 1e-3);       /* d = 1 */
    assert_true(fabs(inv.applied_b_V + 0.5 * (BUS_V + 2.0)) < 1e-3); /* d = -0.5 */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(ideal_averaged_is_plant_advance_bit_for_bit),
        cmocka_unit_test(averaged_dead_time_shifts_the_steady_current),
        cmocka_unit_test(averaged_dead_time_clamps_a_small_command_at_zero),
        cmocka_unit_test(averaged_dead_time_converges_across_zero_crossings),
        cmocka_unit_test(switching_dead_time_shifts_the_mean_current_alike),
        cmocka_unit_test(switching_matches_averaged_and_the_rl_ripple),
        cmocka_unit_test(switching_in_one_exponential_step_keeps_the_ripple),
        cmocka_unit_test(switching_one_step_matches_the_segments),
        cmocka_unit_test(switching_dead_time_takes_the_sign_at_each_edge),
        cmocka_unit_test(bridge_off_freewheels_to_exactly_zero_and_holds),
        cmocka_unit_test(open_phase_holds_zero_against_back_emf),
        cmocka_unit_test(bus_sags_with_the_source_resistance),
        cmocka_unit_test(bus_ripple_and_duty_clip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
