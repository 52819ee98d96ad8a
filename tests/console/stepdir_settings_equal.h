/* STEP/DIR settings compared field by field: the struct's padding bytes are not part of its value. */
#ifndef STEPDIR_SETTINGS_EQUAL_H
#define STEPDIR_SETTINGS_EQUAL_H

#include "pmstep_store.h"

static inline void assert_stepdir_settings_equal(const pmstep_stepdir_settings_t *a, const pmstep_stepdir_settings_t *b)
{
    assert_int_equal(a->microsteps, b->microsteps);
    assert_int_equal(a->invert_direction, b->invert_direction);
    assert_int_equal(a->enable_active_high, b->enable_active_high);
    assert_int_equal(a->diag_active_high, b->diag_active_high);
    assert_int_equal(a->diag_mode, b->diag_mode);
    assert_true(a->following_error_limit_full_steps == b->following_error_limit_full_steps);
    assert_true(a->stall_current_A == b->stall_current_A);
}

#endif /* STEPDIR_SETTINGS_EQUAL_H */
