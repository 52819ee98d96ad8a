/* Mode machine, protections and the control step: strategy of Section III.A,
 * s-alignment (3) -> c-alignment (5) -> controller (6) (or (13), Remark 1). */
#include "pmstep/pmstep.h"
#include "pmstep_internal.h"

#include <math.h> /* isfinite: a classification macro, no libm call */
#include <stddef.h>
#include <string.h>

/* Detection runs every this many periods (supervision at a quarter of the control rate). */
#define DETECTION_DECIMATION 4u

static uint32_t periods_in(float duration_s, float period_s)
{
    return (uint32_t)(duration_s / period_s + 0.5f);
}

/* Coefficients of the angle, observer and law for the electrical model @p model. */
static void apply_model(pmstep_t *inst, const pmstep_electrical_t *model)
{
    pmstep_angle_coeffs_init(&inst->angle_coeffs, inst->cfg, model);
    pmstep_observer_coeffs_init(&inst->observer_coeffs, inst->cfg, model);
    pmstep_law_coeffs_init(&inst->law_coeffs, inst->cfg, model);
}

/* Everything init derives from @p cfg: the coefficients of each block for the configured model,
 * period counts and the detection constants. */
static void derive(pmstep_t *inst, const pmstep_config_t *cfg)
{
    const pmstep_electrical_t configured = pmstep_configured_electrical(cfg);
    inst->cfg = cfg;
    pmstep_ref_coeffs_init(&inst->ref_coeffs, cfg->reference_bandwidth_rad_per_s, cfg->period_s);
    apply_model(inst, &configured);
    inst->commission_plan.s_align_steps = periods_in(cfg->s_align_time_s, cfg->period_s);
    inst->commission_plan.c_align_end_step = periods_in(cfg->c_align_time_s, cfg->period_s);
    inst->commission_plan.window_steps = periods_in(cfg->steady_state_window_s, cfg->period_s);
    inst->commission_plan.inductance_steps = periods_in(cfg->inductance_window_s, cfg->period_s);
    inst->commission_plan.inductance_start_step = 2u + cfg->computational_delay_periods;
    inst->commission_plan.offsets_from_alignment = cfg->alignment_offset_calibration;
    inst->offset_cal_steps = periods_in(cfg->offset_calibration_time_s, cfg->period_s);
    inst->dead_time_duty = 2.0f * cfg->dead_time_s / cfg->period_s;
    inst->compensate_voltage = cfg->dead_time_s > 0.0f || cfg->voltage_bias_level_fraction > 0.0f;
    inst->inv_dead_time_band_per_a = inst->compensate_voltage ? 1.0f / cfg->dead_time_current_band_a : 0.0f;
    inst->commission_plan.bias_estimation = cfg->voltage_bias_level_fraction > 0.0f;
    {
        /* Detection counts checks, one every DETECTION_DECIMATION periods; its low-pass has the
         * time constant detection_time_s / 4. */
        const float check_period_s = (float)DETECTION_DECIMATION * cfg->period_s;
        inst->detection_steps = periods_in(cfg->detection_time_s, check_period_s);
        inst->detection_alpha = 4.0f * check_period_s / (cfg->detection_time_s > 0.0f ? cfg->detection_time_s : 1.0f);
        inst->angle_step_per_speed = (float)cfg->pole_pairs * check_period_s;
    }
    inst->consistency_bound_rad = cfg->speed_consistency_bound_rad_s * inst->angle_step_per_speed;
}

/* True if the @p count floats stored from @p first on (a struct of floats only) are all finite. */
static bool floats_finite(const void *first, size_t count)
{
    const unsigned char *bytes = (const unsigned char *)first;
    float sum = 0.0f;
    size_t n;
    for (n = 0; n < count; ++n) {
        float value;
        memcpy(&value, bytes + n * sizeof value, sizeof value);
        sum += value - value; /* 0 for finite values, NaN otherwise */
    }
    return sum == 0.0f;
}

bool pmstep_derived_coefficients_finite(const pmstep_config_t *cfg)
{
    /* The derived floats lie together in pmstep_t, from dead_time_duty to the last float of
     * law_coeffs (pmstep.h); a scratch instance, on the stack of init/validate, holds them. */
    const size_t first = offsetof(pmstep_t, dead_time_duty);
    const size_t end = offsetof(pmstep_t, law_coeffs) + offsetof(pmstep_law_coeffs_t, linear_speed_term);
    pmstep_t scratch;
    derive(&scratch, cfg);
    return floats_finite((const unsigned char *)&scratch + first, (end - first) / sizeof(float));
}

