/* Private to the core's sources: functions shared between its modules, not part of the API. */
#ifndef PMSTEP_INTERNAL_H
#define PMSTEP_INTERNAL_H

#include "pmstep/pmstep.h"

/* True if every coefficient pmstep_init() derives from @p cfg (an already range-checked
 * configuration) is finite in float32. */
bool pmstep_derived_coefficients_finite(const pmstep_config_t *cfg);

#endif /* PMSTEP_INTERNAL_H */
