/* Summary metrics of a closed-loop run (see metrics.h). */
#include "sil/metrics.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

/* fmax as the C library defines it (a NaN argument gives the other one), inline: fmax is a
 * libm call on x86-64, and these maxima are taken every period. */
static double max_of(double a, double b)
{
    if (b > a) {
        return b;
    }
    return isnan(a) ? b : a;
}

long sil_periods_in(double duration_s, double period_s)
{
    return (long)floor(duration_s / period_s + 0.5);
}

/* The first period k with k T_s >= t_s, as the runner issues a command due at t_s. */
static long first_step_at_or_after(double t_s, double period_s)
{
    long k = (long)ceil(t_s / period_s);
    while (k > 0 && (double)(k - 1) * period_s >= t_s) {
        --k;
    }
    while ((double)k * period_s < t_s) {
        ++k;
    }
    return k;
}

void sil_metrics_init(sil_metrics_t *m, const sil_scenario_t *sc, sil_summary_t *s)
{
    const double period_s = (double)sc->controller.timing.period_s;
    memset(m, 0, sizeof *m);
    memset(s, 0, sizeof *s);
    s->fault_step = -1;
    s->fault_time_s = -1.0;
    /* Alignment starts after the bridge-off offset calibration, when there is one. */
    const long calibration_steps =
        sil_periods_in((double)sc->controller.commissioning.offset_calibration_time_s, period_s);
    m->ts_step = calibration_steps + sil_periods_in((double)sc->controller.alignment.s_align_time_s, period_s);
    m->tc_step = calibration_steps + sil_periods_in((double)sc->controller.alignment.c_align_time_s, period_s);
    m->transient_end_step = m->tc_step + sil_periods_in(sc->transient_window_s, period_s);
    m->settle_step = m->transient_end_step;
    m->loss_speed_error_rad_s = sc->loss_speed_error_rad_s;
    m->loss_angle_error_rad = sc->loss_angle_error_rad;
    m->loss_position_error_rad = sc->loss_position_error_rad;
    s->run_start_time_s = (double)m->tc_step * period_s;
    s->settle_time_s = (double)m->settle_step * period_s;
    s->loss_of_control_time_s = -1.0;
    s->max_angle_error_time_s = -1.0;
    s->max_speed_error_time_s = -1.0;
    s->detection_latency_s = NAN;
    m->s_align_current_A = (double)sc->controller.alignment.s_align_voltage_V / sc->motor.resistance_Ohm;
    m->c_align_current_A = (double)sc->controller.alignment.c_align_voltage_V / sc->motor.resistance_Ohm;
    m->loss_angle_reachable = m->loss_angle_error_rad < PI;
    m->loss_angle_cos = cos(m->loss_angle_error_rad);
    m->loss_angle_sin = sin(m->loss_angle_error_rad);
    m->max_angle_cos = 1.0;
    m->max_angle_sin = 0.0;
    m->microstep = sc->drive == SIL_DRIVE_MICROSTEP;
    m->pole_pairs = (double)sc->motor.pole_pairs;
    if (m->microstep) {
        /* No alignment: the "run" starts when the hold ends (the first speed command). */
        m->ts_step = -1;
        m->tc_step = first_step_at_or_after(sil_scenario_hold_end_s(sc), period_s);
        m->transient_end_step = m->tc_step + sil_periods_in(sc->transient_window_s, period_s);
        m->settle_step = m->transient_end_step;
        s->run_start_time_s = (double)m->tc_step * period_s;
        s->settle_time_s = (double)m->settle_step * period_s;
    }
    m->metrics_start_step =
        sc->metrics_start_s < 0.0 ? m->tc_step : first_step_at_or_after(sc->metrics_start_s, period_s);
    s->metrics_start_time_s = (double)m->metrics_start_step * period_s;
    s->loss_of_synchronism_time_s = -1.0;
}

/* Electrical angle of (c-hat, s-hat) minus p theta as (x, |y|): its magnitude, wrapped to
 * [0, pi], is atan2(|y|, x). */
