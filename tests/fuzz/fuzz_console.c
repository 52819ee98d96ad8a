/* libFuzzer harness of the console with a real core (and position control attached): fuzzed
 * bytes and frames reach pmstep_console_receive() as a UART's main loop would deliver them (one
 * or several frames a call, cut anywhere), period boundaries and control steps run between them
 * on a small R-L winding model driven by the core's own voltages. Invariants after every call:
 *   - bridge on => the step's voltages finite and |u_a|, |u_b| <= the measured bus;
 *   - a latched fault stays (same code) until a CLEAR_FAULT reaches the core;
 *   - the limits are finite, ordered and within their bounds, and change only at a boundary that
 *     applied a SET_CONFIG accepted with the core in IDLE; the configuration always passes
 *     pmstep_validate_config();
 *   - a command waiting in the mailbox is unchanged by any later frame (busy refusals change
 *     nothing);
 *   - the STEP/DIR input on the emulated counter (simulation): every period its count moves by
 *     exactly the edges the counter took (by DIR's sense), and it last read the counter's value;
 *   - every frame the console transmits has its sync byte, a length in 2..64 and a good CRC.
 * A broken invariant aborts with a message (a crash for libFuzzer and for the replay driver).
 *
 * Input layout (every read past the end gives zeros, so any input is valid):
 *   byte 0: bit 0 attach position control, bit 1 the simulation requests, bit 2 (with both) the
 *           STEP/DIR input on the emulated counter (SIM_STEPS, SIM_FOLLOW_STEPS, SIM_STEPDIR);
 *   then operations, one opcode byte each (op % 6) with its payload, until the input or the step
 *   budget (FUZZ_MAX_STEPS) runs out:
 *     0 raw bytes: n (1 byte), then n bytes, in one receive call
 *     1 one frame: type, seq, n, n DATA bytes, framed with a good CRC
 *     2 two frames in one receive call (each as in 1)
 *     3 periods: n (2 bytes): boundary, step, telemetry, each period
 *     4 silence: milliseconds (1 byte) pass without a byte (a frame cut short times out)
 *     5 a frame of a typed request with a special float: type index, value kind, field byte */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pmstep_console.h"

#define FUZZ_MAX_STEPS 30000u
#define FUZZ_PERIOD_S 50e-6f

typedef struct {
    const uint8_t *data;
    size_t size;
    size_t pos;
} reader_t;

static uint8_t read_u8(reader_t *r) { return r->pos < r->size ? r->data[r->pos++] : 0u; }

typedef struct {
    pmstep_console_t con;
    pmstep_config_t cfg;
    pmstep_t motor;
    pmstep_position_t position;
    pmstep_position_output_t position_out;
    pmstep_stepdir_t stepdir;
    bool stepdir_attached;
    pmstep_console_snapshot_t snap;
    pmstep_config_t cfg_before;
    double i_a_A, i_b_A; /* the winding model's currents */
    uint32_t now_ms;
    unsigned steps;
    pmstep_fault_t latched;
    uint8_t tx_state, tx_len, tx_pos; /* the transmitted stream's frame parser */
    uint8_t tx_buf[PMSTEP_CONSOLE_MAX_PAYLOAD + 3u];
} state_t;

static void fail(const state_t *st, const char *what)
{
    fprintf(stderr, "fuzz_console: invariant broken after %u steps: %s\n", st->steps, what);
    abort();
}

#define CHECK(cond, what)   \
    do {                    \
        if (!(cond)) {      \
            fail(st, what); \
        }                   \
    } while (0)

static bool is_finite(float x) { return isfinite(x) != 0; }

