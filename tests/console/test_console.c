/*
 * Unit tests of the command and telemetry interface (console/): framing, replies, the
 * mailbox at period boundaries, configuration by name and id, telemetry decimation, and a
 * seeded fuzz of bad input that must never reach the core.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pmstep_console.h"
#include "console_test_frame.h"
#include "stepdir_settings_equal.h"

static pmstep_console_t con;
static pmstep_config_t cfg;
static pmstep_t motor;
static pmstep_console_snapshot_t snap;

static int setup(void **state)
{
    (void)state;
    pmstep_console_init(&con, "pmstep 0.1.0 test");
    cfg = pmstep_console_app_config(50e-6f, 1u, 16.5f, 66.0f);
    assert_int_equal(pmstep_init(&motor, &cfg), PMSTEP_OK);
    memset(&snap, 0, sizeof snap);
    snap.period = UINT32_MAX; /* no step yet */
    return 0;
}

/* ---- host side of the protocol ---- */

static void send_request(uint8_t type, uint8_t seq, const void *data, uint32_t n)
{
    uint8_t buf[80];
    const uint32_t len = console_test_frame(buf, type, seq, data, n);
    pmstep_console_receive(&con, buf, len, 0u);
}

typedef console_test_reply_t reply_t;

/* Decodes the frames the console transmitted; @return how many. */
static unsigned replies(reply_t *r, unsigned max)
{
    uint8_t tx[PMSTEP_CONSOLE_TX_BYTES];
    const uint32_t n = pmstep_console_transmit(&con, tx, sizeof tx);
    return console_test_replies(tx, n, r, max);
}

static int16_t ack_status(const reply_t *r) { return console_test_i16(r->data); }

static void boundary(void) { pmstep_console_boundary(&con, &motor, &cfg, &snap); }

/* One control period of the core with zero currents on a 48 V bus. */
static void step(void)
{
    const pmstep_meas_t m = {0.0f, 0.0f, 48.0f, 0.0f, 0.0f, 0.0f};
    boundary();
    pmstep_step(&motor, &m, &snap.out);
    snap.meas = m;
    snap.period++;
    pmstep_console_telemetry(&con, &snap);
}

/* ---- tests ---- */

static void test_crc(void **state)
{
    const uint8_t check[] = "123456789";
    (void)state;
    assert_int_equal(pmstep_console_crc16(0xFFFFu, check, 9u), 0x29B1u); /* CRC-16/CCITT-FALSE check value */
}

static void test_hello(void **state)
{
    reply_t r[2];
    (void)state;
    send_request(PMSTEP_CONSOLE_HELLO, 7u, NULL, 0u);
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(r[0].type, 0x81u);
    assert_int_equal(r[0].seq, 7u);
    assert_int_equal(r[0].data[0], PMSTEP_CONSOLE_PROTOCOL_VERSION);
    assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_MAX_PAYLOAD);
    assert_int_equal(r[0].data[2], 0u); /* no stored configuration */
    assert_int_equal(r[0].data[3], 2u); /* its own configuration in force: configured */
    assert_memory_equal(&r[0].data[4], "pmstep 0.1.0 test", 17u);
}

