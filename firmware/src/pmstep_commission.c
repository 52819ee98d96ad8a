/* Remark 2 calibration and self-commissioning from the alignment phases (see pmstep_commission.h). */
#include "pmstep/pmstep_commission.h"

#include "pmstep_internal.h"

#include <math.h> /* isfinite: a classification macro, no libm call */
#include <string.h>

/* The alignments' sums and t_c's one-off out of line (GCC, Clang): inlined into pmstep_step() by
 * link-time optimisation, their registers weigh on RUN's code as well. */
#if defined(__GNUC__)
#define COMMISSION_OUT_OF_LINE __attribute__((noinline))
#else
#define COMMISSION_OUT_OF_LINE
#endif

void pmstep_commission_clear(pmstep_commission_sums_t *sums)
{
    memset(sums, 0, sizeof *sums);
}

void pmstep_commission_add_bridge_off(pmstep_commission_sums_t *sums, float i_a_A, float i_b_A, float u_a_V,
                                      float u_b_V)
{
    sums->zero_sum_a_A += i_a_A;
    sums->zero_sum_b_A += i_b_A;
    sums->zero_voltage_sum_a_V += u_a_V;
    sums->zero_voltage_sum_b_V += u_b_V;
    sums->zero_count_a++;
    sums->zero_count_b++;
}

/* Sample in the W samples before @p end? */
static bool in_window(uint32_t sample, uint32_t end, uint32_t window)
{
    return sample < end && sample + window >= end;
}

bool pmstep_commission_low_level(const pmstep_commission_plan_t *plan, uint32_t sample, uint32_t end)
{
    return plan->bias_estimation && in_window(sample, end, plan->window_steps);
}

/* End of the full-voltage steady-state window of an alignment ending at @p end. */
static uint32_t high_window_end(const pmstep_commission_plan_t *plan, uint32_t end)
{
    return plan->bias_estimation ? end - plan->window_steps : end;
}

/* A sample into a flux integral's sums; @p first: the integral's first sample (its voltage,
 * of the period before it, is not part of the integral). */
static void add_flux_sample(pmstep_flux_sums_t *flux, bool first, float current_A, float voltage_V)
{
    if (first) {
        flux->start_A = current_A;
    } else {
        flux->voltage_sum_V += voltage_V;
    }
    flux->current_sum_A += current_A;
    flux->end_A = current_A;
}

/* The drop to the lower level of an alignment ending at @p end: samples end - W - 1 (the last of
 * the full-level window) .. end - 1, voltages over the W periods between them. */
static void add_drop_sample(pmstep_flux_sums_t *drop, const pmstep_commission_plan_t *plan, uint32_t sample,
                            uint32_t end, float current_A, float voltage_V)
{
    if (plan->bias_estimation && sample + plan->window_steps + 1u >= end) {
        add_flux_sample(drop, sample + plan->window_steps + 1u == end, current_A, voltage_V);
    }
}

static float mean_or_zero(float sum, uint32_t count)
{
    return count > 0u ? sum / (float)count : 0.0f;
}

/* A sample of the steady-state window of @p window samples ending at @p end, if it is one. */
static void add_window_sample(pmstep_window_sums_t *sums, uint32_t sample, uint32_t end, uint32_t window,
                              float driven_A, float voltage_V, float undriven_A)
{
    if (in_window(sample, end, window)) {
        sums->current_sum_A += driven_A;
        sums->voltage_sum_V += voltage_V;
        sums->undriven_sum_A += undriven_A;
        if (in_window(sample, end, window / 2u)) {
            sums->late_current_sum_A += driven_A;
        }
    }
}

/* The samples of an alignment ending at @p end, phase @p driven driven: its steady-state windows,
 * the undriven phase's offset at the full level's, the drop to the lower level. */
static void add_alignment_sample(pmstep_alignment_sums_t *sums, const pmstep_commission_plan_t *plan, uint32_t sample,
                                 uint32_t end, bool phase_b_driven, float driven_A, float voltage_V, float undriven_A)
{
    pmstep_window_sums_t *full = phase_b_driven ? &sums->s_full : &sums->c_full;
    pmstep_window_sums_t *low = phase_b_driven ? &sums->s_low : &sums->c_low;
    const uint32_t full_end = high_window_end(plan, end);
    add_window_sample(full, sample, full_end, plan->window_steps, driven_A, voltage_V, undriven_A);
    if (plan->offsets_from_alignment && in_window(sample, full_end, plan->window_steps)) {
        /* The undriven phase's voltage is 0: its current -> 0. */
        if (phase_b_driven) {
            sums->zero_sum_a_A += undriven_A;
            sums->zero_count_a++;
        } else {
            sums->zero_sum_b_A += undriven_A;
            sums->zero_count_b++;
        }
    }
    if (plan->bias_estimation) {
        add_window_sample(low, sample, end, plan->window_steps / 2u, driven_A, voltage_V, undriven_A);
    }
    add_drop_sample(phase_b_driven ? &sums->s_drop : &sums->c_drop, plan, sample, end, driven_A, voltage_V);
}

