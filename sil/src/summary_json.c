/* pmstep-sil's summary.json: every figure of sil_summary_t, grouped as the documentation describes. */
#include "summary_json.h"

#include <math.h>

#include "pmstep_hal_host.h"
#include "sil/microstep.h"
#include "pmstep/pmstep_text.h"

/* A position scenario's figures (sil_position_summary_t; electrical rad = p times mechanical). */
static void add_position_json(cJSON *root, const sil_summary_t *s)
{
    const sil_position_summary_t *p = &s->position;
    cJSON *position = cJSON_CreateObject();
    cJSON_AddNumberToObject(position, "moves", p->moves);
    cJSON_AddNumberToObject(position, "rejected_moves", p->rejected_moves);
    cJSON_AddNumberToObject(position, "unfinished_moves", p->unfinished_moves);
    cJSON_AddNumberToObject(position, "max_final_error_electrical_rad", p->max_final_error_rad);
    cJSON_AddNumberToObject(position, "mean_final_error_electrical_rad", p->mean_final_error_rad);
    cJSON_AddNumberToObject(position, "worst_move", p->worst_move);
    cJSON_AddNumberToObject(position, "max_overshoot_fraction", p->max_overshoot_fraction);
    cJSON_AddNumberToObject(position, "max_estimate_error_electrical_rad", p->max_estimate_error_rad);
    cJSON_AddNumberToObject(position, "max_tracking_error_electrical_rad", p->max_tracking_error_rad);
    cJSON_AddNumberToObject(position, "hold_duration_s", p->hold_duration_s);
    cJSON_AddNumberToObject(position, "hold_max_error_electrical_rad", p->hold_max_error_rad);
    cJSON_AddNumberToObject(position, "hold_max_estimate_error_electrical_rad", p->hold_max_estimate_error_rad);
    cJSON_AddNumberToObject(position, "hold_drift_electrical_rad_s", p->hold_drift_rad_s);
    cJSON_AddItemToObject(root, "position", position);
}

/* A STEP/DIR scenario's figures (sil_stepdir_summary_t; errors in full steps, pi / (2 p) mechanical rad). */
static void add_stepdir_json(cJSON *root, const sil_scenario_t *sc, const sil_summary_t *s)
{
    const sil_stepdir_summary_t *d = &s->stepdir;
    cJSON *stepdir = cJSON_CreateObject();
    cJSON_AddNumberToObject(stepdir, "microsteps", (double)d->microsteps);
    cJSON_AddStringToObject(stepdir, "diag_mode", sc->stepdir_diag_mode == PMSTEP_DIAG_PULSE ? "pulse" : "level");
    cJSON_AddNumberToObject(stepdir, "moves", d->moves);
    cJSON_AddNumberToObject(stepdir, "first_move_s", d->first_move_s);
    cJSON_AddNumberToObject(stepdir, "last_move_end_s", d->last_move_end_s);
    cJSON_AddNumberToObject(stepdir, "peak_speed_rad_s", d->peak_speed_rad_s);
    cJSON_AddNumberToObject(stepdir, "following_start_s", d->following_start_s);
    cJSON_AddNumberToObject(stepdir, "following_end_s", d->following_end_s);
    cJSON_AddNumberToObject(stepdir, "generator_steps", (double)d->generator_steps);
    cJSON_AddNumberToObject(stepdir, "drive_steps", (double)d->drive_steps);
    cJSON_AddNumberToObject(stepdir, "max_error_moving_full_steps", d->max_error_moving_full_steps);
    cJSON_AddNumberToObject(stepdir, "rms_error_moving_full_steps", d->rms_error_moving_full_steps);
    cJSON_AddNumberToObject(stepdir, "max_error_full_steps", d->max_error_full_steps);
    cJSON_AddNumberToObject(stepdir, "rms_error_full_steps", d->rms_error_full_steps);
    cJSON_AddNumberToObject(stepdir, "final_error_full_steps", d->final_error_full_steps);
    cJSON_AddNumberToObject(stepdir, "lost_full_steps", (double)d->lost_full_steps);
    cJSON_AddNumberToObject(stepdir, "error_beyond_full_step_s", d->error_beyond_full_step_s);
    cJSON_AddNumberToObject(stepdir, "diag_periods", (double)d->diag_periods);
    cJSON_AddNumberToObject(stepdir, "diag_first_s", d->diag_first_s);
    cJSON_AddItemToObject(root, "stepdir", stepdir);
}

