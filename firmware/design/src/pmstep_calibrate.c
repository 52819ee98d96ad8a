/*
 * Self-commissioning on the drive (see pmstep_calibrate.h and docs/design/19-self-commissioning.md):
 * measuring runs, identification runs, the final design. Runs at period boundaries; every
 * decision is taken on what the core reports (its mode, fault and commissioning results).
 */
#include "pmstep/pmstep_calibrate.h"

#include <stddef.h>
#include <string.h>

#define SQRT2 1.41421356f
#define TIME_CONSTANT_GUESS_S 2e-3f /* L/R assumed before L is measured (steppers: 0.5-5 ms) */
#define FLUX_RATIO_GUESS 1.0f       /* p L I / k_M assumed before k_M is measured (steppers: 0.5-3) */
#define RUN_START_HOLD_S 0.1f       /* RUN at zero speed before identification's first ramp */
#define ADC_LEVELS 2048.0f          /* current resolution of a 12-bit bipolar measurement: range / 2048 */

static bool finite_positive(float x)
{
    return (x - x) == 0.0f && x > 0.0f;
}

static uint32_t periods_of(float seconds, float period_s)
{
    return (uint32_t)(seconds / period_s + 0.5f);
}

bool pmstep_calibrate_active(const pmstep_calibrate_t *cal)
{
    return cal != NULL && (cal->stage == PMSTEP_CALIBRATE_MEASURING || cal->stage == PMSTEP_CALIBRATE_IDENTIFYING);
}

pmstep_status_t pmstep_calibrate_start(pmstep_calibrate_t *cal, const pmstep_calibrate_request_t *req,
                                       const pmstep_config_t *board, float bus_voltage_V)
{
    if (cal == NULL || req == NULL || board == NULL) {
        return PMSTEP_ERR_NULL_ARGUMENT;
    }
    memset(cal, 0, sizeof *cal);
    cal->request = *req;
    cal->board = *board;
    cal->bus_voltage_V = bus_voltage_V;
    if (!finite_positive(req->rated_current_A) || req->pole_pairs < 1 || !finite_positive(bus_voltage_V)
        || !(req->detent_per_holding >= 0.0f && req->detent_per_holding <= PMSTEP_CALIBRATE_MAX_DETENT_PER_HOLDING)) {
        cal->stage = PMSTEP_CALIBRATE_FAILED;
        cal->status = PMSTEP_CALIBRATE_ERR_REQUEST;
        return PMSTEP_ERR_BAD_COMMAND_VALUE;
    }
    cal->stage = PMSTEP_CALIBRATE_MEASURING;
    cal->design_resistance_Ohm = PMSTEP_CALIBRATE_MIN_RESISTANCE_OHM;
    cal->speed_of_top = PMSTEP_CALIBRATE_SPEED_OF_TOP;
    return PMSTEP_OK;
}

static void fail(pmstep_calibrate_t *cal, pmstep_t *inst, int32_t status)
{
    (void)pmstep_stop(inst); /* the bridge off (a fault has it off already) */
    cal->running = false;
    cal->stage = PMSTEP_CALIBRATE_FAILED;
    cal->status = status;
}

void pmstep_calibrate_cancel(pmstep_calibrate_t *cal, pmstep_t *inst)
{
    if (pmstep_calibrate_active(cal)) {
        fail(cal, inst, PMSTEP_CALIBRATE_ERR_CANCELLED);
    }
}

/* The designer's input for the motor as far as it is known: @p r, @p l, @p k_m (0: guessed), @p j, @p f
 * (0: J estimated from the holding torque). */