COMMISSION_OUT_OF_LINE void pmstep_commission_add_alignment(pmstep_commission_sums_t *sums,
                                                            const pmstep_commission_plan_t *plan, uint32_t sample,
                                                            float i_a_A, float i_b_A, float u_a_V, float u_b_V,
                                                            bool u_a_known)
{
    pmstep_alignment_sums_t *alignment = &sums->alignment;
    if (sample >= plan->inductance_start_step && sample - plan->inductance_start_step <= plan->inductance_steps) {
        /* Samples m0..m0+N of the rise, voltages over the N periods between them. */
        add_flux_sample(&alignment->rise, sample == plan->inductance_start_step, i_b_A, u_b_V);
    }
    if (sample < plan->s_align_steps) {
        add_alignment_sample(alignment, plan, sample, plan->s_align_steps, true, i_b_A, u_b_V, i_a_A);
        return;
    }
    if ((alignment->swing_start_step == 0u) && u_a_known) {
        alignment->swing_start_step = sample; /* >= s_align_steps >= 1 */
        add_flux_sample(&alignment->swing, true, i_a_A, u_a_V);
    } else if (alignment->swing_start_step > 0u) {
        add_flux_sample(&alignment->swing, false, i_a_A, u_a_V);
    } else {
        /* phase a's current still negative: the swing has not started */
    }
    add_alignment_sample(alignment, plan, sample, plan->c_align_end_step, false, i_a_A, u_a_V, i_b_A);
}

void pmstep_commission_take_bridge_off(const pmstep_commission_sums_t *sums, pmstep_commissioning_t *result)
{
    result->offset_a_A = mean_or_zero(sums->zero_sum_a_A, sums->zero_count_a);
    result->offset_b_A = mean_or_zero(sums->zero_sum_b_A, sums->zero_count_b);
    result->phase_voltage_offset_a_V = mean_or_zero(sums->zero_voltage_sum_a_V, sums->zero_count_a);
    result->phase_voltage_offset_b_V = mean_or_zero(sums->zero_voltage_sum_b_V, sums->zero_count_b);
}

void pmstep_commission_repeat(pmstep_commission_sums_t *sums, pmstep_commissioning_t *result)
{
    /* What the alignments' samples are calibrated and compensated with goes back to its value
     * before the first run; the rest is written again at the repeat's t_c. */
    memset(&sums->alignment, 0, sizeof sums->alignment);
    pmstep_commission_take_bridge_off(sums, result);
    result->phase_a_current_scale = 1.0f;
    result->voltage_bias_a_V = 0.0f; /* compensated from t_c on, in every mode */
    result->voltage_bias_b_V = 0.0f;
    result->measured = false;
    result->alignment_repeats++;
}

/* Measured value plausible: finite and within [1/2, 2] x the configured one. */
static bool plausible(float measured, float configured)
{
    return isfinite(measured) && measured >= 0.5f * configured && measured <= 2.0f * configured;
}

/* Trapezoid integral (A s) of the samples 0..n whose sum is @p sum, minus the offset. */
static float current_integral(float sum, float first, float last, uint32_t periods, float offset, float period_s)
{
    return period_s * (sum - 0.5f * (first + last) - (float)periods * offset);
}

/* R = u/i from a steady-state window's sums. */
static float window_resistance(float voltage_sum_V, float current_sum_A, uint32_t count, float offset_a)
{
    return (voltage_sum_V / (float)count) / (current_sum_A / (float)count - offset_a);
}

/* Two steady states (means u_1, i_1 and u_2, i_2) of one phase: R, and the bias u_1 - R i_1. */
static float two_level_resistance(float u_1, float i_1, float u_2, float i_2, float *bias_V)
{
    const float resistance_Ohm = (u_1 - u_2) / (i_1 - i_2);
    *bias_V = u_1 - resistance_Ohm * i_1;
    return resistance_Ohm;
}

