/* Gain designer (firmware/design): each preset's design meets condition (4) and the rated
 * current, passes validation, places the observer's poles where docs/design says; bad motor data
 * gets its named error. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_design.h"

typedef struct {
    const char *name;
    float r, l, j, f, k_m;
    int32_t p;
    float rated_A, bus_V;
} motor_data_t;

/* sil/scenarios/motors/ */
static const motor_data_t presets[] = {
    {"paper", 3.0f, 0.006f, 0.01f, 0.0f, 2.0f, 6, 8.0f, 48.0f},
    {"17hs4401", 1.5f, 0.0028f, 5.4e-6f, 1e-4f, 0.16638f, 50, 1.7f, 24.0f},
    {"bj42d29", 1.4f, 0.0026f, 7.6e-6f, 1e-4f, 0.19328f, 50, 1.5f, 24.0f},
    {"as1050", 0.28f, 0.00086f, 3.6e-5f, 3e-4f, 0.16971f, 50, 5.0f, 48.0f},
};

static pmstep_design_input_t input_of(const motor_data_t *m, bool robust)
{
    pmstep_design_input_t in;
    in.motor.resistance_Ohm = m->r;
    in.motor.inductance_H = m->l;
    in.motor.inertia_kgm2 = m->j;
    in.motor.friction_Nms_rad = m->f;
    in.motor.torque_constant_Nm_A = m->k_m;
    in.motor.pole_pairs = m->p;
    in.motor.detent_torque_Nm = 0.0f;
    in.motor.rated_current_A = m->rated_A;
    in.current_sense_range_A = 3.0f * m->rated_A;
    in.bus_sense_range_V = 2.0f * m->bus_V;
    in.bus_voltage_V = m->bus_V;
    in.period_s = 50e-6f;
    in.computational_delay_periods = robust ? 1u : 0u;
    in.self_commissioning = robust;
    in.dead_time_s = robust ? 1e-6f : 0.0f;
    in.current_resolution_A = robust ? 0.005f : 0.0f;
    in.phase_voltage_sensing = false;
    in.low_speed_drive = false;
    in.holding_torque_Nm = 0.0f; /* no datasheet check */
    in.accept_implausible = false;
    return in;
}

/* docs/design/05-protections-and-detection.md: 0.04 I, plus the dead time's floor 4 V t_d / L in robust mode (on the
 * AS1050 at 48 V and 1 us, 0.2 A + 0.223 A). */
static void residual_bound_has_the_dead_time_floor(void **state)
{
    size_t n;
    (void)state;
    for (n = 0; n < sizeof presets / sizeof presets[0]; ++n) {
        const pmstep_design_input_t ideal = input_of(&presets[n], false);
        const pmstep_design_input_t robust = input_of(&presets[n], true);
        const float rated_share_A = 0.04f * presets[n].rated_A;
        const float floor_A = 4.0f * presets[n].bus_V * 1e-6f / presets[n].l;
        pmstep_config_t cfg;
        pmstep_design_report_t report;
        assert_int_equal(pmstep_design(&ideal, &cfg, &report), PMSTEP_OK);
        assert_float_equal(cfg.detection.observer_residual_bound_A, rated_share_A, 1e-6f * rated_share_A);
        assert_int_equal(pmstep_design(&robust, &cfg, &report), PMSTEP_OK);
        assert_float_equal(cfg.detection.observer_residual_bound_A, rated_share_A + floor_A,
                           1e-5f * (rated_share_A + floor_A));
    }
}

