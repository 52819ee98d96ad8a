/* Homing without a switch (pmstep_homing.h): seek a hard stop, make it the zero, back off. */
#include "pmstep/pmstep_homing.h"

#include <math.h> /* fabsf: one instruction, no libm call */
#include <stddef.h>

#define TWO_PI 6.2831853f
#define HALF_PI 1.5707963f
/* The designer's share of the stall torque k_M I_s the loop's push on contact, J k_w v, may take:
 * the rest is left for T_L-hat's rise before the current test fires. */
#define CONTACT_PUSH_SHARE 0.25f
/* The designer's speed at most this share of the lowest bus's back-EMF speed V_min / k_M. */
#define BUS_SPEED_SHARE 0.1f
/* The designer's acceleration: J a at this share of the stall torque. */
#define ACCEL_TORQUE_SHARE 0.25f
/* Cruising: the reference above this share of the homing speed with at most this share of the
 * homing acceleration left in it. */
#define CRUISE_SPEED_SHARE 0.5f
#define CRUISE_ACCEL_SHARE 0.01f

pmstep_status_t pmstep_homing_design(const pmstep_config_t *cfg, pmstep_homing_config_t *homing)
{
    float k_m;
    float j;
    float bus_speed;
    if (cfg == NULL || homing == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    k_m = cfg->motor.torque_constant_Nm_A;
    j = cfg->motor.inertia_kgm2;
    /* half the rated current, and half the trip where that is lower: always below the trip */
    homing->stall_current_A = 0.5f * cfg->motor.rated_current_A;
    if (cfg->limits.max_phase_current_A < cfg->motor.rated_current_A) {
        homing->stall_current_A = 0.5f * cfg->limits.max_phase_current_A;
    }
    /* the loop's push on contact J k_w v within a quarter of the stall torque */
    homing->speed_rad_s = CONTACT_PUSH_SHARE * k_m * homing->stall_current_A / (j * cfg->gains.speed_gain_per_s);
    bus_speed = BUS_SPEED_SHARE * cfg->limits.min_bus_voltage_V / k_m;
    if (homing->speed_rad_s > bus_speed) {
        homing->speed_rad_s = bus_speed;
    }
    homing->accel_rad_s2 = ACCEL_TORQUE_SHARE * k_m * homing->stall_current_A / j;
    homing->max_travel_rad = TWO_PI;
    homing->stall_error_rad = 0.5f * HALF_PI / (float)cfg->motor.pole_pairs; /* half a full step */
    homing->back_off_rad = HALF_PI / (float)cfg->motor.pole_pairs;           /* one full step */
    return PMSTEP_OK;
}

static bool finite(float x)
{
    return (x - x) == 0.0f; /* NaN and Inf give NaN */
}

pmstep_status_t pmstep_homing_start(pmstep_homing_t *homing, pmstep_position_t *pos, const pmstep_homing_config_t *cfg,
                                    int32_t direction)
{
    float position_rad;
    float target_rad;
    pmstep_status_t status;
    if (homing == NULL || pos == NULL || cfg == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    if (!finite(cfg->speed_rad_s) || !finite(cfg->accel_rad_s2) || !finite(cfg->max_travel_rad)
        || !finite(cfg->stall_current_A) || !finite(cfg->stall_error_rad) || !finite(cfg->back_off_rad)) {
        return PMSTEP_ERR_NONFINITE_PARAMETER;
    }
    if (!(cfg->speed_rad_s > 0.0f) || !(cfg->accel_rad_s2 > 0.0f) || !(cfg->max_travel_rad > 0.0f)
        || !(cfg->stall_error_rad > 0.0f) || !(cfg->back_off_rad >= 0.0f) || !(cfg->stall_current_A > 0.0f)
        || !(cfg->stall_current_A < pos->inst->cfg->limits.max_phase_current_A)
        || (direction != 1 && direction != -1)) {
        return PMSTEP_ERR_HOMING;
    }
    status = pmstep_get_position(pos, &position_rad);
    if (status != PMSTEP_OK) {
        return status;
    }
    target_rad = position_rad + (float)direction * cfg->max_travel_rad;
    status = pmstep_position_move_to(pos, target_rad, cfg->speed_rad_s, cfg->accel_rad_s2, 0.0f);
    if (status != PMSTEP_OK) {
        return status; /* the travel beyond the estimate's range */
    }
    homing->cfg = *cfg;
    homing->target_rad = pos->motion.target;
    homing->state = PMSTEP_HOMING_SEEKING;
    homing->direction = (float)direction;
    homing->stop_rad = 0.0f;
    homing->stalled_by_current = false;
    return PMSTEP_OK;
}

/* The stop found: the loop at rest where the rotor is, the zero there, then the back-off. */
static void stop_found(pmstep_homing_t *homing, pmstep_position_t *pos, bool by_current)
{
    (void)pmstep_get_position(pos, &homing->stop_rad);
    homing->stalled_by_current = by_current;
    (void)pmstep_position_rest_here(pos);
    (void)pmstep_position_set_zero(pos);
    if (homing->cfg.back_off_rad > 0.0f) {
        (void)pmstep_position_move_to(pos, -homing->direction * homing->cfg.back_off_rad, homing->cfg.speed_rad_s,
                                      homing->cfg.accel_rad_s2, 0.0f);
        homing->target_rad = pos->motion.target;
        homing->state = PMSTEP_HOMING_BACKING_OFF;
    } else {
        homing->state = PMSTEP_HOMING_DONE;
    }
}

pmstep_homing_state_t pmstep_homing_update(pmstep_homing_t *homing, pmstep_position_t *pos, const pmstep_output_t *out,
                                           const pmstep_position_output_t *pos_out)
{
    const bool active = homing->state == PMSTEP_HOMING_SEEKING || homing->state == PMSTEP_HOMING_BACKING_OFF;
    if (!active) {
        return homing->state;
    }
    if (!pos_out->tracked || !pos_out->position_mode || pos->steps != NULL
        || pos->motion.target != homing->target_rad) {
        /* left RUN, or another command took the loop: a speed command, STEP/DIR, a move, a stop or a zero */
        homing->state = PMSTEP_HOMING_ABORTED;
        return homing->state;
    }
    if (homing->state == PMSTEP_HOMING_SEEKING) {
        /* cruising: the profile's reference at its speed with no acceleration left in it */
        const bool cruising = homing->direction * pos->now.speed > CRUISE_SPEED_SHARE * homing->cfg.speed_rad_s
                              && fabsf(pos->now.accel) <= CRUISE_ACCEL_SHARE * homing->cfg.accel_rad_s2;
        if (pmstep_homing_stalled(homing->direction, pos_out->position_error_rad, homing->cfg.stall_error_rad,
                                  out->i_q_ref_A, homing->cfg.stall_current_A, cruising)) {
            stop_found(homing, pos, homing->direction * pos_out->position_error_rad <= homing->cfg.stall_error_rad);
        } else if (!pos_out->moving) {
            homing->state = PMSTEP_HOMING_NOT_FOUND; /* the move to max_travel_rad ended: the loop holds there */
        } else {
            /* seeking on */
        }
    } else if (!pos_out->moving) {
        homing->state = PMSTEP_HOMING_DONE;
    } else {
        /* backing off */
    }
    return homing->state;
}
