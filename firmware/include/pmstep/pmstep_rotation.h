/**
 * @file pmstep_rotation.h
 * @brief Rotations of the estimated angle by the small electrical angle the rotor turns
 *        in a few control periods, by polynomials (no libm call in the step).
 *
 * Used where the step must account for the rotation within or across periods: the
 * voltage placed at the angle it acts at (pmstep_law.c), the observer's back-EMF over its
 * period (pmstep_observer.c), the speed-consistency check over a detection period
 * (pmstep_detect.c). The first two fold their fixed angle-per-speed into polynomial
 * coefficients in w-hat at init.
 */
#ifndef PMSTEP_ROTATION_H
#define PMSTEP_ROTATION_H

#ifdef __cplusplus
extern "C" {
#endif

/**
 * cos(delta), sin(delta) by their Taylor polynomials to delta^4 and delta^5:
 * |error| < delta^6/720 and delta^7/5040, i.e. below 2.2e-5 for |delta| <= 0.5 rad and
 * below 4.2e-3 for |delta| <= 1.2 rad.
 */
static inline void pmstep_small_rotation(float delta_rad, float *cos_delta, float *sin_delta)
{
    const float d2 = delta_rad * delta_rad;
    *cos_delta = 1.0f - 0.5f * d2 * (1.0f - d2 * (1.0f / 12.0f));
    *sin_delta = delta_rad * (1.0f - d2 * (1.0f / 6.0f) * (1.0f - d2 * (1.0f / 20.0f)));
}

/** (c + j s)(cos_r + j sin_r): the angle (c, s) turned by the rotation (cos_r, sin_r). */
static inline void pmstep_turn(float c, float s, float cos_r, float sin_r, float *c_out, float *s_out)
{
    *c_out = c * cos_r - s * sin_r;
    *s_out = s * cos_r + c * sin_r;
}

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_ROTATION_H */
