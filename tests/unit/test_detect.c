/* Detection in RUN on the real core: a lost angle latches its fault, or re-aligns with the
 * bridge on, after the detection's persistence (the only fake: the held measurements). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_instance.h" /* the test sets the flux integrals inside the instance */
#include "pmstep/pmstep_text.h"

/* s-alignment's current in phase b (u_cs / R = 8 A), then holds the c-aligned state (i_a = 8 A,
 * rotor still) into RUN. */
static void hold_to_run(pmstep_t *inst, pmstep_output_t *out)
{
    const pmstep_meas_t s_aligned = {0.0f, 8.0f, 48.0f, 0.0f, 0.0f, 0.0f};
    const pmstep_meas_t c_aligned = {8.0f, 0.0f, 48.0f, 0.0f, 0.0f, 0.0f};
    uint32_t k;
    assert_int_equal(pmstep_start(inst), PMSTEP_OK);
    for (k = 0; k <= inst->derived.commission_plan.c_align_end_step; ++k) {
        pmstep_step(inst, k < inst->derived.commission_plan.s_align_steps ? &s_aligned : &c_aligned, out);
    }
    assert_int_equal(out->mode, PMSTEP_MODE_RUN);
}

static void lost_angle_faults_or_realigns_after_the_detection_time(void **state)
{
    pmstep_config_t cfg = pmstep_paper_config();
    const pmstep_meas_t m = {8.0f, 0.0f, 48.0f, 0.0f, 0.0f, 0.0f};
    pmstep_t inst;
    pmstep_output_t out;
    uint32_t k;
    uint32_t jump_step;
    (void)state;
    cfg.alignment.s_align_time_s = 0.02f;
    cfg.alignment.c_align_time_s = 0.04f;
    cfg.detection.speed_consistency_bound_rad_s = 0.0f; /* only the magnitude check in this test */
    cfg.detection.stall_speed_error_rad_s = 0.0f;
    for (cfg.detection.max_realignments = 0u; cfg.detection.max_realignments <= 1u; ++cfg.detection.max_realignments) {
        assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
        hold_to_run(&inst, &out);
        /* Hold c-hat at 1.5 (|c^2 + s^2 - 1| = 1.25): with i_a = i_a(t_c), c-hat = 1 + (L p/k_M) phi1. */
        jump_step = inst.step_count;
        for (k = 0; k < 1000u && out.mode == PMSTEP_MODE_RUN; ++k) {
            inst.angle.phi_a = 0.5f / inst.derived.angle_coeffs.flux_to_angle;
            inst.angle.phi_a_compensation = 0.0f;
            inst.angle.phi_b = 0.0f;
            inst.angle.phi_b_compensation = 0.0f;
            pmstep_step(&inst, &m, &out);
        }
        print_message("max_realignments %u: mode %s after %u periods\n", (unsigned)cfg.detection.max_realignments,
                      pmstep_mode_str(out.mode), (unsigned)k);
        /* detected after 20 ms of the condition: 100 checks, one every PMSTEP_DETECTION_DECIMATION periods */
        assert_true(inst.step_count - jump_step >= 397u && inst.step_count - jump_step <= 400u);
        assert_false(out.bridge_enable);
        if (cfg.detection.max_realignments == 0u) {
            assert_int_equal(out.mode, PMSTEP_MODE_FAULT);
            assert_int_equal(out.fault, PMSTEP_FAULT_ANGLE_MAGNITUDE);
            assert_string_equal(pmstep_fault_str(out.fault), "ANGLE_MAGNITUDE");
        } else {
            pmstep_commissioning_t result;
            assert_int_equal(out.mode, PMSTEP_MODE_S_ALIGN);
            assert_int_equal(out.fault, PMSTEP_FAULT_NONE);
            pmstep_get_commissioning(&inst, &result);
            assert_int_equal(result.realignments, 1u);
            pmstep_step(&inst, &m, &out); /* the alignment drives again */
            assert_true(out.bridge_enable);
            assert_true(out.u_b_V == cfg.alignment.s_align_voltage_V);
        }
    }
}

/* A speed or load estimate beyond what the bus and the trip allow (4 V_max / k_M = 120 rad/s, 4 k_M
 * I_trip = 120 N m on the paper's motor) latches ESTIMATE_RANGE at the next check, before the
 * observer runs away to overflow; within the range nothing happens. */
static void estimate_out_of_range_faults(void **state)
{
    const pmstep_meas_t m = {8.0f, 0.0f, 48.0f, 0.0f, 0.0f, 0.0f};
    unsigned which;
    (void)state;
    for (which = 0; which < 3u; ++which) {
        pmstep_config_t cfg = pmstep_paper_config();
        pmstep_t inst;
        pmstep_output_t out;
        uint32_t k;
        cfg.alignment.s_align_time_s = 0.02f;
        cfg.alignment.c_align_time_s = 0.04f;
        assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
        hold_to_run(&inst, &out);
        assert_float_equal(inst.derived.observer_coeffs.speed_bound_rad_s, 4.0f * 60.0f / 2.0f, 1e-3f);
        assert_float_equal(inst.derived.observer_coeffs.load_bound_Nm, 4.0f * 2.0f * 15.0f, 1e-3f);
        for (k = 0; k < 8u && out.mode == PMSTEP_MODE_RUN; ++k) {
            if (which == 0u) {
                inst.observer.speed_hat_rad_s = -121.0f;
            } else if (which == 1u) {
                inst.observer.load_hat_Nm = 121.0f;
            } else {
                inst.observer.speed_hat_rad_s = 100.0f; /* within */
            }
            pmstep_step(&inst, &m, &out);
        }
        if (which < 2u) {
            assert_int_equal(out.mode, PMSTEP_MODE_FAULT);
            assert_int_equal(out.fault, PMSTEP_FAULT_ESTIMATE_RANGE);
            assert_string_equal(pmstep_fault_str(out.fault), "ESTIMATE_RANGE");
            assert_false(out.bridge_enable);
        } else {
            assert_int_not_equal(out.fault, PMSTEP_FAULT_ESTIMATE_RANGE);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(lost_angle_faults_or_realigns_after_the_detection_time),
        cmocka_unit_test(estimate_out_of_range_faults),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