static const char *homing_state_name(pmstep_homing_state_t state)
{
    static const char *const names[] = {"idle", "seeking", "backing_off", "done", "not_found", "aborted"};
    return (unsigned)state < sizeof names / sizeof names[0] ? names[state] : "unknown";
}

static void add_homing_json(cJSON *root, const sil_summary_t *s)
{
    const sil_homing_summary_t *h = &s->homing;
    cJSON *homing = cJSON_CreateObject();
    cJSON_AddNumberToObject(homing, "speed_rad_s", (double)h->config.speed_rad_s);
    cJSON_AddNumberToObject(homing, "accel_rad_s2", (double)h->config.accel_rad_s2);
    cJSON_AddNumberToObject(homing, "max_travel_rad", (double)h->config.max_travel_rad);
    cJSON_AddNumberToObject(homing, "stall_current_a", (double)h->config.stall_current_A);
    cJSON_AddNumberToObject(homing, "stall_error_rad", (double)h->config.stall_error_rad);
    cJSON_AddNumberToObject(homing, "back_off_rad", (double)h->config.back_off_rad);
    cJSON_AddNumberToObject(homing, "start_status", (double)h->start_status);
    cJSON_AddStringToObject(homing, "state", homing_state_name(h->state));
    cJSON_AddNumberToObject(homing, "start_s", h->start_s);
    cJSON_AddNumberToObject(homing, "contact_s", h->contact_s);
    cJSON_AddNumberToObject(homing, "found_s", h->found_s);
    cJSON_AddNumberToObject(homing, "done_s", h->done_s);
    cJSON_AddStringToObject(homing, "found_by", h->by_current ? "current" : "following_error");
    cJSON_AddNumberToObject(homing, "zero_rad", h->zero_rad);
    cJSON_AddNumberToObject(homing, "stop_error_full_steps", h->stop_error_full_steps);
    cJSON_AddNumberToObject(homing, "contact_peak_current_a", h->contact_peak_current_A);
    cJSON_AddNumberToObject(homing, "seek_peak_stop_torque_nm", h->seek_peak_stop_torque_Nm);
    cJSON_AddNumberToObject(homing, "final_from_stop_full_steps", h->final_from_stop_full_steps);
    cJSON_AddNumberToObject(homing, "final_position_error_full_steps", h->final_position_error_full_steps);
    cJSON_AddItemToObject(root, "homing", homing);
}