static void design_input(const pmstep_calibrate_t *cal, float r, float l, float k_m, float j, float f, bool robust,
                         pmstep_design_input_t *in)
{
    const float current_A = cal->request.rated_current_A;
    const float p = (float)cal->request.pole_pairs;
    const float l_H = l > 0.0f ? l : TIME_CONSTANT_GUESS_S * r;
    const float k_Nm_A = k_m > 0.0f ? k_m : p * l_H * current_A / FLUX_RATIO_GUESS;
    const float holding_Nm = SQRT2 * k_Nm_A * current_A;
    memset(in, 0, sizeof *in);
    in->motor.resistance_Ohm = r;
    in->motor.inductance_H = l_H;
    in->motor.torque_constant_Nm_A = k_Nm_A;
    in->motor.inertia_kgm2 = j;
    in->motor.friction_Nms_rad = f;
    in->motor.pole_pairs = cal->request.pole_pairs;
    in->motor.detent_torque_Nm = cal->request.detent_per_holding * holding_Nm;
    in->motor.rated_current_A = current_A;
    in->holding_torque_Nm = holding_Nm;
    in->bus_voltage_V = cal->bus_voltage_V;
    in->current_sense_range_A = cal->board.limits.current_sense_range_A;
    in->bus_sense_range_V = cal->board.limits.bus_sense_range_V;
    in->period_s = cal->board.timing.period_s;
    in->computational_delay_periods = cal->board.timing.computational_delay_periods;
    in->self_commissioning = robust;
    in->dead_time_s = robust ? cal->board.inverter.dead_time_s : 0.0f;
    in->phase_voltage_sensing = cal->board.inverter.phase_voltage_sensing;
    in->current_resolution_A = cal->board.limits.current_sense_range_A / ADC_LEVELS;
    in->accept_implausible = true; /* guesses, or a measurement: checked where they are used */
}

/* A measuring run's configuration: the robust design for the R the run is designed for, ending at t_c. */
static pmstep_status_t measuring_config(pmstep_calibrate_t *cal, pmstep_config_t *cfg)
{
    pmstep_design_input_t in;
    pmstep_status_t st;
    design_input(cal, cal->design_resistance_Ohm, cal->inductance_H, cal->torque_constant_Nm_A, 0.0f, 0.0f, true, &in);
    st = pmstep_design(&in, cfg, &cal->report);
    if (st != PMSTEP_OK) {
        return st;
    }
    cfg->commissioning.measure_only = true;
    cfg->commissioning.identification_time_s = 0.0f;
    cfg->commissioning.use_identified_mechanics = false;
    cal->run_limit = periods_of(cfg->commissioning.offset_calibration_time_s + cfg->alignment.c_align_time_s
                                    + PMSTEP_CALIBRATE_RUN_MARGIN_S,
                                cfg->timing.period_s);
    return pmstep_validate_config(cfg);
}

/* Identification's plan, in seconds from the run's start: RUN begins at t_run; +v at t_run + hold0;
 * -v once that is reached and held; 0 once -v is held (the window's end); the stop after that ramp. */
typedef struct {
    float run_s, up_s, down_s, zero_s, stop_s;
    float speed_rad_s, accel_rad_s2;
} plan_t;

static plan_t identification_plan(const pmstep_calibrate_t *cal, const pmstep_config_t *cfg)
{
    plan_t p;
    const float j = cal->report.inertia_kgm2;
    p.speed_rad_s = cal->speed_of_top * cal->report.top_speed_rad_s;
    p.accel_rad_s2 =
        PMSTEP_CALIBRATE_ACCEL_OF_RATED * cfg->motor.torque_constant_Nm_A * cal->request.rated_current_A / j;
    p.run_s = cfg->commissioning.offset_calibration_time_s + cfg->alignment.c_align_time_s;
    p.up_s = p.run_s + RUN_START_HOLD_S;
    p.down_s = p.up_s + p.speed_rad_s / p.accel_rad_s2 + PMSTEP_CALIBRATE_HOLD_S;
    p.zero_s = p.down_s + 2.0f * p.speed_rad_s / p.accel_rad_s2 + PMSTEP_CALIBRATE_HOLD_S;
    p.stop_s = p.zero_s + p.speed_rad_s / p.accel_rad_s2 + RUN_START_HOLD_S;
    return p;
}

/* An identification run's configuration: the design for the measured R, L, k_M and the J, F known so
 * far, the identification window over the plan's ramps (not used in RUN: the next design uses it). */
