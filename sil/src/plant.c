/* Model (1) of the paper, RK4 with voltages held over the control period. */
#include "sil/plant.h"

#include <math.h>
#include <stddef.h>

plant_params_t plant_paper_params(void)
{
    plant_params_t p;
    p.resistance_Ohm = 3.0;
    p.inductance_H = 0.006;
    p.inertia_kgm2 = 0.01;
    p.friction_Nms_rad = 0.0;
    p.torque_constant_Nm_A = 2.0;
    p.pole_pairs = 6;
    return p;
}

double plant_load_torque(const plant_load_t *load, double t_s, double omega_rad_s)
{
    switch (load->kind) {
    case PLANT_LOAD_NONE:
        return 0.0;
    case PLANT_LOAD_CONSTANT:
        return load->torque_Nm;
    case PLANT_LOAD_STEP:
        return t_s >= load->step_time_s ? load->torque_Nm : 0.0;
    case PLANT_LOAD_PROPORTIONAL:
        return load->coefficient_Nms_rad * omega_rad_s;
    case PLANT_LOAD_TABLE: {
        int k;
        const int n = load->table_points;
        if (n <= 0) {
            return 0.0;
        }
        if (t_s <= load->table_time_s[0]) {
            return load->table_torque_Nm[0];
        }
        for (k = 1; k < n; ++k) {
            if (t_s < load->table_time_s[k]) {
                const double t0 = load->table_time_s[k - 1];
                const double w = (t_s - t0) / (load->table_time_s[k] - t0);
                return load->table_torque_Nm[k - 1] + w * (load->table_torque_Nm[k] - load->table_torque_Nm[k - 1]);
            }
        }
        return load->table_torque_Nm[n - 1];
    }
    }
    return 0.0;
}

/* (1) with sin p theta and cos p theta given. */
static void derivative_at(const plant_params_t *params, const plant_load_t *load, double t_s, const plant_state_t *x,
                          double s, double c, double u_a_V, double u_b_V, plant_state_t *dx)
{
    const double inv_l = 1.0 / params->inductance_H;
    const double inv_j = 1.0 / params->inertia_kgm2;
    const double k_m = params->torque_constant_Nm_A;
    const double load_Nm = plant_load_torque(load, t_s, x->omega_rad_s);

    dx->theta_rad = x->omega_rad_s;
    dx->omega_rad_s = inv_j * (-params->friction_Nms_rad * x->omega_rad_s
                               + k_m * (-x->i_a_A * s + x->i_b_A * c) - load_Nm);
    dx->i_a_A = inv_l * (-params->resistance_Ohm * x->i_a_A + k_m * x->omega_rad_s * s + u_a_V);
    dx->i_b_A = inv_l * (-params->resistance_Ohm * x->i_b_A - k_m * x->omega_rad_s * c + u_b_V);
}

void plant_derivative(const plant_params_t *params, const plant_load_t *load, double t_s,
                      const plant_state_t *x, double u_a_V, double u_b_V, plant_state_t *dx)
{
    const double angle = (double)params->pole_pairs * x->theta_rad;
    derivative_at(params, load, t_s, x, sin(angle), cos(angle), u_a_V, u_b_V, dx);
}

/* sin and cos of (angle + delta) from those of angle. Within a substep delta = p (theta_stage -
 * theta) is tiny, so its sine and cosine come from their Taylor series (truncation below
 * 1e-17 for |delta| < 0.01): one sincos per substep instead of four. */
static void rotate(double s0, double c0, double delta, double *s, double *c)
{
    double sd, cd;
    if (fabs(delta) < 0.01) {
        const double d2 = delta * delta;
        sd = delta * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0)));
        cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0));
    } else {
        sd = sin(delta);
        cd = cos(delta);
    }
    *s = s0 * cd + c0 * sd;
    *c = c0 * cd - s0 * sd;
}