/* The [sensors], [inverter] and [bus] settings and what the ADC clipped. */
static cJSON *measurement_chain_json(const sil_scenario_t *sc)
{
    const pmstep_hal_host_t *port = pmstep_hal_host_state();
    cJSON *chain = cJSON_CreateObject();
    cJSON *sensors = cJSON_CreateObject();
    cJSON *inverter = cJSON_CreateObject();
    cJSON *bus = cJSON_CreateObject();
    cJSON_AddNumberToObject(sensors, "adc_bits", sc->sensors.adc_bits);
    cJSON_AddNumberToObject(sensors, "current_full_scale_A", sc->sensors.current_full_scale_A);
    cJSON_AddNumberToObject(sensors, "offset_a_A", sc->sensors.offset_a_A);
    cJSON_AddNumberToObject(sensors, "offset_b_A", sc->sensors.offset_b_A);
    cJSON_AddNumberToObject(sensors, "gain_error_a", sc->sensors.gain_error_a);
    cJSON_AddNumberToObject(sensors, "gain_error_b", sc->sensors.gain_error_b);
    cJSON_AddNumberToObject(sensors, "noise_rms_A", sc->sensors.noise_rms_A);
    cJSON_AddNumberToObject(sensors, "bus_full_scale_V", sc->sensors.bus_full_scale_V);
    cJSON_AddNumberToObject(sensors, "bus_noise_rms_V", sc->sensors.bus_noise_rms_V);
    cJSON_AddNumberToObject(sensors, "phase_voltage_bits", sc->sensors.phase_voltage_bits);
    cJSON_AddNumberToObject(sensors, "phase_voltage_full_scale_V", sc->sensors.phase_voltage_full_scale_V);
    cJSON_AddNumberToObject(sensors, "phase_voltage_offset_a_V", sc->sensors.phase_voltage_offset_a_V);
    cJSON_AddNumberToObject(sensors, "phase_voltage_offset_b_V", sc->sensors.phase_voltage_offset_b_V);
    cJSON_AddNumberToObject(sensors, "phase_voltage_gain_error_a", sc->sensors.phase_voltage_gain_error_a);
    cJSON_AddNumberToObject(sensors, "phase_voltage_gain_error_b", sc->sensors.phase_voltage_gain_error_b);
    cJSON_AddNumberToObject(sensors, "phase_voltage_noise_rms_V", sc->sensors.phase_voltage_noise_rms_V);
    cJSON_AddBoolToObject(sensors, "phase_voltage_sensing", sc->controller.inverter.phase_voltage_sensing);
    cJSON_AddItemToObject(chain, "sensors", sensors);
    cJSON_AddStringToObject(inverter, "model", sc->inverter.model == SIL_INVERTER_SWITCHING ? "switching" : "averaged");
    cJSON_AddNumberToObject(inverter, "dead_time_s", sc->inverter.dead_time_s);
    cJSON_AddItemToObject(chain, "inverter", inverter);
    cJSON_AddNumberToObject(bus, "voltage_V", sc->bus_voltage_V);
    cJSON_AddNumberToObject(bus, "source_resistance_Ohm", sc->bus.source_resistance_Ohm);
    cJSON_AddNumberToObject(bus, "ripple_V", sc->bus.ripple_V);
    cJSON_AddNumberToObject(bus, "ripple_Hz", sc->bus.ripple_Hz);
    cJSON_AddItemToObject(chain, "bus", bus);
    /* Phase samples (two per period) and bus samples at an end code of the ADC. */
    cJSON_AddNumberToObject(chain, "adc_clipped_current_samples", (double)port->sensors.clipped_current_samples);
    cJSON_AddNumberToObject(chain, "adc_clipped_bus_samples", (double)port->sensors.clipped_bus_samples);
    cJSON_AddNumberToObject(chain, "adc_clipped_phase_voltage_samples", (double)port->sensors.clipped_voltage_samples);
    return chain;
}

/* Ground truth against what the core reported, and what its commissioning measured. */
static void add_robustness_json(cJSON *root, const sil_summary_t *s)
{
    cJSON *robust = cJSON_CreateObject();
    cJSON *comm = cJSON_CreateObject();
    const pmstep_commissioning_t *c = &s->commissioning;
    cJSON_AddNumberToObject(robust, "run_start_time_s", s->run_start_time_s);
    cJSON_AddNumberToObject(robust, "settle_time_s", s->settle_time_s);
    cJSON_AddNumberToObject(robust, "max_angle_error_rad", s->max_angle_error_rad);
    cJSON_AddNumberToObject(robust, "max_angle_error_time_s", s->max_angle_error_time_s);
    cJSON_AddNumberToObject(robust, "final_angle_error_rad", s->final_angle_error_rad);
    cJSON_AddNumberToObject(robust, "max_speed_error_rad_s", s->max_speed_error_after_settle_rad_s);
    cJSON_AddNumberToObject(robust, "max_speed_error_time_s", s->max_speed_error_time_s);
    cJSON_AddNumberToObject(robust, "loss_of_control_time_s", s->loss_of_control_time_s);
    if (isnan(s->detection_latency_s)) {
        cJSON_AddNullToObject(robust, "detection_latency_s");
    } else {
        cJSON_AddNumberToObject(robust, "detection_latency_s", s->detection_latency_s);
    }
    cJSON_AddBoolToObject(robust, "nonfinite_seen", s->nonfinite_seen);
    cJSON_AddItemToObject(root, "robustness", robust);
    cJSON_AddNumberToObject(comm, "offset_a_A", (double)c->offset_a_A);
    cJSON_AddNumberToObject(comm, "offset_b_A", (double)c->offset_b_A);
    cJSON_AddNumberToObject(comm, "offset_samples", (double)c->offset_samples);
    cJSON_AddNumberToObject(comm, "resistance_Ohm", (double)c->resistance_Ohm);
    cJSON_AddNumberToObject(comm, "inductance_H", (double)c->inductance_H);
    cJSON_AddNumberToObject(comm, "torque_constant_Nm_A", (double)c->torque_constant_Nm_A);
    cJSON_AddNumberToObject(comm, "equilibrium_cos", (double)c->equilibrium_cos);
    cJSON_AddNumberToObject(comm, "equilibrium_sin", (double)c->equilibrium_sin);
    cJSON_AddNumberToObject(comm, "voltage_bias_a_V", (double)c->voltage_bias_a_V);
    cJSON_AddNumberToObject(comm, "voltage_bias_b_V", (double)c->voltage_bias_b_V);
    cJSON_AddNumberToObject(comm, "inertia_kgm2", (double)c->inertia_kgm2);
    cJSON_AddNumberToObject(comm, "friction_Nms_rad", (double)c->friction_Nms_rad);
    cJSON_AddStringToObject(comm, "identification", pmstep_identification_str(c->identification));
    cJSON_AddNumberToObject(comm, "realignments", (double)c->realignments);
    cJSON_AddNumberToObject(comm, "alignment_repeats", (double)c->alignment_repeats);
    cJSON_AddBoolToObject(comm, "measured", c->measured);
    cJSON_AddItemToObject(root, "commissioning", comm);
}

