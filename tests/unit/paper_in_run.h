/* A paper-configured instance put in RUN as at t_c, without the alignments (the estimate at the
 * c-alignment's equilibrium): the state the vector hold's tests start from. */
#ifndef PAPER_IN_RUN_H
#define PAPER_IN_RUN_H

#include <math.h>

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_angle.h"

/* A configuration and the instance that points at it: the vector hold's tests' fixture. */
typedef struct {
    pmstep_config_t cfg;
    pmstep_t inst;
} paper_run_t;

static inline pmstep_status_t paper_instance_in_run(pmstep_config_t *cfg, pmstep_t *inst)
{
    pmstep_status_t status;
    *cfg = pmstep_paper_config();
    status = pmstep_init(inst, cfg);
    inst->mode = PMSTEP_MODE_RUN;
    inst->run_started = true;
    pmstep_angle_start(&inst->angle, 0.0f, 0.0f);
    return status;
}

/* The estimate's angle now (the one the next period's integrals start from), electrical rad. */
static inline float paper_estimate_angle(const pmstep_t *inst)
{
    float c;
    float s;
    pmstep_angle_estimate(&inst->angle, &inst->derived.angle_coeffs, inst->angle.i_a_prev_A, inst->angle.i_b_prev_A, &c,
                          &s);
    return atan2f(s, c);
}

/* Places the observer's poles at a triple pole w_o (rad/s), as the designer does (docs/design,
 * section 3): a_e = 3 w_o - F/J, g_w b^2 = 3 w_o^2 - a_e F/J, g_T b^2 / J = w_o^3, b = k_M/L.
 * Returns a_e. */
static inline double paper_observer_at_triple_pole(pmstep_observer_coeffs_t *obs, double w_o)
{
    const double f_j = obs->f_over_j_per_s;
    const double b = obs->km_over_l;
    const double a_e = 3.0 * w_o - f_j;
    obs->observer_gain_per_s = (float)(a_e - obs->r_over_l_per_s);
    obs->speed_injection_gain = (float)((3.0 * w_o * w_o - a_e * f_j) / (b * b));
    obs->load_injection_gain = (float)(w_o * w_o * w_o / (b * b * obs->inv_j));
    return a_e;
}

#endif /* PAPER_IN_RUN_H */
