/* pmstep-tune --motor-db FILE --name NAME: a motor from the [motor_constants NAME] sections Klipper
 * users keep (klipper_tmc_autotune's format: resistance, inductance, holding_torque, max_current,
 * steps_per_revolution; "key: value" or "key = value"). */
#include <ini.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pmstep/pmstep_design.h"
#include "pmstep_tune.h"

typedef struct {
    const char *name;
    bool found;
    double resistance_Ohm, inductance_H, holding_torque_Nm, max_current_A, steps_per_revolution;
    int given; /* bits: the five keys above, in that order */
    char message[160];
} motor_db_ctx_t;

static const char *const db_keys[] = {"resistance", "inductance", "holding_torque", "max_current",
                                      "steps_per_revolution"};

static int on_entry(void *user, const char *section, const char *key, const char *value)
{
    motor_db_ctx_t *ctx = (motor_db_ctx_t *)user;
    double *fields[] = {&ctx->resistance_Ohm, &ctx->inductance_H, &ctx->holding_torque_Nm, &ctx->max_current_A,
                        &ctx->steps_per_revolution};
    char *end = NULL;
    double v;
    size_t k;
    if (strncmp(section, "motor_constants ", 16) != 0 || strcmp(section + 16, ctx->name) != 0) {
        return 1;
    }
    ctx->found = true;
    for (k = 0; k < sizeof db_keys / sizeof db_keys[0]; ++k) {
        if (strcmp(key, db_keys[k]) == 0) {
            v = strtod(value, &end);
            if (end == value || *end != '\0' || !isfinite(v) || !(v > 0.0)) {
                snprintf(ctx->message, sizeof ctx->message, "[motor_constants %s] %s: '%s' is not a number > 0",
                         ctx->name, key, value);
                return 0;
            }
            *fields[k] = v;
            ctx->given |= 1 << k;
        }
    }
    return 1; /* other keys of the section (klipper_tmc_autotune's extras) are not ours */
}

int load_motor_db(sil_scenario_t *sc, const char *path, const char *name, char *err, size_t err_size)
{
    motor_db_ctx_t ctx;
    FILE *f = fopen(path, "r");
    size_t k;
    int line;
    if (f == NULL) {
        snprintf(err, err_size, "%s: cannot open", path);
        return -1;
    }
    memset(&ctx, 0, sizeof ctx);
    ctx.name = name;
    line = ini_parse_file(f, on_entry, &ctx);
    fclose(f);
    if (line != 0) {
        snprintf(err, err_size, "%s:%d: %s", path, line, ctx.message[0] != '\0' ? ctx.message : "malformed line");
        return -1;
    }
    if (!ctx.found) {
        snprintf(err, err_size, "%s: no [motor_constants %s] section", path, name);
        return -1;
    }
    for (k = 0; k < sizeof db_keys / sizeof db_keys[0]; ++k) {
        if ((ctx.given & (1 << k)) == 0) {
            snprintf(err, err_size, "%s: [motor_constants %s] has no %s", path, name, db_keys[k]);
            return -1;
        }
    }
    if (fmod(ctx.steps_per_revolution, 4.0) != 0.0) {
        snprintf(err, err_size,
                 "%s: [motor_constants %s] steps_per_revolution %g is not a two-phase motor's (a "
                 "multiple of 4)",
                 path, name, ctx.steps_per_revolution);
        return -1;
    }
    snprintf(sc->name, sizeof sc->name, "%s", name);
    sc->datasheet.rated_current_A = ctx.max_current_A;
    sc->datasheet.holding_torque_Nm = ctx.holding_torque_Nm;
    sc->datasheet.detent_torque_Nm = 0.0; /* not in the database */
    /* The plant: the datasheet's winding; k_M from the holding torque with both phases at rated
     * current; J and F, which the database does not give, estimated (the designer is told J = 0 and
     * estimates it itself; F as 1.5 % of T_H at 60 rad/s). */
    sc->motor.resistance_Ohm = ctx.resistance_Ohm;
    sc->motor.inductance_H = ctx.inductance_H;
    sc->motor.torque_constant_Nm_A = ctx.holding_torque_Nm / (sqrt(2.0) * ctx.max_current_A);
    sc->motor.pole_pairs = (int)(ctx.steps_per_revolution / 4.0);
    sc->motor.inertia_kgm2 = (double)PMSTEP_DESIGN_INERTIA_PER_TORQUE * pow(ctx.holding_torque_Nm, 1.5);
    sc->motor.friction_Nms_rad = MOTOR_DB_FRICTION_PER_TORQUE * ctx.holding_torque_Nm;
    sc->motor.detent_torque_Nm = 0.0;
    return 0;
}
