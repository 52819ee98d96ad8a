/* libFuzzer harness of the control core: a fuzzed configuration, then a fuzzed sequence of
 * commands and measurements (raw, special values, or from a small motor model driven by the
 * core's own voltages, so that the alignments and RUN are reached), with the core's
 * invariants checked after every call:
 *   - init accepts exactly what pmstep_validate_config accepts, and an accepted configuration
 *     has every derived coefficient finite (recomputed through the blocks' public functions);
 *   - every float of every output is finite;
 *   - bridge on => mode S_ALIGN, C_ALIGN or RUN, bus finite, |u_a|, |u_b| <= the measured bus;
 *   - bridge off => u_a = u_b = 0 and not voltage_limited;
 *   - mode FAULT <=> fault != NONE; a FAULT stays (same code, same step) until clear_fault or
 *     reset; start and stop are refused in FAULT;
 *   - telemetry is zero outside RUN; re-alignments never exceed max_realignments.
 * A broken invariant aborts with a message (a crash for libFuzzer and for the replay driver).
 *
 * Input layout (every read past the end gives zeros, so any input is valid):
 *   byte 0: bit 7 set: the configuration is the next sizeof(pmstep_config_t) bytes, raw;
 *           else bits 0-1 choose a base configuration (config_fields.h) and bits 2-6 give the
 *           number of perturbations, each 6 bytes: word index, kind, 4 payload bytes;
 *   then operations (fuzz_core.c, LLVMFuzzerTestOneInput: op % 13), one opcode byte each with its payload, until the input or the step budget
 *   (FUZZ_MAX_STEPS) runs out. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "config_fields.h"
#include "pmstep/pmstep.h"

#define FUZZ_MAX_STEPS 40000u

typedef struct {
    const uint8_t *data;
    size_t size;
    size_t pos;
} reader_t;

static uint8_t read_u8(reader_t *r) { return r->pos < r->size ? r->data[r->pos++] : 0u; }

static uint16_t read_u16(reader_t *r)
{
    const uint16_t lo = read_u8(r);
    return (uint16_t)(lo | (uint16_t)(read_u8(r) << 8));
}

static float read_f32(reader_t *r)
{
    uint8_t bytes[4];
    float value;
    size_t n;
    for (n = 0; n < 4u; ++n) {
        bytes[n] = read_u8(r);
    }
    memcpy(&value, bytes, sizeof value);
    return value;
}

static void fail(const char *what, unsigned step)
{
    fprintf(stderr, "fuzz_core: invariant broken after step %u: %s\n", step, what);
    abort();
}

#define CHECK(cond, what)          \
    do {                           \
        if (!(cond)) {             \
            fail(what, st->steps); \
        }                          \
    } while (0)

/* Values that sit on the edges of what the core compares against. */
static float special_value(uint8_t kind, float base, float bound)
{
    switch (kind % 12u) {
    case 0: return NAN;
    case 1: return INFINITY;
    case 2: return -INFINITY;
    case 3: return 0.0f;
    case 4: return -0.0f;
    case 5: return 1e-40f;
    case 6: return 3.4e38f;
    case 7: return -3.4e38f;
    case 8: return nextafterf(bound, INFINITY);
    case 9: return bound;
    case 10: return -nextafterf(bound, INFINITY);
    default: return base * 2.0f;
    }
}

/* Perturbation of one 4-byte word of the configuration. */
static void perturb(pmstep_config_t *cfg, reader_t *r)
{
    const size_t words = sizeof *cfg / 4u;
    const size_t offset = (read_u8(r) % words) * 4u;
    const uint8_t kind = read_u8(r);
    const float payload = read_f32(r);
    float old;
    float value;
    memcpy(&old, (unsigned char *)cfg + offset, sizeof old);
    switch (kind % 8u) {
    case 0: value = payload; break; /* raw bits */
    case 1: value = old * 0.5f; break;
    case 2: value = old * 2.0f; break;
    case 3: value = nextafterf(old, INFINITY); break;
    case 4: value = nextafterf(old, -INFINITY); break;
    case 5: value = special_value((uint8_t)(kind >> 3), old, old); break;
    case 6: value = old * (1.0f + ldexpf((float)(kind >> 3), -6)); break; /* small scale up */
    default: {
        /* an integer word (pole pairs, delay, realignments) */
        uint32_t word = (uint32_t)(kind >> 3);
        memcpy(&value, &word, sizeof value);
        break;
    }
    }
    memcpy((unsigned char *)cfg + offset, &value, sizeof value);
}