pmstep_status_t pmstep_init(pmstep_t *inst, const pmstep_config_t *cfg)
{
    pmstep_status_t status;
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    status = pmstep_validate_config(cfg);
    if (status != PMSTEP_OK) {
        return status;
    }
    derive(inst, cfg);
    pmstep_reset(inst);
    return PMSTEP_OK;
}

/* Forgets what the last alignment measured: offsets 0, the configured model, sums cleared. */
static void clear_commissioning(pmstep_t *inst)
{
    const pmstep_electrical_t configured = pmstep_configured_electrical(inst->cfg);
    memset(&inst->commissioning, 0, sizeof inst->commissioning);
    inst->commissioning.current_scale_a = 1.0f;
    pmstep_commission_clear(&inst->scratch.sums);
    apply_model(inst, &configured);
}

/* Clears the dynamic state of the strategy; keeps commands (targets) untouched. */
static void clear_dynamic_state(pmstep_t *inst)
{
    inst->mode_step = 0u;
    inst->run_started = false;
    pmstep_angle_start(&inst->angle, 0.0f, 0.0f);
    pmstep_observer_start(&inst->observer, 0.0f, 0.0f);
    inst->u_applied_a_v = 0.0f;
    inst->u_applied_b_v = 0.0f;
    inst->u_pending_a_v = 0.0f;
    inst->u_pending_b_v = 0.0f;
}

void pmstep_reset(pmstep_t *inst)
{
    inst->mode = PMSTEP_MODE_IDLE;
    inst->fault = PMSTEP_FAULT_NONE;
    inst->fault_step = 0u;
    inst->step_count = 0u;
    pmstep_ref_reset(&inst->speed_ref, 0.0f);
    pmstep_ref_reset(&inst->i_d_ref, 0.0f);
    clear_dynamic_state(inst);
    clear_commissioning(inst); /* the scratch union holds the sums until t_c; start_run() sets up the rest */
}

pmstep_status_t pmstep_start(pmstep_t *inst)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode != PMSTEP_MODE_IDLE) {
        return PMSTEP_ERR_BAD_MODE;
    }
    clear_dynamic_state(inst);
    clear_commissioning(inst);
    inst->mode = inst->offset_cal_steps > 0u ? PMSTEP_MODE_OFFSET_CAL : PMSTEP_MODE_S_ALIGN;
    return PMSTEP_OK;
}

pmstep_status_t pmstep_stop(pmstep_t *inst)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode == PMSTEP_MODE_FAULT) {
        return PMSTEP_ERR_BAD_MODE;
    }
    clear_dynamic_state(inst);
    inst->mode = PMSTEP_MODE_IDLE;
    return PMSTEP_OK;
}

pmstep_status_t pmstep_clear_fault(pmstep_t *inst)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (inst->mode != PMSTEP_MODE_FAULT) {
        return PMSTEP_ERR_BAD_MODE;
    }
    clear_dynamic_state(inst);
    inst->fault = PMSTEP_FAULT_NONE;
    inst->mode = PMSTEP_MODE_IDLE;
    return PMSTEP_OK;
}

/* x - x is 0 for every finite x and NaN for NaN and +/-Inf, so one compare checks a
 * sum of such differences (cheaper than one isfinite per value on the FPU). */
static bool all_finite4(float a, float b, float c, float d)
{
    return ((a - a) + (b - b)) + ((c - c) + (d - d)) == 0.0f;
}

pmstep_status_t pmstep_set_speed_target(pmstep_t *inst, float target_rad_s, float ramp_rate_rad_s2)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!all_finite4(target_rad_s, ramp_rate_rad_s2, 0.0f, 0.0f) || !(ramp_rate_rad_s2 > 0.0f)) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    pmstep_ref_set_target(&inst->speed_ref, target_rad_s, ramp_rate_rad_s2);
    return PMSTEP_OK;
}