static void every_preset_gets_a_valid_design(void **state)
{
    size_t n;
    int robust;
    (void)state;
    for (n = 0; n < sizeof presets / sizeof presets[0]; ++n) {
        for (robust = 0; robust <= 1; ++robust) {
            const pmstep_design_input_t in = input_of(&presets[n], robust != 0);
            const float p = (float)in.motor.pole_pairs;
            pmstep_config_t cfg;
            pmstep_design_report_t report;
            pmstep_t inst;
            float lhs;
            float rhs;
            print_message("%s robust=%d\n", presets[n].name, robust);
            assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
            assert_int_equal(pmstep_validate_config(&cfg), PMSTEP_OK);
            assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
            /* (4): k_M u_cc/(p L R) - (u_cs^2 + u_cc^2)/(2 R^2) > 0, with margin 2 by the rule. */
            lhs = in.motor.torque_constant_Nm_A * cfg.alignment.c_align_voltage_V
                  / (p * in.motor.inductance_H * in.motor.resistance_Ohm);
            rhs = (cfg.alignment.s_align_voltage_V * cfg.alignment.s_align_voltage_V
                   + cfg.alignment.c_align_voltage_V * cfg.alignment.c_align_voltage_V)
                  / (2.0f * in.motor.resistance_Ohm * in.motor.resistance_Ohm);
            assert_true(lhs > rhs);
            assert_true(report.condition_4_margin >= 1.99f);
            /* Alignment current at most the rated current. */
            assert_true(cfg.alignment.s_align_voltage_V / in.motor.resistance_Ohm
                        <= in.motor.rated_current_A * 1.0001f);
            assert_true(cfg.alignment.c_align_voltage_V / in.motor.resistance_Ohm
                        <= in.motor.rated_current_A * 1.0001f);
            assert_true(cfg.limits.max_phase_current_A > in.motor.rated_current_A);
            /* PI current loop: K_I = K^2/8, K = R/L + K_i (poles 0.15 K and 0.85 K, real); on the q
             * axis K k_w / 5, its slow pole a fifth of the speed loop's (docs/design/02-current-and-speed-loops.md). */
            {
                const float k = in.motor.resistance_Ohm / in.motor.inductance_H + cfg.gains.current_gain_per_s;
                assert_float_equal(cfg.gains.current_integral_gain_per_s2, 0.125f * k * k, 1e-3f * k * k);
                assert_float_equal(cfg.gains.current_integral_gain_q_per_s2, 0.2f * k * cfg.gains.speed_gain_per_s,
                                   1e-4f * k * cfg.gains.speed_gain_per_s);
            }
            /* Robust: the back-EMF angle correction at twice the observer's bandwidth w_o,
             * half on where the back EMF equals R I + 2 V_bus t_d / T_s (docs/design/15-back-emf-angle-correction.md); off in
             * paper mode. */
            if (robust != 0) {
                const float corner_rad_s = (in.motor.resistance_Ohm * in.motor.rated_current_A
                                            + 2.0f * in.bus_voltage_V * in.dead_time_s / in.period_s)
                                           / in.motor.torque_constant_Nm_A;
                assert_float_equal(cfg.gains.emf_angle_gain_per_s, 2.0f * report.observer_bandwidth_rad_s, 1e-3f);
                assert_float_equal(cfg.gains.emf_angle_corner_rad_s, corner_rad_s, 1e-5f * corner_rad_s);
                assert_true(cfg.gains.emf_angle_gain_per_s
                            < in.motor.resistance_Ohm / in.motor.inductance_H + cfg.gains.observer_gain_per_s);
            } else {
                assert_true(cfg.gains.emf_angle_gain_per_s == 0.0f && cfg.gains.emf_angle_corner_rad_s == 0.0f);
            }
            /* Robust: the angle smoothing weighs the turned previous estimate and the reading
             * equally (docs/design/16-angle-smoothing.md); off in paper mode. */
            assert_true(cfg.gains.angle_smoothing == (robust != 0 ? 0.5f : 0.0f));
            /* Robust: the transient observer boost at 3, beyond the designed residual bound (docs/design
             * section 18); off in paper mode. */
            assert_true(cfg.gains.transient_observer_boost == (robust != 0 ? 3.0f : 0.0f));
            assert_true(robust == 0 || cfg.detection.observer_residual_bound_A > 0.0f);
            /* Robust: RUN takes the measured L and k_M. L from the current rise where the rotor stays
             * still over its window (the paper's motor, w_n T_L ~ 0.05), else from the level drops:
             * no rise window for the hybrids (~0.45-0.75), the voltage-bias level on. */
            assert_true(cfg.commissioning.use_measured_inductance == (robust != 0));
            assert_true(cfg.commissioning.use_measured_torque_constant == (robust != 0));
            if (robust != 0) {
                assert_true((cfg.commissioning.inductance_window_s > 0.0f) == (n == 0));
                assert_true(report.alignment_frequency_rad_s * cfg.commissioning.inductance_window_s < 0.1f);
                assert_true(cfg.commissioning.voltage_bias_level_fraction > 0.0f);
            }
            /* Top speed: the bus's, where (R I + k_M w)^2 + (p w L I)^2 = (0.9 V)^2, within the
             * control rate's 0.4 electrical rad per period (no preset reaches it). */
            assert_true(report.top_speed_rad_s == report.bus_speed_rad_s);
            assert_true((float)p * report.top_speed_rad_s * in.period_s <= 0.4f);
            {
                const double w = (double)report.bus_speed_rad_s;
                const double i = (double)in.motor.rated_current_A;
                const double u_q = (double)in.motor.resistance_Ohm * i + (double)in.motor.torque_constant_Nm_A * w;
                const double u_d = (double)p * w * (double)in.motor.inductance_H * i;
                assert_true(fabs(sqrt(u_q * u_q + u_d * u_d) - 0.9 * (double)in.bus_voltage_V)
                            < 1e-3 * (double)in.bus_voltage_V);
            }
        }
    }
}