/* The figures both drives report, for the comparison with the microstepping baseline. */
static void add_baseline_json(cJSON *root, const sil_scenario_t *sc, const sil_summary_t *s)
{
    cJSON_AddBoolToObject(root, "loss_of_synchronism", s->loss_of_synchronism);
    cJSON_AddNumberToObject(root, "loss_of_synchronism_time_s", s->loss_of_synchronism_time_s);
    cJSON_AddNumberToObject(root, "max_load_angle_rad", s->max_load_angle_rad);
    cJSON_AddNumberToObject(root, "rms_phase_current_A", s->rms_phase_current_A);
    cJSON_AddNumberToObject(root, "metrics_start_s", s->metrics_start_time_s);
    if (sc->drive == SIL_DRIVE_MICROSTEP) {
        cJSON *drive = cJSON_CreateObject();
        cJSON_AddNumberToObject(drive, "current_A", sc->datasheet.rated_current_A);
        cJSON_AddNumberToObject(drive, "current_gain_per_s",
                                SIL_MICROSTEP_GAIN_FRACTION / (double)sc->controller.timing.period_s);
        cJSON_AddNumberToObject(drive, "pull_out_torque_Nm",
                                sc->motor.torque_constant_Nm_A * sc->datasheet.rated_current_A);
        cJSON_AddItemToObject(root, "microstep", drive);
    }
}