/* The limits are finite, ordered and bounded, and the whole configuration valid. */
static void check_config(const state_t *st)
{
    const pmstep_limits_config_t *l = &st->cfg.limits;
    CHECK(pmstep_validate_config(&st->cfg) == PMSTEP_OK, "the configuration in force is invalid");
    CHECK(is_finite(l->max_phase_current_A) && is_finite(l->min_bus_voltage_V) && is_finite(l->max_bus_voltage_V),
          "a limit is not finite");
    CHECK(l->min_bus_voltage_V < l->max_bus_voltage_V, "bus limits out of order");
    CHECK(l->max_phase_current_A <= PMSTEP_MAX_TRIP_PER_RATED_CURRENT * st->cfg.motor.rated_current_A,
          "current trip above its multiple of the rated current");
    CHECK(l->max_phase_current_A <= PMSTEP_SENSE_RANGE_USABLE_FRACTION * l->current_sense_range_A,
          "current trip beyond the sensing range");
    CHECK(l->max_bus_voltage_V <= PMSTEP_SENSE_RANGE_USABLE_FRACTION * l->bus_sense_range_V,
          "overvoltage trip beyond the sensing range");
    CHECK(l->current_sense_range_A == 16.5f && l->bus_sense_range_V == 66.0f, "the port's ranges changed");
}

/* Every byte the console transmitted goes through a frame parser: sync, length, CRC. */
static void check_transmitted(state_t *st)
{
    uint8_t out[256];
    uint32_t n;
    while ((n = pmstep_console_transmit(&st->con, out, sizeof out)) > 0u) {
        uint32_t k;
        for (k = 0; k < n; ++k) {
            const uint8_t b = out[k];
            if (st->tx_state == 0u) {
                CHECK(b == PMSTEP_CONSOLE_SYNC, "a transmitted frame does not start with the sync byte");
                st->tx_state = 1u;
            } else if (st->tx_state == 1u) {
                CHECK(b >= 2u && b <= PMSTEP_CONSOLE_MAX_PAYLOAD, "a transmitted frame's length is out of range");
                st->tx_len = b;
                st->tx_buf[0] = b;
                st->tx_pos = 1u;
                st->tx_state = 2u;
            } else {
                st->tx_buf[st->tx_pos++] = b;
                if (st->tx_pos == (uint8_t)(st->tx_len + 3u)) {
                    const uint16_t crc = pmstep_console_crc16(0xFFFFu, st->tx_buf, (uint32_t)st->tx_len + 1u);
                    const uint16_t sent = (uint16_t)(st->tx_buf[st->tx_len + 1u] | (st->tx_buf[st->tx_len + 2u] << 8));
                    CHECK(crc == sent, "a transmitted frame's CRC is wrong");
                    st->tx_state = 0u;
                }
            }
        }
    }
}

/* Bytes to the console in one call; a command already waiting must come out unchanged. */
static void receive(state_t *st, const uint8_t *bytes, uint32_t n)
{
    const bool was_pending = pmstep_console_pending(&st->con);
    const pmstep_console_request_t mail = st->con.mail;
    pmstep_console_receive(&st->con, bytes, n, st->now_ms);
    if (was_pending) {
        CHECK(pmstep_console_pending(&st->con), "a waiting command left the mailbox without a boundary");
        CHECK(memcmp(&mail, &st->con.mail, sizeof mail) == 0, "a later frame changed the waiting command");
    }
    check_transmitted(st);
}

static uint32_t frame(uint8_t *buf, uint8_t type, uint8_t seq, const uint8_t *data, uint32_t n)
{
    uint16_t crc;
    buf[0] = PMSTEP_CONSOLE_SYNC;
    buf[1] = (uint8_t)(n + 2u);
    buf[2] = type;
    buf[3] = seq;
    memcpy(&buf[4], data, n);
    crc = pmstep_console_crc16(0xFFFFu, &buf[1], n + 3u);
    buf[4 + n] = (uint8_t)(crc & 0xFFu);
    buf[5 + n] = (uint8_t)(crc >> 8);
    return n + 6u;
}

/* A frame from the input: type, seq, DATA length (at most 62), DATA. */
static uint32_t read_frame(reader_t *r, uint8_t *buf)
{
    uint8_t data[PMSTEP_CONSOLE_MAX_PAYLOAD];
    const uint8_t type = read_u8(r);
    const uint8_t seq = read_u8(r);
    const uint32_t n = read_u8(r) % (PMSTEP_CONSOLE_MAX_PAYLOAD - 1u);
    uint32_t k;
    for (k = 0; k < n; ++k) {
        data[k] = read_u8(r);
    }
    return frame(buf, type, seq, data, n);
}

/* One period as the applications run it: boundary (the mailbox applied), step on the winding
 * model, the position update, telemetry. */