static pmstep_status_t identification_config(pmstep_calibrate_t *cal, pmstep_config_t *cfg)
{
    pmstep_design_input_t in;
    pmstep_status_t st;
    plan_t plan;
    design_input(cal, cal->resistance_Ohm, cal->inductance_H, cal->torque_constant_Nm_A, cal->design_inertia_kgm2,
                 cal->design_friction_Nms_rad, cal->request.robust, &in);
    st = pmstep_design(&in, cfg, &cal->report);
    if (st != PMSTEP_OK) {
        return st;
    }
    plan = identification_plan(cal, cfg);
    cfg->commissioning.identification_time_s = plan.zero_s - plan.run_s;
    cfg->commissioning.use_identified_mechanics = false;
    cfg->commissioning.measure_only = false;
    cal->run_limit = periods_of(plan.stop_s + PMSTEP_CALIBRATE_RUN_MARGIN_S, cfg->timing.period_s);
    return pmstep_validate_config(cfg);
}

static void start_run(pmstep_calibrate_t *cal, pmstep_t *inst, pmstep_config_t *cfg, uint32_t period)
{
    const pmstep_status_t st =
        cal->stage == PMSTEP_CALIBRATE_MEASURING ? measuring_config(cal, cfg) : identification_config(cal, cfg);
    pmstep_status_t init;
    if (st != PMSTEP_OK) {
        fail(cal, inst, (int32_t)st);
        return;
    }
    init = pmstep_init(inst, cfg);
    if (init == PMSTEP_OK) {
        init = pmstep_start(inst);
    }
    if (init != PMSTEP_OK) {
        fail(cal, inst, (int32_t)init);
        return;
    }
    cal->running = true;
    cal->identified = false;
    cal->run_start = period;
    cal->profile_step = 0u;
    cal->rounds++;
    cal->runs++;
    cal->fault = PMSTEP_FAULT_NONE;
}

/* The end of a measuring run: the core IDLE (measured at t_c) or in FAULT. */
static void end_measuring_run(pmstep_calibrate_t *cal, pmstep_t *inst)
{
    pmstep_commissioning_t cm;
    const pmstep_fault_t fault = pmstep_get_fault(inst);
    const float designed = cal->design_resistance_Ohm;
    pmstep_get_commissioning(inst, &cm);
    cal->running = false;
    cal->fault = fault;
    if (fault == PMSTEP_FAULT_OPEN_PHASE_A || fault == PMSTEP_FAULT_OPEN_PHASE_B) {
        /* Less than a quarter of the designed current: the winding is more than 4 x the R designed for,
         * up to the largest the drive calibrates and the bus drives at the rated current (the
         * designer's limit, R I at most PMSTEP_CALIBRATE_USABLE_BUS of the bus). */
        const float bus_limit_Ohm = PMSTEP_CALIBRATE_USABLE_BUS * cal->bus_voltage_V / cal->request.rated_current_A;
        const float largest_Ohm =
            bus_limit_Ohm < PMSTEP_CALIBRATE_MAX_RESISTANCE_OHM ? bus_limit_Ohm : PMSTEP_CALIBRATE_MAX_RESISTANCE_OHM;
        const float next_Ohm = designed * PMSTEP_CALIBRATE_PROBE_STEP;
        if (designed >= largest_Ohm) {
            fail(cal, inst, PMSTEP_CALIBRATE_ERR_NO_MOTOR);
            return;
        }
        cal->design_resistance_Ohm = next_Ohm < largest_Ohm ? next_Ohm : largest_Ohm;
        return;
    }
    if (fault != PMSTEP_FAULT_NONE && fault != PMSTEP_FAULT_COMMISSIONING && fault != PMSTEP_FAULT_ALIGNMENT_MOTION) {
        fail(cal, inst, PMSTEP_CALIBRATE_ERR_FAULT);
        return;
    }
    if (!finite_positive(cm.resistance_Ohm)) { /* the rotor never settled: the same run again */
        if (cal->rounds >= PMSTEP_CALIBRATE_MEASURE_ROUNDS) {
            fail(cal, inst, PMSTEP_CALIBRATE_ERR_FAULT);
        }
        return;
    }
    /* What this run measured designs the next (a measured R at most 4 x the one designed for: the
     * current of a larger one would have tripped the open-phase check). */
    cal->resistance_Ohm = cm.resistance_Ohm;
    cal->inductance_H = finite_positive(cm.inductance_H) ? cm.inductance_H : cal->inductance_H;
    cal->torque_constant_Nm_A =
        finite_positive(cm.torque_constant_Nm_A) ? cm.torque_constant_Nm_A : cal->torque_constant_Nm_A;
    if (fault == PMSTEP_FAULT_NONE && cm.resistance_Ohm >= (1.0f - PMSTEP_CALIBRATE_R_AGREEMENT) * designed
        && cm.resistance_Ohm <= (1.0f + PMSTEP_CALIBRATE_R_AGREEMENT) * designed) {
        cal->stage = PMSTEP_CALIBRATE_IDENTIFYING; /* R, L, k_M of a run designed for them */
        cal->rounds = 0u;
        return;
    }
    cal->design_resistance_Ohm = cm.resistance_Ohm < PMSTEP_CALIBRATE_PROBE_STEP * designed
                                     ? cm.resistance_Ohm
                                     : PMSTEP_CALIBRATE_PROBE_STEP * designed;
    if (cal->rounds >= PMSTEP_CALIBRATE_MEASURE_ROUNDS) {
        fail(cal, inst, PMSTEP_CALIBRATE_ERR_NOT_CONVERGED);
    }
}

