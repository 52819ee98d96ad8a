/* pmstep-tune: the validation profile (the speed profile every mode writes or runs) and
 * --validate, the design run in the SIL. */
#include <math.h>
#include <stdio.h>

#include "pmstep/pmstep_text.h"
#include "pmstep_tune.h"

/* Validation profile (docs/design/09-validation.md): hold, +0.8 top, -0.8 top, +0.05 top, -0.05 top, 0. */
#define PROFILE_HOLD_S 0.3
#define RAMP_ACCEL_FRACTION 0.2 /* of the rated acceleration k_M I / J */
#define MIN_RAMP_S 0.05
#define TRACKING_BOUND_OF_TOP 0.02
#define ANGLE_BOUND_RAD 0.05
#define LOAD_STEP_OF_HOLDING 0.5
#define SYNC_ANGLE_BOUND_RAD 0.5

static double ramp_time_s(const sil_scenario_t *sc, double speed_change_rad_s)
{
    const double accel =
        RAMP_ACCEL_FRACTION * sc->motor.torque_constant_Nm_A * sc->datasheet.rated_current_A / sc->motor.inertia_kgm2;
    const double t = fabs(speed_change_rad_s) / accel;
    return t > MIN_RAMP_S ? t : MIN_RAMP_S;
}

static void add_point(sil_scenario_t *sc, double t_s, double speed_rad_s)
{
    sc->speed_time_s[sc->speed_points] = t_s;
    sc->speed_value_rad_s[sc->speed_points] = speed_rad_s;
    sc->speed_points++;
}

/* A speed profile through @p levels (each held PROFILE_HOLD_S), starting 0.1 s after t_c. */
void set_profile(sil_scenario_t *sc, const double *levels, int n_levels)
{
    double t = (double)sc->controller.alignment.c_align_time_s
               + (double)sc->controller.commissioning.offset_calibration_time_s;
    double speed = 0.0;
    int k;
    sc->speed_points = 0;
    add_point(sc, 0.0, 0.0);
    t += 0.1;
    add_point(sc, t, 0.0);
    for (k = 0; k < n_levels; ++k) {
        t += ramp_time_s(sc, levels[k] - speed);
        add_point(sc, t, levels[k]);
        t += PROFILE_HOLD_S;
        add_point(sc, t, levels[k]);
        speed = levels[k];
    }
    sc->duration_s = t;
}
/* After the load step: the largest |omega - omega*| and the last time it was above the bound. */
typedef struct {
    double from_s;
    double bound_rad_s;
    double max_error_rad_s;
    double last_above_s;
} load_watch_t;

static bool watch_load(const sil_sample_t *x, void *user)
{
    load_watch_t *w = (load_watch_t *)user;
    if (x->t_s >= w->from_s && x->out->mode == PMSTEP_MODE_RUN) {
        const double error = fabs(x->omega_rad_s - (double)x->out->speed_ref_rad_s);
        if (error > w->max_error_rad_s) {
            w->max_error_rad_s = error;
        }
        if (error > w->bound_rad_s) {
            w->last_above_s = x->t_s;
        }
    }
    return true;
}

bool run_ok(const char *what, const sil_summary_t *s, int rc)
{
    if (rc != 0 || s->fault != PMSTEP_FAULT_NONE || s->final_mode != PMSTEP_MODE_RUN || s->nonfinite_seen) {
        printf("  %-34s FAIL: %s at %.3f s\n", what, rc != 0 ? "init refused" : pmstep_fault_str(s->fault),
               s->fault_time_s);
        return false;
    }
    return true;
}

/* @p max_inertia_error_pct >= 0: with identification in RUN, the first run must identify J
 * within that many percent of the plant's. */
/* A run's outcome into @p c (NULL: nothing). */
static void record(tune_check_t *c, const char *check, const sil_summary_t *s, int rc, double speed_error_rad_s,
                   double bound_rad_s, bool pass)
{
    if (c == NULL) {
        return;
    }
    c->check = check;
    c->ran = rc == 0;
    c->fault = (int)s->fault;
    c->fault_time_s = s->fault_time_s;
    c->angle_error_rad = s->max_angle_error_rad;
    c->speed_error_rad_s = speed_error_rad_s;
    c->speed_bound_rad_s = bound_rad_s;
    c->synchronous = rc == 0 && s->fault == PMSTEP_FAULT_NONE && s->final_mode == PMSTEP_MODE_RUN && !s->nonfinite_seen
                     && s->max_angle_error_rad < SYNC_ANGLE_BOUND_RAD;
    c->pass = pass;
}

