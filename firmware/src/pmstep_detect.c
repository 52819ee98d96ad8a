/* Detection in RUN: angle magnitude, speed consistency, stall, observer residual (pmstep_detect.h). */
#include "pmstep/pmstep_detect.h"

#include "pmstep_internal.h"
#include "pmstep/pmstep_rotation.h"

/* The low-passes' time constant is the persistence over this. */
#define PERSISTENCE_PER_TIME_CONSTANT 4.0f

void pmstep_detect_coeffs_init(pmstep_detect_coeffs_t *coeffs, const pmstep_config_t *cfg)
{
    const float check_period_s = (float)PMSTEP_DETECTION_DECIMATION * cfg->timing.period_s;
    const float persistence_s = cfg->detection.persistence_s;
    coeffs->persistence_checks = pmstep_periods_in(persistence_s, check_period_s);
    /* Low-pass time constant persistence_s / 4; unused (and 1 s assumed) with every detector off. */
    coeffs->alpha = PERSISTENCE_PER_TIME_CONSTANT * check_period_s / (persistence_s > 0.0f ? persistence_s : 1.0f);
    coeffs->angle_step_per_speed = (float)cfg->motor.pole_pairs * check_period_s;
    coeffs->consistency_bound_rad = cfg->detection.speed_consistency_bound_rad_s * coeffs->angle_step_per_speed;
}

void pmstep_detect_start(pmstep_detector_t *detector)
{
    static const pmstep_detector_t fresh = {1.0f, 0.0f, 0.0f, 0.0f, 0u, 0u, 0u, 0u};
    *detector = fresh;
}

/* Counts the checks @p condition has held; true once it has held @p limit checks. */
static bool persists(uint32_t *count, bool condition, uint32_t limit)
{
    *count = condition ? *count + 1u : 0u;
    return *count >= limit;
}

pmstep_fault_t pmstep_detect_check(pmstep_detector_t *detector, const pmstep_detect_coeffs_t *coeffs,
                                   const pmstep_detection_config_t *cfg, const pmstep_output_t *out,
                                   const pmstep_meas_t *sample)
{
    const uint32_t limit = coeffs->persistence_checks;
    pmstep_fault_t found = PMSTEP_FAULT_NONE;
    if (cfg->angle_magnitude_bound > 0.0f) {
        const float magnitude_error = out->cos_hat * out->cos_hat + out->sin_hat * out->sin_hat - 1.0f;
        if (persists(&detector->magnitude_count, pmstep_abs(magnitude_error) > cfg->angle_magnitude_bound, limit)) {
            found = PMSTEP_FAULT_ANGLE_MAGNITUDE;
        }
    }
    if (cfg->speed_consistency_bound_rad_s > 0.0f) {
        /* The last check's estimate turned by p w-hat x check period, against the estimate now:
         * gap = sin of the angle between them. */
        float cos_turn;
        float sin_turn;
        float cos_expected;
        float sin_expected;
        float gap;
        pmstep_small_rotation(coeffs->angle_step_per_speed * out->speed_hat_rad_s, &cos_turn, &sin_turn);
        pmstep_turn(detector->prev_cos_hat, detector->prev_sin_hat, cos_turn, sin_turn, &cos_expected, &sin_expected);
        gap = cos_expected * out->sin_hat - sin_expected * out->cos_hat;
        detector->rotation_gap_rad += coeffs->alpha * (gap - detector->rotation_gap_rad);
        detector->prev_cos_hat = out->cos_hat;
        detector->prev_sin_hat = out->sin_hat;
        if (persists(&detector->consistency_count,
                     pmstep_abs(detector->rotation_gap_rad) > coeffs->consistency_bound_rad, limit)) {
            found = PMSTEP_FAULT_SPEED_INCONSISTENT;
        }
    }
    if (cfg->stall_speed_error_rad_s > 0.0f
        && persists(&detector->stall_count,
                    pmstep_abs(out->speed_hat_rad_s - out->speed_ref_rad_s) > cfg->stall_speed_error_rad_s, limit)) {
        found = PMSTEP_FAULT_STALL;
    }
    if (cfg->observer_residual_bound_A > 0.0f) {
        const float residual = pmstep_abs(sample->i_a_A - out->i_a_hat_A) + pmstep_abs(sample->i_b_A - out->i_b_hat_A);
        detector->residual_A += coeffs->alpha * (residual - detector->residual_A);
        if (persists(&detector->residual_count, detector->residual_A > cfg->observer_residual_bound_A, limit)) {
            found = PMSTEP_FAULT_OBSERVER_RESIDUAL;
        }
    }
    return found;
}
