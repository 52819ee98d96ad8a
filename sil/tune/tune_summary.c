/* pmstep-tune --summary: the design's outcome and the validation's runs as JSON, for the tools
 * that sweep motors (tools/sweep_motors.py). */
#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>

#include "pmstep/pmstep_text.h"
#include "pmstep_tune.h"

int write_summary(const char *path, const char *motor_path, bool robust, pmstep_status_t status,
                  const pmstep_design_report_t *r, const tune_check_t *checks, int n_checks)
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
        cJSON_AddNumberToObject(design, "current_bandwidth_rad_s", (double)r->current_bandwidth_rad_s);
        cJSON_AddNumberToObject(design, "observer_bandwidth_rad_s", (double)r->observer_bandwidth_rad_s);
        cJSON_AddNumberToObject(design, "speed_bandwidth_rad_s", (double)r->speed_bandwidth_rad_s);
        cJSON_AddNumberToObject(design, "alignment_current_A", (double)r->alignment_current_A);
        cJSON_AddNumberToObject(design, "alignment_frequency_rad_s", (double)r->alignment_frequency_rad_s);
        cJSON_AddNumberToObject(design, "alignment_damping", (double)r->alignment_damping);
        cJSON_AddNumberToObject(design, "condition_4_margin", (double)r->condition_4_margin);
        cJSON_AddNumberToObject(design, "magnetising_current_A", (double)r->magnetising_current_A);
        cJSON_AddNumberToObject(design, "rated_torque_Nm", (double)r->rated_torque_Nm);
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