/* integral(u - bias - R i) (V s) over the @p periods of @p flux, the currents less @p offset_A. */
static float window_flux(const pmstep_flux_sums_t *flux, uint32_t periods, float offset_A, float resistance_Ohm,
                         float bias_V, float period_s)
{
    const float charge_A_s =
        current_integral(flux->current_sum_A, flux->start_A, flux->end_A, periods, offset_A, period_s);
    return period_s * (flux->voltage_sum_V - (float)periods * bias_V) - resistance_Ohm * charge_A_s;
}

/* The window of @p window samples held a steady state: the means of its halves of the driven
 * phase's current differ by at most PMSTEP_ALIGNMENT_STEADY_TOLERANCE times @p level_A, the
 * alignment's full-level current. (The undriven phase's is not compared: a rotor still swinging
 * a little about its rest moves it by several %, its mean and R stay right.) Non-finite sums
 * pass: the plausibility check names them. */
static bool steady(const pmstep_window_sums_t *sums, uint32_t window, float level_A)
{
    const uint32_t late = window / 2u;
    float change_A;
    if (late == 0u) {
        return true; /* a window of one sample has no halves to compare */
    }
    change_A = (sums->current_sum_A - sums->late_current_sum_A) / (float)(window - late)
               - sums->late_current_sum_A / (float)late;
    return !(pmstep_abs(change_A) > PMSTEP_ALIGNMENT_STEADY_TOLERANCE * pmstep_abs(level_A));
}

/* Every steady-state window of the alignments held a steady state (see steady()). */
static bool alignments_steady(const pmstep_alignment_sums_t *sums, const pmstep_commission_plan_t *plan,
                              float offset_a_A, float offset_b_A)
{
    const uint32_t low_window = plan->window_steps / 2u;
    const float s_level_A = sums->s_full.current_sum_A / (float)plan->window_steps - offset_b_A;
    const float c_level_A = sums->c_full.current_sum_A / (float)plan->window_steps - offset_a_A;
    bool all =
        steady(&sums->s_full, plan->window_steps, s_level_A) && steady(&sums->c_full, plan->window_steps, c_level_A);
    if (plan->bias_estimation) {
        all = all && steady(&sums->s_low, low_window, s_level_A) && steady(&sums->c_low, low_window, c_level_A);
    }
    return all;
}

/* Newton steps on the rotor's rest angle under the currents (i_a, i_b), from (cos, sin) of p theta
 * near it: (1)'s torque k_M (i_b cos - i_a sin) against the model's detent torque
 * -T_d sin(4 p theta), with the configured k_M (the detent's share is a correction). Each step
 * turns (cos, sin) by torque / stiffness to third order, which keeps its length within 1e-4 of 1
 * for a turn of 0.2 rad. */
#define REST_ANGLE_NEWTON_STEPS 3u
static void rest_angle(float i_a_A, float i_b_A, const pmstep_motor_config_t *motor, float *cos_io, float *sin_io)
{
    uint32_t step;
    for (step = 0u; step < REST_ANGLE_NEWTON_STEPS; step++) {
        const float c = *cos_io;
        const float s = *sin_io;
        const float cos_2 = c * c - s * s;
        const float sin_2 = 2.0f * c * s;
        const float torque_Nm =
            motor->torque_constant_Nm_A * (i_b_A * c - i_a_A * s) - motor->detent_torque_Nm * 2.0f * sin_2 * cos_2;
        const float stiffness_Nm = motor->torque_constant_Nm_A * (i_a_A * c + i_b_A * s)
                                   + 4.0f * motor->detent_torque_Nm * (cos_2 * cos_2 - sin_2 * sin_2);
        const float turn = torque_Nm / stiffness_Nm;
        const float cos_turn = 1.0f - 0.5f * turn * turn;
        const float sin_turn = turn * (1.0f - turn * turn / 6.0f);
        *cos_io = c * cos_turn - s * sin_turn;
        *sin_io = s * cos_turn + c * sin_turn;
    }
}

/* Where the rotor rests in an alignment: (cos, sin) of p theta at its full level and at its end
 * (the lower level with the voltage bias, else the same). */
typedef struct {
    float cos_full, sin_full;
    float cos_end, sin_end;
} pmstep_rest_t;

/* The mean currents of an alignment's windows less their offsets, phase a's on phase b's scale. */
typedef struct {
    float full_a_A, full_b_A;
    float low_a_A, low_b_A;
} pmstep_window_currents_t;