static void detent_compensation_fades_where_the_current_loop_ends(void **state)
{
    /* 4 p w_f = 2 x the current loop's bandwidth 0.2 / T_s: 40 rad/s on the hybrids (p = 50) at
     * 20 kHz, 333.3 rad/s on a p = 6 motor; no fade without a detent torque. */
    size_t n;
    (void)state;
    for (n = 0; n < sizeof presets / sizeof presets[0]; ++n) {
        pmstep_design_input_t in = input_of(&presets[n], true);
        pmstep_config_t cfg;
        pmstep_design_report_t report;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_true(cfg.gains.detent_fade_speed_rad_s == 0.0f);
        in.motor.detent_torque_Nm = 0.02f;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(cfg.gains.detent_fade_speed_rad_s, 2.0f * 4000.0f / (4.0f * (float)presets[n].p), 1e-3f);
    }
}

/* docs/design/04-alignment.md: with a detent torque s-alignment leads in for the swing's settling time
 * (rounded up to 10 ms), and its own part and c-alignment stay as designed without one. */
static void s_alignment_leads_in_where_there_is_a_detent(void **state)
{
    size_t n;
    int robust;
    (void)state;
    for (n = 0; n < sizeof presets / sizeof presets[0]; ++n) {
        for (robust = 0; robust <= 1; ++robust) {
            pmstep_design_input_t in = input_of(&presets[n], robust != 0);
            pmstep_config_t plain;
            pmstep_config_t detent;
            pmstep_design_report_t report;
            float lead_in_ms;
            assert_int_equal(pmstep_design(&in, &plain, &report), PMSTEP_OK);
            assert_true(plain.alignment.s_lead_in_time_s == 0.0f);
            in.motor.detent_torque_Nm = 0.02f;
            assert_int_equal(pmstep_design(&in, &detent, &report), PMSTEP_OK);
            assert_int_equal(pmstep_validate_config(&detent), PMSTEP_OK);
            lead_in_ms = 1000.0f * detent.alignment.s_lead_in_time_s;
            print_message("%s robust=%d: lead-in %.0f ms, t_s %.3f s, t_c %.3f s\n", presets[n].name, robust,
                          (double)lead_in_ms, (double)detent.alignment.s_align_time_s,
                          (double)detent.alignment.c_align_time_s);
            assert_true(lead_in_ms >= 9.99f && fabsf(lead_in_ms / 10.0f - roundf(lead_in_ms / 10.0f)) < 1e-3f);
            /* the settling time, without the windows robust mode adds */
            assert_true(detent.alignment.s_lead_in_time_s <= plain.alignment.s_align_time_s + 1e-6f);
            assert_float_equal(detent.alignment.s_align_time_s - detent.alignment.s_lead_in_time_s,
                               plain.alignment.s_align_time_s, 1e-6f);
            assert_float_equal(detent.alignment.c_align_time_s - detent.alignment.s_align_time_s,
                               plain.alignment.c_align_time_s - plain.alignment.s_align_time_s, 1e-6f);
        }
    }
}

/* docs/design/04-alignment.md#alignment-current: c-alignment pulls the rotor a full step across the
 * detent, which needs k_M I_al >= T_d / 0.9186. The current is raised to twice that, within 0.8 of
 * (4)'s limit k_M/(p L) (0.951 A on the 17HS4401) and the rating; a detent beyond what that current
 * pulls across is refused. */
static void alignment_current_pulls_the_rotor_across_the_detent(void **state)
{
    static const struct {
        float detent_Nm;
        float current_A; /* expected alignment current */
        pmstep_status_t expected;
    } cases[] = {
        {0.02f, 0.594214f, PMSTEP_OK}, /* the preset's: (4)'s half limit covers it */
        {0.07f, 0.916057f, PMSTEP_OK}, /* twice the barrier's least current */
        {0.10f, 0.950742f, PMSTEP_OK}, /* 0.8 of (4)'s limit: margin 1.45 */
        {0.15f, 0.0f, PMSTEP_ERR_DETENT_ABOVE_ALIGNMENT},
    };
    size_t n;
    int robust;
    (void)state;
    for (robust = 0; robust <= 1; ++robust) {
        for (n = 0; n < sizeof cases / sizeof cases[0]; ++n) {
            pmstep_design_input_t in = input_of(&presets[1], robust != 0);
            pmstep_config_t cfg;
            pmstep_design_report_t report;
            in.motor.detent_torque_Nm = cases[n].detent_Nm;
            assert_int_equal(pmstep_design(&in, &cfg, &report), cases[n].expected);
            if (cases[n].expected != PMSTEP_OK) {
                continue;
            }
            assert_float_equal(report.alignment_current_A, cases[n].current_A, 1e-4f);
            assert_float_equal(cfg.alignment.c_align_voltage_V, in.motor.resistance_Ohm * cases[n].current_A, 1e-4f);
            assert_true(report.condition_4_margin >= 1.2499f);
            assert_float_equal(report.detent_margin,
                               0.918559f * in.motor.torque_constant_Nm_A * cases[n].current_A / cases[n].detent_Nm,
                               1e-3f);
            assert_true(report.detent_margin > 1.0f);
        }
    }
}

