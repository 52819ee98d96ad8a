/* pmstep-tune --identify: commissioning and the identification window run in the SIL. */
#include <stdio.h>

#include "pmstep/pmstep_text.h"
#include "pmstep_tune.h"

/* Identification window over the profile +0.8 top, -0.8 top (each held), from t_c; the lowest
 * speed that enters the fit is the designer's (docs/design/10-inertia-and-friction.md). */
void set_identification(sil_scenario_t *sc, double top_speed_rad_s, bool use_in_run)
{
    const double levels[] = {0.8 * top_speed_rad_s, -0.8 * top_speed_rad_s};
    const double t_c = (double)sc->controller.alignment.c_align_time_s
                       + (double)sc->controller.commissioning.offset_calibration_time_s;
    set_profile(sc, levels, 2);
    sc->controller.commissioning.identification_time_s = (float)(sc->duration_s - t_c);
    sc->controller.commissioning.use_identified_mechanics = use_in_run;
}

/* --identify: commissioning and the identification window in the SIL with the first design.
 * @return 0 and the identified J, F in @p result; 1 when the run faulted or identified nothing. */
int identify(const sil_scenario_t *designed, double top_speed_rad_s, pmstep_commissioning_t *result)
{
    static sil_scenario_t sc;
    sil_summary_t s;
    int rc;
    sc = *designed;
    set_identification(&sc, top_speed_rad_s, false);
    sc.duration_s += 0.01; /* the window closes on a sample, up to PMSTEP_IDENTIFICATION_DECIMATION periods late */
    sc.load.kind = PLANT_LOAD_NONE;
    rc = sil_run(&sc, NULL, NULL, false, &s);
    if (!run_ok("identification run", &s, rc)) {
        return 1;
    }
    *result = s.commissioning;
    printf("pmstep-tune: identification over %.3f s from t_c (|w*| >= %.1f rad/s): %s\n",
           (double)sc.controller.commissioning.identification_time_s,
           (double)sc.controller.commissioning.identification_min_speed_rad_s,
           pmstep_identification_str(result->identification));
    return result->identification == PMSTEP_IDENT_DONE || result->identification == PMSTEP_IDENT_FRICTION_NEGATIVE ? 0
                                                                                                                   : 1;
}