/* An alignment's rests from its nominal equilibrium (cos, sin): under the full window's
 * currents, then under the lower level's from there (the rotor follows its equilibrium down). */
static pmstep_rest_t alignment_rest(const pmstep_window_currents_t *currents, bool low_level,
                                    const pmstep_motor_config_t *motor, float cos_nominal, float sin_nominal)
{
    pmstep_rest_t rest;
    rest.cos_full = cos_nominal;
    rest.sin_full = sin_nominal;
    rest_angle(currents->full_a_A, currents->full_b_A, motor, &rest.cos_full, &rest.sin_full);
    rest.cos_end = rest.cos_full;
    rest.sin_end = rest.sin_full;
    if (low_level) {
        rest_angle(currents->low_a_A, currents->low_b_A, motor, &rest.cos_end, &rest.sin_end);
    }
    return rest;
}

/* What the finish's stages hand on (see pmstep_commission_finish()). */
typedef struct {
    float offset_a_A, offset_b_A; /* the current offsets, the alignments' samples included */
    float r_a_Ohm, r_b_Ohm;       /* each phase's R: the configured one until the windows measure it */
    float inductance_H;           /* the L that RUN takes: the configured one, or the measured one */
    float drop_turn_per_A;        /* m of the drops' L (0: L not from the drops) */
    pmstep_rest_t s_rest, c_rest; /* where the rotor rested in each alignment */
} pmstep_finish_t;

/* Offsets from every sample with a true current of 0; the result's measured values cleared. */
static void finish_offsets(const pmstep_commission_sums_t *sums, const pmstep_config_t *cfg, pmstep_finish_t *fin,
                           pmstep_commissioning_t *result)
{
    const pmstep_alignment_sums_t *alignment = &sums->alignment;
    fin->offset_a_A =
        mean_or_zero(sums->zero_sum_a_A + alignment->zero_sum_a_A, sums->zero_count_a + alignment->zero_count_a);
    fin->offset_b_A =
        mean_or_zero(sums->zero_sum_b_A + alignment->zero_sum_b_A, sums->zero_count_b + alignment->zero_count_b);
    /* Both phases start at the configured R on purpose; each is then measured apart. */
    /* cppcheck-suppress duplicateAssignExpression ; the same start value for both phases, intended */
    fin->r_a_Ohm = cfg->motor.resistance_Ohm;
    fin->r_b_Ohm = cfg->motor.resistance_Ohm;
    fin->inductance_H = cfg->motor.inductance_H;
    fin->drop_turn_per_A = 0.0f;
    fin->s_rest = (pmstep_rest_t){0.0f, 1.0f, 0.0f, 1.0f};
    fin->c_rest = (pmstep_rest_t){1.0f, 0.0f, 1.0f, 0.0f};
    result->offset_a_A = fin->offset_a_A;
    result->offset_b_A = fin->offset_b_A;
    result->offset_samples =
        sums->zero_count_a + sums->zero_count_b + alignment->zero_count_a + alignment->zero_count_b;
    result->resistance_Ohm = 0.0f;
    result->phase_a_current_scale = 1.0f;
    result->inductance_H = 0.0f;
    result->torque_constant_Nm_A = 0.0f;
    result->equilibrium_cos = 1.0f;
    result->equilibrium_sin = 0.0f;
    result->voltage_bias_a_V = 0.0f;
    result->voltage_bias_b_V = 0.0f;
    result->measured = true;
}

/* Each phase's R from its steady states: two levels give R and the voltage bias, one level u/i. */
static void finish_resistance(const pmstep_alignment_sums_t *alignment, const pmstep_commission_plan_t *plan,
                              pmstep_finish_t *fin, pmstep_commissioning_t *result)
{
    const float n_full = (float)plan->window_steps;
    const float n_low = (float)(plan->window_steps / 2u);
    if (plan->bias_estimation) {
        fin->r_b_Ohm = two_level_resistance(
            alignment->s_full.voltage_sum_V / n_full, alignment->s_full.current_sum_A / n_full - fin->offset_b_A,
            alignment->s_low.voltage_sum_V / n_low, alignment->s_low.current_sum_A / n_low - fin->offset_b_A,
            &result->voltage_bias_b_V);
        fin->r_a_Ohm = two_level_resistance(
            alignment->c_full.voltage_sum_V / n_full, alignment->c_full.current_sum_A / n_full - fin->offset_a_A,
            alignment->c_low.voltage_sum_V / n_low, alignment->c_low.current_sum_A / n_low - fin->offset_a_A,
            &result->voltage_bias_a_V);
    } else {
        /* Steady states of (3) and (5): R = u/i on each phase. */
        fin->r_b_Ohm = window_resistance(alignment->s_full.voltage_sum_V, alignment->s_full.current_sum_A,
                                         plan->window_steps, fin->offset_b_A);
        fin->r_a_Ohm = window_resistance(alignment->c_full.voltage_sum_V, alignment->c_full.current_sum_A,
                                         plan->window_steps, fin->offset_a_A);
    }
}

