/**
 * @file pmstep_text.h
 * @brief Texts for the core's codes, in their own library (pmstep_text) so the
 *        control core carries no strings; link it where a person reads them
 *        (consoles, logs, the SIL, tests).
 */
#ifndef PMSTEP_TEXT_H
#define PMSTEP_TEXT_H

#include "pmstep/pmstep_types.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Human-readable text for a status code. */
const char *pmstep_status_str(pmstep_status_t status);

/** Name of a fault code, e.g. "SPEED_INCONSISTENT" (the enum's suffix; pmstep_types.h describes each). */
const char *pmstep_fault_str(pmstep_fault_t fault);

/** Human-readable name of a mode. */
const char *pmstep_mode_str(pmstep_mode_t mode);

/** Name of an identification outcome, e.g. "POOR_EXCITATION" (the enum's suffix; pmstep_types.h). */
const char *pmstep_identification_str(pmstep_identification_t identification);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_TEXT_H */
