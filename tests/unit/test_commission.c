/* Remark 2 calibration, self-commissioning and the alignments' dead-time compensation on the
 * real core, fed by a locked-rotor RL model of both phases (the only fake). Detection in RUN:
 * test_detect.c. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_instance.h" /* the tests look inside the instance */
#include "pmstep/pmstep_text.h"

/* Short alignments (40 ms each, 22 time constants L/R) so a test runs a few thousand periods. */
static pmstep_config_t short_config(void)
{
    pmstep_config_t cfg = pmstep_paper_config();
    cfg.alignment.s_align_time_s = 0.04f;
    cfg.alignment.c_align_time_s = 0.08f;
    cfg.commissioning.steady_state_window_s = 0.005f; /* 100 periods; L/R = 2 ms, so 7.5 time constants in */
    cfg.commissioning.inductance_window_s = 0.0005f;  /* 10 periods of current rise */
    cfg.commissioning.alignment_offset_calibration = true;
    return cfg;
}

/* The voltage-bias option on short_config(): each alignment 4 x longer, its last 40 ms at half
 * voltage (the lower level settles for 20 ms, 11 L/R), a compensation band for the bias. */
static pmstep_config_t two_level_config(void)
{
    pmstep_config_t cfg = short_config();
    cfg.alignment.s_align_time_s = 0.16f;
    cfg.alignment.c_align_time_s = 0.32f;
    cfg.commissioning.steady_state_window_s = 0.04f;
    cfg.commissioning.voltage_bias_level_fraction = 0.5f;
    cfg.inverter.dead_time_current_band_A = 0.05f;
    return cfg;
}

/* Both phases as R, L with the rotor locked (no back-EMF), exact for held voltages;
 * the sensors add an offset. */
typedef struct {
    double r_Ohm, l_H, i_a_A, i_b_A, offset_a_A, offset_b_A;
    double bias_V;  /* the bridge falls short by this at positive current (a dead time) */
    double emf_b_V; /* a rotor's back-EMF on phase b, where a test moves it */
} rl_plant_t;

static pmstep_meas_t rl_sample(const rl_plant_t *p)
{
    pmstep_meas_t m;
    m.i_a_A = (float)(p->i_a_A + p->offset_a_A);
    m.i_b_A = (float)(p->i_b_A + p->offset_b_A);
    m.bus_voltage_V = 48.0f;
    m.load_torque_Nm = 0.0f;
    m.phase_voltage_a_V = 0.0f;
    m.phase_voltage_b_V = 0.0f;
    return m;
}

static void rl_advance(rl_plant_t *p, const pmstep_output_t *out, double period_s)
{
    const double decay = exp(-p->r_Ohm * period_s / p->l_H);
    const double u_a = out->bridge_enable ? (double)out->u_a_V - (p->i_a_A > 0.0 ? p->bias_V : 0.0) : 0.0;
    const double u_b =
        (out->bridge_enable ? (double)out->u_b_V - (p->i_b_A > 0.0 ? p->bias_V : 0.0) : 0.0) - p->emf_b_V;
    p->i_a_A = p->i_a_A * decay + u_a / p->r_Ohm * (1.0 - decay);
    p->i_b_A = p->i_b_A * decay + u_b / p->r_Ohm * (1.0 - decay);
}

/* Runs until the core leaves the alignment (RUN or FAULT) or @p max_steps. */
static void run_rl(pmstep_t *inst, rl_plant_t *plant, pmstep_output_t *out, uint32_t max_steps)
{
    uint32_t k;
    for (k = 0; k < max_steps; ++k) {
        const pmstep_meas_t m = rl_sample(plant);
        pmstep_step(inst, &m, out);
        if (out->mode == PMSTEP_MODE_RUN || out->mode == PMSTEP_MODE_FAULT) {
            return;
        }
        rl_advance(plant, out, (double)inst->cfg->timing.period_s);
    }
}

