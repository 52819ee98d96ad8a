/* Sensorless position control on the speed controller (pmstep_position.h). */
#include "pmstep/pmstep_position.h"

#include <math.h> /* fabsf: one instruction, no libm call */
#include <stddef.h>

#define POSITION_ONE ((int32_t)1)
#define POSITION_ZERO ((int32_t)0)
#define POSITION_PI 3.14159265358979f
/* 2 pi = HI + LO with HI = 201/32 exact in 8 bits: n HI is exact for |n| < 2^16 turns. */
#define POSITION_TWO_PI_HI 6.28125f
#define POSITION_TWO_PI_LO 1.93530717958648e-3f

/* atan(z) on [0, 1], odd polynomial of degree 9 (Abramowitz & Stegun 4.4.49, |error| <= 1e-5). */
#define ATAN_C1 0.9998660f
#define ATAN_C3 (-0.3302995f)
#define ATAN_C5 0.1801410f
#define ATAN_C7 (-0.0851330f)
#define ATAN_C9 0.0208351f

float pmstep_atan2_poly(float y, float x)
{
    const float ax = fabsf(x);
    const float ay = fabsf(y);
    const float big = ax > ay ? ax : ay;
    const float small = ax > ay ? ay : ax;
    float z;
    float z2;
    float angle;
    if (!(big > 0.0f)) {
        return 0.0f;
    }
    z = small / big;
    z2 = z * z;
    angle = z * (ATAN_C1 + z2 * (ATAN_C3 + z2 * (ATAN_C5 + z2 * (ATAN_C7 + z2 * ATAN_C9))));
    if (ay > ax) {
        angle = 0.5f * POSITION_PI - angle;
    }
    if (x < 0.0f) {
        angle = POSITION_PI - angle;
    }
    return y < 0.0f ? -angle : angle;
}

/* theta-hat (mechanical rad) from the last estimate, the turn count and the zero. */
static float estimate(const pmstep_position_t *pos)
{
    const float fine = pmstep_atan2_poly(pos->sin_hat, pos->cos_hat) - pos->zero_rad;
    const float turns = (float)pos->turns;
    return (POSITION_TWO_PI_HI * turns + (POSITION_TWO_PI_LO * turns + fine)) * pos->inv_pole_pairs;
}

pmstep_status_t pmstep_position_init(pmstep_position_t *pos, pmstep_t *inst, const pmstep_position_config_t *cfg)
{
    const pmstep_config_t *core;
    if (pos == NULL || inst == NULL || cfg == NULL || inst->cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    core = inst->cfg;
    if ((cfg->gain_per_s - cfg->gain_per_s) != 0.0f || (cfg->integral_gain_per_s2 - cfg->integral_gain_per_s2) != 0.0f) {
        return PMSTEP_ERR_NONFINITE_PARAMETER;
    }
    if (!(cfg->gain_per_s > 0.0f) || cfg->gain_per_s > 0.5f * core->gains.speed_gain_per_s) {
        return PMSTEP_ERR_POSITION_GAIN;
    }
    if (cfg->integral_gain_per_s2 < 0.0f || cfg->integral_gain_per_s2 > 0.25f * cfg->gain_per_s * cfg->gain_per_s) {
        return PMSTEP_ERR_POSITION_INTEGRAL_GAIN;
    }
    pos->inst = inst;
    pos->cfg = *cfg;
    pos->inv_pole_pairs = 1.0f / (float)core->motor.pole_pairs;
    pos->period_s = core->timing.period_s;
    pos->inv_bandwidth_s = 1.0f / inst->ref_coeffs.bandwidth_rad_s;
    pos->cos_hat = 1.0f;
    pos->sin_hat = 0.0f;
    pos->speed_hat_rad_s = 0.0f;
    pos->zero_rad = 0.0f;
    pos->turns = 0;
    pos->sin_negative = 0;
    pos->tracked = false;
    pos->position_mode = false;
    pos->error_integral_rad_s = 0.0f;
    return PMSTEP_OK;
}

void pmstep_position_step(pmstep_position_t *pos, const pmstep_meas_t *meas, pmstep_output_t *out,
                          pmstep_position_output_t *pos_out)
{
    pmstep_step(pos->inst, meas, out);
    pmstep_position_update(pos, out, pos_out);
}

void pmstep_position_update(pmstep_position_t *pos, const pmstep_output_t *out, pmstep_position_output_t *pos_out)
{
    int32_t sin_negative;
    float position_rad;
    if (out->mode != PMSTEP_MODE_RUN) {
        /* Not in RUN (or left it: stop, fault, re-alignment): the position is lost. */
        pos->tracked = false;
        pos->position_mode = false;
        pos_out->position_rad = 0.0f;
        pos_out->position_ref_rad = 0.0f;
        pos_out->position_error_rad = 0.0f;
        pos_out->tracked = false;
        pos_out->position_mode = false;
        pos_out->moving = false;
        return;
    }
    if (!pos->tracked) {
        /* RUN's first period: (c-hat, s-hat) = (1, 0) at the c-alignment's equilibrium. */
        pos->tracked = true;
        pos->turns = 0;
        pos->zero_rad = 0.0f;
        pos->sin_negative = 0;
        pos->position_mode = false;
    }
    /* One turn on when s-hat goes negative with c-hat < 0 (through pi), one back the other way. */
    sin_negative = (out->sin_hat < 0.0f) ? POSITION_ONE : POSITION_ZERO;
    if (out->cos_hat < 0.0f) {
        pos->turns += sin_negative - pos->sin_negative;
    }
    pos->sin_negative = sin_negative;
    pos->cos_hat = out->cos_hat;
    pos->sin_hat = out->sin_hat;
    pos->speed_hat_rad_s = out->speed_hat_rad_s;
    position_rad = estimate(pos);

    if (pos->position_mode && pos->inst->speed_ref.ramp_rate_per_s > 0.0f) {
        pos->position_mode = false; /* a speed command (pmstep_set_speed_target) since the last period */
    }
    pos_out->position_rad = position_rad;
    pos_out->tracked = true;
    pos_out->position_mode = pos->position_mode;
    pos_out->position_ref_rad = position_rad;
    pos_out->position_error_rad = 0.0f;
    pos_out->moving = false;
}

pmstep_status_t pmstep_get_position(const pmstep_position_t *pos, float *position_rad)
{
    if (pos == NULL || position_rad == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    *position_rad = estimate(pos);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_position_set_zero(pmstep_position_t *pos)
{
    if (pos == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!pos->tracked) {
        return PMSTEP_ERR_BAD_MODE;
    }
    pos->turns = 0;
    pos->zero_rad = pmstep_atan2_poly(pos->sin_hat, pos->cos_hat);
    return PMSTEP_OK;
}
