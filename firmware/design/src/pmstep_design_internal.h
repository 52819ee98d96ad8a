/* Private to the gain designer's sources: the helpers, bounds and checks its files share. */
#ifndef PMSTEP_DESIGN_INTERNAL_H
#define PMSTEP_DESIGN_INTERNAL_H

#include "pmstep/pmstep_design.h"

#include <stdbool.h>

/* A winding faster than the control rate's bandwidths (pmstep_design.c): the current loop at this
 * many times R/L, the observer's current pole 3 w_o at this many times R/L + F/J; and the fastest winding designed for, (R/L + F/J) T_s, which
 * keeps (R/L + K_i) T_s and (R/L + K_e) T_s under the 0.5 init accepts. */
#define WINDING_RATE_MARGIN 1.25f
#define MAX_WINDING_RATE_X_PERIOD 0.35f
/* Alignment current: this fraction of k_M/(p L), where condition (4) runs out, within the rated
 * current ... */
#define CONDITION_4_FRACTION 0.5f
/* ... raised where the detent torque asks for more. c-alignment turns the rotor a full step against
 * the detent's -T_d sin(4 p theta); the alignment's k_M I sin(p theta') beats it over the whole step
 * only if k_M I >= T_d / DETENT_BARRIER_RATIO, the least sin(x) / -sin(4 x) over the quarter of the
 * step where the detent opposes (x in (pi/4, pi/2), least at x = 1.150). The current is raised to
 * DETENT_BARRIER_MARGIN times that, within MAX_CONDITION_4_FRACTION of (4)'s limit and the rated
 * current (docs/design/04-alignment.md). */
#define DETENT_BARRIER_RATIO 0.918559f
#define DETENT_BARRIER_MARGIN 2.0f
#define MAX_CONDITION_4_FRACTION 0.8f
/* Protections. */
#define USABLE_BUS_FRACTION 0.9f
/* Where the drive's current sensing cannot read twice the rated current, the trip goes down to
 * what it reads (PMSTEP_SENSE_RANGE_USABLE_FRACTION of its range), but not below this many times the
 * rated current: a drive that trips at its motor's rating cannot drive it. */
#define MIN_TRIP_CURRENT_PER_RATED 1.25f
/* Likewise the overvoltage trip, down to the bus measurement's usable range, but not below this
 * many times the nominal bus (supply tolerance and regeneration). */
#define MIN_MAX_BUS_FRACTION 1.1f

static inline float max2(float a, float b)
{
    return a > b ? a : b;
}

static inline float min2(float a, float b)
{
    return a < b ? a : b;
}

/* Every input finite. */
bool pmstep_design_finite_input(const pmstep_design_input_t *in);

/* A rotor's inertia from its holding torque (PMSTEP_DESIGN_INERTIA_PER_TORQUE T_H^1.5). */
float pmstep_design_inertia_estimate(float holding_torque_Nm);

/* The alignment current (docs/design/04-alignment.md#alignment-current). */
float pmstep_design_alignment_current(const pmstep_design_input_t *in);

/* The input the designer cannot design for, with its named error (pmstep_design()'s refusals). */
pmstep_status_t pmstep_design_check_input(const pmstep_design_input_t *in);

#endif /* PMSTEP_DESIGN_INTERNAL_H */
