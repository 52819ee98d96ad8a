/* Test support: currents of model (1) with the rotor held at constant speed
 * (a dynamometer), propagated exactly over one period of held voltage.
 * Double precision; used as "exact plant samples" by the unit tests. */
#ifndef EXACT_PLANT_H
#define EXACT_PLANT_H

#include <complex.h>
#include <math.h>

typedef struct {
    double r_Ohm, l_H, k_m, pole_pairs;
    double speed_rad_s; /* held constant */
    double theta_rad;   /* theta at the present sample */
    double i_a, i_b;    /* currents at the present sample */
} exact_plant_t;

/* Advances one period T with (u_a, u_b) held:
 * i(T) = e^{-aT} i + u/(R)(1 - e^{-aT}) + (k_M w / L) * integral of e^{-a(T-s)} (sin, -cos)(p theta(s)) ds. */
static inline void exact_plant_advance(exact_plant_t *x, double u_a, double u_b, double period_s)
{
    const double a = x->r_Ohm / x->l_H;
    const double decay = exp(-a * period_s);
    const double nu = x->pole_pairs * x->speed_rad_s;
    const double complex start = cexp(I * x->pole_pairs * x->theta_rad);
    const double complex integral = start * (cexp(I * nu * period_s) - decay) / (a + I * nu);
    const double emf = x->k_m * x->speed_rad_s / x->l_H;
    x->i_a = decay * x->i_a + u_a / x->r_Ohm * (1.0 - decay) + emf * cimag(integral);
    x->i_b = decay * x->i_b + u_b / x->r_Ohm * (1.0 - decay) - emf * creal(integral);
    x->theta_rad += x->speed_rad_s * period_s;
}

#endif
