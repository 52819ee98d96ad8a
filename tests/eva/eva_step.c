/* Frama-C EVA harness: pmstep_step in every mode, reached the way an application reaches it:
 * init with the configuration EVA_CONFIG (eva_configs.h), then any number of periods, each
 * with any command (start, stop, clear_fault, reset, set-points, a vector hold and its release,
 * an angle estimate set, any float included) and a step
 * with any measurement: each field any finite value, or NaN, or +/-Inf. The output invariant is
 * asserted after every step. */
#include <math.h>

#include "eva_configs.h"

/* EVA_CONFIG: one configuration of eva_configs.h; unset, all four, each analysed apart (split). */
static pmstep_config_t any_config(void)
{
#ifdef EVA_CONFIG
    return EVA_CONFIG();
#else
    int which = Frama_C_interval(0, 3);
    /*@ split which; */
    switch (which) {
    case 0: return eva_paper_config();
    case 1: return eva_features_config();
    case 2: return eva_sensed_config();
    default: return eva_known_load_config();
    }
#endif
}

/* Any float32: NaN, +Inf, -Inf or any finite value. */
static float any_float(void)
{
    switch (Frama_C_interval(0, 3)) {
    case 0: return NAN;
    case 1: return INFINITY;
    case 2: return -INFINITY;
    default: return eva_any_finite();
    }
}

int main(void)
{
    static pmstep_t inst;
    static pmstep_config_t cfg;
    pmstep_meas_t meas;
    pmstep_output_t out;
    cfg = any_config();
    if (pmstep_init(&inst, &cfg) != PMSTEP_OK) {
        return 1;
    }
    while (Frama_C_nondet(0, 1)) {
        switch (Frama_C_interval(0, 9)) {
        case 9:
            /* every command refuses a missing instance */
            (void)pmstep_init(NULL, &cfg);
            (void)pmstep_start(NULL);
            (void)pmstep_stop(NULL);
            (void)pmstep_clear_fault(NULL);
            (void)pmstep_set_speed_target(NULL, 0.0f, 1.0f);
            (void)pmstep_set_id_target(NULL, 0.0f);
            (void)pmstep_hold_vector(NULL, 1.0f, 0.0f, 0.0f, 0.0f);
            (void)pmstep_set_angle_estimate(NULL, 1.0f, 0.0f);
            break;
        case 0: (void)pmstep_start(&inst); break;
        case 1: (void)pmstep_stop(&inst); break;
        case 2: (void)pmstep_clear_fault(&inst); break;
        case 3: pmstep_reset(&inst); break;
        case 4: (void)pmstep_set_speed_target(&inst, any_float(), any_float()); break;
        case 5: (void)pmstep_set_id_target(&inst, any_float()); break;
        case 7:
            (void)pmstep_hold_vector(&inst, any_float(), any_float(), any_float(), any_float());
            if (Frama_C_nondet(0, 1)) {
                pmstep_release_vector(&inst);
            }
            break;
        case 8: (void)pmstep_set_angle_estimate(&inst, any_float(), any_float()); break;
        default:
            meas.i_a_A = any_float();
            meas.i_b_A = any_float();
            meas.bus_voltage_V = any_float();
            meas.load_torque_Nm = any_float();
            meas.phase_voltage_a_V = any_float();
            meas.phase_voltage_b_V = any_float();
            pmstep_step(&inst, &meas, &out);
            /*@ assert bridge_off_zero: !out.bridge_enable ==> out.u_a_V == 0.0 && out.u_b_V == 0.0; */
            /*@ assert bridge_on_finite: out.bridge_enable ==> \is_finite(out.u_a_V) && \is_finite(out.u_b_V); */
            /*@ assert bridge_on_bus: out.bridge_enable ==>
                  \abs(out.u_a_V) <= meas.bus_voltage_V && \abs(out.u_b_V) <= meas.bus_voltage_V; */
            break;
        }
    }
    return 0;
}
