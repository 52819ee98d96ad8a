/* Summary metrics of a closed-loop run (see metrics.h). */
#include "sil/metrics.h"

#include <math.h>
#include <string.h>

long sil_periods_in(double duration_s, double period_s)
{
    return (long)floor(duration_s / period_s + 0.5);
}

void sil_metrics_init(sil_metrics_t *m, const sil_scenario_t *sc, sil_summary_t *s)
{
    const double period_s = (double)sc->controller.period_s;
    memset(m, 0, sizeof *m);
    memset(s, 0, sizeof *s);
    s->fault_step = -1;
    s->fault_time_s = -1.0;
    m->ts_step = sil_periods_in((double)sc->controller.s_align_time_s, period_s);
    m->tc_step = sil_periods_in((double)sc->controller.c_align_time_s, period_s);
    m->transient_end_step = m->tc_step + sil_periods_in(sc->transient_window_s, period_s);
    m->s_align_current_a = (double)sc->controller.s_align_voltage_v / sc->motor.resistance_ohm;
    m->c_align_current_a = (double)sc->controller.c_align_voltage_v / sc->motor.resistance_ohm;
}

void sil_metrics_add(sil_metrics_t *m, const sil_sample_t *x, sil_summary_t *s)
{
    const pmstep_output_t *out = x->out;
    if (x->step == m->ts_step) {
        s->cos_ptheta_at_ts = x->cos_ptheta;
        s->sin_ptheta_at_ts = x->sin_ptheta;
        s->i_b_residual_at_ts_a = x->i_b_a - m->s_align_current_a;
    }
    if (x->step == m->tc_step) {
        s->cos_ptheta_at_tc = x->cos_ptheta;
        s->sin_ptheta_at_tc = x->sin_ptheta;
        s->i_a_residual_at_tc_a = x->i_a_a - m->c_align_current_a;
    }
    s->max_phase_voltage_v = fmax(s->max_phase_voltage_v, fmax(fabs(x->u_a_v), fabs(x->u_b_v)));
    s->max_phase_current_a = fmax(s->max_phase_current_a, fmax(fabs(x->i_a_a), fabs(x->i_b_a)));
    if (out->voltage_limited) {
        s->voltage_limited_periods++;
    }
    if (out->mode == PMSTEP_MODE_RUN) {
        const double speed_error = fabs(x->omega_rad_s - (double)out->speed_ref_rad_s);
        s->max_cos_error = fmax(s->max_cos_error, fabs((double)out->cos_hat - x->cos_ptheta));
        s->max_sin_error = fmax(s->max_sin_error, fabs((double)out->sin_hat - x->sin_ptheta));
        if (x->step < m->transient_end_step) {
            s->transient_max_speed_error_rad_s = fmax(s->transient_max_speed_error_rad_s, speed_error);
            m->transient_sq += speed_error * speed_error;
            ++m->transient_n;
        } else {
            s->tracking_max_speed_error_rad_s = fmax(s->tracking_max_speed_error_rad_s, speed_error);
            m->tracking_sq += speed_error * speed_error;
            ++m->tracking_n;
        }
        s->final_load_hat_nm = (double)out->load_hat_nm;
        s->final_load_nm = x->load_nm;
    }
    if (out->fault != PMSTEP_FAULT_NONE && s->fault == PMSTEP_FAULT_NONE) {
        s->fault = out->fault;
        s->fault_step = (long)out->fault_step;
        s->fault_time_s = x->t_s;
    }
    s->final_mode = out->mode;
    s->steps = x->step + 1;
}

void sil_metrics_finish(const sil_metrics_t *m, sil_summary_t *s)
{
    s->transient_rms_speed_error_rad_s = m->transient_n ? sqrt(m->transient_sq / (double)m->transient_n) : 0.0;
    s->tracking_rms_speed_error_rad_s = m->tracking_n ? sqrt(m->tracking_sq / (double)m->tracking_n) : 0.0;
    s->final_load_error_nm = fabs(s->final_load_hat_nm - s->final_load_nm);
}