/* The phases' apparent R differ by their sensors' gains: phase b is the reference. Then where the
 * rotor rests in each alignment. */
static void finish_rests(const pmstep_alignment_sums_t *alignment, const pmstep_commission_plan_t *plan,
                         const pmstep_config_t *cfg, pmstep_finish_t *fin, pmstep_commissioning_t *result)
{
    const float n_full = (float)plan->window_steps;
    const float n_low = (float)(plan->window_steps / 2u);
    const float scale_a = fin->r_a_Ohm / fin->r_b_Ohm;
    const pmstep_window_currents_t s_currents = {(alignment->s_full.undriven_sum_A / n_full - fin->offset_a_A)
                                                     * scale_a,
                                                 alignment->s_full.current_sum_A / n_full - fin->offset_b_A,
                                                 (alignment->s_low.undriven_sum_A / n_low - fin->offset_a_A) * scale_a,
                                                 alignment->s_low.current_sum_A / n_low - fin->offset_b_A};
    const pmstep_window_currents_t c_currents = {(alignment->c_full.current_sum_A / n_full - fin->offset_a_A) * scale_a,
                                                 alignment->c_full.undriven_sum_A / n_full - fin->offset_b_A,
                                                 (alignment->c_low.current_sum_A / n_low - fin->offset_a_A) * scale_a,
                                                 alignment->c_low.undriven_sum_A / n_low - fin->offset_b_A};
    result->resistance_Ohm = fin->r_b_Ohm;
    result->phase_a_current_scale = scale_a;
    fin->s_rest = alignment_rest(&s_currents, plan->bias_estimation, &cfg->motor, 0.0f, 1.0f);
    fin->c_rest = alignment_rest(&c_currents, plan->bias_estimation, &cfg->motor, 1.0f, 0.0f);
    result->equilibrium_cos = fin->c_rest.cos_end;
    result->equilibrium_sin = fin->c_rest.sin_end;
}

/* L from the drops (see the header), over the step between the steady states' means: phase b's,
 * and phase a's on phase b's scale (a's current is scaled by r_a / r_b in RUN, so its apparent L
 * is divided by that). The rotor follows its equilibrium down, so each drop's flux also holds
 * k_M / p times the change of the driven phase's flux direction (sin on b, cos on a):
 * L = L_0 - (k_M / p) m, L_0 here, m's share once k_M is known (finish_torque_constant()). */
static void finish_drop_inductance(const pmstep_alignment_sums_t *alignment, const pmstep_commission_plan_t *plan,
                                   float period_s, pmstep_finish_t *fin, pmstep_commissioning_t *result)
{
    const float n_full = (float)plan->window_steps;
    const float n_low = (float)(plan->window_steps / 2u);
    const float step_b_A = alignment->s_low.current_sum_A / n_low - alignment->s_full.current_sum_A / n_full;
    const float step_a_A = (alignment->c_low.current_sum_A / n_low - alignment->c_full.current_sum_A / n_full)
                           * result->phase_a_current_scale;
    result->inductance_H = 0.5f
                           * (window_flux(&alignment->s_drop, plan->window_steps, fin->offset_b_A, fin->r_b_Ohm,
                                          result->voltage_bias_b_V, period_s)
                                  / step_b_A
                              + window_flux(&alignment->c_drop, plan->window_steps, fin->offset_a_A, fin->r_a_Ohm,
                                            result->voltage_bias_a_V, period_s)
                                    / step_a_A);
    fin->drop_turn_per_A = 0.5f
                           * ((fin->s_rest.sin_end - fin->s_rest.sin_full) / step_b_A
                              + (fin->c_rest.cos_end - fin->c_rest.cos_full) / step_a_A);
}

