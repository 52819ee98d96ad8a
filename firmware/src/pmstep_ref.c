/* Reference generator: ramp-limited set-point through H(s) = w0^3/(s+w0)^3 (Section III.B). */
#include "pmstep/pmstep_ref.h"

#include "pmstep_internal.h"

/* Terms of the series for a = w0 T_s <= 0.5: a^j/j! < 1e-12 beyond j = 16. */
#define REF_SERIES_TERMS 18

/* A filter whose differences and error are all below this (in the channel's unit; a moving
 * set-point keeps them far above) is snapped onto its set-point: left alone, its state would
 * decay through the subnormal floats, far below any meaning and slow on some FPUs. */
#define REF_SETTLED 1e-30f

void pmstep_ref_coeffs_init(pmstep_ref_coeffs_t *coeffs, float bandwidth_rad_s, float period_s)
{
    const float a = bandwidth_rad_s * period_s;
    /* power[j] = a^j / j!; every sum below has positive terms only (no cancellation). */
    float power[REF_SERIES_TERMS];
    float exp_a = 0.0f;
    float g2 = 0.0f; /* sum_{j>=3} a^j/j!           -> G_2 = e^-a * g2 */
    float h0 = 0.0f; /* sum_{j>=1} a^j/(j+1)!       */
    float h1 = 0.0f; /* sum_{j>=2} a^j/(j+1)!       */
    float h2 = 0.0f; /* sum_{j>=3} a^j/j! (j-2)/(j+1) */
    int j;

    power[0] = 1.0f;
    for (j = 1; j < REF_SERIES_TERMS; ++j) {
        power[j] = power[j - 1] * a / (float)j;
    }
    /* Smallest terms first. */
    for (j = REF_SERIES_TERMS - 1; j >= 0; --j) {
        const float term_over_next = power[j] / (float)(j + 1); /* a^j/(j+1)! */
        exp_a += power[j];
        if (j >= 1) {
            h0 += term_over_next;
        }
        if (j >= 2) {
            h1 += term_over_next;
        }
        if (j >= 3) {
            g2 += power[j];
            h2 += term_over_next * (float)(j - 2);
        }
    }
    {
        const float e = 1.0f / exp_a; /* e^-a */
        const float half_a2 = 0.5f * a * a;
        /* e^{A T} = e^-a [1 0 0; a 1 0; a^2/2 a 1] in the x coordinates, moved to
         * (d1, d2, y); the y column and the held set-point combine into the
         * error r - y because the DC gain is one (y' += ... is incremental). */
        coeffs->phi[0][0] = e * (1.0f - a);
        coeffs->phi[0][1] = -e * a;
        coeffs->phi[1][0] = e * (a - half_a2);
        coeffs->phi[1][1] = e * (1.0f - half_a2);
        coeffs->phi[2][0] = e * half_a2;
        coeffs->phi[2][1] = e * (half_a2 + a);
        /* Held set-point error r - y: G0 - G1 = e^-a a, G1 - G2 = e^-a a^2/2, G2. */
        coeffs->gamma0[0] = e * a;
        coeffs->gamma0[1] = e * half_a2;
        coeffs->gamma0[2] = e * g2;
        /* Set-point change over the period (first-order hold). */
        coeffs->gamma1[0] = e * h0;
        coeffs->gamma1[1] = e * h1;
        coeffs->gamma1[2] = e * h2;
    }
    coeffs->bandwidth_rad_s = bandwidth_rad_s;
}

void pmstep_ref_reset(pmstep_ref_t *ref, float value)
{
    ref->diff12 = 0.0f;
    ref->diff23 = 0.0f;
    ref->value = value;
    ref->value_compensation = 0.0f;
    ref->setpoint = value;
    ref->target = value;
    ref->ramp_rate_per_s = 0.0f;
    ref->ramp_origin = value;
    ref->ramp_periods = 0u;
    ref->settled = true;
}

void pmstep_ref_set_target(pmstep_ref_t *ref, float target, float ramp_rate_per_s)
{
    ref->settled = ref->settled && (target == ref->value); /* settled: y = r = the old target */
    ref->target = target;
    ref->ramp_origin = ref->setpoint;
    ref->ramp_periods = 0u;
    if (ramp_rate_per_s > 0.0f) {
        ref->ramp_rate_per_s = ramp_rate_per_s;
    } else {
        ref->ramp_rate_per_s = 0.0f;
        ref->setpoint = target;
    }
}

void pmstep_ref_place(pmstep_ref_t *ref, float setpoint, float value, float diff12, float diff23)
{
    pmstep_ref_reset(ref, setpoint);
    ref->diff12 = diff12;
    ref->diff23 = diff23;
    ref->value = value;
    ref->settled = false; /* the next period snaps it if the state is in fact at rest */
}

pmstep_ref_out_t pmstep_ref_output(const pmstep_ref_coeffs_t *coeffs, const pmstep_ref_t *ref)
{
    const float w0 = coeffs->bandwidth_rad_s;
    pmstep_ref_out_t out;
    out.value = ref->value;
    out.rate = w0 * ref->diff23;
    out.accel = w0 * w0 * (ref->diff12 - ref->diff23);
    return out;
}

void pmstep_ref_advance(const pmstep_ref_coeffs_t *coeffs, pmstep_ref_t *ref, float period_s)
{
    const float start = ref->setpoint;
    float next = ref->target;
    float change;
    float error;
    float increment;
    float d1;
    float d2;
    float y;

    /* At rest on its target (as the snap below leaves it): the period would change nothing. */
    if (ref->settled) {
        return;
    }
    if (ref->ramp_rate_per_s > 0.0f && next != start) {
        const float travel = ref->ramp_rate_per_s * ((float)(ref->ramp_periods + 1u) * period_s);
        if (next > ref->ramp_origin + travel) {
            next = ref->ramp_origin + travel;
        } else if (next < ref->ramp_origin - travel) {
            next = ref->ramp_origin - travel;
        }
        ref->ramp_periods++;
    }
    change = next - start;

    error = (start - ref->value) + ref->value_compensation;
    d1 = coeffs->phi[0][0] * ref->diff12 + coeffs->phi[0][1] * ref->diff23 + coeffs->gamma0[0] * error
         + coeffs->gamma1[0] * change;
    d2 = coeffs->phi[1][0] * ref->diff12 + coeffs->phi[1][1] * ref->diff23 + coeffs->gamma0[1] * error
         + coeffs->gamma1[1] * change;
    increment = coeffs->phi[2][0] * ref->diff12 + coeffs->phi[2][1] * ref->diff23 + coeffs->gamma0[2] * error
                + coeffs->gamma1[2] * change;
    {
        const float corrected = increment - ref->value_compensation;
        y = ref->value + corrected;
        ref->value_compensation = (y - ref->value) - corrected;
    }
    if (pmstep_abs(d1) + pmstep_abs(d2) + pmstep_abs(error) < REF_SETTLED) {
        d1 = 0.0f;
        d2 = 0.0f;
        y = next;
        ref->value_compensation = 0.0f;
        ref->settled = (next == ref->target);
    }
    ref->diff12 = d1;
    ref->diff23 = d2;
    ref->value = y;
    ref->setpoint = next;
}