/* The final design: the measured R, L, k_M and the identified J, F, in force. */
static void finish(pmstep_calibrate_t *cal, pmstep_t *inst, pmstep_config_t *cfg)
{
    pmstep_design_input_t in;
    pmstep_status_t st;
    design_input(cal, cal->resistance_Ohm, cal->inductance_H, cal->torque_constant_Nm_A, cal->inertia_kgm2,
                 cal->friction_Nms_rad, cal->request.robust, &in);
    in.accept_implausible = false; /* what was measured must look like a stepper */
    st = pmstep_design(&in, cfg, &cal->report);
    if (st == PMSTEP_OK) {
        st = pmstep_init(inst, cfg);
    }
    if (st != PMSTEP_OK) {
        fail(cal, inst, (int32_t)st);
        return;
    }
    cal->stage = PMSTEP_CALIBRATE_DONE;
    cal->status = PMSTEP_CALIBRATE_OK;
}

/* The end of an identification run (stopped at the plan's end): J and F, or another round. */
/* The window's outcome, once the core has closed it. */
static void take_identification(pmstep_calibrate_t *cal, const pmstep_t *inst)
{
    pmstep_commissioning_t cm;
    pmstep_get_commissioning(inst, &cm);
    if (cal->identified || cm.identification == PMSTEP_IDENT_RUNNING || cm.identification == PMSTEP_IDENT_OFF) {
        return;
    }
    cal->identified = true;
    cal->identification = cm.identification;
    cal->inertia_kgm2 = cm.inertia_kgm2;
    cal->friction_Nms_rad = cm.friction_Nms_rad > 0.0f ? cm.friction_Nms_rad : 0.0f;
}

/* The end of an identification run (stopped at the plan's end, or a fault after its window closed):
 * J and F, or another round. */