static void observer_poles_are_placed(void **state)
{
    /* s^3 + (a_e + F/J) s^2 + (a_e F/J + g_w b^2) s + g_T b^2/J = (s + w_o)^3, b = k_M/L,
     * a_e = R/L + K_e, g_w = 2/lambda, g_T = J/gamma + 2F/lambda (r F negligible). */
    size_t n;
    (void)state;
    for (n = 0; n < sizeof presets / sizeof presets[0]; ++n) {
        const pmstep_design_input_t in = input_of(&presets[n], false);
        const double r = (double)in.motor.resistance_Ohm, l = (double)in.motor.inductance_H;
        const double j = (double)in.motor.inertia_kgm2, f = (double)in.motor.friction_Nms_rad;
        const double b = (double)in.motor.torque_constant_Nm_A / l;
        pmstep_config_t cfg;
        pmstep_design_report_t report;
        double a_e, g_w, g_t, w_o;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        w_o = (double)report.observer_bandwidth_rad_s;
        a_e = r / l + (double)cfg.gains.observer_gain_per_s;
        g_w = 2.0 / (double)cfg.gains.adapt_lambda;
        g_t = j / (double)cfg.gains.adapt_gamma + 2.0 * f / (double)cfg.gains.adapt_lambda;
        assert_true(fabs((a_e + f / j) / (3.0 * w_o) - 1.0) < 1e-4);
        assert_true(fabs((a_e * f / j + g_w * b * b) / (3.0 * w_o * w_o) - 1.0) < 1e-4);
        assert_true(fabs(g_t * b * b / j / (w_o * w_o * w_o) - 1.0) < 1e-4);
        /* Current loop R/L + K_i = 0.2 / T_s; speed loop w_o / 3. */
        assert_true(fabs((r / l + (double)cfg.gains.current_gain_per_s) * 50e-6 - 0.2) < 1e-5);
        assert_true(fabs((double)cfg.gains.speed_gain_per_s - w_o / 3.0) < 1e-3 * w_o);
    }
}

typedef void (*input_edit_t)(pmstep_design_input_t *in);
static void zero_r(pmstep_design_input_t *in) { in->motor.resistance_Ohm = 0.0f; }
static void negative_l(pmstep_design_input_t *in) { in->motor.inductance_H = -1e-3f; }
static void zero_j(pmstep_design_input_t *in) { in->motor.inertia_kgm2 = 0.0f; }
static void zero_km(pmstep_design_input_t *in) { in->motor.torque_constant_Nm_A = 0.0f; }
static void negative_f(pmstep_design_input_t *in) { in->motor.friction_Nms_rad = -1e-4f; }
static void zero_p(pmstep_design_input_t *in) { in->motor.pole_pairs = 0; }
static void nan_r(pmstep_design_input_t *in) { in->motor.resistance_Ohm = NAN; }
static void inf_j(pmstep_design_input_t *in) { in->motor.inertia_kgm2 = INFINITY; }
static void zero_rated(pmstep_design_input_t *in) { in->motor.rated_current_A = 0.0f; }
static void low_bus(pmstep_design_input_t *in) { in->bus_voltage_V = 2.5f; } /* R I = 2.55 V > 0.9 x 2.5 V */
static void zero_bus(pmstep_design_input_t *in) { in->bus_voltage_V = 0.0f; }
static void slow_rate(pmstep_design_input_t *in) { in->period_s = 1e-3f; } /* (R/L) T_s = 0.54 */
/* (R/L + F/J) T_s = 0.376: beyond the 0.35 the discretisation takes */
static void rate_for_winding(pmstep_design_input_t *in) { in->period_s = 7e-4f; }
/* F/J = 7400/s: (R/L + F/J) T_s = 0.40 */
static void heavy_friction(pmstep_design_input_t *in) { in->motor.friction_Nms_rad = 0.04f; }
static void bad_period(pmstep_design_input_t *in) { in->period_s = 0.1f; }
static void bad_delay(pmstep_design_input_t *in) { in->computational_delay_periods = 2u; }
static void long_dead_time(pmstep_design_input_t *in) { in->dead_time_s = 20e-6f; }
static void no_current_sensing(pmstep_design_input_t *in) { in->current_sense_range_A = 0.0f; }
/* 17HS4401: 1.7 A rated needs a trip of 2.125 A at least, so 2.2 A of range (2.09 A usable) is short. */
static void current_sensing_below_rated(pmstep_design_input_t *in) { in->current_sense_range_A = 2.2f; }
/* 24 V bus: the overvoltage trip must reach 26.4 V, and 27 V of range gives 25.65 V. */
static void bus_sensing_below_bus(pmstep_design_input_t *in) { in->bus_sense_range_V = 27.0f; }