/* A command waits for the period boundary, then reaches the core; the ACK gives the period. */
static void test_command_at_period_boundary(void **state)
{
    reply_t r[2];
    const float target[2] = {10.0f, 50.0f};
    (void)state;
    snap.period = 41u;
    send_request(PMSTEP_CONSOLE_START, 1u, NULL, 0u);
    assert_true(pmstep_console_pending(&con));
    assert_int_equal(replies(r, 2), 0u); /* nothing before the boundary */
    step();
    assert_false(pmstep_console_pending(&con));
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(r[0].type, 0x82u);
    assert_int_equal(ack_status(&r[0]), PMSTEP_OK);
    assert_int_equal(console_test_u32(&r[0].data[2]), 42u); /* the step after period 41 */
    assert_int_equal(snap.out.mode, PMSTEP_MODE_S_ALIGN);   /* the step after the boundary ran started */
    send_request(PMSTEP_CONSOLE_SPEED_TARGET, 2u, target, 8u);
    step();
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(ack_status(&r[0]), PMSTEP_OK);
    /* The core refuses a start while running: its status comes back. */
    send_request(PMSTEP_CONSOLE_START, 3u, NULL, 0u);
    step();
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(ack_status(&r[0]), PMSTEP_ERR_BAD_MODE);
    /* A ramp rate of 0 is the core's error too. */
    {
        const float bad_ramp[2] = {5.0f, 0.0f};
        send_request(PMSTEP_CONSOLE_SPEED_TARGET, 4u, bad_ramp, 8u);
        step();
        assert_int_equal(replies(r, 2), 1u);
        assert_int_equal(ack_status(&r[0]), PMSTEP_ERR_BAD_COMMAND_VALUE);
    }
    send_request(PMSTEP_CONSOLE_STOP, 5u, NULL, 0u);
    step();
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(ack_status(&r[0]), PMSTEP_OK);
    assert_int_equal(snap.out.mode, PMSTEP_MODE_IDLE);
}

static void test_errors_answered(void **state)
{
    reply_t r[4];
    const float nan_target[2] = {NAN, 50.0f};
    const float inf_id = INFINITY;
    const uint8_t junk[3] = {1u, 2u, 3u};
    (void)state;
    send_request(0x33u, 9u, NULL, 0u);                       /* unknown */
    send_request(PMSTEP_CONSOLE_SPEED_TARGET, 9u, junk, 3u); /* wrong length */
    send_request(PMSTEP_CONSOLE_SPEED_TARGET, 9u, nan_target, 8u);
    send_request(PMSTEP_CONSOLE_ID_TARGET, 9u, &inf_id, 4u);
    assert_int_equal(replies(r, 4), 4u);
    assert_int_equal(r[0].type, 0xFFu);
    assert_int_equal(r[0].data[0], 0x33u);
    assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_UNKNOWN_COMMAND);
    assert_int_equal(r[1].data[1], PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    assert_int_equal(r[2].data[1], PMSTEP_CONSOLE_ERR_BAD_VALUE);
    assert_int_equal(r[3].data[1], PMSTEP_CONSOLE_ERR_BAD_VALUE);
    assert_false(pmstep_console_pending(&con));
    /* One command at a time: the second before a boundary is refused, not queued. */
    send_request(PMSTEP_CONSOLE_START, 1u, NULL, 0u);
    send_request(PMSTEP_CONSOLE_STOP, 2u, NULL, 0u);
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(r[0].data[0], PMSTEP_CONSOLE_STOP);
    assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_BUSY);
    /* SIM_ADVANCE on a non-simulation console. */
    {
        const uint32_t n = 10u;
        step();
        (void)replies(r, 4);
        send_request(PMSTEP_CONSOLE_SIM_ADVANCE, 3u, &n, 4u);
        assert_int_equal(replies(r, 4), 1u);
        assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_NOT_SUPPORTED);
    }
    assert_int_equal(con.count.rx_error_replies, 6u);
}