static void no_window(pmstep_config_t *c)
{
    c->commissioning.steady_state_window_s = 0.0f;
    c->commissioning.alignment_offset_calibration = true;
}
static void bias_window_too_short(pmstep_config_t *c)
{
    c->commissioning.voltage_bias_level_fraction = 0.5f;
    c->inverter.dead_time_current_band_A = 0.05f;
    c->commissioning.steady_state_window_s = 0.005f;
}
static void bias_window_too_long(pmstep_config_t *c)
{
    c->commissioning.voltage_bias_level_fraction = 0.5f;
    c->inverter.dead_time_current_band_A = 0.05f;
    c->commissioning.steady_state_window_s = 0.015f;
}
static void bias_fraction_one(pmstep_config_t *c)
{
    c->commissioning.voltage_bias_level_fraction = 1.0f;
    c->inverter.dead_time_current_band_A = 0.05f;
}
static void long_window(pmstep_config_t *c) { c->commissioning.steady_state_window_s = 0.021f; }
/* A window no period count holds: refused before it is counted in periods. */
static void huge_window(pmstep_config_t *c) { c->commissioning.steady_state_window_s = 1e30f; }
static void long_rise(pmstep_config_t *c) { c->commissioning.inductance_window_s = 0.021f; }
static void negative_offset_time(pmstep_config_t *c) { c->commissioning.offset_calibration_time_s = -1e-3f; }
static void use_unmeasured_l(pmstep_config_t *c)
{
    c->commissioning.inductance_window_s = 0.0f;
    c->commissioning.use_measured_inductance = true;
}
static void use_unmeasured_r(pmstep_config_t *c)
{
    no_window(c);
    c->commissioning.alignment_offset_calibration = false;
    c->commissioning.use_measured_resistance = true;
}
static void use_unmeasured_km(pmstep_config_t *c)
{
    no_window(c);
    c->commissioning.alignment_offset_calibration = false;
    c->commissioning.use_measured_torque_constant = true;
}
static void dead_time_without_band(pmstep_config_t *c) { c->inverter.dead_time_s = 1e-6f; }
static void dead_time_too_long(pmstep_config_t *c)
{
    c->inverter.dead_time_s = 13e-6f;
    c->inverter.dead_time_current_band_A = 0.1f;
}
static void correction_too_fast(pmstep_config_t *c) { c->gains.angle_correction_gain_per_s = 10000.0f; }
static void correction_negative(pmstep_config_t *c) { c->gains.angle_correction_gain_per_s = -1.0f; }
static void negative_bound(pmstep_config_t *c) { c->detection.stall_speed_error_rad_s = -1.0f; }
static void detection_too_short(pmstep_config_t *c) { c->detection.persistence_s = 3.0f * c->timing.period_s; }
static void nan_window(pmstep_config_t *c) { c->commissioning.steady_state_window_s = NAN; }

static void calibration_settings_are_validated(void **state)
{
    static const struct {
        void (*edit)(pmstep_config_t *);
        pmstep_status_t expected;
    } cases[] = {
        {no_window, PMSTEP_ERR_ALIGNMENT_OFFSETS_UNMEASURED},
        {long_window, PMSTEP_ERR_STEADY_STATE_WINDOW},
        {huge_window, PMSTEP_ERR_STEADY_STATE_WINDOW},
        {long_rise, PMSTEP_ERR_INDUCTANCE_WINDOW},
        {negative_offset_time, PMSTEP_ERR_OFFSET_CALIBRATION_TIME},
        {use_unmeasured_l, PMSTEP_ERR_INDUCTANCE_UNMEASURED},
        {use_unmeasured_r, PMSTEP_ERR_RESISTANCE_UNMEASURED},
        {use_unmeasured_km, PMSTEP_ERR_TORQUE_CONSTANT_UNMEASURED},
        {dead_time_without_band, PMSTEP_ERR_DEAD_TIME_BAND},
        {dead_time_too_long, PMSTEP_ERR_DEAD_TIME},
        {correction_too_fast, PMSTEP_ERR_ANGLE_CORRECTION_GAIN},
        {correction_negative, PMSTEP_ERR_ANGLE_CORRECTION_GAIN},
        {negative_bound, PMSTEP_ERR_DETECTION_BOUND},
        {detection_too_short, PMSTEP_ERR_DETECTION_TIME},
        {nan_window, PMSTEP_ERR_NONFINITE_PARAMETER},
        {bias_window_too_short, PMSTEP_ERR_VOLTAGE_BIAS_SETTLING},
        {bias_window_too_long, PMSTEP_ERR_VOLTAGE_BIAS_WINDOW},
        {bias_fraction_one, PMSTEP_ERR_VOLTAGE_BIAS_FRACTION},
    };
    size_t n;
    pmstep_t inst;
    pmstep_config_t good = short_config();
    (void)state;
    assert_int_equal(pmstep_init(&inst, &good), PMSTEP_OK);
    for (n = 0; n < sizeof cases / sizeof cases[0]; ++n) {
        pmstep_config_t cfg = short_config();
        cases[n].edit(&cfg);
        print_message("case %u: %s\n", (unsigned)n, pmstep_status_str(pmstep_init(&inst, &cfg)));
        assert_int_equal(pmstep_init(&inst, &cfg), cases[n].expected);
    }
}