/* The datasheet check (only with a holding torque given): the 17HS4401's 0.40 N m, 1.7 A, 2.8 mH,
 * 1.5 Ohm, 5.4e-6 kg m^2 pass; a holding torque typed in N cm (40 for 0.40, k_M from it), an L in
 * uH, a J in g cm^2 or an L that no winding of this magnet has do not; accept_implausible designs
 * anyway; a J of 0 is estimated from the holding torque and reported so. */
/* A winding faster than the bandwidths the control rate gives: (R/L) T_s = 0.2 on the 17HS4401 at
 * 373 us is designed with its current loop at 1.25 R/L and the observer's current pole at 1.25 R/L,
 * not refused; the result passes init's checks (pmstep_design() validates it). */
static void fast_winding_gets_a_rate_limited_design(void **state)
{
    pmstep_design_input_t in = input_of(&presets[1], false);
    pmstep_config_t cfg;
    pmstep_design_report_t report;
    const float r_over_l = 1.5f / 0.0028f;
    (void)state;
    in.period_s = 0.2f / r_over_l;
    assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
    assert_float_equal(report.current_bandwidth_rad_s, 1.25f * r_over_l, 1e-2f);
    /* the observer at least at the winding's rate; the light rotor's full-step rule may raise it, to 0.1 / T_s */
    assert_true(3.0f * report.observer_bandwidth_rad_s >= 1.25f * (r_over_l + 1e-4f / 5.4e-6f) - 1e-1f);
    assert_true(report.observer_bandwidth_rad_s <= 0.1f / in.period_s + 1e-2f);
    assert_true(cfg.gains.current_gain_per_s > 0.0f && cfg.gains.observer_gain_per_s > 0.0f);
}

/* A NEMA 11 (R 2.08 Ohm, L 0.739 mH, k_M 0.0442 N m/A, 0.711 A, p = 50) on 48 V: the bus would
 * take it to 816 rad/s, 2.04 electrical rad per period at 20 kHz; its top speed is the control
 * rate's 0.4 rad per period, 160 rad/s, and the stall bound follows it. */
static void top_speed_within_the_control_rate(void **state)
{
    const motor_data_t nema11 = {"nema11", 2.08f, 0.000739f, 3.6e-7f, 1.1e-5f, 0.0442f, 50, 0.711f, 48.0f};
    int robust;
    (void)state;
    for (robust = 0; robust < 2; ++robust) {
        pmstep_design_input_t in = input_of(&nema11, robust != 0);
        pmstep_config_t cfg;
        pmstep_design_report_t report;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(report.bus_speed_rad_s, 816.0f, 1.0f);
        assert_float_equal(report.rate_speed_rad_s, 0.4f / (50.0f * 50e-6f), 1e-3f);
        assert_true(report.top_speed_rad_s == report.rate_speed_rad_s);
        assert_float_equal(report.top_electrical_step_rad, 0.4f, 1e-6f);
        assert_float_equal(cfg.detection.stall_speed_error_rad_s, 0.2f * 160.0f, 1e-3f);
        /* at 6 V the bus's 79 rad/s is below the rate's */
        in.bus_voltage_V = 6.0f;
        in.bus_sense_range_V = 12.0f;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_true(report.top_speed_rad_s == report.bus_speed_rad_s);
        assert_float_equal(report.bus_speed_rad_s, 79.0f, 1.0f);
    }
}

/* The observer's bandwidth from the rotor's full-step time under the rated torque,
 * t_step = sqrt(pi J / (p k_M I)): w_o = 2.674 / t_step within 0.05 / T_s .. 0.1 / T_s. The
 * 17HS4401 (t_step 0.98 ms) at 20 kHz is raised to the ceiling; with 2 x its J (1.38 ms) to
 * 2.674 / t_step; with 16 x (3.9 ms) it stays at the floor. The speed loop follows it (k_w = w_o / 3).
 * Robust mode asks 2.674 / (3 t_step), what its transient boost (x 3) makes of it: the floor for the
 * 17HS4401's J and more; raised for a quarter and a sixteenth of it (0.55 ms, 0.27 ms). */