static void test_config_by_name_and_id(void **state)
{
    reply_t r[2];
    uint8_t req[48];
    const float value = 120.0f;
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    uint32_t id;
    (void)state;
    /* Names are unique; every value reads back what it holds and writes back unchanged. */
    for (id = 0; id < count; ++id) {
        uint32_t j;
        float v;
        pmstep_config_t copy = cfg;
        pmstep_stepdir_settings_t sd = con.stepdir;
        for (j = id + 1u; j < count; ++j) {
            assert_string_not_equal(t[id].name, t[j].name);
        }
        assert_true(pmstep_console_config_get(&cfg, &con.stepdir, id, &v));
        if ((t[id].flags & PMSTEP_CONSOLE_CFG_READ_ONLY) == 0u) {
            assert_int_equal(pmstep_console_config_set(&copy, &sd, id, v), 0);
            assert_memory_equal(&copy, &cfg, sizeof cfg);
            assert_stepdir_settings_equal(&sd, &con.stepdir);
        } else {
            assert_int_equal(pmstep_console_config_set(&copy, &sd, id, v), PMSTEP_CONSOLE_ERR_READ_ONLY);
        }
    }
    {
        float v;
        assert_false(pmstep_console_config_get(&cfg, &con.stepdir, count, &v)); /* past the table */
    }
    /* Get by name. */
    req[0] = 0xFFu;
    memcpy(&req[1], "gains.speed_gain_per_s", 22u);
    send_request(PMSTEP_CONSOLE_GET_CONFIG, 1u, req, 23u);
    step();
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(r[0].type, 0x88u);
    assert_float_equal(console_test_f32(&r[0].data[3]), 100.0f, 0.0f);
    assert_memory_equal(&r[0].data[7], "gains.speed_gain_per_s", 22u);
    /* Set by name in IDLE: validated, applied, the core re-initialised. */
    req[0] = 0xFFu;
    memcpy(&req[1], &value, 4u);
    memcpy(&req[5], "gains.speed_gain_per_s", 22u);
    send_request(PMSTEP_CONSOLE_SET_CONFIG, 2u, req, 27u);
    step();
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(ack_status(&r[0]), PMSTEP_OK);
    {
        float v = 0.0f;
        assert_true(pmstep_console_config_get(&cfg, &con.stepdir, 12u, &v)); /* gains.speed_gain_per_s */
        assert_float_equal(v, 120.0f, 0.0f);
    }
    /* A value the core's validation refuses: its status, and the configuration unchanged. */
    {
        const float bad = -1.0f;
        req[0] = 0u; /* motor.resistance_Ohm */
        memcpy(&req[1], &bad, 4u);
        send_request(PMSTEP_CONSOLE_SET_CONFIG, 3u, req, 5u);
        step();
        assert_int_equal(replies(r, 2), 1u);
        assert_int_equal(ack_status(&r[0]), PMSTEP_ERR_RESISTANCE);
        float ohm = 0.0f;
        assert_true(pmstep_console_config_get(&cfg, &con.stepdir, 0u, &ohm)); /* motor.resistance_Ohm */
        assert_float_equal(ohm, 3.0f, 0.0f);
    }
    /* Read-only (the port's period), unknown name, non-integer integer. */
    {
        const float one = 1.0f;
        const float half = 0.5f;
        req[0] = 6u; /* period_s */
        memcpy(&req[1], &one, 4u);
        send_request(PMSTEP_CONSOLE_SET_CONFIG, 4u, req, 5u);
        req[0] = 0xFFu;
        memcpy(&req[5], "no_such_value", 13u);
        send_request(PMSTEP_CONSOLE_SET_CONFIG, 5u, req, 18u);
        req[0] = 5u; /* pole_pairs */
        memcpy(&req[1], &half, 4u);
        send_request(PMSTEP_CONSOLE_SET_CONFIG, 6u, req, 5u);
        step();
        assert_int_equal(replies(r, 2), 3u);
    }
    /* Refused while the motor runs. */
    {
        const float v = 90.0f;
        send_request(PMSTEP_CONSOLE_START, 7u, NULL, 0u);
        step();
        (void)replies(r, 2);
        req[0] = 12u;
        memcpy(&req[1], &v, 4u);
        send_request(PMSTEP_CONSOLE_SET_CONFIG, 8u, req, 5u);
        step();
        assert_int_equal(replies(r, 2), 1u);
        assert_int_equal(r[0].type, 0xFFu);
        assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_NOT_STOPPED);
        float g = 0.0f;
        assert_true(pmstep_console_config_get(&cfg, &con.stepdir, 12u, &g)); /* gains.speed_gain_per_s */
        assert_float_equal(g, 120.0f, 0.0f);
    }
}

