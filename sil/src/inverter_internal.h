/* The inverter's period bookkeeping and plant stepping (inverter_period.c), shared by the averaged
 * model and bridge-off freewheeling (inverter.c) and the switching model (inverter_switching.c).
 * Calls go one way: inverter.c -> inverter_switching.c -> inverter_period.c. Not part of the SIL's API. */
#ifndef SIL_INVERTER_INTERNAL_H
#define SIL_INVERTER_INTERNAL_H

#include <stdbool.h>

#include "sil/inverter.h"

/* Sums over one period. */
typedef struct {
    plant_t *plant;
    sil_inverter_t *inv;
    double t0_s;
    double bus_V; /* bus voltage at the period start (held over the period without ripple) */
    bool started;
    bool constant_u; /* every substep had the first substep's voltages */
    double first_u_V[2];
    double volt_s[2];    /* integral of the phase voltages */
    double charge_c[2];  /* integral of the phase currents */
    double bus_charge_c; /* integral of i_bus */
    double min_a[2], max_a[2];
} sil_inv_period_t;

int sil_inv_sign_of(double x);
double *sil_inv_phase_current(plant_t *plant, int k);
bool *sil_inv_phase_open(plant_t *plant, int k);

/* Bus voltage held over the substep [t, t + h]: at its midpoint when there is ripple. */
double sil_inv_substep_bus_V(sil_inv_period_t *p, double t_s, double h_s);

/* One step of the plant's integrator with u held. bus_fraction[k] = u_k / V_bus (for i_bus). A non-zero
 * diode_sign[k] marks a phase conducting through the freewheel diodes: if its current
 * reaches or crosses zero within the substep it is set to exactly 0 and the phase opens. */
void sil_inv_substep(sil_inv_period_t *p, double t_s, double h_s, const double u_V[2], const double bus_fraction[2],
                     const int diode_sign[2]);

/* Switching bridge over one period (inverter_switching.c): in one exponential step when
 * @p one_step, else segment by segment in steps of at most T / substeps. */
void sil_inv_switching_period(sil_inv_period_t *p, double period_s, int substeps, bool one_step);

#endif
