/*
 * The console's position requests (pmstep_console.h, 0x0D..0x10) on pmstep_position: in a file
 * of its own so that an image without position control (pmstep_console_attach_position never
 * called) links none of it, nor the position library.
 */
#include "pmstep_console.h"

#include <stddef.h>

/* HOME: the designer's homing settings with the request's speed, travel and stall current. */
static pmstep_status_t home(pmstep_console_t *c, const float *args)
{
    pmstep_homing_config_t h;
    const float direction = args[0];
    pmstep_status_t st = pmstep_homing_design(c->position->inst->cfg, &h);
    if (st == PMSTEP_OK) {
        if (args[1] != 0.0f) {
            h.speed_rad_s = args[1];
        }
        h.max_travel_rad = args[2];
        if (args[3] != 0.0f) {
            h.stall_current_A = args[3];
        }
        st = pmstep_homing_start(&c->homing, c->position, &h, direction > 0.0f ? 1 : (direction < 0.0f ? -1 : 0));
    }
    return st;
}

/* HOME_STATUS: the homing's state and stop, and theta-hat now. */
static pmstep_status_t home_status(const pmstep_console_t *c, pmstep_console_position_reading_t *reading)
{
    pmstep_status_t st = pmstep_get_position(c->position, &reading->position_rad);
    if (st != PMSTEP_OK) {
        reading->position_rad = 0.0f;
    }
    reading->homing_state = (uint8_t)c->homing.state;
    reading->homing_by_current = c->homing.stalled_by_current ? 1u : 0u;
    reading->homing_stop_rad = c->homing.stop_rad;
    return PMSTEP_OK;
}

static int32_t position_apply(pmstep_console_t *c, uint8_t cmd, const float *args,
                              pmstep_console_position_reading_t *reading)
{
    pmstep_position_t *pos = c->position;
    pmstep_status_t st;
    switch (cmd) {
    case PMSTEP_CONSOLE_HOME: st = home(c, args); break;
    case PMSTEP_CONSOLE_HOME_STATUS: st = home_status(c, reading); break;
    case PMSTEP_CONSOLE_MOVE_TO: st = pmstep_position_move_to(pos, args[0], args[1], args[2], args[3]); break;
    case PMSTEP_CONSOLE_HOLD: st = pmstep_position_hold(pos, args[0]); break;
    case PMSTEP_CONSOLE_SET_POSITION_ZERO: st = pmstep_position_set_zero(pos); break;
    case PMSTEP_CONSOLE_SET_CONFIG: { /* the core took a new configuration: the loop's gains from it */
        pmstep_position_config_t gains;
        st = pmstep_position_design(pos->inst->cfg, &gains);
        if (st == PMSTEP_OK) {
            st = pmstep_position_init(pos, pos->inst, &gains);
        }
        break;
    }
    default: /* GET_POSITION: the present period's estimate and theta* */
        reading->position_rad = 0.0f;
        reading->position_ref_rad = 0.0f;
        reading->position_error_rad = 0.0f;
        reading->flags = (uint8_t)((pos->out.tracked ? PMSTEP_CONSOLE_POSITION_TRACKED : 0u)
                                   | (pos->out.position_mode ? PMSTEP_CONSOLE_POSITION_MODE : 0u)
                                   | (pos->out.moving ? PMSTEP_CONSOLE_POSITION_MOVING : 0u));
        st = pmstep_get_position(pos, &reading->position_rad);
        if (st == PMSTEP_OK) {
            st = pmstep_position_reference(pos, &reading->position_ref_rad);
        }
        if (st == PMSTEP_OK) {
            reading->position_error_rad = reading->position_ref_rad - reading->position_rad;
        } else {
            reading->position_rad = 0.0f;
            reading->position_ref_rad = 0.0f;
        }
        break;
    }
    return (int32_t)st;
}

void pmstep_console_attach_position(pmstep_console_t *c, pmstep_position_t *pos)
{
    c->position = pos;
    c->position_apply = pos != NULL ? position_apply : NULL;
    c->homing.state = PMSTEP_HOMING_IDLE;
}

void pmstep_console_home_period(pmstep_console_t *c, const pmstep_output_t *out,
                                const pmstep_position_output_t *pos_out)
{
    if (c->position != NULL) {
        (void)pmstep_homing_update(&c->homing, c->position, out, pos_out);
    }
}