static void test_status_and_telemetry(void **state)
{
    reply_t r[16];
    const uint32_t dec = 4u;
    unsigned k;
    unsigned n;
    (void)state;
    send_request(PMSTEP_CONSOLE_START, 1u, NULL, 0u);
    step();
    send_request(PMSTEP_CONSOLE_TELEMETRY, 2u, &dec, 4u);
    step(); /* applied at the boundary of period 1 */
    (void)replies(r, 16);
    for (k = 0; k < 12u; ++k) {
        step();
    }
    n = replies(r, 16);
    assert_int_equal(n, 3u); /* periods 4, 8, 12: the multiples of the decimation */
    for (k = 0; k < n; ++k) {
        assert_int_equal(r[k].type, PMSTEP_CONSOLE_TELEMETRY_FRAME);
        assert_int_equal(console_test_u32(r[k].data), 4u + 4u * k);
        assert_int_equal(r[k].data[4], PMSTEP_MODE_S_ALIGN);
        assert_float_equal(console_test_f32(&r[k].data[6 + 4 * 7]), 48.0f, 0.0f); /* bus */
    }
    send_request(PMSTEP_CONSOLE_GET_STATUS, 3u, NULL, 0u);
    step();
    n = replies(r, 16);
    assert_int_equal(r[n - 1u].type, 0x87u);
    assert_int_equal(console_test_u32(r[n - 1u].data), snap.period - 1u); /* the snapshot before this boundary's step */
    assert_int_equal(r[n - 1u].data[4], PMSTEP_MODE_S_ALIGN);
    send_request(PMSTEP_CONSOLE_GET_COMMISSIONING, 4u, NULL, 0u);
    step();
    n = replies(r, 16);
    assert_int_equal(r[n - 1u].type, 0x8Au);
    assert_int_equal(r[n - 1u].n, 41u);
}

/* Two requests in one receive call (a UART poll reads several bytes): the second, refused as
 * busy, leaves the waiting one exactly as it was. Each case of the review's finding. */
static void send_two(uint8_t type1, const void *data1, uint32_t n1, uint8_t type2, const void *data2, uint32_t n2)
{
    uint8_t buf[160];
    uint32_t len = console_test_frame(buf, type1, 1u, data1, n1);
    len += console_test_frame(buf + len, type2, 2u, data2, n2);
    pmstep_console_receive(&con, buf, len, 0u);
}

static void set_config_data(uint8_t *req, uint8_t id, float value)
{
    req[0] = id;
    memcpy(&req[1], &value, 4u);
}

static uint8_t config_id(const char *name)
{
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    uint32_t id;
    for (id = 0; id < count; ++id) {
        if (strcmp(t[id].name, name) == 0) {
            return (uint8_t)id;
        }
    }
    fail_msg("no configuration value %s", name);
    return 0u;
}

static float config_value(const char *name)
{
    float v = 0.0f;
    assert_true(pmstep_console_config_get(&cfg, &con.stepdir, config_id(name), &v));
    return v;
}