cJSON *sil_summary_json(const sil_scenario_t *sc, const sil_summary_t *s)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *align = cJSON_CreateObject();
    cJSON *speed = cJSON_CreateObject();
    cJSON *angle = cJSON_CreateObject();
    cJSON *timing = cJSON_CreateObject();
    cJSON *fault = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scenario", sc->name);
    cJSON_AddStringToObject(root, "controller", sc->drive == SIL_DRIVE_MICROSTEP ? "microstep" : "pmstep");
    cJSON_AddNumberToObject(root, "pole_pairs", sc->motor.pole_pairs);
    cJSON_AddNumberToObject(root, "control_period_s", (double)sc->controller.timing.period_s);
    cJSON_AddNumberToObject(root, "substeps", sc->substeps);
    cJSON_AddStringToObject(root, "integrator", sc->integrator == PLANT_INTEGRATOR_RK4 ? "rk4" : "exponential");
    cJSON_AddNumberToObject(root, "delay_periods", sc->controller.timing.computational_delay_periods);
    cJSON_AddNumberToObject(root, "s_align_time_s", (double)sc->controller.alignment.s_align_time_s);
    cJSON_AddNumberToObject(root, "c_align_time_s", (double)sc->controller.alignment.c_align_time_s);
    cJSON_AddNumberToObject(root, "transient_window_s", sc->transient_window_s);
    cJSON_AddNumberToObject(root, "theta0_deg", sc->theta0_rad * 180.0 / 3.14159265358979323846);
    cJSON_AddNumberToObject(root, "seed", (double)sc->seed);
    cJSON_AddItemToObject(root, "measurement_chain", measurement_chain_json(sc));

    cJSON_AddNumberToObject(align, "cos_ptheta_at_ts", s->cos_ptheta_at_ts);
    cJSON_AddNumberToObject(align, "sin_ptheta_at_ts", s->sin_ptheta_at_ts);
    cJSON_AddNumberToObject(align, "i_b_minus_ucs_over_r_at_ts_A", s->i_b_residual_at_ts_A);
    cJSON_AddNumberToObject(align, "cos_ptheta_at_tc", s->cos_ptheta_at_tc);
    cJSON_AddNumberToObject(align, "sin_ptheta_at_tc", s->sin_ptheta_at_tc);
    cJSON_AddNumberToObject(align, "i_a_minus_ucc_over_r_at_tc_A", s->i_a_residual_at_tc_A);
    cJSON_AddItemToObject(root, "alignment", align);

    cJSON_AddNumberToObject(speed, "transient_max_abs_error_rad_s", s->transient_max_speed_error_rad_s);
    cJSON_AddNumberToObject(speed, "transient_rms_error_rad_s", s->transient_rms_speed_error_rad_s);
    cJSON_AddNumberToObject(speed, "tracking_max_abs_error_rad_s", s->tracking_max_speed_error_rad_s);
    cJSON_AddNumberToObject(speed, "tracking_rms_error_rad_s", s->tracking_rms_speed_error_rad_s);
    cJSON_AddItemToObject(root, "speed", speed);

    cJSON_AddNumberToObject(root, "final_load_hat_Nm", s->final_load_hat_Nm);
    cJSON_AddNumberToObject(root, "final_load_Nm", s->final_load_Nm);
    cJSON_AddNumberToObject(root, "final_load_abs_error_Nm", s->final_load_error_Nm);
    cJSON_AddNumberToObject(angle, "max_abs_cos_error", s->max_cos_error);
    cJSON_AddNumberToObject(angle, "max_abs_sin_error", s->max_sin_error);
    cJSON_AddItemToObject(root, "angle_estimate", angle);
    cJSON_AddNumberToObject(root, "max_abs_phase_voltage_V", s->max_phase_voltage_V);
    cJSON_AddNumberToObject(root, "max_abs_phase_current_a", s->max_phase_current_A);
    cJSON_AddNumberToObject(root, "voltage_limited_periods", (double)s->voltage_limited_periods);
    cJSON_AddNumberToObject(root, "inverter_clipped_periods", (double)s->inverter_limited_periods);
    cJSON_AddStringToObject(root, "final_mode", pmstep_mode_str(s->final_mode));
    add_robustness_json(root, s);
    add_baseline_json(root, sc, s);
    if (sc->position_moves > 0 && sc->drive == SIL_DRIVE_PMSTEP) {
        add_position_json(root, s);
    }
    if (sc->position_moves > 0 && sc->position_source == SIL_SOURCE_STEPDIR) {
        add_stepdir_json(root, sc, s);
    }
    if (sc->motor.stop_side != 0) {
        cJSON_AddNumberToObject(root, "stop_contact_s", s->stop_contact_s);
    }
    if (sc->position_moves > 0 && sc->position_source == SIL_SOURCE_HOMING) {
        add_homing_json(root, s);
    }

    cJSON_AddNumberToObject(fault, "code", (double)s->fault);
    cJSON_AddStringToObject(fault, "name", pmstep_fault_str(s->fault));
    cJSON_AddStringToObject(fault, "text", pmstep_fault_str(s->fault));
    cJSON_AddNumberToObject(fault, "step", (double)s->fault_step);
    cJSON_AddNumberToObject(fault, "time_s", s->fault_time_s);
    cJSON_AddItemToObject(root, "fault", fault);

    cJSON_AddNumberToObject(timing, "steps", (double)s->steps);
    cJSON_AddNumberToObject(timing, "simulated_s", s->sim_time_s);
    cJSON_AddNumberToObject(timing, "wall_s", s->wall_time_s);
    cJSON_AddNumberToObject(timing, "cpu_s", s->cpu_time_s);
    cJSON_AddNumberToObject(timing, "plant_wall_s", s->plant_time_s);
    cJSON_AddNumberToObject(timing, "firmware_wall_s", s->firmware_time_s);
    cJSON_AddNumberToObject(timing, "real_time_factor", s->real_time_factor);
    cJSON_AddItemToObject(root, "timing", timing);
    return root;
}