static void observer_follows_the_full_step_time(void **state)
{
    const float scale[5] = {1.0f, 2.0f, 16.0f, 0.25f, 0.0625f};
    int k;
    (void)state;
    for (k = 0; k < 5; ++k) {
        pmstep_design_input_t in = input_of(&presets[1], false);
        pmstep_config_t cfg;
        pmstep_design_report_t report;
        float t_step_s;
        float expected;
        in.motor.inertia_kgm2 *= scale[k];
        t_step_s = sqrtf(3.14159265f * in.motor.inertia_kgm2
                         / ((float)in.motor.pole_pairs * in.motor.torque_constant_Nm_A * in.motor.rated_current_A));
        expected = 2.674f / t_step_s;
        expected = expected > 0.1f / in.period_s ? 0.1f / in.period_s : expected;
        expected = expected < 0.05f / in.period_s ? 0.05f / in.period_s : expected;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(report.observer_bandwidth_rad_s, expected, 1e-3f * expected);
        assert_float_equal(report.speed_bandwidth_rad_s, expected / 3.0f, 1e-3f * expected);
        in = input_of(&presets[1], true);
        in.motor.inertia_kgm2 *= scale[k];
        expected = 2.674f / (3.0f * t_step_s);
        expected = expected > 0.1f / in.period_s ? 0.1f / in.period_s : expected;
        expected = expected < 0.05f / in.period_s ? 0.05f / in.period_s : expected;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        print_message("J x %g: t_step %.3f ms, robust w_o %.0f rad/s\n", (double)scale[k], 1e3 * (double)t_step_s,
                      (double)report.observer_bandwidth_rad_s);
        assert_float_equal(report.observer_bandwidth_rad_s, expected, 1e-3f * expected);
        assert_true(k >= 3 ? report.observer_bandwidth_rad_s > 0.05f / in.period_s + 1.0f
                           : report.observer_bandwidth_rad_s == 0.05f / in.period_s);
    }
}

static void datasheet_check_names_what_no_stepper_has(void **state)
{
    pmstep_config_t cfg;
    pmstep_design_report_t report;
    pmstep_design_input_t in;
    (void)state;
    in = input_of(&presets[1], false);
    in.holding_torque_Nm = 0.40f;
    assert_int_equal(pmstep_design_check_datasheet(&in), PMSTEP_OK);
    assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
    assert_false(report.inertia_estimated);
    in.holding_torque_Nm = 40.0f; /* k_M still 0.166: 100 x off */
    assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_ERR_DATASHEET_TORQUE_CONSTANT);
    in.accept_implausible = true;
    assert_int_equal(pmstep_design_check_datasheet(&in), PMSTEP_ERR_DATASHEET_TORQUE_CONSTANT);
    assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
    in = input_of(&presets[1], false);
    in.holding_torque_Nm = 0.40f;
    in.motor.inductance_H = 2.8e-6f; /* uH typed as mH: L/R 1.9 us */
    assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_ERR_DATASHEET_TIME_CONSTANT);
    in = input_of(&presets[1], false);
    in.holding_torque_Nm = 0.40f;
    in.motor.inertia_kgm2 = 54.0f * 1e-7f * 1e3f; /* g cm^2 taken for 1e-4 kg m^2 units: 1000 x */
    assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_ERR_DATASHEET_INERTIA);
    in = input_of(&presets[1], false);
    in.holding_torque_Nm = 0.40f;
    in.motor.inductance_H = 0.3e-3f; /* p L I / k_M = 50 x 0.3 mH x 1.7 / 0.166 = 0.15 ... */
    in.motor.resistance_Ohm = 0.15f; /* (L/R 2 ms) passes; 0.1 mH gives 0.05: refused */
    assert_int_equal(pmstep_design_check_datasheet(&in), PMSTEP_OK);
    in.motor.inductance_H = 0.1e-3f;
    in.motor.resistance_Ohm = 0.05f;
    assert_int_equal(pmstep_design_check_datasheet(&in), PMSTEP_ERR_DATASHEET_FLUX_RATIO);
    /* No J: estimated as 2.1e-5 x 0.40^1.5 = 5.3e-6 kg m^2 and reported; paper mode designs for
     * the top of the estimate's range, twice that, robust mode for the estimate. */
    {
        int robust;
        for (robust = 0; robust < 2; ++robust) {
            in = input_of(&presets[1], robust != 0);
            in.holding_torque_Nm = 0.40f;
            in.motor.inertia_kgm2 = 0.0f;
            assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
            assert_true(report.inertia_estimated);
            assert_float_equal(report.inertia_kgm2, (robust != 0 ? 1.0f : 2.0f) * 2.1e-5f * 0.40f * sqrtf(0.40f),
                               1e-9f);
            assert_float_equal(cfg.motor.inertia_kgm2, report.inertia_kgm2, 0.0f);
        }
    }
}