typedef struct {
    pmstep_t inst;
    pmstep_config_t cfg;
    pmstep_output_t out;
    unsigned steps;
    bool in_fault; /* the last output was FAULT and nothing has cleared it */
    pmstep_fault_t fault;
    uint32_t fault_step;
    /* The motor model (paper's motor, scaled) the core drives. */
    double theta, omega, i_a, i_b;
    double u_a, u_b; /* voltage applied over the coming period */
    double r_Ohm, l_H, j, km;
    uint32_t rng;
} state_t;

static double uniform(state_t *st)
{
    st->rng ^= st->rng << 13;
    st->rng ^= st->rng >> 17;
    st->rng ^= st->rng << 5;
    return (double)st->rng / 4294967296.0 - 0.5;
}

static void check_output(state_t *st, const pmstep_meas_t *meas)
{
    const pmstep_output_t *o = &st->out;
    const float floats[] = {o->u_a_V,       o->u_b_V,     o->cos_hat,   o->sin_hat,         o->speed_hat_rad_s,
                            o->load_hat_Nm, o->i_a_hat_A, o->i_b_hat_A, o->speed_ref_rad_s, o->speed_ref_rate_rad_s2,
                            o->i_d_A,       o->i_q_A,     o->i_d_ref_A, o->i_q_ref_A};
    size_t n;
    for (n = 0; n < sizeof floats / sizeof floats[0]; ++n) {
        CHECK(fuzz_finite(floats[n]), "an output is not finite");
    }
    CHECK((unsigned)o->mode <= (unsigned)PMSTEP_MODE_OFFSET_CAL, "mode out of range");
    CHECK((unsigned)o->fault <= (unsigned)PMSTEP_FAULT_ESTIMATE_RANGE, "fault out of range");
    CHECK((o->mode == PMSTEP_MODE_FAULT) == (o->fault != PMSTEP_FAULT_NONE), "mode FAULT and fault code disagree");
    if (o->bridge_enable) {
        CHECK(o->mode == PMSTEP_MODE_S_ALIGN || o->mode == PMSTEP_MODE_C_ALIGN || o->mode == PMSTEP_MODE_RUN,
              "bridge on in a mode that keeps it off");
        CHECK(fuzz_finite(meas->bus_voltage_V), "bridge on with a bus that is not finite");
        CHECK(fabsf(o->u_a_V) <= meas->bus_voltage_V && fabsf(o->u_b_V) <= meas->bus_voltage_V,
              "bridge on with |u| above the measured bus");
    } else {
        CHECK(o->u_a_V == 0.0f && o->u_b_V == 0.0f, "bridge off with a voltage other than 0");
        CHECK(!o->voltage_limited, "bridge off but voltage_limited");
    }
    if (o->mode != PMSTEP_MODE_RUN) {
        for (n = 2; n < sizeof floats / sizeof floats[0]; ++n) {
            CHECK(floats[n] == 0.0f, "telemetry not zero outside RUN");
        }
    }
    {
        pmstep_commissioning_t commissioning;
        pmstep_get_commissioning(&st->inst, &commissioning);
        CHECK(commissioning.realignments <= fuzz_max_realignments(&st->cfg), "more re-alignments than configured");
    }
    if (st->in_fault) {
        CHECK(o->mode == PMSTEP_MODE_FAULT && o->fault == st->fault && o->fault_step == st->fault_step,
              "a latched fault changed without clear_fault");
    }
    if (o->mode == PMSTEP_MODE_FAULT) {
        st->in_fault = true;
        st->fault = o->fault;
        st->fault_step = o->fault_step;
    }
}

static void step(state_t *st, const pmstep_meas_t *meas)
{
    st->steps++;
    pmstep_step(&st->inst, meas, &st->out);
    check_output(st, meas);
}

/* Advances the motor model by one control period under the last voltage (0 with the bridge off). */
static void plant_advance(state_t *st, double period_s, double load_Nm)
{
    const int substeps = 4;
    const double dt = period_s / substeps;
    const double p = 6.0;
    int k;
    for (k = 0; k < substeps; ++k) {
        const double s = sin(p * st->theta);
        const double c = cos(p * st->theta);
        const double torque = st->km * (-st->i_a * s + st->i_b * c) - load_Nm;
        /* semi-implicit in the currents: stable at any period */
        st->i_a = (st->i_a + dt / st->l_H * (st->u_a + st->km * st->omega * s)) / (1.0 + dt * st->r_Ohm / st->l_H);
        st->i_b = (st->i_b + dt / st->l_H * (st->u_b - st->km * st->omega * c)) / (1.0 + dt * st->r_Ohm / st->l_H);
        st->omega += dt * torque / st->j;
        st->theta += dt * st->omega;
    }
}

