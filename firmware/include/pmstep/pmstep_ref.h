/**
 * @file pmstep_ref.h
 * @brief Reference generator: a ramp-limited set-point r(t) filtered by
 *        H(s) = w0^3/(s + w0)^3 (Section III.B), giving y, y', y''.
 *
 * Realisation: a chain of three first-order lags x1' = w0(r - x1),
 * x2' = w0(x1 - x2), x3' = w0(x2 - x3), so y = x3, y' = w0(x2 - x3),
 * y'' = w0^2 (x1 - 2 x2 + x3). The state kept is (x1 - x2, x2 - x3, x3): the
 * derivatives then need no difference of nearly equal floats. The set-point is
 * piecewise linear between samples, so the first-order-hold discretisation
 * used here is exact. A settled filter (differences and error below 1e-30 in the
 * channel's unit) is snapped onto its set-point rather than left to decay through
 * the subnormal floats.
 */
#ifndef PMSTEP_REF_H
#define PMSTEP_REF_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Discretised filter, shared by every channel with the same w0 and T_s. */
typedef struct {
    float phi[3][2];       /**< e^{A T_s} in the (d1, d2, y) coordinates, columns of d1 and d2 */
    float gamma0[3];       /**< response to the held set-point error r - y at the period start */
    float gamma1[3];       /**< response to the set-point change over the period (linear in time) */
    float bandwidth_rad_s; /**< w0 */
} pmstep_ref_coeffs_t;

/** One filtered set-point channel. */
typedef struct {
    float diff12;             /**< x1 - x2 */
    float diff23;             /**< x2 - x3 */
    float value;              /**< x3 = y */
    float value_compensation; /**< Kahan compensation of y: y increments are far below its ulp near rest */
    float setpoint;           /**< r at the present sample */
    float target;             /**< value r ramps towards */
    float ramp_rate_per_s;    /**< |dr/dt| limit; 0 means a step */
    float ramp_origin;        /**< set-point when the target was set */
    uint32_t ramp_periods;    /**< periods since then: r = origin +/- rate * n T_s, never accumulated */
    bool settled;             /**< at rest on its target (differences 0, y = r = target): a period changes nothing */
} pmstep_ref_t;

/** Filter output at one sample. */
typedef struct {
    float value; /**< y */
    float rate;  /**< y' per second */
    float accel; /**< y'' per second^2 */
} pmstep_ref_out_t;

/** Exact discretisation; valid for 0 < w0 T_s <= 0.5 (pmstep_validate_config checks). */
void pmstep_ref_coeffs_init(pmstep_ref_coeffs_t *coeffs, float bandwidth_rad_s, float period_s);

/** Puts the filter at rest at @p value (set-point, target and output equal). */
void pmstep_ref_reset(pmstep_ref_t *ref, float value);

/** Sets the target and the ramp rate (rate <= 0 means a step change now). */
void pmstep_ref_set_target(pmstep_ref_t *ref, float target, float ramp_rate_per_s);

/** Puts the filter at the state (y, x1 - x2, x2 - x3) with the set-point (and target) held at
 *  @p setpoint, no ramp: a trajectory of H(s) continued from outside (position loop). */
void pmstep_ref_place(pmstep_ref_t *ref, float setpoint, float value, float diff12, float diff23);

/** Output at the present sample (no state change). */
pmstep_ref_out_t pmstep_ref_output(const pmstep_ref_coeffs_t *coeffs, const pmstep_ref_t *ref);

/** Advances the set-point ramp and the filter by one period. */
void pmstep_ref_advance(const pmstep_ref_coeffs_t *coeffs, pmstep_ref_t *ref, float period_s);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_REF_H */