static void period(state_t *st)
{
    pmstep_meas_t meas;
    pmstep_output_t *out = &st->snap.out;
    const uint8_t cmd = pmstep_console_pending_command(&st->con);
    const bool idle_before = pmstep_get_mode(&st->motor) == PMSTEP_MODE_IDLE;
    st->cfg_before = st->cfg;
    pmstep_console_boundary(&st->con, &st->motor, &st->cfg, &st->snap);
    if (memcmp(&st->cfg_before, &st->cfg, sizeof st->cfg) != 0) {
        CHECK(cmd == PMSTEP_CONSOLE_SET_CONFIG && idle_before,
              "the configuration changed without a SET_CONFIG in IDLE");
        check_config(st);
    }
    if (cmd == PMSTEP_CONSOLE_CLEAR_FAULT) {
        st->latched = pmstep_get_mode(&st->motor) == PMSTEP_MODE_FAULT ? st->latched : PMSTEP_FAULT_NONE;
    }
    meas.i_a_A = (float)st->i_a_A;
    meas.i_b_A = (float)st->i_b_A;
    meas.bus_voltage_V = 48.0f;
    meas.load_torque_Nm = 0.0f;
    meas.phase_voltage_a_V = 0.0f;
    meas.phase_voltage_b_V = 0.0f;
    if (st->stepdir_attached) {
        /* the counter read once a period, as a port reads its timer: the count moves by its edges */
        const int32_t steps = st->stepdir.steps;
        const uint32_t edges = st->con.sim_step_edges;
        int32_t moved;
        pmstep_stepdir_count(&st->stepdir, pmstep_console_sim_steps_period(&st->con));
        moved = (int32_t)(st->con.sim_step_edges - edges);
        CHECK(moved >= -128 && moved <= 127, "more edges in a period than a SIM_STEPS carries");
        CHECK(st->stepdir.steps - steps == (st->stepdir.cfg.invert_direction ? -moved : moved),
              "the STEP/DIR input lost or invented an edge");
        CHECK(st->stepdir.last_counter == st->con.sim_step_counter, "the STEP/DIR input did not read the counter");
    }
    pmstep_position_step(&st->position, &meas, out, &st->position_out);
    if (st->stepdir_attached) {
        (void)pmstep_stepdir_diag(&st->stepdir, out->mode, st->position_out.position_rad, st->position_out.tracked);
    }
    st->snap.meas = meas;
    st->snap.period++;
    st->steps++;
    if (out->bridge_enable) {
        CHECK(is_finite(out->u_a_V) && is_finite(out->u_b_V), "bridge on with a voltage not finite");
        CHECK(fabsf(out->u_a_V) <= meas.bus_voltage_V && fabsf(out->u_b_V) <= meas.bus_voltage_V,
              "bridge on with a voltage beyond the bus");
    } else {
        CHECK(out->u_a_V == 0.0f && out->u_b_V == 0.0f, "bridge off with a voltage");
    }
    if (st->latched != PMSTEP_FAULT_NONE) {
        CHECK(out->mode == PMSTEP_MODE_FAULT && out->fault == st->latched, "a latched fault left without CLEAR_FAULT");
    } else if (out->mode == PMSTEP_MODE_FAULT) {
        st->latched = out->fault;
    }
    /* The winding (R, L of the configuration; no rotor): its current follows the voltage. */
    {
        const double r = (double)st->cfg.motor.resistance_Ohm;
        const double decay = exp(-r / (double)st->cfg.motor.inductance_H * (double)FUZZ_PERIOD_S);
        const double u_a = out->bridge_enable ? (double)out->u_a_V : 0.0;
        const double u_b = out->bridge_enable ? (double)out->u_b_V : 0.0;
        st->i_a_A = u_a / r + (st->i_a_A - u_a / r) * decay;
        st->i_b_A = u_b / r + (st->i_b_A - u_b / r) * decay;
    }
    pmstep_console_telemetry(&st->con, &st->snap);
    check_transmitted(st);
}

