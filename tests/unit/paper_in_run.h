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
    pmstep_angle_estimate(&inst->angle, &inst->angle_coeffs, inst->angle.i_a_prev_A, inst->angle.i_b_prev_A, &c, &s);
    return atan2f(s, c);
}

#endif /* PAPER_IN_RUN_H */