static void angle_error_xy(const pmstep_output_t *out, const sil_sample_t *x, double *ex, double *ey)
{
    const double c = (double)out->cos_hat;
    const double s = (double)out->sin_hat;
    *ex = c * x->cos_ptheta + s * x->sin_ptheta;
    *ey = fabs(s * x->cos_ptheta - c * x->sin_ptheta);
}

static bool sample_finite(const sil_sample_t *x)
{
    const pmstep_output_t *o = x->out;
    const double sum = x->theta_rad + x->omega_rad_s + x->i_a_A + x->i_b_A + x->u_a_V + x->u_b_V + (double)o->u_a_V
                       + (double)o->u_b_V + (double)o->cos_hat + (double)o->sin_hat + (double)o->speed_hat_rad_s
                       + (double)o->load_hat_Nm + (double)o->i_a_hat_A + (double)o->i_b_hat_A;
    return isfinite(sum) != 0;
}

/* Microstep: the load angle theta_e* - p theta, continuous, offset by 2 pi n so that it starts in
 * (-pi, pi] (the rotor aligns to the nearest p theta = 0 mod 2 pi); beyond +/- pi the rotor has
 * slipped a pole pair: loss of synchronism. */
static void add_load_angle(sil_metrics_t *m, const sil_sample_t *x, sil_summary_t *s)
{
    double angle = x->angle_ref_rad - m->pole_pairs * x->theta_rad;
    if (!m->load_angle_ready) {
        m->load_angle_offset_rad = -2.0 * PI * ceil((angle - PI) / (2.0 * PI));
        m->load_angle_ready = true;
    }
    angle = fabs(angle + m->load_angle_offset_rad);
    if (x->step >= m->metrics_start_step) {
        s->max_load_angle_rad = max_of(s->max_load_angle_rad, angle);
    }
    if (angle > PI && !s->loss_of_synchronism) {
        s->loss_of_synchronism = true;
        s->loss_of_synchronism_time_s = x->t_s;
        if (s->loss_of_control_time_s < 0.0) {
            s->loss_of_control_time_s = x->t_s;
        }
    }
}

/* Off course: in a position scenario's position mode, the true position more than
 * loss_position_error_rad (electrical) from theta* - a positioning drive's loss of control is
 * a lost step; its speed may leave omega* by more (a held rotor swings onto a load step's load
 * angle) without losing anything. Otherwise the speed error above loss_speed_error_rad_s. */
static bool off_course(const sil_metrics_t *m, const sil_sample_t *x, double speed_error)
{
    if (x->position != NULL && x->position->position_mode) {
        return fabs(x->position_reference_rad - x->position_rad) * m->pole_pairs > m->loss_position_error_rad;
    }
    return speed_error > m->loss_speed_error_rad_s;
}

/* The largest |omega - omega*| after settling and the time of its first sample. */
static void note_speed_error_after_settle(sil_summary_t *s, double speed_error, double t_s)
{
    if (speed_error > s->max_speed_error_after_settle_rad_s) {
        s->max_speed_error_after_settle_rad_s = speed_error;
        s->max_speed_error_time_s = t_s;
    }
}

