/* The run's summary as JSON (summary.json of pmstep-sil): pmstep-sil's own, not the runner's API. */
#ifndef SIL_SUMMARY_JSON_H
#define SIL_SUMMARY_JSON_H

#include <cjson/cJSON.h>

#include "sil/runner.h"

/* The summary of a run of @p sc: its figures, each group in an object (the caller deletes it). */
cJSON *sil_summary_json(const sil_scenario_t *sc, const sil_summary_t *s);

#endif