/* @p n periods of the model: measurements with offsets and noise, bus with ripple. */
static void run_plant(state_t *st, reader_t *r, unsigned n)
{
    const double bus = 25.0 + 0.2 * read_u8(r); /* 25 .. 76 V: both sides of the paper's limits */
    const double ripple = 0.02 * read_u8(r);
    const double noise = 0.0005 * read_u8(r);
    const double offset = 0.002 * ((double)read_u8(r) - 128.0);
    const double load = 0.02 * ((double)read_u8(r) - 128.0);
    const double period_s = (double)fuzz_period_s(&st->cfg);
    unsigned k;
    for (k = 0; k < n && st->steps < FUZZ_MAX_STEPS; ++k) {
        pmstep_meas_t meas;
        meas.i_a_A = (float)(st->i_a + offset + noise * uniform(st));
        meas.i_b_A = (float)(st->i_b - offset + noise * uniform(st));
        meas.bus_voltage_V = (float)(bus + ripple * uniform(st));
        meas.load_torque_Nm = (float)load;
        /* the sensed mean voltage of the period just ended: what the model applied */
        meas.phase_voltage_a_V = (float)(st->u_a + 10.0 * offset + 10.0 * noise * uniform(st));
        meas.phase_voltage_b_V = (float)(st->u_b - 10.0 * offset + 10.0 * noise * uniform(st));
        step(st, &meas);
        st->u_a = st->out.bridge_enable ? (double)st->out.u_a_V : 0.0;
        st->u_b = st->out.bridge_enable ? (double)st->out.u_b_V : 0.0;
        plant_advance(st, period_s, load);
        if (!(fabs(st->i_a) < 1e6 && fabs(st->i_b) < 1e6 && fabs(st->omega) < 1e6)) {
            st->theta = st->omega = st->i_a = st->i_b = 0.0; /* keep the model's numbers tame */
        }
    }
}