static void bridge_off_calibration_measures_the_offsets(void **state)
{
    pmstep_config_t cfg = short_config();
    rl_plant_t plant = {3.0, 0.006, 0.0, 0.0, 0.02, -0.01, 0.0};
    pmstep_t inst;
    pmstep_output_t out;
    pmstep_commissioning_t result;
    uint32_t k;
    (void)state;
    cfg.commissioning.offset_calibration_time_s = 0.001f; /* 20 periods */
    cfg.commissioning.alignment_offset_calibration = false;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_start(&inst), PMSTEP_OK);
    for (k = 0; k < 20u; ++k) {
        const pmstep_meas_t m = rl_sample(&plant);
        pmstep_step(&inst, &m, &out);
        assert_int_equal(out.mode, PMSTEP_MODE_OFFSET_CAL);
        assert_false(out.bridge_enable);
        rl_advance(&plant, &out, 50e-6);
    }
    run_rl(&inst, &plant, &out, 4000u);
    pmstep_get_commissioning(&inst, &result);
    print_message("offsets %.6f %.6f from %u samples\n", (double)result.offset_a_A, (double)result.offset_b_A,
                  (unsigned)result.offset_samples);
    assert_true(result.measured);
    assert_int_equal(result.offset_samples, 40u);
    assert_true(fabsf(result.offset_a_A - 0.02f) < 1e-7f);
    assert_true(fabsf(result.offset_b_A + 0.01f) < 1e-7f);
}

static void locked_rotor_gives_r_and_l_and_fails_the_torque_constant(void **state)
{
    /* R and L 20 % and 10 % above the configured 3 Ohm, 6 mH; offsets on both sensors.
     * The rotor never swings in c-alignment, so k_M comes out near 0: a commissioning fault.
     * (RUN keeps the configured L here, so the flux swing takes it: k_M reads the 0.6 mH it
     * misses times the 6.7 A step times p, 0.024 N m/A.) */
    pmstep_config_t cfg = short_config();
    rl_plant_t plant = {3.6, 0.0066, 0.0, 0.0, 0.02, -0.01, 0.0};
    pmstep_t inst;
    pmstep_output_t out;
    pmstep_commissioning_t result;
    (void)state;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_start(&inst), PMSTEP_OK);
    run_rl(&inst, &plant, &out, 4000u);
    pmstep_get_commissioning(&inst, &result);
    print_message("R %.6f L %.7f k_M %.5f offsets %.6f %.6f\n", (double)result.resistance_Ohm,
                  (double)result.inductance_H, (double)result.torque_constant_Nm_A, (double)result.offset_a_A,
                  (double)result.offset_b_A);
    assert_true(fabsf(result.offset_a_A - 0.02f) < 1e-5f);
    assert_true(fabsf(result.offset_b_A + 0.01f) < 1e-5f);
    assert_true(fabsf(result.resistance_Ohm - 3.6f) < 3.6f * 1e-4f);
    /* The trapezoid rule over 10 periods of an exponential with tau = 1.83 ms: error ~ (T/tau)^2/12. */
    assert_true(fabsf(result.inductance_H - 0.0066f) < 0.0066f * 1e-3f);
    assert_true(fabsf(result.torque_constant_Nm_A) < 0.05f);
    assert_int_equal(out.mode, PMSTEP_MODE_FAULT);
    assert_int_equal(out.fault, PMSTEP_FAULT_COMMISSIONING);
    assert_int_equal(out.fault_step, 1600u + 1u);
}