void sil_metrics_add(sil_metrics_t *m, const sil_sample_t *x, sil_summary_t *s)
{
    const pmstep_output_t *out = x->out;
    if (!sample_finite(x)) {
        s->nonfinite_seen = true;
    }
    if (!m->microstep) {
        pmstep_get_commissioning(x->inst, &s->commissioning);
    }
    if (x->step >= m->metrics_start_step) {
        m->current_sq += 0.5 * (x->i_a_A * x->i_a_A + x->i_b_A * x->i_b_A);
        ++m->current_n;
    }
    if (m->microstep) {
        add_load_angle(m, x, s);
    }
    if (x->step == m->ts_step) {
        s->cos_ptheta_at_ts = x->cos_ptheta;
        s->sin_ptheta_at_ts = x->sin_ptheta;
        s->i_b_residual_at_ts_A = x->i_b_A - m->s_align_current_A;
    }
    if (out->mode == PMSTEP_MODE_RUN && !m->run_reached && !m->microstep) {
        m->run_reached = true;
        s->cos_ptheta_at_tc = x->cos_ptheta;
        s->sin_ptheta_at_tc = x->sin_ptheta;
        s->i_a_residual_at_tc_A = x->i_a_A - m->c_align_current_A;
    }
    s->max_phase_voltage_V = max_of(s->max_phase_voltage_V, max_of(fabs(x->u_a_V), fabs(x->u_b_V)));
    s->max_phase_current_A = max_of(s->max_phase_current_A, max_of(fabs(x->i_a_A), fabs(x->i_b_A)));
    if (out->voltage_limited) {
        s->voltage_limited_periods++;
    }
    if (out->mode == PMSTEP_MODE_RUN) {
        const double speed_error = fabs(x->omega_rad_s - (double)out->speed_ref_rad_s);
        if (x->step < m->transient_end_step) {
            s->transient_max_speed_error_rad_s = max_of(s->transient_max_speed_error_rad_s, speed_error);
            m->transient_sq += speed_error * speed_error;
            ++m->transient_n;
        } else {
            s->tracking_max_speed_error_rad_s = max_of(s->tracking_max_speed_error_rad_s, speed_error);
            m->tracking_sq += speed_error * speed_error;
            ++m->tracking_n;
        }
        s->final_load_hat_Nm = (double)out->load_hat_Nm;
        s->final_load_Nm = x->load_Nm;
        if (m->microstep) {
            if (x->step >= m->settle_step) {
                note_speed_error_after_settle(s, speed_error, x->t_s);
            }
        } else {
            /* The angle estimate (c-hat, s-hat) against the plant's p theta. */
            bool angle_lost;
            double ex, ey;
            s->max_cos_error = max_of(s->max_cos_error, fabs((double)out->cos_hat - x->cos_ptheta));
            s->max_sin_error = max_of(s->max_sin_error, fabs((double)out->sin_hat - x->sin_ptheta));
            angle_error_xy(out, x, &ex, &ey);
            m->last_angle_x = ex;
            m->last_angle_y = ey;
            if (x->step >= m->settle_step) {
                if (ey * m->max_angle_cos - ex * m->max_angle_sin > 0.0) { /* above the max so far */
                    const double r = hypot(ex, ey);
                    s->max_angle_error_rad = atan2(ey, ex);
                    s->max_angle_error_time_s = x->t_s;
                    m->max_angle_cos = ex / r;
                    m->max_angle_sin = ey / r;
                }
                note_speed_error_after_settle(s, speed_error, x->t_s);
            }
            angle_lost = m->loss_angle_reachable && ey * m->loss_angle_cos - ex * m->loss_angle_sin > 0.0;
            if (s->loss_of_control_time_s < 0.0 && (off_course(m, x, speed_error) || angle_lost)) {
                s->loss_of_control_time_s = x->t_s;
            }
            if (angle_lost && !s->loss_of_synchronism) {
                s->loss_of_synchronism = true;
                s->loss_of_synchronism_time_s = x->t_s;
            }
        }
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
    s->final_load_error_Nm = fabs(s->final_load_hat_Nm - s->final_load_Nm);
    if (m->last_angle_x != 0.0 || m->last_angle_y != 0.0) {
        s->final_angle_error_rad = atan2(m->last_angle_y, m->last_angle_x);
    }
    s->rms_phase_current_A = m->current_n ? sqrt(m->current_sq / (double)m->current_n) : 0.0;
    if (!m->microstep) {
        s->max_load_angle_rad = s->max_angle_error_rad;
    }
    if (s->loss_of_control_time_s >= 0.0 && s->fault != PMSTEP_FAULT_NONE) {
        s->detection_latency_s = s->fault_time_s - s->loss_of_control_time_s;
    }
}
