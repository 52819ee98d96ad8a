/* Identification of J and F at the start of RUN (see pmstep_identify.h). */
#include "pmstep/pmstep_identify.h"

#include <math.h> /* sqrtf: one vsqrt.f32 / sqrtss with -fno-math-errno; isfinite: a classification macro */
#include <string.h>

void pmstep_identify_clear(pmstep_identify_sums_t *sums)
{
    memset(sums, 0, sizeof *sums);
}

/* det [[a, b, c], [b, d, e], [c, e, f]] of a symmetric 3x3 matrix. */
static float det3_symmetric(float a, float b, float c, float d, float e, float f)
{
    return a * (d * f - e * e) - b * (b * f - c * e) + c * (b * e - c * d);
}

/* det of the 3x3 matrix with columns (u, v, w). */
static float det3_columns(const float u[3], const float v[3], const float w[3])
{
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - v[0] * (u[1] * w[2] - u[2] * w[1])
           + w[0] * (u[1] * v[2] - u[2] * v[1]);
}

bool pmstep_identify_solve(const pmstep_identify_sums_t *sums, float min_determinant, pmstep_identify_fit_t *fit)
{
    float s0;
    float sa;
    float sw;
    float col_1[3];
    float col_a[3];
    float col_w[3];
    float rhs[3];
    float det;
    float c_0;
    float c_a;
    float c_w;
    if (!(sums->n > 0.0f && sums->aa > 0.0f && sums->ww > 0.0f)) {
        return false; /* a regressor without energy: the system is singular */
    }
    /* Normalised system: D^-1 N D^-1 z = D^-1 b, D = diag(sqrt(N_ii)), c = D^-1 z. */
    s0 = 1.0f / sqrtf(sums->n);
    sa = 1.0f / sqrtf(sums->aa);
    sw = 1.0f / sqrtf(sums->ww);
    col_1[0] = 1.0f;
    col_1[1] = sums->a * s0 * sa;
    col_1[2] = sums->w * s0 * sw;
    col_a[0] = col_1[1];
    col_a[1] = 1.0f;
    col_a[2] = sums->aw * sa * sw;
    col_w[0] = col_1[2];
    col_w[1] = col_a[2];
    col_w[2] = 1.0f;
    rhs[0] = sums->y * s0;
    rhs[1] = sums->ay * sa;
    rhs[2] = sums->wy * sw;
    det = det3_symmetric(1.0f, col_1[1], col_1[2], 1.0f, col_a[2], 1.0f);
    if (!(det >= min_determinant)) {
        return false; /* also NaN */
    }
    /* Cramer's rule. */
    c_0 = det3_columns(rhs, col_a, col_w) / det * s0;
    c_a = det3_columns(col_1, rhs, col_w) / det * sa;
    c_w = det3_columns(col_1, col_a, rhs) / det * sw;
    if (!(isfinite(c_0) && isfinite(c_a) && isfinite(c_w))) {
        return false;
    }
    fit->offset = c_0;
    fit->accel_coeff = c_a;
    fit->speed_coeff = c_w;
    return true;
}

void pmstep_identify_finish(const pmstep_identify_sums_t *sums, float torque_constant_Nm_A, float inertia_kgm2,
                            float period_s, pmstep_commissioning_t *result)
{
    pmstep_identify_fit_t fit;
    float j;
    float f;
    if (!pmstep_identify_solve(sums, PMSTEP_IDENTIFICATION_MIN_DETERMINANT, &fit)) {
        result->identification = PMSTEP_IDENT_POOR_EXCITATION;
        return;
    }
    j = torque_constant_Nm_A * fit.accel_coeff;
    f = torque_constant_Nm_A * fit.speed_coeff;
    result->inertia_kgm2 = j;
    result->friction_Nms_rad = f;
    if (!(j >= 0.5f * inertia_kgm2 && j <= 2.0f * inertia_kgm2 && isfinite(f) && f * period_s < 0.5f * j)) {
        result->identification = PMSTEP_IDENT_IMPLAUSIBLE;
    } else if (f < 0.0f) {
        result->identification = PMSTEP_IDENT_FRICTION_NEGATIVE;
    } else {
        result->identification = PMSTEP_IDENT_DONE;
    }
}