static void two_levels_give_r_and_the_voltage_bias(void **state)
{
    /* The bridge falls short by 0.3 V at positive current: one level would read R 0.3 V / 6.7 A
     * (4.5 %) high; the second level at half voltage separates R from the bias. */
    pmstep_config_t cfg = two_level_config();
    rl_plant_t plant = {3.6, 0.0066, 0.0, 0.0, 0.02, -0.01, 0.3};
    pmstep_t inst;
    pmstep_output_t out;
    pmstep_commissioning_t result;
    uint32_t k;
    (void)state;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_start(&inst), PMSTEP_OK);
    for (k = 0; k < 3200u; ++k) { /* s-alignment: the last 800 periods at half voltage */
        const pmstep_meas_t m = rl_sample(&plant);
        pmstep_step(&inst, &m, &out);
        assert_true(out.u_b_V == (k < 2400u ? 24.0f : 12.0f));
        rl_advance(&plant, &out, 50e-6);
    }
    run_rl(&inst, &plant, &out, 8000u);
    pmstep_get_commissioning(&inst, &result);
    print_message("R %.6f bias %.6f %.6f V\n", (double)result.resistance_Ohm, (double)result.voltage_bias_a_V,
                  (double)result.voltage_bias_b_V);
    assert_true(fabsf(result.resistance_Ohm - 3.6f) < 3.6f * 1e-4f);
    assert_true(fabsf(result.voltage_bias_a_V - 0.3f) < 1e-3f);
    assert_true(fabsf(result.voltage_bias_b_V - 0.3f) < 1e-3f);
}

/* A rotor still moving in a steady-state window: one that sat on s-alignment's unstable
 * equilibrium and tips over late, passing through p theta = 0 where the driven phase b sees its
 * whole back-EMF: 10 V for 5 ms early in s-alignment's full-level window (periods 1700..1799 of
 * 6400), which moves that window's first half's mean of i_b by about 0.7 A, against a tolerance of
 * 5 % of the 6.7 A driven. Moving in the
 * first run only: the alignments are repeated once and give R and the bias as when nothing moved
 * (then the locked rotor's k_M fails, as above). Moving in every run: ALIGNMENT_MOTION after the
 * repeat. */
static void moving_rotor_repeats_the_alignments(void **state)
{
    const uint32_t run_periods = 6400u;
    uint32_t moving_runs;
    (void)state;
    for (moving_runs = 1u; moving_runs <= 2u; ++moving_runs) {
        pmstep_config_t cfg = two_level_config();
        rl_plant_t plant = {3.6, 0.0066, 0.0, 0.0, 0.02, -0.01, 0.3, 0.0};
        pmstep_t inst;
        pmstep_output_t out;
        pmstep_commissioning_t result;
        uint32_t k;
        assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
        assert_int_equal(pmstep_start(&inst), PMSTEP_OK);
        for (k = 0u; k < 3u * run_periods; ++k) {
            const pmstep_meas_t m = rl_sample(&plant);
            const uint32_t in_run = k % run_periods;
            pmstep_step(&inst, &m, &out);
            if (out.mode == PMSTEP_MODE_RUN || out.mode == PMSTEP_MODE_FAULT) {
                break;
            }
            plant.emf_b_V = (k / run_periods < moving_runs && in_run >= 1700u && in_run < 1800u) ? 10.0 : 0.0;
            rl_advance(&plant, &out, 50e-6);
        }
        pmstep_get_commissioning(&inst, &result);
        print_message("moving in %u run(s): mode %s, fault %s at period %u, repeats %u, R %.6f, bias %.6f %.6f V\n",
                      (unsigned)moving_runs, pmstep_mode_str(out.mode), pmstep_fault_str(out.fault), (unsigned)k,
                      (unsigned)result.alignment_repeats, (double)result.resistance_Ohm,
                      (double)result.voltage_bias_a_V, (double)result.voltage_bias_b_V);
        assert_int_equal(k, 2u * run_periods); /* t_c of the repeat */
        assert_int_equal(result.alignment_repeats, 1u);
        assert_int_equal(out.mode, PMSTEP_MODE_FAULT);
        assert_false(out.bridge_enable);
        if (moving_runs == 1u) {
            assert_int_equal(out.fault, PMSTEP_FAULT_COMMISSIONING);
            assert_true(fabsf(result.resistance_Ohm - 3.6f) < 3.6f * 1e-4f);
            assert_true(fabsf(result.voltage_bias_a_V - 0.3f) < 1e-3f);
            assert_true(fabsf(result.voltage_bias_b_V - 0.3f) < 1e-3f);
        } else {
            assert_int_equal(out.fault, PMSTEP_FAULT_ALIGNMENT_MOTION);
        }
    }
}

