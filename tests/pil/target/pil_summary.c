/* The summary of a closed-loop run on the target, in the keys of the host runner's summary.json
 * that tests/pil/pil_summary_compare.c compares (PIL closed loop and console images). */
#include "pil_summary.h"

#include "pmstep/pmstep_text.h"

void pil_write_summary(FILE *f, const char *target, const sil_summary_t *s, double duration_s, int substeps)
{
    fprintf(f, "{\n");
    fprintf(f, "  \"scenario\": \"paper\",\n  \"target\": \"%s\",\n", target);
    fprintf(f, "  \"duration_s\": %.17g,\n  \"substeps\": %d,\n", duration_s, substeps);
    fprintf(f, "  \"alignment\": {\n");
    fprintf(f, "    \"cos_ptheta_at_ts\": %.17g,\n    \"sin_ptheta_at_ts\": %.17g,\n", s->cos_ptheta_at_ts,
            s->sin_ptheta_at_ts);
    fprintf(f, "    \"i_b_minus_ucs_over_r_at_ts_A\": %.17g,\n", s->i_b_residual_at_ts_A);
    fprintf(f, "    \"cos_ptheta_at_tc\": %.17g,\n    \"sin_ptheta_at_tc\": %.17g,\n", s->cos_ptheta_at_tc,
            s->sin_ptheta_at_tc);
    fprintf(f, "    \"i_a_minus_ucc_over_r_at_tc_A\": %.17g\n  },\n", s->i_a_residual_at_tc_A);
    fprintf(f, "  \"speed\": {\n");
    fprintf(f, "    \"transient_max_abs_error_rad_s\": %.17g,\n    \"transient_rms_error_rad_s\": %.17g,\n",
            s->transient_max_speed_error_rad_s, s->transient_rms_speed_error_rad_s);
    fprintf(f, "    \"tracking_max_abs_error_rad_s\": %.17g,\n    \"tracking_rms_error_rad_s\": %.17g\n  },\n",
            s->tracking_max_speed_error_rad_s, s->tracking_rms_speed_error_rad_s);
    fprintf(f, "  \"final_load_hat_Nm\": %.17g,\n  \"final_load_Nm\": %.17g,\n", s->final_load_hat_Nm,
            s->final_load_Nm);
    fprintf(f, "  \"final_load_abs_error_Nm\": %.17g,\n", s->final_load_error_Nm);
    fprintf(f, "  \"angle_estimate\": {\n    \"max_abs_cos_error\": %.17g,\n    \"max_abs_sin_error\": %.17g\n  },\n",
            s->max_cos_error, s->max_sin_error);
    fprintf(f, "  \"max_abs_phase_voltage_V\": %.17g,\n  \"max_abs_phase_current_a\": %.17g,\n", s->max_phase_voltage_V,
            s->max_phase_current_A);
    fprintf(f, "  \"voltage_limited_periods\": %ld,\n  \"inverter_clipped_periods\": %ld,\n",
            s->voltage_limited_periods, s->inverter_limited_periods);
    fprintf(f, "  \"final_mode\": \"%s\",\n", pmstep_mode_str(s->final_mode));
    fprintf(
        f,
        "  \"fault\": {\n    \"code\": %d,\n    \"text\": \"%s\",\n    \"step\": %ld,\n    \"time_s\": %.17g\n  },\n",
        (int)s->fault, pmstep_fault_str(s->fault), s->fault_step, s->fault_time_s);
    fprintf(f, "  \"timing\": {\n    \"steps\": %ld\n  }\n}\n", s->steps);
}