static void test_busy_refusal_changes_nothing(void **state)
{
    reply_t r[4];
    uint8_t set[5];
    uint8_t get[1];
    const float speed[2] = {10.0f, 50.0f};
    const float huge_speed[2] = {1e30f, 50.0f};
    const float id_target = 300.0f;
    const float trip_before = config_value("limits.max_phase_current_A");
    const float max_bus_before = config_value("limits.max_bus_voltage_V");
    (void)state;
    /* SET_CONFIG of the bus limit, then GET_CONFIG of the current trip: the set applies to the
     * bus limit, not to the trip the busy GET named. */
    set_config_data(set, config_id("limits.max_bus_voltage_V"), 55.0f);
    get[0] = config_id("limits.max_phase_current_A");
    send_two(PMSTEP_CONSOLE_SET_CONFIG, set, 5u, PMSTEP_CONSOLE_GET_CONFIG, get, 1u);
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(r[0].data[0], PMSTEP_CONSOLE_GET_CONFIG);
    assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_BUSY);
    step();
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(r[0].type, PMSTEP_CONSOLE_SET_CONFIG | 0x80u);
    assert_int_equal(ack_status(&r[0]), PMSTEP_OK);
    assert_float_equal(config_value("limits.max_phase_current_A"), trip_before, 0.0f);
    assert_float_equal(config_value("limits.max_bus_voltage_V"), 55.0f, 0.0f);
    assert_true(max_bus_before != 55.0f);
    /* SET_CONFIG of the trip, then SPEED_TARGET 1e30: the trip takes the SET's value. */
    set_config_data(set, config_id("limits.max_phase_current_A"), 10.0f);
    send_two(PMSTEP_CONSOLE_SET_CONFIG, set, 5u, PMSTEP_CONSOLE_SPEED_TARGET, huge_speed, 8u);
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_BUSY);
    step();
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(ack_status(&r[0]), PMSTEP_OK);
    assert_float_equal(config_value("limits.max_phase_current_A"), 10.0f, 0.0f);
    /* SPEED_TARGET 10, then ID_TARGET 300: the speed target the core gets is 10 rad/s. */
    send_request(PMSTEP_CONSOLE_START, 3u, NULL, 0u);
    step();
    (void)replies(r, 4);
    send_two(PMSTEP_CONSOLE_SPEED_TARGET, speed, 8u, PMSTEP_CONSOLE_ID_TARGET, &id_target, 4u);
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(r[0].data[0], PMSTEP_CONSOLE_ID_TARGET);
    assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_BUSY);
    step();
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(r[0].type, PMSTEP_CONSOLE_SPEED_TARGET | 0x80u);
    assert_float_equal(motor.speed_ref.target, 10.0f, 0.0f);
    assert_float_equal(motor.i_d_ref.target, 0.0f, 0.0f);
}

/* START applied at a boundary, SET_CONFIG at the next one before any step ran: the snapshot still
 * reads IDLE, the core does not; the configuration is refused and the start stands. */
static void test_set_config_after_start_refused(void **state)
{
    reply_t r[2];
    uint8_t set[5];
    (void)state;
    send_request(PMSTEP_CONSOLE_START, 1u, NULL, 0u);
    boundary(); /* applied; no step yet, the snapshot says IDLE */
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(ack_status(&r[0]), PMSTEP_OK);
    assert_int_equal(snap.out.mode, PMSTEP_MODE_IDLE);
    set_config_data(set, config_id("gains.speed_gain_per_s"), 90.0f);
    send_request(PMSTEP_CONSOLE_SET_CONFIG, 2u, set, 5u);
    boundary();
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(r[0].type, 0xFFu);
    assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_NOT_STOPPED);
    assert_float_equal(config_value("gains.speed_gain_per_s"), 100.0f, 0.0f);
    assert_int_not_equal(pmstep_get_mode(&motor), PMSTEP_MODE_IDLE);
}

/* In FAULT a configuration change is refused: the fault stays latched until CLEAR_FAULT. */
static void test_set_config_in_fault_refused(void **state)
{
    reply_t r[2];
    uint8_t set[5];
    const pmstep_meas_t over = {100.0f, 0.0f, 48.0f, 0.0f, 0.0f, 0.0f};
    (void)state;
    send_request(PMSTEP_CONSOLE_START, 1u, NULL, 0u);
    step();
    pmstep_step(&motor, &over, &snap.out); /* overcurrent */
    assert_int_equal(pmstep_get_mode(&motor), PMSTEP_MODE_FAULT);
    (void)replies(r, 2);
    set_config_data(set, config_id("gains.speed_gain_per_s"), 90.0f);
    send_request(PMSTEP_CONSOLE_SET_CONFIG, 2u, set, 5u);
    boundary();
    assert_int_equal(replies(r, 2), 1u);
    assert_int_equal(r[0].data[1], PMSTEP_CONSOLE_ERR_NOT_STOPPED);
    assert_int_equal(pmstep_get_mode(&motor), PMSTEP_MODE_FAULT);
    assert_int_equal(motor.fault, PMSTEP_FAULT_OVERCURRENT);
}

/* Bad input of every kind, seeded: never a command, never a change of the core's instance,
 * every byte accounted for, and the console answers a good request afterwards. */