static void expect_command(state_t *st, pmstep_status_t status, bool allowed_in_fault)
{
    if (st->in_fault && !allowed_in_fault) {
        CHECK(status == PMSTEP_ERR_BAD_MODE, "a command other than clear_fault/reset accepted in FAULT");
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static state_t state;
    state_t *st = &state;
    reader_t r = {data, size, 0u};
    const uint8_t head = read_u8(&r);
    pmstep_status_t status;
    size_t n;

    memset(st, 0, sizeof *st);
    if ((head & 0x80u) != 0u) {
        for (n = 0; n < sizeof st->cfg; ++n) {
            ((unsigned char *)&st->cfg)[n] = read_u8(&r);
        }
    } else {
        unsigned count = (head >> 2) & 0x1fu;
        st->cfg = fuzz_base_config((head & 3u) % FUZZ_BASE_CONFIGS);
        while (count-- > 0u) {
            perturb(&st->cfg, &r);
        }
    }
    for (n = 0; n < FUZZ_BOOL_FIELDS; ++n) {
        unsigned char *b = (unsigned char *)&st->cfg + fuzz_bool_fields[n];
        *b = (unsigned char)(*b & 1u);
    }

    status = pmstep_init(&st->inst, &st->cfg);
    if (status != pmstep_validate_config(&st->cfg)) {
        fail("init and validate disagree", 0u);
    }
    if (status != PMSTEP_OK) {
        if (getenv("FUZZ_CORE_VERBOSE") != NULL) {
            fprintf(stderr, "fuzz_core: init refused: %d\n", (int)status);
        }
        return 0;
    }
    if (!fuzz_derived_coefficients_finite(&st->cfg)) {
        fail("init accepted a configuration with a derived coefficient that is not finite", 0u);
    }

    st->r_Ohm = 3.0;
    st->l_H = 0.006;
    st->j = 0.01;
    st->km = 2.0;
    st->theta = 0.5;
    st->rng = 0x9e3779b9u;

    while (r.pos < r.size && st->steps < FUZZ_MAX_STEPS) {
        const uint8_t op = read_u8(&r);
        switch (op % 13u) {
        case 0:
            status = pmstep_start(&st->inst);
            expect_command(st, status, false);
            break;
        case 1:
            status = pmstep_stop(&st->inst);
            expect_command(st, status, false);
            break;
        case 2:
            status = pmstep_clear_fault(&st->inst);
            CHECK((status == PMSTEP_OK) == st->in_fault, "clear_fault accepted outside FAULT or refused in FAULT");
            st->in_fault = false;
            break;
        case 3:
            pmstep_reset(&st->inst);
            st->in_fault = false;
            break;
        case 4: {
            const float target = read_f32(&r);
            const float rate = read_f32(&r);
            (void)pmstep_set_speed_target(&st->inst, target, rate);
            break;
        }
        case 5: {
            const float target = 0.25f * (float)((int)read_u8(&r) - 128);
            const float rate = 1.0f + 10.0f * (float)read_u8(&r);
            status = pmstep_set_speed_target(&st->inst, target, rate);
            CHECK(status == PMSTEP_OK, "a plain speed target refused");
            break;
        }
        case 6: (void)pmstep_set_id_target(&st->inst, read_f32(&r)); break;
        case 7:
        case 8:
            /* the bulk of the run: the model for up to 4096 periods */
            run_plant(st, &r, read_u16(&r) & 0x0fffu);
            break;
        case 9: {
            pmstep_meas_t meas;
            meas.i_a_A = read_f32(&r);
            meas.i_b_A = read_f32(&r);
            meas.bus_voltage_V = read_f32(&r);
            meas.load_torque_Nm = read_f32(&r);
            meas.phase_voltage_a_V = read_f32(&r);
            meas.phase_voltage_b_V = read_f32(&r);
            step(st, &meas);
            break;
        }
        case 10: {
            /* the model's sample with one field on an edge */
            const uint8_t which = read_u8(&r);
            const uint8_t kind = read_u8(&r);
            pmstep_meas_t meas;
            meas.i_a_A = (float)st->i_a;
            meas.i_b_A = (float)st->i_b;
            meas.bus_voltage_V = 48.0f;
            meas.load_torque_Nm = 0.0f;
            meas.phase_voltage_a_V = (float)st->u_a;
            meas.phase_voltage_b_V = (float)st->u_b;
            switch (which % 7u) {
            case 0: meas.i_a_A = special_value(kind, meas.i_a_A, fuzz_current_limit_a(&st->cfg)); break;
            case 1: meas.i_b_A = special_value(kind, meas.i_b_A, fuzz_current_limit_a(&st->cfg)); break;
            case 2: meas.bus_voltage_V = special_value(kind, meas.bus_voltage_V, fuzz_max_bus_v(&st->cfg)); break;
            case 3: meas.bus_voltage_V = special_value(kind, meas.bus_voltage_V, fuzz_min_bus_v(&st->cfg)); break;
            case 4: meas.phase_voltage_a_V = special_value(kind, meas.phase_voltage_a_V, 60.0f); break;
            case 5: meas.phase_voltage_b_V = special_value(kind, meas.phase_voltage_b_V, 60.0f); break;
            default: meas.load_torque_Nm = special_value(kind, 1.0f, 1.0f); break;
            }
            step(st, &meas);
            break;
        }
        case 12:
            /* a missing argument is refused, never dereferenced */
            CHECK(pmstep_init(NULL, &st->cfg) == PMSTEP_ERR_NULL_ARGUMENT
                      && pmstep_validate_config(NULL) == PMSTEP_ERR_NULL_ARGUMENT
                      && pmstep_start(NULL) == PMSTEP_ERR_NULL_ARGUMENT && pmstep_stop(NULL) == PMSTEP_ERR_NULL_ARGUMENT
                      && pmstep_clear_fault(NULL) == PMSTEP_ERR_NULL_ARGUMENT
                      && pmstep_set_speed_target(NULL, 1.0f, 1.0f) == PMSTEP_ERR_NULL_ARGUMENT
                      && pmstep_set_id_target(NULL, 0.0f) == PMSTEP_ERR_NULL_ARGUMENT,
                  "a missing argument not refused");
            break;
        default: {
            /* the model's state jumps: a stalled or pushed rotor, a current step */
            st->theta += 0.05 * ((double)read_u8(&r) - 128.0);
            st->omega = 0.5 * ((double)read_u8(&r) - 128.0);
            st->i_a += 0.05 * ((double)read_u8(&r) - 128.0);
            break;
        }
        }
    }
    if (getenv("FUZZ_CORE_VERBOSE") != NULL) {
        pmstep_commissioning_t commissioning;
        pmstep_get_commissioning(&st->inst, &commissioning);
        fprintf(stderr, "fuzz_core: %u steps, mode %d, fault %d, realignments %u\n", st->steps, (int)st->out.mode,
                (int)st->out.fault, (unsigned)commissioning.realignments);
    }
    return 0;
}
