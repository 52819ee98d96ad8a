/* Open-loop microstepping drive at rated current: the SIL's baseline (microstep.h). */
#include "sil/microstep.h"

#include "sil/inverter.h"

#include <math.h>
#include <string.h>

void sil_microstep_init(sil_microstep_t *drive, const sil_scenario_t *sc)
{
    memset(drive, 0, sizeof *drive);
    drive->period_s = (double)sc->controller.timing.period_s;
    drive->current_A = sc->datasheet.rated_current_A;
    drive->resistance_Ohm = (double)sc->controller.motor.resistance_Ohm;
    drive->inductance_H = (double)sc->controller.motor.inductance_H;
    drive->pole_pairs = (double)sc->controller.motor.pole_pairs;
    drive->gain_per_s = SIL_MICROSTEP_GAIN_FRACTION / drive->period_s;
}

void sil_microstep_set_speed_target(sil_microstep_t *drive, double target_rad_s, double ramp_rate_rad_s2)
{
    drive->target_rad_s = target_rad_s;
    drive->ramp_rate_rad_s2 = ramp_rate_rad_s2;
    drive->moving = true;
}

void sil_microstep_set_angle(sil_microstep_t *drive, double angle_ref_rad)
{
    if (drive->angle_mode) {
        /* mechanical: the angle is electrical */
        drive->speed_ref_rad_s = (angle_ref_rad - drive->angle_ref_rad) / (drive->period_s * drive->pole_pairs);
    } else {
        drive->speed_ref_rad_s = 0.0;
    }
    drive->target_rad_s = drive->speed_ref_rad_s; /* no ramp left running: the telemetry's rate is 0 */
    drive->angle_ref_rad = angle_ref_rad;
    drive->angle_mode = true;
    drive->moving = true;
}

/* omega* over [t_k, t_k + T_s]: a ramp towards the target that stops there. Returns the
 * integral of omega* over the period (rad) and leaves omega*(t_k + T_s). */
static double advance_reference(sil_microstep_t *drive)
{
    const double h = drive->period_s;
    const double w0 = drive->speed_ref_rad_s;
    const double gap = drive->target_rad_s - w0;
    double reach_s;
    if (gap == 0.0) {
        return w0 * h;
    }
    reach_s = drive->ramp_rate_rad_s2 > 0.0 ? fabs(gap) / drive->ramp_rate_rad_s2 : 0.0;
    if (reach_s >= h) {
        const double w1 = w0 + (gap > 0.0 ? 1.0 : -1.0) * drive->ramp_rate_rad_s2 * h;
        drive->speed_ref_rad_s = w1;
        return 0.5 * (w0 + w1) * h;
    }
    /* The ramp ends inside the period: trapezoid up to it, the target after. */
    drive->speed_ref_rad_s = drive->target_rad_s;
    return 0.5 * (w0 + drive->target_rad_s) * reach_s + drive->target_rad_s * (h - reach_s);
}

void sil_microstep_step(sil_microstep_t *drive, const pmstep_meas_t *meas, pmstep_output_t *out)
{
    const double angle = drive->angle_ref_rad;
    const double c = cos(angle), s = sin(angle);
    const double current = drive->current_A;
    const double elec_speed = drive->pole_pairs * drive->speed_ref_rad_s; /* theta_e*' (rad/s) */
    const double i_a_ref = current * c, i_b_ref = current * s;
    const double di_a_ref = -current * elec_speed * s, di_b_ref = current * elec_speed * c; /* A/s */
    const double r = drive->resistance_Ohm, l = drive->inductance_H, la = l * drive->gain_per_s;
    const double bus_V = (double)meas->bus_voltage_V;
    bool clipped = false;
    /* u = R i* + L (d/dt) i* + L a (i* - i_meas): no back-EMF feed-forward. */
    const double u_a = r * i_a_ref + l * di_a_ref + la * (i_a_ref - (double)meas->i_a_A);
    const double u_b = r * i_b_ref + l * di_b_ref + la * (i_b_ref - (double)meas->i_b_A);

    memset(out, 0, sizeof *out);
    if (bus_V > 0.0 && isfinite(bus_V)) {
        out->u_a_V = (float)sil_inverter_clip(u_a, bus_V, &clipped);
        out->u_b_V = (float)sil_inverter_clip(u_b, bus_V, &clipped);
    }
    out->bridge_enable = true;
    out->voltage_limited = clipped;
    out->mode = drive->moving ? PMSTEP_MODE_RUN : PMSTEP_MODE_C_ALIGN;
    out->fault = PMSTEP_FAULT_NONE;
    out->cos_hat = (float)c;
    out->sin_hat = (float)s;
    out->speed_ref_rad_s = (float)drive->speed_ref_rad_s;
    if (drive->speed_ref_rad_s != drive->target_rad_s) {
        out->speed_ref_rate_rad_s2 =
            (float)(drive->target_rad_s > drive->speed_ref_rad_s ? drive->ramp_rate_rad_s2 : -drive->ramp_rate_rad_s2);
    }
    out->i_a_hat_A = (float)i_a_ref;
    out->i_b_hat_A = (float)i_b_ref;
    if (!drive->angle_mode) {
        drive->angle_ref_rad = angle + drive->pole_pairs * advance_reference(drive);
    }
}