static void test_fuzz_never_reaches_core(void **state)
{
    pmstep_t before;
    reply_t r[4];
    uint8_t buf[128];
    unsigned round;
    (void)state;
    srand(12345u);
    memcpy(&before, &motor, sizeof motor);
    for (round = 0; round < 20000u; ++round) {
        const unsigned kind = (unsigned)rand() % 5u;
        uint32_t n = 0;
        uint32_t k;
        if (kind == 0u) { /* garbage without a sync byte */
            n = 1u + (uint32_t)rand() % 100u;
            for (k = 0; k < n; ++k) {
                buf[k] = (uint8_t)(rand() % 255);
                if (buf[k] == PMSTEP_CONSOLE_SYNC) {
                    buf[k] = 0x5Au;
                }
            }
        } else if (kind == 1u) { /* a good START with its CRC broken */
            n = console_test_frame(buf, PMSTEP_CONSOLE_START, 1u, NULL, 0u);
            buf[n - 1u - (uint32_t)rand() % 2u] ^= (uint8_t)(1u + (unsigned)rand() % 255u);
        } else if (kind == 2u) { /* length out of range */
            buf[0] = PMSTEP_CONSOLE_SYNC;
            buf[1] = (rand() % 2) != 0 ? (uint8_t)(PMSTEP_CONSOLE_MAX_PAYLOAD + 1u + (unsigned)rand() % 100u) : 1u;
            n = 2u;
        } else if (kind == 3u) { /* a frame cut short, then silence */
            n = console_test_frame(buf, PMSTEP_CONSOLE_STOP, 1u, NULL, 0u) - 1u - (uint32_t)rand() % 4u;
        } else { /* a STOP with one payload byte flipped (the CRC no longer matches) */
            n = console_test_frame(buf, PMSTEP_CONSOLE_STOP, 1u, NULL, 0u);
            buf[2] ^= 0x10u;
        }
        pmstep_console_receive(&con, buf, n, round * 100u);
        pmstep_console_poll(&con, round * 100u + 50u); /* a truncated frame times out */
        assert_false(pmstep_console_pending(&con));
        boundary();
    }
    assert_memory_equal(&before, &motor, sizeof motor);
    assert_int_equal(replies(r, 4), 0u);
    assert_int_equal(con.count.rx_frames, 0u);
    assert_int_equal(con.count.commands_applied, 0u);
    assert_true(con.count.rx_garbage_bytes > 0u && con.count.rx_crc_errors > 0u && con.count.rx_bad_length > 0u
                && con.count.rx_truncated > 0u);
    send_request(PMSTEP_CONSOLE_HELLO, 1u, NULL, 0u);
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(r[0].type, 0x81u);
}

/* A flood with nobody reading: frames dropped and counted, nothing blocks. */
static void test_flood_drops_and_counts(void **state)
{
    unsigned k;
    reply_t r[1];
    (void)state;
    for (k = 0; k < 1000u; ++k) {
        send_request(PMSTEP_CONSOLE_HELLO, (uint8_t)k, NULL, 0u);
    }
    assert_int_equal(con.count.rx_frames, 1000u);
    assert_true(con.count.tx_dropped > 0u);
    assert_int_equal(con.count.tx_frames + con.count.tx_dropped, 1000u);
    assert_int_equal(replies(r, 1), con.count.tx_frames);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_crc, setup),
        cmocka_unit_test_setup(test_hello, setup),
        cmocka_unit_test_setup(test_command_at_period_boundary, setup),
        cmocka_unit_test_setup(test_errors_answered, setup),
        cmocka_unit_test_setup(test_config_by_name_and_id, setup),
        cmocka_unit_test_setup(test_busy_refusal_changes_nothing, setup),
        cmocka_unit_test_setup(test_set_config_after_start_refused, setup),
        cmocka_unit_test_setup(test_set_config_in_fault_refused, setup),
        cmocka_unit_test_setup(test_status_and_telemetry, setup),
        cmocka_unit_test_setup(test_fuzz_never_reaches_core, setup),
        cmocka_unit_test_setup(test_flood_drops_and_counts, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
