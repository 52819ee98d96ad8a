/* Identification of J and F at the start of RUN (see pmstep_identify.h). */
#include "pmstep/pmstep_identify.h"

#include <math.h> /* fabsf: one vabs.f32, no libm call */
#include <string.h>

void pmstep_identify_clear(pmstep_identify_sums_t *sums)
{
    memset(sums, 0, sizeof *sums);
}

bool pmstep_identify_solve(const pmstep_identify_sums_t *sums, float min_determinant, pmstep_identify_fit_t *fit)
{
    /* The constant's equation gives c_0 = (sum y - c_a sum a - c_w sum w)/n; the other two,
     * centred (S_xz = sum x z - sum x sum z / n), are a 2x2 system solved by Cramer's rule. Its
     * determinant over sum a^2 sum w^2 is the determinant of the 3x3 system normalised by its
     * diagonal (the cosine matrix of the columns 1, a, w): the conditioning, in any units. */
    float inv_n;
    float s_aa;
    float s_aw;
    float s_ww;
    float s_ay;
    float s_wy;
    float det;
    float c_a;
    float c_w;
    if (!(sums->n > 0.0f)) {
        return false;
    }
    inv_n = 1.0f / sums->n;
    s_aa = sums->aa - sums->a * sums->a * inv_n;
    s_aw = sums->aw - sums->a * sums->w * inv_n;
    s_ww = sums->ww - sums->w * sums->w * inv_n;
    s_ay = sums->ay - sums->a * sums->y * inv_n;
    s_wy = sums->wy - sums->w * sums->y * inv_n;
    det = s_aa * s_ww - s_aw * s_aw;
    if (!(det > 0.0f && det >= min_determinant * (sums->aa * sums->ww))) {
        return false; /* also a regressor without energy, and NaN */
    }
    c_a = (s_ay * s_ww - s_wy * s_aw) / det;
    c_w = (s_wy * s_aa - s_ay * s_aw) / det;
    fit->offset = (sums->y - c_a * sums->a - c_w * sums->w) * inv_n;
    fit->accel_coeff = c_a;
    fit->speed_coeff = c_w;
    return true;
}

bool pmstep_identify_sample(pmstep_identify_sums_t *sums, const pmstep_commissioning_config_t *comm,
                            uint32_t window_periods, const pmstep_output_t *out)
{
    const float w = out->speed_ref_rad_s;
    if (fabsf(w) >= comm->identification_min_speed_rad_s) {
        const float a = out->speed_ref_rate_rad_s2;
        const float y = out->i_q_A;
        sums->n += 1.0f;
        sums->a += a;
        sums->w += w;
        sums->aa += a * a;
        sums->aw += a * w;
        sums->ww += w * w;
        sums->y += y;
        sums->ay += a * y;
        sums->wy += w * y;
    }
    sums->periods += PMSTEP_IDENTIFICATION_DECIMATION;
    return sums->periods >= window_periods;
}

bool pmstep_identify_finish(const pmstep_identify_sums_t *sums, const pmstep_config_t *cfg, pmstep_electrical_t *model,
                            pmstep_commissioning_t *result)
{
    pmstep_identify_fit_t fit = {0.0f, 0.0f, 0.0f}; /* set by the solve when it succeeds */
    float j;
    float f;
    result->identification = PMSTEP_IDENT_POOR_EXCITATION;
    if (!pmstep_identify_solve(sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit)) {
        return false;
    }
    /* i_q = (J w*' + F w* + T_L)/k_M */
    j = model->torque_constant_Nm_A * fit.accel_coeff;
    f = model->torque_constant_Nm_A * fit.speed_coeff;
    result->inertia_kgm2 = j;
    result->friction_Nms_rad = f;
    result->identification = PMSTEP_IDENT_IMPLAUSIBLE;
    if (!(j * PMSTEP_IDENTIFICATION_INERTIA_RANGE >= cfg->motor.inertia_kgm2
          && j <= PMSTEP_IDENTIFICATION_INERTIA_RANGE * cfg->motor.inertia_kgm2
          && fabsf(f) * cfg->timing.period_s < 0.5f * j)) {
        return false; /* also J or F not finite */
    }
    result->identification = f < 0.0f ? PMSTEP_IDENT_FRICTION_NEGATIVE : PMSTEP_IDENT_DONE;
    model->inertia_kgm2 = j;
    model->friction_Nms_rad = f < 0.0f ? 0.0f : f; /* below what the fit resolves: none (the outcome says so) */
    return cfg->commissioning.use_identified_mechanics;
}
