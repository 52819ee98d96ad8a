/* pmstep-tune --summary: the design's outcome and the validation's runs as JSON, for the tools
 * that sweep motors (tools/sweep_motors.py). */
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>

#include "pmstep/pmstep_text.h"
#include "pmstep_tune.h"

/* The values a calibration is compared on, of one design. */
static cJSON *design_values(const pmstep_config_t *c, const pmstep_design_report_t *r)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddNumberToObject(o, "resistance_Ohm", (double)c->motor.resistance_Ohm);
    cJSON_AddNumberToObject(o, "inductance_H", (double)c->motor.inductance_H);
    cJSON_AddNumberToObject(o, "torque_constant_Nm_A", (double)c->motor.torque_constant_Nm_A);
    cJSON_AddNumberToObject(o, "inertia_kgm2", (double)c->motor.inertia_kgm2);
    cJSON_AddNumberToObject(o, "friction_Nms_rad", (double)c->motor.friction_Nms_rad);
    cJSON_AddNumberToObject(o, "top_speed_rad_s", (double)r->top_speed_rad_s);
    cJSON_AddNumberToObject(o, "current_bandwidth_rad_s", (double)r->current_bandwidth_rad_s);
    cJSON_AddNumberToObject(o, "observer_bandwidth_rad_s", (double)r->observer_bandwidth_rad_s);
    cJSON_AddNumberToObject(o, "speed_gain_per_s", (double)c->gains.speed_gain_per_s);
    cJSON_AddNumberToObject(o, "s_align_voltage_V", (double)c->alignment.s_align_voltage_V);
    cJSON_AddNumberToObject(o, "c_align_time_s", (double)c->alignment.c_align_time_s);
    cJSON_AddNumberToObject(o, "max_phase_current_A", (double)c->limits.max_phase_current_A);
    return o;
}

int write_summary(const char *path, const char *motor_path, bool robust, pmstep_status_t status,
                  const pmstep_design_report_t *r, const tune_check_t *checks, int n_checks,
                  const tune_calibration_t *cal)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *design = cJSON_CreateObject();
    cJSON *runs = cJSON_CreateArray();
    char *text;
    FILE *f;
    int k;
    bool passed = status == PMSTEP_OK && n_checks > 0;
    bool synchronous = passed;
    cJSON_AddStringToObject(root, "motor", motor_path);
    cJSON_AddStringToObject(root, "mode", robust ? "robust" : "paper");
    cJSON_AddNumberToObject(design, "status", (double)status);
    cJSON_AddStringToObject(design, "text", pmstep_status_str(status));
    if (status == PMSTEP_OK) {
        cJSON_AddNumberToObject(design, "top_speed_rad_s", (double)r->top_speed_rad_s);
        cJSON_AddNumberToObject(design, "top_electrical_step_rad", (double)r->top_electrical_step_rad);
        cJSON_AddNumberToObject(design, "bus_speed_rad_s", (double)r->bus_speed_rad_s);
        cJSON_AddNumberToObject(design, "rate_speed_rad_s", (double)r->rate_speed_rad_s);
        cJSON_AddNumberToObject(design, "current_bandwidth_rad_s", (double)r->current_bandwidth_rad_s);
        cJSON_AddNumberToObject(design, "observer_bandwidth_rad_s", (double)r->observer_bandwidth_rad_s);
        cJSON_AddNumberToObject(design, "speed_bandwidth_rad_s", (double)r->speed_bandwidth_rad_s);
        cJSON_AddNumberToObject(design, "alignment_current_A", (double)r->alignment_current_A);
        cJSON_AddNumberToObject(design, "alignment_frequency_rad_s", (double)r->alignment_frequency_rad_s);
        cJSON_AddNumberToObject(design, "alignment_damping", (double)r->alignment_damping);
        cJSON_AddNumberToObject(design, "condition_4_margin", (double)r->condition_4_margin);
        cJSON_AddNumberToObject(design, "detent_margin", (double)r->detent_margin);
        cJSON_AddNumberToObject(design, "magnetising_current_A", (double)r->magnetising_current_A);
        cJSON_AddNumberToObject(design, "rated_torque_Nm", (double)r->rated_torque_Nm);
        cJSON_AddNumberToObject(design, "weakening_current_A", (double)r->weakening_current_A);
        cJSON_AddNumberToObject(design, "weakened_speed_rad_s", (double)r->weakened_speed_rad_s);
    }
    cJSON_AddItemToObject(root, "design", design);
    for (k = 0; k < n_checks; ++k) {
        const tune_check_t *c = &checks[k];
        cJSON *run = cJSON_CreateObject();
        cJSON_AddStringToObject(run, "check", c->check);
        cJSON_AddBoolToObject(run, "ran", c->ran);
        cJSON_AddStringToObject(run, "fault", pmstep_fault_str((pmstep_fault_t)c->fault));
        cJSON_AddNumberToObject(run, "fault_time_s", c->fault_time_s);
        cJSON_AddNumberToObject(run, "angle_error_rad", c->angle_error_rad);
        cJSON_AddNumberToObject(run, "speed_error_rad_s", c->speed_error_rad_s);
        cJSON_AddNumberToObject(run, "speed_bound_rad_s", c->speed_bound_rad_s);
        cJSON_AddBoolToObject(run, "synchronous", c->synchronous);
        cJSON_AddBoolToObject(run, "pass", c->pass);
        cJSON_AddItemToArray(runs, run);
        passed = passed && c->pass;
        synchronous = synchronous && c->synchronous;
    }
    cJSON_AddItemToObject(root, "checks", runs);
    if (cal != NULL && cal->ran) {
        cJSON *c = cJSON_CreateObject();
        cJSON_AddNumberToObject(c, "status", (double)cal->status);
        cJSON_AddStringToObject(c, "text", calibrate_status_text(cal->status));
        cJSON_AddStringToObject(c, "fault", pmstep_fault_str((pmstep_fault_t)cal->fault));
        cJSON_AddNumberToObject(c, "runs", (double)cal->runs);
        cJSON_AddNumberToObject(c, "simulated_s", cal->simulated_s);
        cJSON_AddItemToObject(c, "datasheet", design_values(&cal->datasheet, &cal->datasheet_report));
        if (cal->status == PMSTEP_CALIBRATE_OK) {
            cJSON_AddItemToObject(c, "drive", design_values(&cal->drive, &cal->drive_report));
        }
        cJSON_AddItemToObject(root, "self_commissioning", c);
    }
    cJSON_AddBoolToObject(root, "passed", passed);
    cJSON_AddBoolToObject(root, "synchronous", synchronous);
    text = cJSON_Print(root);
    cJSON_Delete(root);
    if (text == NULL) {
        fprintf(stderr, "pmstep-tune: out of memory writing %s\n", path);
        return -1;
    }
    f = fopen(path, "w");
    if (f == NULL || fputs(text, f) < 0 || fclose(f) != 0) {
        fprintf(stderr, "pmstep-tune: cannot write %s\n", path);
        free(text);
        return -1;
    }
    free(text);
    return 0;
}