static void end_identification_run(pmstep_calibrate_t *cal, pmstep_t *inst, pmstep_config_t *cfg)
{
    const float designed = cal->report.inertia_kgm2;
    pmstep_identification_t outcome;
    take_identification(cal, inst);
    outcome = cal->identification;
    cal->running = false;
    (void)pmstep_stop(inst);
    if (!cal->identified
        || (outcome != PMSTEP_IDENT_DONE && outcome != PMSTEP_IDENT_FRICTION_NEGATIVE
            && !(outcome == PMSTEP_IDENT_IMPLAUSIBLE && finite_positive(cal->inertia_kgm2)
                 && (cal->friction_Nms_rad - cal->friction_Nms_rad) == 0.0f))) {
        fail(cal, inst, PMSTEP_CALIBRATE_ERR_IDENTIFICATION);
        return;
    }
    if (cal->inertia_kgm2 >= 0.5f * designed && cal->inertia_kgm2 <= 2.0f * designed) {
        finish(cal, inst, cfg);
        return;
    }
    /* Far from the J designed for: the next run is designed for the one identified. */
    cal->identified = false;
    cal->design_inertia_kgm2 = cal->inertia_kgm2;
    cal->design_friction_Nms_rad = cal->friction_Nms_rad;
    if (cal->rounds >= PMSTEP_CALIBRATE_IDENTIFY_ROUNDS) {
        fail(cal, inst, PMSTEP_CALIBRATE_ERR_IDENTIFICATION);
    }
}

/* Identification's speed commands, each at its period; the run's end after the last. */
static void identification_profile(pmstep_calibrate_t *cal, pmstep_t *inst, pmstep_config_t *cfg, uint32_t elapsed)
{
    const plan_t plan = identification_plan(cal, cfg);
    const float period_s = cfg->timing.period_s;
    const float at_s[4] = {plan.up_s, plan.down_s, plan.zero_s, plan.stop_s};
    const float speed[3] = {plan.speed_rad_s, -plan.speed_rad_s, 0.0f};
    take_identification(cal, inst);
    while (cal->profile_step < 4u && elapsed >= periods_of(at_s[cal->profile_step], period_s)) {
        if (cal->profile_step < 3u) {
            (void)pmstep_set_speed_target(inst, speed[cal->profile_step], plan.accel_rad_s2);
        } else {
            end_identification_run(cal, inst, cfg);
            return;
        }
        cal->profile_step++;
    }
}

pmstep_calibrate_stage_t pmstep_calibrate_boundary(pmstep_calibrate_t *cal, pmstep_t *inst, pmstep_config_t *cfg,
                                                   uint32_t period)
{
    pmstep_mode_t mode;
    uint32_t elapsed;
    if (cal == NULL || inst == NULL || cfg == NULL) {
        return PMSTEP_CALIBRATE_FAILED;
    }
    if (!pmstep_calibrate_active(cal)) {
        return cal->stage;
    }
    if (!cal->running) {
        start_run(cal, inst, cfg, period);
        return cal->stage;
    }
    mode = pmstep_get_mode(inst);
    elapsed = period - cal->run_start;
    if (elapsed == 0u) {
        return cal->stage; /* the start has not stepped yet */
    }
    if (cal->stage == PMSTEP_CALIBRATE_MEASURING && (mode == PMSTEP_MODE_IDLE || mode == PMSTEP_MODE_FAULT)) {
        end_measuring_run(cal, inst);
    } else if (cal->stage == PMSTEP_CALIBRATE_IDENTIFYING && mode == PMSTEP_MODE_FAULT && cal->identified) {
        cal->fault = pmstep_get_fault(inst); /* on the way back to rest: the window's outcome stands */
        end_identification_run(cal, inst, cfg);
    } else if (cal->stage == PMSTEP_CALIBRATE_IDENTIFYING && mode == PMSTEP_MODE_FAULT) {
        /* The design for a J still guessed may not hold the full levels: the next run at half of them. */
        cal->fault = pmstep_get_fault(inst);
        cal->running = false;
        cal->speed_of_top *= 0.5f;
        cal->design_inertia_kgm2 = 2.0f * cal->report.inertia_kgm2;
        if (cal->rounds >= PMSTEP_CALIBRATE_IDENTIFY_ROUNDS) {
            fail(cal, inst, PMSTEP_CALIBRATE_ERR_FAULT);
        }
    } else if (cal->stage == PMSTEP_CALIBRATE_IDENTIFYING) {
        identification_profile(cal, inst, cfg, elapsed);
    }
    if (cal->running && elapsed > cal->run_limit) {
        fail(cal, inst, PMSTEP_CALIBRATE_ERR_TIMEOUT);
    }
    return cal->stage;
}
