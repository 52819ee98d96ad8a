/* Model (1) of the paper with voltages held over each step: RK4, or the exponential
 * time-differencing RK4 of plant.h. */
#include "sil/plant.h"

#include <math.h>
#include <stddef.h>

/* The exponential step's stages forced inline: called through a function, each stage's state
 * and N go through memory (a quarter of the plant's time); inline they stay in registers.
 * The arithmetic is the same, so are the results. */
#if defined(__GNUC__)
#define PLANT_INLINE __attribute__((always_inline)) static inline
#else
#define PLANT_INLINE static inline
#endif

plant_params_t plant_paper_params(void)
{
    plant_params_t p;
    p.resistance_Ohm = 3.0;
    p.inductance_H = 0.006;
    p.inertia_kgm2 = 0.01;
    p.friction_Nms_rad = 0.0;
    p.torque_constant_Nm_A = 2.0;
    p.pole_pairs = 6;
    p.detent_torque_Nm = 0.0;
    p.stop_side = 0;
    p.stop_position_rad = 0.0;
    p.stop_stiffness_Nm_rad = 0.0;
    p.stop_damping_Nms_rad = 0.0;
    return p;
}

/* The loads that vary within a step: proportional to the speed, or a table in time. */
static double varying_load_torque(const plant_load_t *load, double t_s, double omega_rad_s)
{
    int k;
    const int n = load->table_points;
    if (load->kind == PLANT_LOAD_PROPORTIONAL) {
        return load->coefficient_Nms_rad * omega_rad_s;
    }
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

/* The load torque, with the kinds a step meets most (none, constant, a step) inline: it is
 * taken at every stage of every step. */
PLANT_INLINE double load_torque_at(const plant_load_t *load, double t_s, double omega_rad_s)
{
    switch (load->kind) {
    case PLANT_LOAD_NONE: return 0.0;
    case PLANT_LOAD_CONSTANT: return load->torque_Nm;
    case PLANT_LOAD_STEP: return t_s >= load->step_time_s ? load->torque_Nm : 0.0;
    case PLANT_LOAD_PROPORTIONAL:
    case PLANT_LOAD_TABLE: break;
    }
    return varying_load_torque(load, t_s, omega_rad_s);
}

double plant_load_torque(const plant_load_t *load, double t_s, double omega_rad_s)
{
    return load_torque_at(load, t_s, omega_rad_s);
}

/* Detent torque -T_d sin 4 p theta (Nm) from s = sin p theta, c = cos p theta:
 * sin 4x = 2 sin 2x cos 2x = 4 s c (c^2 - s^2), no further sincos. */
static double detent_torque(const plant_params_t *params, double s, double c)
{
    return -params->detent_torque_Nm * 4.0 * s * c * (c * c - s * s);
}

double plant_stop_torque(const plant_params_t *params, double theta_rad, double omega_rad_s)
{
    const double side = (double)params->stop_side;
    const double depth_rad = side * (theta_rad - params->stop_position_rad);
    double push_Nm;
    if (params->stop_side == 0 || depth_rad <= 0.0) {
        return 0.0;
    }
    push_Nm = params->stop_stiffness_Nm_rad * depth_rad + params->stop_damping_Nms_rad * side * omega_rad_s;
    return push_Nm > 0.0 ? -side * push_Nm : 0.0;
}

/* (1) with sin p theta and cos p theta given. The detent term is added only when T_d != 0, so
 * T_d = 0 leaves every result bit for bit as it was without it. */
static void derivative_at(const plant_params_t *params, const plant_load_t *load, double t_s, const plant_state_t *x,
                          double s, double c, double u_a_V, double u_b_V, plant_state_t *dx)
{
    const double inv_l = 1.0 / params->inductance_H;
    const double inv_j = 1.0 / params->inertia_kgm2;
    const double k_m = params->torque_constant_Nm_A;
    const double load_Nm = load_torque_at(load, t_s, x->omega_rad_s);
    double torque_Nm = -params->friction_Nms_rad * x->omega_rad_s + k_m * (-x->i_a_A * s + x->i_b_A * c) - load_Nm;

    if (params->detent_torque_Nm != 0.0) {
        torque_Nm += detent_torque(params, s, c);
    }
    if (params->stop_side != 0) {
        torque_Nm += plant_stop_torque(params, x->theta_rad, x->omega_rad_s);
    }
    dx->theta_rad = x->omega_rad_s;
    dx->omega_rad_s = inv_j * torque_Nm;
    dx->i_a_A = inv_l * (-params->resistance_Ohm * x->i_a_A + k_m * x->omega_rad_s * s + u_a_V);
    dx->i_b_A = inv_l * (-params->resistance_Ohm * x->i_b_A - k_m * x->omega_rad_s * c + u_b_V);
}

void plant_derivative(const plant_params_t *params, const plant_load_t *load, double t_s, const plant_state_t *x,
                      double u_a_V, double u_b_V, plant_state_t *dx)
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

void plant_sin_cos(plant_t *plant, double *sin_ptheta, double *cos_ptheta)
{
    const double angle = (double)plant->params.pole_pairs * plant->x.theta_rad;
    const double delta = angle - plant->trig_angle_rad;
    if (!plant->trig_valid || !(fabs(delta) < 0.01)) {
        /* A new base angle: one sincos. */
        plant->trig_sin = sin(angle);
        plant->trig_cos = cos(angle);
        plant->trig_angle_rad = angle;
        plant->trig_valid = true;
        *sin_ptheta = plant->trig_sin;
        *cos_ptheta = plant->trig_cos;
        return;
    }
    /* Within 0.01 rad of the base (the steps of a period, a slow rotor): rotated from the
     * base, never from a rotated value, so nothing accumulates. */
    rotate(plant->trig_sin, plant->trig_cos, delta, sin_ptheta, cos_ptheta);
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

static void rk4_substep(plant_t *plant, double t_s, double h, double u_a_V, double u_b_V, double *charge_a_c,
                        double *charge_b_c)
{
    const plant_state_t x = plant->x;
    const double p = (double)plant->params.pole_pairs;
    double s0, c0;
    const bool oa = plant->open_a || plant->broken_a;
    const bool ob = plant->open_b || plant->broken_b;
    plant_state_t k1, k2, k3, k4, y2, y3, y4;
    double s, c;
    plant_sin_cos(plant, &s0, &c0);
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
    plant->x.omega_rad_s =
        x.omega_rad_s + h / 6.0 * (k1.omega_rad_s + 2.0 * (k2.omega_rad_s + k3.omega_rad_s) + k4.omega_rad_s);
    plant->x.i_a_A = x.i_a_A + h / 6.0 * (k1.i_a_A + 2.0 * (k2.i_a_A + k3.i_a_A) + k4.i_a_A);
    plant->x.i_b_A = x.i_b_A + h / 6.0 * (k1.i_b_A + 2.0 * (k2.i_b_A + k3.i_b_A) + k4.i_b_A);
    if (charge_a_c != NULL && charge_b_c != NULL) {
        /* The currents at the four stages, weighted as RK4 weights the derivatives. */
        *charge_a_c = h / 6.0 * (x.i_a_A + 2.0 * (y2.i_a_A + y3.i_a_A) + y4.i_a_A);
        *charge_b_c = h / 6.0 * (x.i_b_A + 2.0 * (y2.i_b_A + y3.i_b_A) + y4.i_b_A);
    }
}

/* N(t, y) of plant.h: (1) less its linear part A (y - y*), with sin and cos of p theta given;
 * the detent torque is part of N. */
PLANT_INLINE void coupling_at(const plant_params_t *params, const plant_load_t *load, double t_s,
                              const plant_state_t *y, double s, double c, plant_state_t *n)
{
    const double k_m = params->torque_constant_Nm_A;
    /* A proportional load is linear in w: it is in A (speed_linear_per_s), integrated exactly. */
    const double load_Nm = load->kind == PLANT_LOAD_PROPORTIONAL ? 0.0 : load_torque_at(load, t_s, y->omega_rad_s);
    const double emf_per_l = k_m * y->omega_rad_s / params->inductance_H;
    double torque_Nm = k_m * (-y->i_a_A * s + y->i_b_A * c) - load_Nm;
    if (params->detent_torque_Nm != 0.0) {
        torque_Nm += detent_torque(params, s, c); /* T_d = 0: bit for bit as without the term */
    }
    if (params->stop_side != 0) {
        torque_Nm += plant_stop_torque(params, y->theta_rad, y->omega_rad_s); /* none: bit for bit as without it */
    }
    n->theta_rad = y->omega_rad_s;
    n->omega_rad_s = torque_Nm / params->inertia_kgm2;
    n->i_a_A = emf_per_l * s;
    n->i_b_A = -emf_per_l * c;
}

#define PHI_TERMS 20

/* e^z and phi_1, phi_2, phi_3 of z (phi_k(z) = sum_j z^j / (j + k)!): by their series for
 * |z| < 1 (no cancellation; the terms are summed until they no longer change the sums, a
 * handful for the |z| of a control period), by phi_{k+1} = (phi_k - 1/k!) / z above. */
static double phi_functions(double z, double phi[3])
{
    if (z == 0.0) {
        phi[0] = 1.0;
        phi[1] = 0.5;
        phi[2] = 1.0 / 6.0;
        return 1.0;
    }
    if (fabs(z) < 1.0) {
        /* 1 / (j + 4) for the series' terms (no division in the loop). */
        static const double inv[PHI_TERMS] = {1.0 / 4,  1.0 / 5,  1.0 / 6,  1.0 / 7,  1.0 / 8,  1.0 / 9,  1.0 / 10,
                                              1.0 / 11, 1.0 / 12, 1.0 / 13, 1.0 / 14, 1.0 / 15, 1.0 / 16, 1.0 / 17,
                                              1.0 / 18, 1.0 / 19, 1.0 / 20, 1.0 / 21, 1.0 / 22, 1.0 / 23};
        double term3 = 1.0 / 6.0;
        int j;
        phi[0] = 1.0;
        phi[1] = 0.5;
        phi[2] = 0.0;
        /* phi_3 by its series; phi_2 = 1/2 + z phi_3, phi_1 = 1 + z phi_2 (no cancellation: |z| < 1). */
        for (j = 0; j < PHI_TERMS; ++j) { /* |z|^20 / 23! is far below the double epsilon */
            const double before = phi[2];
            phi[2] += term3;
            if (phi[2] == before) {
                break;
            }
            term3 *= z * inv[j];
        }
        phi[1] = 0.5 + z * phi[2];
        phi[0] = 1.0 + z * phi[1];
        return 1.0 + z * phi[0];
    }
    phi[0] = (exp(z) - 1.0) / z;
    phi[1] = (phi[0] - 1.0) / z;
    phi[2] = (phi[1] - 0.5) / z;
    return exp(z);
}

/* The ETDRK4 weights of a component with linear coefficient lambda over a step h. */
static void etd_weights(double lambda, double h, plant_etd_weights_t *w)
{
    const double z = lambda * h;
    double phi[3], phi_half[3];
    w->decay = phi_functions(z, phi);
    w->decay_half = phi_functions(0.5 * z, phi_half);
    w->half = 0.5 * h * phi_half[0];
    w->w_start = h * (phi[0] - 3.0 * phi[1] + 4.0 * phi[2]);
    w->w_mid = h * (phi[1] - 2.0 * phi[2]);
    w->w_end = h * (4.0 * phi[2] - phi[1]);
}

/* The weights for h, R/L and F/J, recomputed only when one of them changes. A proportional load
 * c w adds to the friction: (F + c)/J, whatever its size (c T_s / J beyond 2 made RK4 diverge),
 * and a negative c, a load that drives, grows as it should. */
static void update_weights(plant_t *plant, double h)
{
    const double r_over_l = plant->params.resistance_Ohm / plant->params.inductance_H;
    const double load_per_speed = plant->load.kind == PLANT_LOAD_PROPORTIONAL ? plant->load.coefficient_Nms_rad : 0.0;
    const double f_over_j = (plant->params.friction_Nms_rad + load_per_speed) / plant->params.inertia_kgm2;
    if (h != plant->cache_h_s || r_over_l != plant->cache_r_over_l || f_over_j != plant->cache_f_over_j) {
        plant->cache_h_s = h;
        plant->cache_r_over_l = r_over_l;
        plant->cache_f_over_j = f_over_j;
        etd_weights(-r_over_l, h, &plant->cache_current);
        etd_weights(0.0, h, &plant->cache_free); /* constants times h: no series for z = 0 */
        if (f_over_j == 0.0) {
            plant->cache_speed = plant->cache_free;
        } else {
            etd_weights(-f_over_j, h, &plant->cache_speed);
        }
    }
}

/* One component of ETDRK4 (Cox and Matthews): w = y - y*, n0..n3 = N at the start, the two
 * midpoint stages and the end stage. */
static double etd_stage_a(const plant_etd_weights_t *w, double w0, double n0)
{
    return w->decay_half * w0 + w->half * n0;
}

static double etd_stage_c(const plant_etd_weights_t *w, double wa, double n0, double nb)
{
    return w->decay_half * wa + w->half * (2.0 * nb - n0);
}

static double etd_end(const plant_etd_weights_t *w, double w0, double n0, double na, double nb, double nc)
{
    return w->decay * w0 + w->w_start * n0 + 2.0 * w->w_mid * (na + nb) + w->w_end * nc;
}

/* The torque of the extra currents at stage k (0 start, 1 middle, 2 end). */
static void add_extra_torque(const plant_t *plant, int k, double s, double c, plant_state_t *n)
{
    const double ia = plant->torque_extra_a_a[k];
    const double ib = plant->torque_extra_b_a[k];
    if (ia != 0.0 || ib != 0.0) {
        n->omega_rad_s += plant->params.torque_constant_Nm_A * (-ia * s + ib * c) / plant->params.inertia_kgm2;
    }
}

/* N at one stage of the exponential step (k: 0 start, 1 middle, 2 end): the coupling, the
 * extra currents' torque, an open phase held. */
PLANT_INLINE void stage_coupling(const plant_t *plant, int k, double t_s, const plant_state_t *y, double s, double c,
                                 plant_state_t *n)
{
    coupling_at(&plant->params, &plant->load, t_s, y, s, c, n);
    add_extra_torque(plant, k, s, c, n);
    hold_open(n, plant->open_a || plant->broken_a, plant->open_b || plant->broken_b);
}

/* Exponential time differencing RK4 on w = y - y* (plant.h). theta has no linear part;
 * an open phase has none either and its N is zero, so it holds. */
static void exponential_substep(plant_t *plant, double t_s, double h, double u_a_V, double u_b_V, double *charge_a_c,
                                double *charge_b_c)
{
    const plant_params_t *par = &plant->params;
    const plant_state_t x = plant->x;
    const double p = (double)par->pole_pairs;
    const bool oa = plant->open_a || plant->broken_a;
    const bool ob = plant->open_b || plant->broken_b;
    const plant_etd_weights_t *wt, *ww, *wa, *wb;
    double star_a, star_b;
    plant_state_t w0, n0, na, nb, nc, ya, yb, yc;
    double s0, c0, s, c;
    plant_sin_cos(plant, &s0, &c0);
    update_weights(plant, h);
    wt = &plant->cache_free;
    ww = &plant->cache_speed;
    wa = oa ? &plant->cache_free : &plant->cache_current;
    wb = ob ? &plant->cache_free : &plant->cache_current;
    star_a = oa ? x.i_a_A : u_a_V / par->resistance_Ohm;
    star_b = ob ? x.i_b_A : u_b_V / par->resistance_Ohm;
    w0.theta_rad = x.theta_rad;
    w0.omega_rad_s = x.omega_rad_s;
    w0.i_a_A = x.i_a_A - star_a;
    w0.i_b_A = x.i_b_A - star_b;

    stage_coupling(plant, 0, t_s, &x, s0, c0, &n0);
    ya.theta_rad = etd_stage_a(wt, w0.theta_rad, n0.theta_rad);
    ya.omega_rad_s = etd_stage_a(ww, w0.omega_rad_s, n0.omega_rad_s);
    ya.i_a_A = etd_stage_a(wa, w0.i_a_A, n0.i_a_A) + star_a;
    ya.i_b_A = etd_stage_a(wb, w0.i_b_A, n0.i_b_A) + star_b;
    rotate(s0, c0, p * (ya.theta_rad - x.theta_rad), &s, &c);
    stage_coupling(plant, 1, t_s + 0.5 * h, &ya, s, c, &na);
    yb.theta_rad = etd_stage_a(wt, w0.theta_rad, na.theta_rad);
    yb.omega_rad_s = etd_stage_a(ww, w0.omega_rad_s, na.omega_rad_s);
    yb.i_a_A = etd_stage_a(wa, w0.i_a_A, na.i_a_A) + star_a;
    yb.i_b_A = etd_stage_a(wb, w0.i_b_A, na.i_b_A) + star_b;
    rotate(s0, c0, p * (yb.theta_rad - x.theta_rad), &s, &c);
    stage_coupling(plant, 1, t_s + 0.5 * h, &yb, s, c, &nb);
    yc.theta_rad = etd_stage_c(wt, ya.theta_rad, n0.theta_rad, nb.theta_rad);
    yc.omega_rad_s = etd_stage_c(ww, ya.omega_rad_s, n0.omega_rad_s, nb.omega_rad_s);
    yc.i_a_A = etd_stage_c(wa, ya.i_a_A - star_a, n0.i_a_A, nb.i_a_A) + star_a;
    yc.i_b_A = etd_stage_c(wb, ya.i_b_A - star_b, n0.i_b_A, nb.i_b_A) + star_b;
    rotate(s0, c0, p * (yc.theta_rad - x.theta_rad), &s, &c);
    stage_coupling(plant, 2, t_s + h, &yc, s, c, &nc);

    plant->x.theta_rad = etd_end(wt, w0.theta_rad, n0.theta_rad, na.theta_rad, nb.theta_rad, nc.theta_rad);
    plant->x.omega_rad_s = etd_end(ww, w0.omega_rad_s, n0.omega_rad_s, na.omega_rad_s, nb.omega_rad_s, nc.omega_rad_s);
    plant->x.i_a_A = oa ? x.i_a_A : etd_end(wa, w0.i_a_A, n0.i_a_A, na.i_a_A, nb.i_a_A, nc.i_a_A) + star_a;
    plant->x.i_b_A = ob ? x.i_b_A : etd_end(wb, w0.i_b_A, n0.i_b_A, na.i_b_A, nb.i_b_A, nc.i_b_A) + star_b;
    if (charge_a_c != NULL && charge_b_c != NULL) {
        /* Simpson's rule, the midpoint as the mean of the two midpoint stages. */
        *charge_a_c = h / 6.0 * (x.i_a_A + 2.0 * (ya.i_a_A + yb.i_a_A) + plant->x.i_a_A);
        *charge_b_c = h / 6.0 * (x.i_b_A + 2.0 * (yb.i_b_A + ya.i_b_A) + plant->x.i_b_A);
    }
}

static void method_substep(plant_t *plant, double t_s, double h, double u_a_V, double u_b_V, double *charge_a_c,
                           double *charge_b_c)
{
    if (plant->integrator == PLANT_INTEGRATOR_EXPONENTIAL) {
        exponential_substep(plant, t_s, h, u_a_V, u_b_V, charge_a_c, charge_b_c);
    } else {
        rk4_substep(plant, t_s, h, u_a_V, u_b_V, charge_a_c, charge_b_c);
    }
}

void plant_substep(plant_t *plant, double t_s, double h, double u_a_V, double u_b_V, double *charge_a_c,
                   double *charge_b_c)
{
    const double t_step_s = plant->load.step_time_s;
    if (plant->load.kind == PLANT_LOAD_STEP && t_s < t_step_s && t_step_s <= t_s + h) {
        /* A load step inside the step (or at its end): integrate up to it without the load
         * and on from it with the load, so no stage samples the jump (which would make the
         * error first order in h). */
        const plant_load_t load = plant->load;
        const double h1 = t_step_s - t_s;
        const double h2 = h - h1;
        double qa1 = 0.0, qb1 = 0.0, qa2 = 0.0, qb2 = 0.0;
        const bool charges = charge_a_c != NULL && charge_b_c != NULL;
        plant->load.kind = PLANT_LOAD_NONE;
        method_substep(plant, t_s, h1, u_a_V, u_b_V, charges ? &qa1 : NULL, charges ? &qb1 : NULL);
        plant->load.kind = PLANT_LOAD_CONSTANT;
        if (h2 > 0.0) {
            method_substep(plant, t_step_s, h2, u_a_V, u_b_V, charges ? &qa2 : NULL, charges ? &qb2 : NULL);
        }
        plant->load = load;
        if (charges) {
            *charge_a_c = qa1 + qa2;
            *charge_b_c = qb1 + qb2;
        }
        return;
    }
    method_substep(plant, t_s, h, u_a_V, u_b_V, charge_a_c, charge_b_c);
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