/* Without a rise window, L comes from the drops to the lower level: the same two levels as above
 * (bridge 0.3 V short, offsets), L 10 % above the configured 6 mH. Over each drop the integrand
 * u - bias - R i vanishes in both steady states, so L (i_2 - i_1) is the integral over the decay:
 * trapezoid error (T/tau)^2/12 ~ 6e-5, the lower level settled to e^-11. The rotor is locked, so
 * k_M fails as in the locked-rotor test above; L is still reported. */
static void level_drops_give_l_without_a_rise_window(void **state)
{
    pmstep_config_t cfg = two_level_config();
    rl_plant_t plant = {3.6, 0.0066, 0.0, 0.0, 0.02, -0.01, 0.3};
    pmstep_t inst;
    pmstep_output_t out;
    pmstep_commissioning_t result;
    (void)state;
    cfg.commissioning.inductance_window_s = 0.0f;
    cfg.commissioning.use_measured_inductance = true;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_start(&inst), PMSTEP_OK);
    run_rl(&inst, &plant, &out, 8000u);
    pmstep_get_commissioning(&inst, &result);
    print_message("L %.7f H (true 0.0066), R %.6f\n", (double)result.inductance_H, (double)result.resistance_Ohm);
    assert_true(fabsf(result.inductance_H - 0.0066f) < 0.0066f * 1e-3f);
    assert_int_equal(out.fault, PMSTEP_FAULT_COMMISSIONING); /* k_M: the locked rotor never swings */
    /* Without the voltage-bias level there are no drops: a measured L needs the rise window. */
    cfg.commissioning.voltage_bias_level_fraction = 0.0f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_ERR_INDUCTANCE_UNMEASURED);
}

/* The rest of p theta under (i_a, i_b) against the detent torque, by bisection in double on
 * k_M (i_b cos x - i_a sin x) = T_d sin 4x within 0.3 rad of the current vector's angle. */