/* A request of the typed kinds with a special float in its first value. */
static uint32_t special_frame(reader_t *r, uint8_t *buf)
{
    static const uint8_t types[] = {PMSTEP_CONSOLE_SPEED_TARGET, PMSTEP_CONSOLE_ID_TARGET, PMSTEP_CONSOLE_SET_CONFIG,
                                    PMSTEP_CONSOLE_MOVE_TO,      PMSTEP_CONSOLE_HOLD,      PMSTEP_CONSOLE_TELEMETRY};
    static const float specials[] = {NAN,   INFINITY, -INFINITY, 0.0f,   -0.0f, 1e-40f, 3.4e38f, -3.4e38f,
                                     1e30f, 60.0f,    10.0f,     300.0f, 0.5f,  1.0f,   -1.0f,   16.0f};
    const uint8_t type = types[read_u8(r) % sizeof types];
    const float value = specials[read_u8(r) % (sizeof specials / sizeof specials[0])];
    const uint8_t field = read_u8(r);
    uint8_t data[16] = {0};
    uint32_t n;
    if (type == PMSTEP_CONSOLE_SET_CONFIG) {
        data[0] = field;
        memcpy(&data[1], &value, 4u);
        n = 5u;
    } else {
        memcpy(&data[0], &value, 4u);
        memcpy(&data[4], &value, 4u);
        memcpy(&data[8], &value, 4u);
        n = type == PMSTEP_CONSOLE_SPEED_TARGET ? 8u : type == PMSTEP_CONSOLE_MOVE_TO ? 12u : 4u;
    }
    return frame(buf, type, field, data, n);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static state_t state;
    state_t *st = &state;
    reader_t r = {data, size, 0u};
    const uint8_t setup = read_u8(&r);
    pmstep_position_config_t gains;
    memset(st, 0, sizeof *st);
    st->cfg = pmstep_console_app_config(FUZZ_PERIOD_S, 1u, 16.5f, 66.0f);
    st->cfg.alignment.s_align_time_s = 0.02f; /* RUN within the step budget */
    st->cfg.alignment.c_align_time_s = 0.04f;
    if (pmstep_init(&st->motor, &st->cfg) != PMSTEP_OK || pmstep_position_design(&st->cfg, &gains) != PMSTEP_OK
        || pmstep_position_init(&st->position, &st->motor, &gains) != PMSTEP_OK) {
        fail(st, "the harness's configuration is refused");
    }
    pmstep_console_init(&st->con, "pmstep fuzz");
    if ((setup & 1u) != 0u) {
        pmstep_console_attach_position(&st->con, &st->position);
    }
    if ((setup & 2u) != 0u) {
        pmstep_console_attach_simulation(&st->con);
    }
    if ((setup & 7u) == 7u) {
        if (pmstep_console_attach_sim_stepdir(&st->con, &st->stepdir, &st->cfg) != PMSTEP_OK) {
            fail(st, "the STEP/DIR input is refused");
        }
        st->stepdir_attached = true;
    }
    st->snap.period = UINT32_MAX;
    while (r.pos < r.size && st->steps < FUZZ_MAX_STEPS) {
        uint8_t buf[2u * (PMSTEP_CONSOLE_MAX_PAYLOAD + 6u)];
        uint32_t n = 0;
        const uint8_t op = read_u8(&r) % 6u;
        st->now_ms++;
        switch (op) {
        case 0: {
            const uint32_t count = read_u8(&r);
            for (n = 0; n < count && n < sizeof buf; ++n) {
                buf[n] = read_u8(&r);
            }
            break;
        }
        case 1: n = read_frame(&r, buf); break;
        case 2:
            n = read_frame(&r, buf);
            n += read_frame(&r, buf + n);
            break;
        case 3: {
            const unsigned periods = (unsigned)read_u8(&r) | ((unsigned)read_u8(&r) << 8);
            unsigned k;
            for (k = 0; k < periods && st->steps < FUZZ_MAX_STEPS; ++k) {
                period(st);
            }
            st->now_ms += periods / 20u;
            break;
        }
        case 4:
            st->now_ms += read_u8(&r);
            pmstep_console_poll(&st->con, st->now_ms);
            break;
        default: n = special_frame(&r, buf); break;
        }
        if (n > 0u) {
            receive(st, buf, n);
        }
    }
    check_config(st);
    return 0;
}