int validate(const sil_scenario_t *designed, double top_speed_rad_s, double max_inertia_error_pct, tune_check_t *checks)
{
    static sil_scenario_t sc;
    sil_summary_t s;
    const double levels[] = {0.8 * top_speed_rad_s, -0.8 * top_speed_rad_s, 0.05 * top_speed_rad_s,
                             -0.05 * top_speed_rad_s, 0.0};
    const double tracking_bound = TRACKING_BOUND_OF_TOP * top_speed_rad_s;
    const double load_fractions[] = {0.5, 0.05};
    int failures = 0;
    int k;
    int rc;

    sc = *designed;
    set_profile(&sc, levels, 5);
    sc.load.kind = PLANT_LOAD_NONE;
    rc = sil_run(&sc, NULL, NULL, false, &s);
    if (run_ok("ramps to +-80 % and +-5 % of top", &s, rc)) {
        const bool pass =
            s.max_speed_error_after_settle_rad_s < tracking_bound && s.max_angle_error_rad < ANGLE_BOUND_RAD;
        record(checks, "ramps", &s, rc, s.max_speed_error_after_settle_rad_s, tracking_bound, pass);
        printf("  %-34s %s: |w - w*| %.3f rad/s (bound %.3f), angle error %.4f rad (bound %.2f)\n",
               "ramps to +-80 % and +-5 % of top", pass ? "pass" : "FAIL", s.max_speed_error_after_settle_rad_s,
               tracking_bound, s.max_angle_error_rad, ANGLE_BOUND_RAD);
        if (s.commissioning.identification != PMSTEP_IDENT_OFF) {
            const double j_error_pct = 100.0 * ((double)s.commissioning.inertia_kgm2 / sc.motor.inertia_kgm2 - 1.0);
            const bool used = s.commissioning.identification == PMSTEP_IDENT_DONE
                              || s.commissioning.identification == PMSTEP_IDENT_FRICTION_NEGATIVE;
            const bool ident_pass = max_inertia_error_pct < 0.0 || (used && fabs(j_error_pct) <= max_inertia_error_pct);
            printf("  %-34s %s: %s, J %.4g kg m^2 (%+.2f %% off the plant's), F %.4g N m s/rad\n", "identified in RUN",
                   ident_pass ? "pass" : "FAIL", pmstep_identification_str(s.commissioning.identification),
                   (double)s.commissioning.inertia_kgm2, j_error_pct, (double)s.commissioning.friction_Nms_rad);
            failures += ident_pass ? 0 : 1;
        }
        failures += pass ? 0 : 1;
    } else {
        record(checks, "ramps", &s, rc, s.max_speed_error_after_settle_rad_s, tracking_bound, false);
        ++failures;
    }
    for (k = 0; k < 2; ++k) {
        const double level = load_fractions[k] * top_speed_rad_s;
        const double step_Nm = LOAD_STEP_OF_HOLDING * sc.datasheet.holding_torque_Nm;
        load_watch_t watch;
        char what[64];
        set_profile(&sc, &level, 1);
        sc.load.kind = PLANT_LOAD_STEP;
        sc.load.torque_Nm = step_Nm;
        sc.load.step_time_s = sc.duration_s - 0.5 * PROFILE_HOLD_S;
        sc.duration_s += 0.5 * PROFILE_HOLD_S;
        watch.from_s = sc.load.step_time_s;
        watch.bound_rad_s = tracking_bound;
        watch.max_error_rad_s = 0.0;
        watch.last_above_s = watch.from_s;
        snprintf(what, sizeof what, "%.2f Nm step at %.0f %% of top", step_Nm, 100.0 * load_fractions[k]);
        rc = sil_run(&sc, watch_load, &watch, false, &s);
        if (run_ok(what, &s, rc)) {
            const bool pass = s.max_angle_error_rad < SYNC_ANGLE_BOUND_RAD;
            record(checks == NULL ? NULL : &checks[1 + k], k == 0 ? "step_50" : "step_5", &s, rc, watch.max_error_rad_s,
                   tracking_bound, pass);
            printf("  %-34s %s: dip %.2f rad/s, back within %.3f rad/s after %.1f ms, angle error %.4f rad\n", what,
                   pass ? "pass" : "FAIL", watch.max_error_rad_s, tracking_bound,
                   1e3 * (watch.last_above_s - watch.from_s), s.max_angle_error_rad);
            failures += pass ? 0 : 1;
        } else {
            record(checks == NULL ? NULL : &checks[1 + k], k == 0 ? "step_50" : "step_5", &s, rc, watch.max_error_rad_s,
                   tracking_bound, false);
            ++failures;
        }
    }
    printf("pmstep-tune: validation %s (%d miss%s)\n", failures == 0 ? "passed" : "FAILED", failures,
           failures == 1 ? "" : "es");
    return failures == 0 ? 0 : 1;
}