static double rest_by_bisection(double i_a_A, double i_b_A, double k_Nm_A, double detent_Nm)
{
    const double psi = atan2(i_b_A, i_a_A);
    double lo = psi - 0.3;
    double hi = psi + 0.3;
    int k;
    for (k = 0; k < 60; k++) {
        const double mid = 0.5 * (lo + hi);
        const double torque = k_Nm_A * (i_b_A * cos(mid) - i_a_A * sin(mid)) - detent_Nm * sin(4.0 * mid);
        if (torque > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return 0.5 * (lo + hi);
}

/* The sums of a steady state held over a window of @p window samples. */
static void steady_window(pmstep_window_sums_t *sums, uint32_t window, double driven_A, double voltage_V,
                          double undriven_A)
{
    const double late = (double)(window / 2u);
    sums->current_sum_A = (float)(window * driven_A);
    sums->voltage_sum_V = (float)(window * voltage_V);
    sums->undriven_sum_A = (float)(window * undriven_A);
    sums->late_current_sum_A = (float)(late * driven_A);
}

/* The windows' sums of a rotor resting where an undriven phase's current of 0.2 x the driven one
 * (a dead-time compensation above the bridge's) and the detent torque put it, and the swing's flux
 * (k_M / p)(cos p theta_c - cos p theta_s) between the rests at a held current: k_M and the rest
 * at t_c come out as the plant's, not as for a rotor on the phase axes (k_M 0.78 x). */
static void rest_comes_from_both_phases_currents(void **state)
{
    const double driven_A = 2.0;
    const double undriven_A = 0.4;
    const float k_Nm_A = 2.0f;
    const uint32_t window = 100u;
    const uint32_t swing_periods = 800u;
    pmstep_config_t cfg = short_config();
    pmstep_commission_plan_t plan;
    pmstep_commission_sums_t sums;
    pmstep_commissioning_t result;
    double detent_Nm;
    (void)state;
    for (detent_Nm = 0.0; detent_Nm < 0.5; detent_Nm += 0.4) {
        const double rest_s = rest_by_bisection(undriven_A, driven_A, k_Nm_A, detent_Nm);
        const double rest_c = rest_by_bisection(driven_A, undriven_A, k_Nm_A, detent_Nm);
        const double flux_Wb = (double)k_Nm_A / (double)cfg.motor.pole_pairs * (cos(rest_c) - cos(rest_s));
        const double r_Ohm = (double)cfg.motor.resistance_Ohm;
        cfg.motor.detent_torque_Nm = (float)detent_Nm;
        cfg.motor.torque_constant_Nm_A = k_Nm_A;
        memset(&plan, 0, sizeof plan);
        plan.window_steps = window;
        plan.s_align_steps = 1000u;
        plan.c_align_end_step = plan.s_align_steps + swing_periods;
        pmstep_commission_clear(&sums);
        steady_window(&sums.alignment.s_full, window, driven_A, r_Ohm * driven_A, undriven_A);
        steady_window(&sums.alignment.c_full, window, driven_A, r_Ohm * driven_A, undriven_A);
        /* Phase a held at the driven current over the swing (the last sample added by finish). */
        sums.alignment.swing.start_A = (float)driven_A;
        sums.alignment.swing.end_A = (float)driven_A;
        sums.alignment.swing.current_sum_A = (float)(swing_periods * driven_A);
        sums.alignment.swing.voltage_sum_V = (float)((swing_periods - 1u) * r_Ohm * driven_A);
        sums.alignment.swing_start_step = plan.s_align_steps; /* phase a's voltage known from t_s */
        assert_int_equal(pmstep_commission_finish(&sums, &plan, &cfg, (float)driven_A,
                                                  (float)(r_Ohm * driven_A + flux_Wb / (double)cfg.timing.period_s),
                                                  &result),
                         PMSTEP_FAULT_NONE);
        print_message("  T_d %.1f N m: rests %.4f and %.4f rad, k_M %.5f N m/A, rest at t_c (%.5f, %.5f)\n", detent_Nm,
                      rest_s, rest_c, (double)result.torque_constant_Nm_A, (double)result.equilibrium_cos,
                      (double)result.equilibrium_sin);
        assert_float_equal(result.torque_constant_Nm_A, k_Nm_A, 2e-3);
        assert_float_equal(result.equilibrium_cos, cos(rest_c), 1e-4);
        assert_float_equal(result.equilibrium_sin, sin(rest_c), 1e-4);
    }
}

/* With phase-voltage sensing, R comes from the sensed voltages: the same two levels as above,
 * with a bridge 0.3 V short at positive current and a voltage sensor that reads 1 % high, give
 * R as that sensor sees it, 1.01 x 3.6 Ohm (so u - R i vanishes at standstill in the flux
 * integrals, which use the same sensor), and no voltage bias (nothing is short of the sensed
 * voltage). */
static void sensed_voltages_give_r_as_the_sensor_sees_it(void **state)
{
    const double sensor_gain = 1.01;
    pmstep_config_t cfg = two_level_config();
    rl_plant_t plant = {3.6, 0.0066, 0.0, 0.0, 0.02, -0.01, 0.3};
    pmstep_t inst;
    pmstep_output_t out;
    pmstep_commissioning_t result;
    double applied_a_V = 0.0;
    double applied_b_V = 0.0;
    uint32_t k;
    (void)state;
    cfg.inverter.phase_voltage_sensing = true;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_start(&inst), PMSTEP_OK);
    for (k = 0; k < 7000u; ++k) { /* t_c = 6400 periods */
        pmstep_meas_t m = rl_sample(&plant);
        m.phase_voltage_a_V = (float)(sensor_gain * applied_a_V);
        m.phase_voltage_b_V = (float)(sensor_gain * applied_b_V);
        pmstep_step(&inst, &m, &out);
        if (out.mode == PMSTEP_MODE_RUN || out.mode == PMSTEP_MODE_FAULT) {
            break;
        }
        applied_a_V = out.bridge_enable ? (double)out.u_a_V - (plant.i_a_A > 0.0 ? plant.bias_V : 0.0) : 0.0;
        applied_b_V = out.bridge_enable ? (double)out.u_b_V - (plant.i_b_A > 0.0 ? plant.bias_V : 0.0) : 0.0;
        rl_advance(&plant, &out, 50e-6);
    }
    pmstep_get_commissioning(&inst, &result);
    assert_true(result.measured); /* t_c reached (the locked rotor's k_M may fault, as above) */
    print_message("R %.6f bias %.6f %.6f V\n", (double)result.resistance_Ohm, (double)result.voltage_bias_a_V,
                  (double)result.voltage_bias_b_V);
    assert_true(fabsf(result.resistance_Ohm - 1.01f * 3.6f) < 3.6f * 1e-4f);
    assert_true(fabsf(result.voltage_bias_a_V) < 1e-3f);
    assert_true(fabsf(result.voltage_bias_b_V) < 1e-3f);
}

static void dead_time_is_compensated_on_the_driven_phase(void **state)
{
    pmstep_config_t cfg = short_config();
    pmstep_t inst;
    pmstep_output_t out;
    pmstep_meas_t m = {0.0f, 0.0f, 48.0f, 0.0f, 0.0f, 0.0f};
    (void)state;
    cfg.inverter.dead_time_s = 1e-6f;
    cfg.inverter.dead_time_current_band_A = 0.1f;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_start(&inst), PMSTEP_OK);
    pmstep_step(&inst, &m, &out);
    /* Two half-bridges per phase, each losing V_bus t_d / T_s = 0.96 V. The driven phase is
     * compensated in full from the first period, its current still 0 (the current its voltage
     * drives it to, u/R, is what counts): a phase started below the dead time's loss would
     * otherwise stay clamped at zero current. */
    assert_int_equal(out.mode, PMSTEP_MODE_S_ALIGN);
    assert_true(fabsf(out.u_b_V - (24.0f + 1.92f)) < 1e-4f);
    assert_true(out.u_a_V == 0.0f);
    m.i_a_A = 0.05f; /* the undriven phase by its sample, linear inside the band: half */
    m.i_b_A = 8.0f;
    pmstep_step(&inst, &m, &out);
    assert_true(fabsf(out.u_a_V - 0.96f) < 1e-4f);
    assert_true(fabsf(out.u_b_V - (24.0f + 1.92f)) < 1e-4f);
    /* The integrators get the voltage the bridge delivers, without the compensation. */
    assert_true(fabsf(inst.actuator.u_applied_b_V - 24.0f) < 1e-5f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(calibration_settings_are_validated),
        cmocka_unit_test(bridge_off_calibration_measures_the_offsets),
        cmocka_unit_test(locked_rotor_gives_r_and_l_and_fails_the_torque_constant),
        cmocka_unit_test(two_levels_give_r_and_the_voltage_bias),
        cmocka_unit_test(moving_rotor_repeats_the_alignments),
        cmocka_unit_test(level_drops_give_l_without_a_rise_window),
        cmocka_unit_test(rest_comes_from_both_phases_currents),
        cmocka_unit_test(sensed_voltages_give_r_as_the_sensor_sees_it),
        cmocka_unit_test(dead_time_is_compensated_on_the_driven_phase),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