static plant_state_t axpy(const plant_state_t *x, double h, const plant_state_t *dx)
{
    plant_state_t y;
    y.theta_rad = x->theta_rad + h * dx->theta_rad;
    y.omega_rad_s = x->omega_rad_s + h * dx->omega_rad_s;
    y.i_a_A = x->i_a_A + h * dx->i_a_A;
    y.i_b_A = x->i_b_A + h * dx->i_b_A;
    return y;
}

/* An open phase (bridge off, current extinguished) keeps i = 0: its current does not change. */
static void hold_open(plant_state_t *dx, bool open_a, bool open_b)
{
    if (open_a) {
        dx->i_a_A = 0.0;
    }
    if (open_b) {
        dx->i_b_A = 0.0;
    }
}

void plant_substep(plant_t *plant, double t_s, double h, double u_a_V, double u_b_V, double *charge_a_c,
                   double *charge_b_c)
{
    const plant_state_t x = plant->x;
    const double p = (double)plant->params.pole_pairs;
    const double s0 = sin(p * x.theta_rad);
    const double c0 = cos(p * x.theta_rad);
    const bool oa = plant->open_a;
    const bool ob = plant->open_b;
    plant_state_t k1, k2, k3, k4, y2, y3, y4;
    double s, c;
    derivative_at(&plant->params, &plant->load, t_s, &x, s0, c0, u_a_V, u_b_V, &k1);
    hold_open(&k1, oa, ob);
    y2 = axpy(&x, 0.5 * h, &k1);
    rotate(s0, c0, p * (y2.theta_rad - x.theta_rad), &s, &c);
    derivative_at(&plant->params, &plant->load, t_s + 0.5 * h, &y2, s, c, u_a_V, u_b_V, &k2);
    hold_open(&k2, oa, ob);
    y3 = axpy(&x, 0.5 * h, &k2);
    rotate(s0, c0, p * (y3.theta_rad - x.theta_rad), &s, &c);
    derivative_at(&plant->params, &plant->load, t_s + 0.5 * h, &y3, s, c, u_a_V, u_b_V, &k3);
    hold_open(&k3, oa, ob);
    y4 = axpy(&x, h, &k3);
    rotate(s0, c0, p * (y4.theta_rad - x.theta_rad), &s, &c);
    derivative_at(&plant->params, &plant->load, t_s + h, &y4, s, c, u_a_V, u_b_V, &k4);
    hold_open(&k4, oa, ob);
    plant->x.theta_rad = x.theta_rad + h / 6.0 * (k1.theta_rad + 2.0 * (k2.theta_rad + k3.theta_rad) + k4.theta_rad);
    plant->x.omega_rad_s = x.omega_rad_s + h / 6.0 * (k1.omega_rad_s + 2.0 * (k2.omega_rad_s + k3.omega_rad_s) + k4.omega_rad_s);
    plant->x.i_a_A = x.i_a_A + h / 6.0 * (k1.i_a_A + 2.0 * (k2.i_a_A + k3.i_a_A) + k4.i_a_A);
    plant->x.i_b_A = x.i_b_A + h / 6.0 * (k1.i_b_A + 2.0 * (k2.i_b_A + k3.i_b_A) + k4.i_b_A);
    if (charge_a_c != NULL && charge_b_c != NULL) {
        /* The currents at the four stages, weighted as RK4 weights the derivatives. */
        *charge_a_c = h / 6.0 * (x.i_a_A + 2.0 * (y2.i_a_A + y3.i_a_A) + y4.i_a_A);
        *charge_b_c = h / 6.0 * (x.i_b_A + 2.0 * (y2.i_b_A + y3.i_b_A) + y4.i_b_A);
    }
}

void plant_advance(plant_t *plant, double u_a_V, double u_b_V, double period_s, int substeps)
{
    const double h = period_s / (double)substeps;
    const double t0 = plant->time_s;
    int n;
    for (n = 0; n < substeps; ++n) {
        plant_substep(plant, t0 + (double)n * h, h, u_a_V, u_b_V, NULL, NULL);
    }
    /* Time from the period count, not accumulated substeps. */
    plant->time_s = t0 + period_s;
}