static void bad_motor_data_gets_a_named_error(void **state)
{
    static const struct {
        input_edit_t edit;
        pmstep_status_t expected;
    } cases[] = {
        {zero_r, PMSTEP_ERR_RESISTANCE},
        {negative_l, PMSTEP_ERR_INDUCTANCE},
        {zero_j, PMSTEP_ERR_INERTIA},
        {zero_km, PMSTEP_ERR_TORQUE_CONSTANT},
        {negative_f, PMSTEP_ERR_FRICTION},
        {zero_p, PMSTEP_ERR_POLE_PAIRS},
        {nan_r, PMSTEP_ERR_NONFINITE_PARAMETER},
        {inf_j, PMSTEP_ERR_NONFINITE_PARAMETER},
        {zero_rated, PMSTEP_ERR_RATED_CURRENT},
        {low_bus, PMSTEP_ERR_BUS_BELOW_RATED},
        {zero_bus, PMSTEP_ERR_BUS_BELOW_RATED},
        {slow_rate, PMSTEP_ERR_RATE_TOO_SLOW},
        {rate_for_winding, PMSTEP_ERR_RATE_TOO_SLOW},
        {heavy_friction, PMSTEP_ERR_RATE_TOO_SLOW},
        {bad_period, PMSTEP_ERR_PERIOD},
        {bad_delay, PMSTEP_ERR_DELAY},
        {long_dead_time, PMSTEP_ERR_DEAD_TIME},
        {no_current_sensing, PMSTEP_ERR_SENSE_RANGE},
        {current_sensing_below_rated, PMSTEP_ERR_SENSE_RANGE_BELOW_RATED},
        {bus_sensing_below_bus, PMSTEP_ERR_BUS_ABOVE_SENSE_RANGE},
    };
    size_t n;
    pmstep_config_t cfg;
    pmstep_design_report_t report;
    (void)state;
    for (n = 0; n < sizeof cases / sizeof cases[0]; ++n) {
        pmstep_design_input_t in = input_of(&presets[1], true);
        cases[n].edit(&in);
        assert_int_equal(pmstep_design(&in, &cfg, &report), cases[n].expected);
    }
    {
        const pmstep_design_input_t in = input_of(&presets[1], false);
        assert_int_equal(pmstep_design(NULL, &cfg, &report), PMSTEP_ERR_NULL_ARGUMENT);
        assert_int_equal(pmstep_design(&in, NULL, &report), PMSTEP_ERR_NULL_ARGUMENT);
        assert_int_equal(pmstep_design(&in, &cfg, NULL), PMSTEP_ERR_NULL_ARGUMENT);
    }
}

/* Phase-voltage sensing is the drive's: the design passes it on and designs the same gains. */
static void phase_voltage_sensing_is_passed_on(void **state)
{
    pmstep_design_input_t in = input_of(&presets[1], true);
    pmstep_config_t without;
    pmstep_config_t with;
    pmstep_design_report_t report;
    (void)state;
    assert_int_equal(pmstep_design(&in, &without, &report), PMSTEP_OK);
    in.phase_voltage_sensing = true;
    assert_int_equal(pmstep_design(&in, &with, &report), PMSTEP_OK);
    assert_false(without.inverter.phase_voltage_sensing);
    assert_true(with.inverter.phase_voltage_sensing);
    /* the compensation's ripple dead zone: robust mode without sensing only */
    assert_true(without.inverter.ripple_dead_zone);
    assert_false(with.inverter.ripple_dead_zone);
    with.inverter.phase_voltage_sensing = false;
    assert_memory_equal(&with.gains, &without.gains, sizeof with.gains);
    assert_int_equal(pmstep_validate_config(&with), PMSTEP_OK);
}

/* The low-speed drive (pmstep_hold.h), asked for: robust mode with currents sensed only turns the
 * hold's vector below the speed whose back EMF is twice the dead time's loss, 2 V t_d / (T_s k_M)
 * (17HS4401 at 24 V, 1 us, 20 kHz, k_M 0.166 N m/A: 5.8 rad/s), and whose detent frequency 4 p w
 * is half the held rotor's natural frequency sqrt(p k_M I / J) (the 17HS4401's 4.05 rad/s, the
 * BJ42D29's 3.45, the AS1050's 2.71; the paper motor's 2.04 above its 0.96); off unless asked, in
 * the paper's design and with phase-voltage sensing. */
