/**
 * @file pmstep_identify.h
 * @brief Identification of the inertia J and the viscous friction F at the start of RUN.
 *
 * Model (1) gives the torque balance k_M i_q = J w' + F w + T_L (the detent torque of a hybrid
 * averages out over its periods once the rotor turns). While the speed tracks its reference,
 * w ~ w* and w' ~ w*', and the reference's values are free of noise; so over a window that
 * holds acceleration, the least-squares fit of the sampled q current
 *     i_q = c_0 + c_a w*' + c_w w*        (one sample a period)
 * gives J = k_M c_a, F = k_M c_w and T_L = k_M c_0 (k_M of the model in use). The regression
 * is on the measured current, not on the observer's load estimate T_L-hat: T_L-hat follows
 * (J - J_0) w' through the observer's triple pole, and that lag took 4.5 % off J on the
 * 17HS4401 in the SIL where the current's fit is within 0.5 % (README, "Self-commissioning").
 *
 * Every PMSTEP_IDENTIFICATION_DECIMATION-th period of the window adds to the normal equations'
 * sums (nine multiply-adds: about 29 instructions on the Cortex-M4, so a sample every period
 * would have taken the RUN step's mean over 600 while the window is open); at the
 * end of the window the system is solved once: the constant eliminated (sums centred), the
 * remaining 2x2 system by Cramer's rule. Its determinant over sum a^2 sum w^2 equals the
 * determinant of the 3x3 normal matrix normalised by its diagonal (the cosine matrix of the
 * columns 1, a, w), which measures the conditioning whatever the units: below
 * PMSTEP_IDENTIFICATION_MIN_DETERMINANT the data cannot separate the regressors (no
 * acceleration, or a speed that never changes) and nothing is identified.
 */
#ifndef PMSTEP_IDENTIFY_H
#define PMSTEP_IDENTIFY_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Identification of J and F: an identified J within [1/this, this] x the configured one is
 *  plausible (PMSTEP_IDENT_IMPLAUSIBLE beyond). The configured J may be the rotor's alone, or the
 *  designer's estimate from the holding torque (within 2x of the rotor's), while the shaft carries
 *  a load: a printer's belt carriage reflects several times a NEMA 17 rotor's inertia. The range
 *  is the designer's own for a datasheet J (pmstep_design_check_datasheet(): 1/10 to 10 x its
 *  estimate). */
#define PMSTEP_IDENTIFICATION_INERTIA_RANGE 10.0f

/** Sums of the normal equations of the fit y = c_0 + c_a a + c_w w (a = w*', w = w*, y = i_q). */
typedef struct {
    float n;          /**< samples */
    float a;          /**< sum a */
    float w;          /**< sum w */
    float aa;         /**< sum a^2 */
    float aw;         /**< sum a w */
    float ww;         /**< sum w^2 */
    float y;          /**< sum y */
    float ay;         /**< sum a y */
    float wy;         /**< sum w y */
    uint32_t periods; /**< RUN periods the window has covered (PMSTEP_IDENTIFICATION_DECIMATION a sample) */
} pmstep_identify_sums_t;

/** Coefficients of the fit, in the units of y per unit of each regressor. */
typedef struct {
    float offset;      /**< c_0 */
    float accel_coeff; /**< c_a: per rad/s^2 */
    float speed_coeff; /**< c_w: per rad/s */
} pmstep_identify_fit_t;

void pmstep_identify_clear(pmstep_identify_sums_t *sums);

/**
 * One sample of the window, taken every PMSTEP_IDENTIFICATION_DECIMATION RUN periods: adds
 * (a = out->speed_ref_rate_rad_s2, w = out->speed_ref_rad_s, y = out->i_q_A) when |w| is at least
 * comm->identification_min_speed_rad_s, and counts the periods it stands for.
 * @return true when the window of @p window_periods periods is covered.
 */
bool pmstep_identify_sample(pmstep_identify_sums_t *sums, const pmstep_commissioning_config_t *comm,
                            uint32_t window_periods, const pmstep_output_t *out);

/**
 * Solves the normal equations of @p sums (see above).
 * @return true and @p fit when the normalised determinant is at least @p min_determinant (the
 *         coefficients may still be non-finite if a sum is: pmstep_identify_finish() judges
 *         them); false, @p fit untouched, when the data are too poorly excited (a regressor
 *         with no energy, a determinant below @p min_determinant or not a number).
 */
bool pmstep_identify_solve(const pmstep_identify_sums_t *sums, float min_determinant, pmstep_identify_fit_t *fit);

/**
 * At the end of the window: J and F from the fit of i_q, with the k_M of @p model (the model RUN
 * uses), judged against the configured J of @p cfg and its control period. Writes
 * result->inertia_kgm2, friction_Nms_rad and identification (PMSTEP_IDENT_DONE,
 * _FRICTION_NEGATIVE, _POOR_EXCITATION or _IMPLAUSIBLE: J outside PMSTEP_IDENTIFICATION_INERTIA_RANGE
 * of the configured one, or |F|/J T_s >= 1/2, which also catches J or F not finite; see
 * pmstep_identification_t).
 * When J is usable, puts J and F (0 for F < 0) into @p model.
 * @return true when @p model was updated and cfg->commissioning.use_identified_mechanics asks
 *         for it to be used.
 */
bool pmstep_identify_finish(const pmstep_identify_sums_t *sums, const pmstep_config_t *cfg, pmstep_electrical_t *model,
                            pmstep_commissioning_t *result);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_IDENTIFY_H */
