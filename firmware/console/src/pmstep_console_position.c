/*
 * The console's position requests (pmstep_console.h, 0x0D..0x10) on pmstep_position: in a file
 * of its own so that an image without position control (pmstep_console_attach_position never
 * called) links none of it, nor the position library.
 */
#include "pmstep_console.h"

#include <stddef.h>

static int32_t position_apply(pmstep_position_t *pos, uint8_t cmd, const float *args,
                              pmstep_console_position_reading_t *reading)
{
    pmstep_status_t st;
    switch (cmd) {
    case PMSTEP_CONSOLE_MOVE_TO:
        st = pmstep_position_move_to(pos, args[0], args[1], args[2], args[3]);
        break;
    case PMSTEP_CONSOLE_HOLD:
        st = pmstep_position_hold(pos, args[0]);
        break;
    case PMSTEP_CONSOLE_SET_POSITION_ZERO:
        st = pmstep_position_set_zero(pos);
        break;
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
}