/* Flux swing of c-alignment (see the header), samples from the first with phase a's current not
 * negative (t_s, or a few periods later) to t_c, on the driven phase a: its current then rises from
 * there and stays far from zero, so its voltage is known (bias included). The rotor turns from its
 * rest at t_s to its rest at t_c:
 * F = L delta i_a + (k_M / p) (cos(p theta_c) - cos(p theta_s)), delta i_a on phase b's scale, L the
 * one RUN takes (the drops' L_0 - (k_M / p) m: solved with k_M). */
static void finish_torque_constant(const pmstep_alignment_sums_t *alignment, const pmstep_commission_plan_t *plan,
                                   const pmstep_config_t *cfg, float i_a_A, float u_a_V, pmstep_finish_t *fin,
                                   pmstep_commissioning_t *result)
{
    const float run_turn_per_A = cfg->commissioning.use_measured_inductance ? fin->drop_turn_per_A : 0.0f;
    pmstep_flux_sums_t swing = alignment->swing;
    float step_a_A;
    float flux_per_pole_pair;
    add_flux_sample(&swing, false, i_a_A, u_a_V); /* t_c's sample closes it */
    step_a_A = result->phase_a_current_scale * (swing.end_A - swing.start_A);
    flux_per_pole_pair = (window_flux(&swing, plan->c_align_end_step - alignment->swing_start_step, fin->offset_a_A,
                                      fin->r_a_Ohm, result->voltage_bias_a_V, cfg->timing.period_s)
                          - fin->inductance_H * step_a_A)
                         / (fin->c_rest.cos_end - fin->s_rest.cos_end - run_turn_per_A * step_a_A);
    result->torque_constant_Nm_A = flux_per_pole_pair * (float)cfg->motor.pole_pairs;
    result->inductance_H -= flux_per_pole_pair * fin->drop_turn_per_A;
    fin->inductance_H -= flux_per_pole_pair * run_turn_per_A;
}

/* The measured R of both phases, k_M, and the L that RUN takes, each within [1/2, 2] x its
 * configured value (see plausible()). */
static bool finish_plausible(bool windows, const pmstep_config_t *cfg, const pmstep_finish_t *fin,
                             const pmstep_commissioning_t *result)
{
    return (!windows
            || (plausible(fin->r_a_Ohm, cfg->motor.resistance_Ohm) && plausible(fin->r_b_Ohm, cfg->motor.resistance_Ohm)
                && plausible(result->torque_constant_Nm_A, cfg->motor.torque_constant_Nm_A)))
           && (!cfg->commissioning.use_measured_inductance || plausible(fin->inductance_H, cfg->motor.inductance_H));
}

COMMISSION_OUT_OF_LINE pmstep_fault_t pmstep_commission_finish(const pmstep_commission_sums_t *sums,
                                                               const pmstep_commission_plan_t *plan,
                                                               const pmstep_config_t *cfg, float i_a_A, float u_a_V,
                                                               pmstep_commissioning_t *result)
{
    const pmstep_alignment_sums_t *alignment = &sums->alignment;
    const bool windows = plan->window_steps > 0u;
    pmstep_finish_t fin;
    finish_offsets(sums, cfg, &fin, result);
    if (windows) {
        finish_resistance(alignment, plan, &fin, result);
        finish_rests(alignment, plan, cfg, &fin, result);
        if (plan->bias_estimation && plan->inductance_steps == 0u) {
            finish_drop_inductance(alignment, plan, cfg->timing.period_s, &fin, result);
        }
    }
    if (plan->inductance_steps > 0u) {
        /* L delta i = integral(u - R i) over the rise; the rotor has not moved yet. */
        result->inductance_H = window_flux(&alignment->rise, plan->inductance_steps, fin.offset_b_A, fin.r_b_Ohm,
                                           result->voltage_bias_b_V, cfg->timing.period_s)
                               / (alignment->rise.end_A - alignment->rise.start_A);
    }
    if (cfg->commissioning.use_measured_inductance) {
        fin.inductance_H = result->inductance_H;
    }
    if (windows && (alignment->swing_start_step > 0u)) {
        finish_torque_constant(alignment, plan, cfg, i_a_A, u_a_V, &fin, result);
    }
    if (windows && !alignments_steady(alignment, plan, fin.offset_a_A, fin.offset_b_A)) {
        return PMSTEP_FAULT_ALIGNMENT_MOTION;
    }
    return finish_plausible(windows, cfg, &fin, result) ? PMSTEP_FAULT_NONE : PMSTEP_FAULT_COMMISSIONING;
}