static void low_speed_drive_below_twice_the_dead_time_loss(void **state)
{
    size_t n;
    (void)state;
    for (n = 0; n < sizeof presets / sizeof presets[0]; ++n) {
        pmstep_design_input_t in = input_of(&presets[n], true);
        pmstep_design_input_t ideal = input_of(&presets[n], false);
        const float emf_band_rad_s = 2.0f * presets[n].bus_V * 1e-6f / (50e-6f * presets[n].k_m);
        const float resonance_band_rad_s =
            0.5f * sqrtf((float)presets[n].p * presets[n].k_m * presets[n].rated_A / presets[n].j)
            / (4.0f * (float)presets[n].p);
        const float expected_rad_s = emf_band_rad_s < resonance_band_rad_s ? emf_band_rad_s : resonance_band_rad_s;
        /* the hybrids' bands are the resonance's, the paper motor's the dead time's */
        assert_true((presets[n].p == 50) == (resonance_band_rad_s < emf_band_rad_s));
        pmstep_config_t cfg;
        pmstep_design_report_t report;
        /* not asked for: the band, the vector in stops only */
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(cfg.standstill.vector_speed_rad_s, expected_rad_s, 1e-5f * expected_rad_s);
        assert_true(cfg.standstill.stops_only);
        in.low_speed_drive = true;
        ideal.low_speed_drive = true;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(cfg.standstill.vector_speed_rad_s, expected_rad_s, 1e-5f * expected_rad_s);
        assert_false(cfg.standstill.stops_only);
        assert_true(cfg.standstill.vector_speed_rad_s < 0.2f * report.top_speed_rad_s);
        in.phase_voltage_sensing = true;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(cfg.standstill.vector_speed_rad_s, 0.0f, 0.0f);
        assert_false(cfg.standstill.stops_only);
        assert_int_equal(pmstep_design(&ideal, &cfg, &report), PMSTEP_OK);
        assert_float_equal(cfg.standstill.vector_speed_rad_s, 0.0f, 0.0f);
        assert_false(cfg.standstill.stops_only);
        assert_false(cfg.inverter.ripple_dead_zone); /* no compensation to shape */
    }
}

/* The magnetising current of robust mode (docs/design/08-robust-mode.md): 25 times the current one period's
 * dead-time volt-seconds move, 2 V t_d / L, within [I/8, 0.35 I]; I/8 with phase-voltage sensing
 * (the integrals take the sensed voltage), 0 in the paper's design. At 1 us: the paper motor
 * 25 x 0.016 A = 0.4 A, below its floor of 1 A; 17HS4401 25 x 2 x 24 V x 1 us / 2.8 mH = 0.4286 A and
 * BJ42D29 0.4615 A, within; AS1050 2.79 A, capped at 1.75 A. The same at 0.5 us: 17HS4401
 * 0.2143 A, BJ42D29 0.2308 A, AS1050 1.3953 A (all within). */
static void magnetising_current_follows_the_dead_time(void **state)
{
    static const float expected_A[] = {1.0f, 0.428571f, 0.461538f, 1.75f};
    static const float expected_half_dead_time_A[] = {1.0f, 0.214286f, 0.230769f, 1.395349f};
    size_t n;
    (void)state;
    for (n = 0; n < sizeof presets / sizeof presets[0]; ++n) {
        pmstep_design_input_t in = input_of(&presets[n], true);
        const pmstep_design_input_t ideal = input_of(&presets[n], false);
        pmstep_config_t cfg;
        pmstep_design_report_t report;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(report.magnetising_current_A, expected_A[n], 1e-5f);
        in.dead_time_s = 0.5e-6f;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(report.magnetising_current_A, expected_half_dead_time_A[n], 1e-5f);
        in.dead_time_s = 1e-6f;
        in.phase_voltage_sensing = true;
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(report.magnetising_current_A, 0.125f * presets[n].rated_A, 1e-6f);
        in.phase_voltage_sensing = false;
        in.dead_time_s = 0.0f; /* nothing to pass through: the floor */
        assert_int_equal(pmstep_design(&in, &cfg, &report), PMSTEP_OK);
        assert_float_equal(report.magnetising_current_A, 0.125f * presets[n].rated_A, 1e-6f);
        assert_int_equal(pmstep_design(&ideal, &cfg, &report), PMSTEP_OK);
        assert_float_equal(report.magnetising_current_A, 0.0f, 0.0f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_preset_gets_a_valid_design),
        cmocka_unit_test(detent_compensation_fades_where_the_current_loop_ends),
        cmocka_unit_test(s_alignment_leads_in_where_there_is_a_detent),
        cmocka_unit_test(alignment_current_pulls_the_rotor_across_the_detent),
        cmocka_unit_test(residual_bound_has_the_dead_time_floor),
        cmocka_unit_test(observer_poles_are_placed),
        cmocka_unit_test(bad_motor_data_gets_a_named_error),
        cmocka_unit_test(datasheet_check_names_what_no_stepper_has),
        cmocka_unit_test(fast_winding_gets_a_rate_limited_design),
        cmocka_unit_test(top_speed_within_the_control_rate),
        cmocka_unit_test(observer_follows_the_full_step_time),
        cmocka_unit_test(phase_voltage_sensing_is_passed_on),
        cmocka_unit_test(low_speed_drive_below_twice_the_dead_time_loss),
        cmocka_unit_test(magnetising_current_follows_the_dead_time),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
