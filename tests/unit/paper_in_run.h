/* A paper-configured instance put in RUN as at t_c, without the alignments (the estimate at the
 * c-alignment's equilibrium): the state the vector hold's tests start from. */
#ifndef PAPER_IN_RUN_H
#define PAPER_IN_RUN_H

#include "pmstep/pmstep.h"
#include "pmstep/pmstep_angle.h"

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

#endif /* PAPER_IN_RUN_H */
