/* Frama-C EVA harness: pmstep_init over every finite configuration (every float field any
 * finite value, every integer any value, every bool either). */
#include "eva_configs.h"

int main(void)
{
    static pmstep_t inst;
    static pmstep_config_t cfg;
    pmstep_status_t status;
    if (Frama_C_nondet(0, 1)) {
        /* a missing instance or configuration is refused */
        return pmstep_init(NULL, &cfg) == PMSTEP_ERR_NULL_ARGUMENT
                       && pmstep_init(&inst, NULL) == PMSTEP_ERR_NULL_ARGUMENT
                   ? 2
                   : 3;
    }
    eva_any_config(&cfg);
    status = pmstep_init(&inst, &cfg);
    /*@ assert init_status: PMSTEP_ERR_DERIVED_NONFINITE <= status <= PMSTEP_OK; */
    return status == PMSTEP_OK ? 0 : 1;
}