pmstep_status_t pmstep_set_id_target(pmstep_t *inst, float target_a)
{
    if (inst == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!all_finite4(target_a, 0.0f, 0.0f, 0.0f)) {
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    pmstep_ref_set_target(&inst->i_d_ref, target_a, 0.0f);
    return PMSTEP_OK;
}

static float abs_f(float x)
{
    return x < 0.0f ? -x : x;
}

/* x within [-limit, limit]. */
static float clamp_f(float x, float limit)
{
    return x > limit ? limit : (x < -limit ? -limit : x);
}

/* Protections, checked while the bridge may be on. */
static pmstep_fault_t check_measurements(const pmstep_config_t *cfg, const pmstep_meas_t *meas)
{
    if (!all_finite4(meas->i_a_a, meas->i_b_a, meas->bus_voltage_v,
                     cfg->known_load_mode ? meas->load_torque_nm : 0.0f)) {
        return PMSTEP_FAULT_MEASUREMENT_NONFINITE;
    }
    if (abs_f(meas->i_a_a) > cfg->max_phase_current_a || abs_f(meas->i_b_a) > cfg->max_phase_current_a) {
        return PMSTEP_FAULT_OVERCURRENT;
    }
    if (meas->bus_voltage_v < cfg->min_bus_voltage_v) {
        return PMSTEP_FAULT_BUS_UNDERVOLTAGE;
    }
    if (meas->bus_voltage_v > cfg->max_bus_voltage_v) {
        return PMSTEP_FAULT_BUS_OVERVOLTAGE;
    }
    return PMSTEP_FAULT_NONE;
}


/* After a detection: align again with the bridge on, keeping what commissioning measured. */
static void realign(pmstep_t *inst)
{
    clear_dynamic_state(inst);
    inst->commissioning.realignments++;
    inst->mode = PMSTEP_MODE_S_ALIGN;
}

/* At t_c, before the first RUN period: Remark 2 offsets and the commissioned model.
 * @return a fault, or PMSTEP_FAULT_NONE. */
static pmstep_fault_t finish_commissioning(pmstep_t *inst, const pmstep_meas_t *raw)
{
    const pmstep_config_t *cfg = inst->cfg;
    pmstep_commissioning_t *result = &inst->commissioning;
    pmstep_electrical_t model = pmstep_configured_electrical(cfg);
    const pmstep_fault_t fault =
        pmstep_commission_finish(&inst->scratch.sums, &inst->commission_plan, cfg, raw->i_a_a, inst->u_applied_a_v,
                                 result);
    if (fault != PMSTEP_FAULT_NONE) {
        return fault;
    }
    if (cfg->use_commissioned_resistance) {
        model.resistance_ohm = result->resistance_ohm;
    }
    if (cfg->use_commissioned_inductance) {
        model.inductance_h = result->inductance_h;
    }
    if (cfg->use_commissioned_torque_constant) {
        model.torque_constant_nm_per_a = result->torque_constant_nm_per_a;
    }
    apply_model(inst, &model);
    return PMSTEP_FAULT_NONE;
}

/* Starts controller (6) at t_c: phi = 0, i-hat = i(t_c), w-hat = T_L-hat = 0, references from 0. */
static void start_run(pmstep_t *inst, const pmstep_meas_t *meas)
{
    const pmstep_ref_t speed_cmd = inst->speed_ref;
    const pmstep_ref_t i_d_cmd = inst->i_d_ref;
    static const pmstep_detector_t fresh_detector = {1.0f, 0.0f, 0.0f, 0.0f, 0u, 0u, 0u, 0u};
    pmstep_angle_start(&inst->angle, meas->i_a_a, meas->i_b_a);
    pmstep_observer_start(&inst->observer, meas->i_a_a, meas->i_b_a);
    pmstep_ref_reset(&inst->speed_ref, 0.0f);
    pmstep_ref_set_target(&inst->speed_ref, speed_cmd.target, speed_cmd.ramp_rate_per_s);
    pmstep_ref_reset(&inst->i_d_ref, 0.0f);
    pmstep_ref_set_target(&inst->i_d_ref, i_d_cmd.target, 0.0f);
    pmstep_ref_reset(&inst->scratch.run.known_load_filter, inst->cfg->known_load_mode ? meas->load_torque_nm : 0.0f);
    inst->scratch.run.detector = fresh_detector; /* the sums are spent: (c-hat, s-hat) = (1, 0) at t_c */
    inst->run_started = true;
}

/* Controller (6) / (13) for one sample; writes the unlimited voltage and telemetry. */
static void run_controller(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out,
                           pmstep_observer_input_t *obs_in, pmstep_observer_mech_rates_t *mech)
{
    const bool known_load = inst->cfg->known_load_mode;
    const pmstep_ref_out_t speed_ref = pmstep_ref_output(&inst->ref_coeffs, &inst->speed_ref);
    const pmstep_ref_out_t i_d_ref = pmstep_ref_output(&inst->ref_coeffs, &inst->i_d_ref);
    const pmstep_ref_out_t load_ref = pmstep_ref_output(&inst->ref_coeffs, &inst->scratch.run.known_load_filter);
    pmstep_law_refs_t refs;
    float cos_hat;
    float sin_hat;
    float i_d;
    float i_q;
    float load_nm;
    float load_rate;
    float i_q_ref;
    float i_q_ref_rate;

    if (!inst->run_started) {
        start_run(inst, meas);
    } else {
        pmstep_angle_update(&inst->angle, &inst->angle_coeffs, meas->i_a_a, meas->i_b_a,
                            inst->u_applied_a_v, inst->u_applied_b_v);
    }
    pmstep_angle_estimate(&inst->angle, &inst->angle_coeffs, meas->i_a_a, meas->i_b_a, &cos_hat, &sin_hat);
    pmstep_park(cos_hat, sin_hat, meas->i_a_a, meas->i_b_a, &i_d, &i_q);

    refs.speed_ref_rad_s = speed_ref.value;
    refs.speed_ref_rate = speed_ref.rate;
    refs.speed_ref_accel = speed_ref.accel;
    refs.i_d_ref_a = i_d_ref.value;
    refs.i_d_ref_rate = i_d_ref.rate;

    load_nm = known_load ? load_ref.value : inst->observer.load_hat_nm;
    i_q_ref = pmstep_law_iq_ref(&inst->law_coeffs, &refs, inst->observer.speed_hat_rad_s, load_nm);

    obs_in->i_a_a = meas->i_a_a;
    obs_in->i_b_a = meas->i_b_a;
    obs_in->cos_hat = cos_hat;
    obs_in->sin_hat = sin_hat;
    obs_in->i_d_a = i_d;
    obs_in->i_q_a = i_q;
    obs_in->i_d_err_a = i_d - refs.i_d_ref_a;
    obs_in->i_q_err_a = i_q - i_q_ref;
    obs_in->known_load_nm = load_ref.value;
    *mech = pmstep_observer_mech_rates(&inst->observer, &inst->observer_coeffs, obs_in, known_load);

    load_rate = known_load ? load_ref.rate : mech->load_hat_rate_nm_per_s;
    i_q_ref_rate = pmstep_law_iq_ref_rate(&inst->law_coeffs, &refs, inst->observer.speed_hat_rad_s,
                                          mech->speed_hat_rate_rad_s2, load_rate);
    pmstep_law_voltages(&inst->law_coeffs, &refs, cos_hat, sin_hat, i_d, i_q, inst->observer.speed_hat_rad_s,
                        i_q_ref, i_q_ref_rate, &out->u_a_v, &out->u_b_v);

    out->cos_hat = cos_hat;
    out->sin_hat = sin_hat;
    out->speed_hat_rad_s = inst->observer.speed_hat_rad_s;
    out->load_hat_nm = load_nm;
    out->i_a_hat_a = inst->observer.i_a_hat_a;
    out->i_b_hat_a = inst->observer.i_b_hat_a;
    out->speed_ref_rad_s = speed_ref.value;
    out->speed_ref_dot_rad_s2 = speed_ref.rate;
    out->i_d_a = i_d;
    out->i_q_a = i_q;
    out->i_d_ref_a = refs.i_d_ref_a;
    out->i_q_ref_a = i_q_ref;
}

/* Scales (u_a, u_b) so neither H-bridge exceeds the measured bus; keeps the vector's direction.
 * The scaled components are clamped to +/- the bus so float rounding of the scale cannot
 * leave one a unit in the last place above it. */
static bool limit_to_bus(float *u_a_v, float *u_b_v, float bus_voltage_v)
{
    const float largest = abs_f(*u_a_v) > abs_f(*u_b_v) ? abs_f(*u_a_v) : abs_f(*u_b_v);
    if (largest > bus_voltage_v) {
        const float scale = bus_voltage_v / largest;
        *u_a_v = clamp_f(*u_a_v * scale, bus_voltage_v);
        *u_b_v = clamp_f(*u_b_v * scale, bus_voltage_v);
        return true;
    }
    return false;
}

static void output_off(pmstep_output_t *out, const pmstep_t *inst)
{
    static const pmstep_output_t zero_output = {0};
    *out = zero_output;
    out->mode = inst->mode;
    out->fault = inst->fault;
    out->fault_step = inst->fault_step;
}

/* Latches @p fault: state cleared, bridge off from this period on. */
static void trip(pmstep_t *inst, pmstep_fault_t fault, pmstep_output_t *out)
{
    clear_dynamic_state(inst);
    inst->mode = PMSTEP_MODE_FAULT;
    inst->fault = fault;
    inst->fault_step = inst->step_count;
    output_off(out, inst);
}

/* Voltage that makes up for the dead time of a phase's two half-bridges (each loses
 * sign(i) V_bus t_d / T_s) and for the measured bias: (2 V_bus t_d / T_s + bias) sign(i),
 * linear in i within the band. */
static float dead_time_voltage(const pmstep_t *inst, float current_a, float bus_voltage_v, float bias_v)
{
    float share = current_a * inst->inv_dead_time_band_per_a;
    share = share > 1.0f ? 1.0f : (share < -1.0f ? -1.0f : share);
    return (inst->dead_time_duty * bus_voltage_v + bias_v) * share;
}

/* Counts the checks @p condition has held; true once it has held @p limit checks. */
static bool persists(uint32_t *count, bool condition, uint32_t limit)
{
    *count = condition ? *count + 1u : 0u;
    return *count >= limit;
}

/* Detection in RUN (config "Detection"), every DETECTION_DECIMATION periods: a condition
 * persisting detection_steps checks.
 * @p sample: the currents this period, as the observer sees them. */
static pmstep_fault_t detect(pmstep_t *inst, const pmstep_output_t *out, const pmstep_meas_t *sample)
{
    const pmstep_config_t *cfg = inst->cfg;
    pmstep_detector_t *d = &inst->scratch.run.detector;
    const uint32_t limit = inst->detection_steps;
    pmstep_fault_t found = PMSTEP_FAULT_NONE;
    if (cfg->angle_magnitude_bound > 0.0f) {
        const float magnitude_error = out->cos_hat * out->cos_hat + out->sin_hat * out->sin_hat - 1.0f;
        if (persists(&d->magnitude_count, abs_f(magnitude_error) > cfg->angle_magnitude_bound, limit)) {
            found = PMSTEP_FAULT_ANGLE_MAGNITUDE;
        }
    }
    if (cfg->speed_consistency_bound_rad_s > 0.0f) {
        /* sin of the estimate's electrical step since the last check, against p w-hat x check period. */
        const float angle_step = d->prev_cos_hat * out->sin_hat - d->prev_sin_hat * out->cos_hat;
        const float gap = angle_step - inst->angle_step_per_speed * out->speed_hat_rad_s;
        d->rotation_gap_rad += inst->detection_alpha * (gap - d->rotation_gap_rad);
        d->prev_cos_hat = out->cos_hat;
        d->prev_sin_hat = out->sin_hat;
        if (persists(&d->consistency_count, abs_f(d->rotation_gap_rad) > inst->consistency_bound_rad, limit)) {
            found = PMSTEP_FAULT_SPEED_INCONSISTENT;
        }
    }
    if (cfg->stall_speed_error_rad_s > 0.0f
        && persists(&d->stall_count, abs_f(out->speed_hat_rad_s - out->speed_ref_rad_s) > cfg->stall_speed_error_rad_s,
                    limit)) {
        found = PMSTEP_FAULT_STALL;
    }
    if (cfg->observer_residual_bound_a > 0.0f) {
        /* A rotor the estimate believes elsewhere (or still) leaves back-EMF the observer cannot explain. */
        const float residual = abs_f(sample->i_a_a - out->i_a_hat_a) + abs_f(sample->i_b_a - out->i_b_hat_a);
        d->residual_a += inst->detection_alpha * (residual - d->residual_a);
        if (persists(&d->residual_count, d->residual_a > cfg->observer_residual_bound_a, limit)) {
            found = PMSTEP_FAULT_OBSERVER_RESIDUAL;
        }
    }
    return found;
}

/* Bridge off and the mode of this period; the offset calibration's samples. */
static void offset_calibration_step(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out)
{
    pmstep_commission_add_bridge_off(&inst->scratch.sums, meas->i_a_a, meas->i_b_a);
    out->mode = PMSTEP_MODE_OFFSET_CAL;
    if (++inst->mode_step >= inst->offset_cal_steps) {
        /* Provisional offsets for the alignment (the dead-time compensation needs the sign of
         * small currents); t_c refines them with the alignment steady states. */
        const pmstep_commission_sums_t *sums = &inst->scratch.sums;
        inst->commissioning.offset_a_a = sums->zero_sum_a_a / (float)sums->zero_count_a;
        inst->commissioning.offset_b_a = sums->zero_sum_b_a / (float)sums->zero_count_b;
        inst->mode = PMSTEP_MODE_S_ALIGN;
        inst->mode_step = 0u;
    }
}

void pmstep_step(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out)
{
    const pmstep_config_t *cfg = inst->cfg;
    pmstep_observer_input_t obs_in;
    pmstep_observer_mech_rates_t mech;
    pmstep_meas_t sample;
    pmstep_fault_t fault;
    float dead_time_a_v = 0.0f;
    float dead_time_b_v = 0.0f;
    float next_a_v;
    float next_b_v;

    inst->step_count++;
    if (inst->mode == PMSTEP_MODE_IDLE || inst->mode == PMSTEP_MODE_FAULT) {
        output_off(out, inst);
        return;
    }
    fault = check_measurements(cfg, meas);
    if (fault != PMSTEP_FAULT_NONE) {
        trip(inst, fault, out);
        return;
    }

    if (inst->mode == PMSTEP_MODE_OFFSET_CAL) {
        output_off(out, inst);
        offset_calibration_step(inst, meas, out);
        return;
    }
    if (inst->mode_step >= inst->commission_plan.c_align_end_step) {
        inst->mode = PMSTEP_MODE_RUN;
    } else if (inst->mode_step >= inst->commission_plan.s_align_steps) {
        inst->mode = PMSTEP_MODE_C_ALIGN;
    }
    if (!inst->commissioning.measured) {
        if (inst->mode != PMSTEP_MODE_RUN) {
            pmstep_commission_add_alignment(&inst->scratch.sums, &inst->commission_plan, inst->mode_step, meas->i_a_a,
                                            meas->i_b_a, inst->u_applied_a_v, inst->u_applied_b_v);
        } else {
            fault = finish_commissioning(inst, meas);
            if (fault != PMSTEP_FAULT_NONE) {
                trip(inst, fault, out);
                return;
            }
        }
    }
    /* Remark 2: the sensor offsets (zero until measured) come off every sample; phase a is put
     * on phase b's scale (1 until measured). */
    sample = *meas;
    sample.i_a_a = (sample.i_a_a - inst->commissioning.offset_a_a) * inst->commissioning.current_scale_a;
    sample.i_b_a -= inst->commissioning.offset_b_a;
    switch (inst->mode) {
    case PMSTEP_MODE_S_ALIGN: /* (3); no telemetry in alignment */
        output_off(out, inst);
        out->u_a_v = 0.0f;
        out->u_b_v = cfg->s_align_voltage_v;
        if (pmstep_commission_low_level(&inst->commission_plan, inst->mode_step, inst->commission_plan.s_align_steps)) {
            out->u_b_v *= cfg->voltage_bias_level_fraction; /* second steady state (Remark 2 bias) */
        }
        break;
    case PMSTEP_MODE_C_ALIGN: /* (5) */
        output_off(out, inst);
        out->u_a_v = cfg->c_align_voltage_v;
        out->u_b_v = 0.0f;
        if (pmstep_commission_low_level(&inst->commission_plan, inst->mode_step,
                                        inst->commission_plan.c_align_end_step)) {
            out->u_a_v *= cfg->voltage_bias_level_fraction;
        }
        break;
    default: /* RUN: (6) or (13); run_controller() writes every telemetry field */
        out->fault = PMSTEP_FAULT_NONE;
        out->fault_step = inst->fault_step;
        run_controller(inst, &sample, out, &obs_in, &mech);
        fault = (inst->step_count % DETECTION_DECIMATION) == 0u ? detect(inst, out, &sample) : PMSTEP_FAULT_NONE;
        if (fault != PMSTEP_FAULT_NONE) {
            if (inst->commissioning.realignments < cfg->max_realignments) {
                realign(inst);
                output_off(out, inst);
            } else {
                trip(inst, fault, out);
            }
            return;
        }
        break;
    }
    if (inst->compensate_voltage) {
        /* Both phases in every mode: the undriven phase of an alignment must really be at 0 V
         * (a short through the bridge: it damps the rotor's swing); left alone, its dead time
         * would clamp it open. The sign of the current: in RUN from the current references
         * (i_d*, i_q*) turned by (c-hat, s-hat), which pass through zero smoothly where a
         * sampled current would sit in the ADC's zero code and let the phase clamp; in the
         * alignments from the offset-corrected samples. */
        float sign_current_a_a = sample.i_a_a;
        float sign_current_b_a = sample.i_b_a;
        if (inst->mode == PMSTEP_MODE_RUN) {
            sign_current_a_a = out->cos_hat * out->i_d_ref_a - out->sin_hat * out->i_q_ref_a;
            sign_current_b_a = out->sin_hat * out->i_d_ref_a + out->cos_hat * out->i_q_ref_a;
        }
        dead_time_a_v = dead_time_voltage(inst, sign_current_a_a, meas->bus_voltage_v,
                                          inst->commissioning.voltage_bias_a_v);
        dead_time_b_v = dead_time_voltage(inst, sign_current_b_a, meas->bus_voltage_v,
                                          inst->commissioning.voltage_bias_b_v);
    }
    out->u_a_v += dead_time_a_v;
    out->u_b_v += dead_time_b_v;
    out->voltage_limited = limit_to_bus(&out->u_a_v, &out->u_b_v, meas->bus_voltage_v);
    if (!all_finite4(out->u_a_v, out->u_b_v, dead_time_a_v, dead_time_b_v)) {
        /* Every mode: the bridge is never enabled with a voltage that is not a number. */
        trip(inst, PMSTEP_FAULT_STATE_NONFINITE, out);
        return;
    }
    out->mode = inst->mode;
    out->bridge_enable = true;

    /* The voltage the bridge applies over the coming period (its dead-time loss taken off). */
    if (cfg->computational_delay_periods == 0u) {
        next_a_v = out->u_a_v - dead_time_a_v;
        next_b_v = out->u_b_v - dead_time_b_v;
    } else {
        next_a_v = inst->u_pending_a_v;
        next_b_v = inst->u_pending_b_v;
        inst->u_pending_a_v = out->u_a_v - dead_time_a_v;
        inst->u_pending_b_v = out->u_b_v - dead_time_b_v;
    }
    inst->u_applied_a_v = next_a_v;
    inst->u_applied_b_v = next_b_v;

    if (inst->mode == PMSTEP_MODE_RUN) {
        if (inst->angle_coeffs.correction_gain > 0.0f) {
            pmstep_angle_correct(&inst->angle, &inst->angle_coeffs, out->cos_hat, out->sin_hat);
        }
        pmstep_observer_advance(&inst->observer, &inst->observer_coeffs, &obs_in, &mech, next_a_v, next_b_v,
                                cfg->period_s);
        pmstep_ref_advance(&inst->ref_coeffs, &inst->speed_ref, cfg->period_s);
        pmstep_ref_advance(&inst->ref_coeffs, &inst->i_d_ref, cfg->period_s);
        if (cfg->known_load_mode) {
            pmstep_ref_set_target(&inst->scratch.run.known_load_filter, meas->load_torque_nm, 0.0f);
            pmstep_ref_advance(&inst->ref_coeffs, &inst->scratch.run.known_load_filter, cfg->period_s);
        }
        if (!all_finite4(inst->observer.speed_hat_rad_s, inst->observer.load_hat_nm, inst->observer.i_a_hat_a,
                         inst->observer.i_b_hat_a)
            || !all_finite4(inst->angle.phi_a, inst->angle.phi_b, 0.0f, 0.0f)) {
            trip(inst, PMSTEP_FAULT_STATE_NONFINITE, out);
            return;
        }
    } else {
        inst->mode_step++;
    }
}

void pmstep_get_commissioning(const pmstep_t *inst, pmstep_commissioning_t *out)
{
    *out = inst->commissioning;
}
