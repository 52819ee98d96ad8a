/*
 * Unit tests of the console's stored configuration (pmstep_console_store.c): a board with an empty
 * store refuses START by name; a record written in pieces, applied, saved and found again at the
 * next boot; every refusal of a record leaves the configuration in force untouched; saves only with
 * the bridge off; a power cut in a save leaves the previous record in force.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "console_test_frame.h"
#include "fake_flash.h"
#include "pmstep_console.h"
#include "stepdir_settings_equal.h"

#define BOARD_ID 0x51454D55u

static pmstep_console_t con;
static pmstep_config_t cfg;
static pmstep_config_t defaults;
static pmstep_t motor;
static pmstep_console_snapshot_t snap;
static fake_flash_t flash;
static pmstep_store_t store;
static pmstep_console_store_t cs;
static uint8_t seq;

typedef console_test_reply_t reply_t;

/* A reset of the board: the store read from the flash as it is, the core initialised on what it
 * gives, the console attached. @return the boot's status. */
static pmstep_store_status_t boot(void)
{
    pmstep_store_status_t st;
    pmstep_console_init(&con, "pmstep test");
    defaults = pmstep_console_app_config(50e-6f, 1u, 16.5f, 66.0f);
    assert_int_equal(pmstep_store_init(&store, &flash.ops, BOARD_ID), PMSTEP_STORE_OK);
    st = pmstep_console_store_boot(&cs, &store, &defaults, &cfg);
    assert_int_equal(pmstep_init(&motor, &cfg), PMSTEP_OK);
    pmstep_console_attach_store(&con, &cs);
    memset(&snap, 0, sizeof snap);
    snap.period = UINT32_MAX;
    return st;
}

static int setup(void **state)
{
    (void)state;
    fake_flash_init(&flash);
    assert_int_equal(boot(), PMSTEP_STORE_EMPTY);
    return 0;
}

static void send_request(uint8_t type, const void *data, uint32_t n) { console_test_send(&con, type, ++seq, data, n); }

static unsigned replies(reply_t *r, unsigned max) { return console_test_take_replies(&con, r, max); }

/* One control period of the core with zero currents on a 48 V bus, the mailbox applied before it. */
static void step(void)
{
    const pmstep_meas_t m = {0.0f, 0.0f, 48.0f, 0.0f, 0.0f, 0.0f};
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    pmstep_step(&motor, &m, &snap.out);
    snap.meas = m;
    snap.period++;
}

/* Sends @p type with @p n bytes, runs a period, and returns its one reply. */
static reply_t request(uint8_t type, const void *data, uint32_t n)
{
    reply_t r[4];
    send_request(type, data, n);
    step();
    assert_int_equal(replies(r, 4), 1u);
    assert_int_equal(r[0].seq, seq);
    return r[0];
}

static int16_t ack(uint8_t type)
{
    const reply_t r = request(type, NULL, 0u);
    assert_int_equal(r.type, type | 0x80u);
    return console_test_i16(r.data);
}

static uint8_t error_code(const reply_t *r, uint8_t type)
{
    assert_int_equal(r->type, PMSTEP_CONSOLE_ERROR_FRAME);
    assert_int_equal(r->data[0], type);
    return r->data[1];
}

/* A record of a motor for this board: the board's configuration, R and the alignment voltages of
 * a 2.1 Ohm NEMA 17 (values the core accepts), sequence 0 as on the wire. */
static uint32_t motor_record(uint8_t *out, uint32_t board_id, float inertia_kgm2)
{
    pmstep_store_record_t rec;
    memset(&rec, 0, sizeof rec);
    rec.config = defaults;
    rec.stepdir = pmstep_console_stepdir_defaults();
    rec.config.motor.inertia_kgm2 = inertia_kgm2;
    rec.measured.flags = PMSTEP_STORE_MEASURED_RESISTANCE;
    rec.measured.resistance_Ohm = 2.0f;
    return pmstep_store_encode(&rec, board_id, 0u, out);
}

/* CONFIG_WRITE in pieces of @p piece bytes. */
static void write_record(const uint8_t *b, uint32_t n, uint32_t piece)
{
    uint32_t off;
    for (off = 0; off < n; off += piece) {
        uint8_t d[64];
        const uint32_t k = n - off < piece ? n - off : piece;
        reply_t r;
        d[0] = (uint8_t)off;
        d[1] = (uint8_t)(off >> 8);
        memcpy(&d[2], &b[off], k);
        send_request(PMSTEP_CONSOLE_CONFIG_WRITE, d, k + 2u);
        assert_int_equal(replies(&r, 1), 1u); /* answered at once */
        assert_int_equal(r.type, PMSTEP_CONSOLE_CONFIG_WRITE | 0x80u);
        assert_int_equal(r.data[0] | (r.data[1] << 8), off + k);
    }
}

static void test_hello_says_not_configured(void **state)
{
    reply_t r;
    (void)state;
    send_request(PMSTEP_CONSOLE_HELLO, NULL, 0u);
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(r.data[0], PMSTEP_CONSOLE_PROTOCOL_VERSION);
    assert_int_equal(r.data[2], PMSTEP_STORE_FORMAT_VERSION);
    assert_int_equal(r.data[3], 1u); /* a store, no motor configured */
}

/* An empty store: START refused by name, the bridge never switched on. */
static void test_empty_store_refuses_start(void **state)
{
    reply_t r;
    (void)state;
    r = request(PMSTEP_CONSOLE_START, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_START), PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
    step();
    assert_int_equal(snap.out.mode, PMSTEP_MODE_IDLE);
    assert_false(snap.out.bridge_enable);
    r = request(PMSTEP_CONSOLE_CONFIG_SAVE, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_SAVE), PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
    /* SET_CONFIG alone does not make a motor configured */
    {
        uint8_t d[5] = {2u, 0, 0, 0, 0};
        const float j = 0.02f;
        memcpy(&d[1], &j, 4u);
        r = request(PMSTEP_CONSOLE_SET_CONFIG, d, 5u);
        assert_int_equal(console_test_i16(r.data), PMSTEP_OK);
    }
    r = request(PMSTEP_CONSOLE_START, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_START), PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
}

static void test_status_names_boot_outcome(void **state)
{
    reply_t r;
    (void)state;
    send_request(PMSTEP_CONSOLE_CONFIG_STATUS, NULL, 0u);
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(r.data[0], 0u);
    assert_int_equal(console_test_i16(&r.data[1]), PMSTEP_STORE_EMPTY);
    assert_int_equal((int8_t)r.data[7], -1);
    assert_int_equal(r.data[12] | (r.data[13] << 8), pmstep_store_record_bytes());
    assert_int_equal(r.data[14], PMSTEP_STORE_FORMAT_VERSION);
    assert_int_equal(console_test_u32(&r.data[15]), pmstep_store_layout_id());
    assert_int_equal(console_test_u32(&r.data[19]), BOARD_ID);
}

/* Written, applied, started; saved; found again at the next boot and read back byte for byte. */
static void test_write_apply_save_boot(void **state)
{
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint8_t back[PMSTEP_STORE_RECORD_MAX_BYTES];
    const uint32_t n = motor_record(b, BOARD_ID, 0.02f);
    uint32_t off = 0u;
    reply_t r;
    (void)state;
    write_record(b, n, 50u);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), 0);
    assert_true(cs.configured);
    assert_true(cfg.motor.inertia_kgm2 == 0.02f);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_SAVE), PMSTEP_STORE_OK);
    assert_int_equal(boot(), PMSTEP_STORE_OK);
    assert_true(cs.configured);
    assert_true(cfg.motor.inertia_kgm2 == 0.02f);
    assert_true(cs.measured.resistance_Ohm == 2.0f);
    do { /* CONFIG_READ from 0 to the end */
        const uint8_t d[2] = {(uint8_t)off, (uint8_t)(off >> 8)};
        uint32_t k;
        r = request(PMSTEP_CONSOLE_CONFIG_READ, d, 2u);
        assert_int_equal(r.type, PMSTEP_CONSOLE_CONFIG_READ | 0x80u);
        assert_int_equal(r.data[0] | (r.data[1] << 8), off);
        assert_int_equal(r.data[2] | (r.data[3] << 8), n);
        k = r.n - 4u;
        assert_true(k > 0u && off + k <= n);
        memcpy(&back[off], &r.data[4], k);
        off += k;
    } while (off < n);
    assert_memory_equal(back, b, n);
    assert_int_equal(ack(PMSTEP_CONSOLE_START), PMSTEP_OK);
    step();
    assert_int_equal(snap.out.mode, PMSTEP_MODE_S_ALIGN);
}

/* Each refused record names its cause and changes nothing: still not configured, defaults in force. */
static void test_refused_records_change_nothing(void **state)
{
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint32_t n;
    (void)state;
    n = motor_record(b, BOARD_ID + 1u, 0.02f);
    write_record(b, n, 58u);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), PMSTEP_STORE_ERR_BOARD);
    n = motor_record(b, BOARD_ID, 0.02f);
    b[100] ^= 4u;
    write_record(b, n, 58u);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), PMSTEP_STORE_ERR_CRC);
    n = motor_record(b, BOARD_ID, -1.0f); /* J < 0: the core's own code comes back */
    write_record(b, n, 58u);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), PMSTEP_ERR_INERTIA);
    n = motor_record(b, BOARD_ID, 0.02f);
    write_record(b, n - 8u, 58u); /* cut short */
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), PMSTEP_STORE_ERR_LENGTH);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), PMSTEP_STORE_ERR_LENGTH); /* nothing staged any more */
    assert_false(cs.configured);
    assert_memory_equal(&cfg, &defaults, sizeof cfg);
}

static void test_write_out_of_order_refused(void **state)
{
    const uint8_t gap[4] = {10u, 0u, 1u, 2u};
    uint8_t big[60];
    reply_t r;
    (void)state;
    send_request(PMSTEP_CONSOLE_CONFIG_WRITE, gap, sizeof gap);
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_WRITE), PMSTEP_CONSOLE_ERR_BAD_VALUE);
    memset(big, 0, sizeof big);
    for (;;) { /* fill the staging buffer to its end: one more byte is refused */
        const uint32_t room = (uint32_t)sizeof cs.staging - cs.staged;
        const uint32_t k = room < 58u ? room : 58u;
        big[0] = (uint8_t)cs.staged;
        big[1] = (uint8_t)(cs.staged >> 8);
        send_request(PMSTEP_CONSOLE_CONFIG_WRITE, big, (k == 0u ? 1u : k) + 2u);
        assert_int_equal(replies(&r, 1), 1u);
        if (k == 0u) {
            assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_WRITE), PMSTEP_CONSOLE_ERR_BAD_VALUE);
            break;
        }
        assert_int_equal(r.type, PMSTEP_CONSOLE_CONFIG_WRITE | 0x80u);
    }
}

/* Saves and erases only with the motor stopped; APPLY and DEFAULTS only in IDLE. */
static void test_not_while_running(void **state)
{
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    const uint32_t n = motor_record(b, BOARD_ID, 0.02f);
    reply_t r;
    (void)state;
    write_record(b, n, 58u);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), 0);
    assert_int_equal(ack(PMSTEP_CONSOLE_START), PMSTEP_OK);
    step();
    r = request(PMSTEP_CONSOLE_CONFIG_SAVE, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_SAVE), PMSTEP_CONSOLE_ERR_NOT_STOPPED);
    r = request(PMSTEP_CONSOLE_CONFIG_ERASE, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_ERASE), PMSTEP_CONSOLE_ERR_NOT_STOPPED);
    r = request(PMSTEP_CONSOLE_CONFIG_DEFAULTS, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_DEFAULTS), PMSTEP_CONSOLE_ERR_NOT_STOPPED);
    write_record(b, n, 58u);
    r = request(PMSTEP_CONSOLE_CONFIG_APPLY, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_APPLY), PMSTEP_CONSOLE_ERR_NOT_STOPPED);
    assert_int_equal(flash.erases + flash.programs, 0u);
    /* Stopped, but the last step still had the bridge on: the store refuses to write. */
    assert_int_equal(ack(PMSTEP_CONSOLE_STOP), PMSTEP_OK);
    snap.out.bridge_enable = true;
    snap.out.mode = PMSTEP_MODE_IDLE;
    send_request(PMSTEP_CONSOLE_CONFIG_SAVE, NULL, 0u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(console_test_i16(r.data), PMSTEP_STORE_ERR_BRIDGE_ON);
    assert_int_equal(flash.erases + flash.programs, 0u);
}

static void test_defaults_and_erase(void **state)
{
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    const uint32_t n = motor_record(b, BOARD_ID, 0.02f);
    reply_t r;
    (void)state;
    write_record(b, n, 58u);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), 0);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_SAVE), PMSTEP_STORE_OK);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_DEFAULTS), PMSTEP_OK);
    assert_false(cs.configured);
    assert_memory_equal(&cfg, &defaults, sizeof cfg);
    r = request(PMSTEP_CONSOLE_START, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_START), PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
    assert_int_equal(boot(), PMSTEP_STORE_OK); /* the flash untouched by DEFAULTS */
    assert_true(cs.configured);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_ERASE), PMSTEP_STORE_OK);
    assert_int_equal(boot(), PMSTEP_STORE_EMPTY);
    assert_false(cs.configured);
}

/* SET_CONFIG of a STEP/DIR setting by name: the ACK's status and the value in force after it. */
static int16_t set_by_name(const char *name, float value)
{
    uint8_t d[64];
    const uint32_t k = (uint32_t)strlen(name);
    reply_t r;
    d[0] = 0xFFu;
    memcpy(&d[1], &value, 4u);
    memcpy(&d[5], name, k);
    r = request(PMSTEP_CONSOLE_SET_CONFIG, d, 5u + k);
    if (r.type == PMSTEP_CONSOLE_ERROR_FRAME) {
        return (int16_t)(1000 + r.data[1]); /* an error reply: 1000 + its code */
    }
    assert_int_equal(r.type, PMSTEP_CONSOLE_SET_CONFIG | 0x80u);
    return console_test_i16(r.data);
}

/* GET_CONFIG by name: the value, and flags in @p flags. */
static float get_by_name(const char *name, uint8_t *flags)
{
    uint8_t d[64];
    const uint32_t k = (uint32_t)strlen(name);
    reply_t r;
    d[0] = 0xFFu;
    memcpy(&d[1], name, k);
    r = request(PMSTEP_CONSOLE_GET_CONFIG, d, 1u + k);
    assert_int_equal(r.type, PMSTEP_CONSOLE_GET_CONFIG | 0x80u);
    assert_memory_equal(&r.data[7], name, k);
    *flags = r.data[2];
    return console_test_f32(&r.data[3]);
}

/* The STEP/DIR settings over the console: read with their flag, each out-of-range value refused with its
 * own code and nothing changed, the rest in force at once, saved with the motor's record and in force
 * again after a reset; CONFIG_DEFAULTS brings back the defaults. */
static void test_stepdir_settings_set_saved_and_booted(void **state)
{
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    const uint32_t n = motor_record(b, BOARD_ID, 0.02f);
    const pmstep_stepdir_settings_t defaults_sd = pmstep_console_stepdir_defaults();
    const pmstep_config_t before = cfg;
    uint8_t flags = 0u;
    (void)state;
    assert_stepdir_settings_equal(&con.stepdir, &defaults_sd);
    assert_true(get_by_name("stepdir.microsteps", &flags) == 16.0f);
    assert_int_equal(flags, PMSTEP_CONSOLE_CFG_STEPDIR);
    assert_true(get_by_name("stepdir.following_error_limit_full_steps", &flags) == 1.0f);
    assert_true(get_by_name("stepdir.enable_active_high", &flags) == 0.0f);
    assert_true(get_by_name("stepdir.diag_active_high", &flags) == 1.0f);
    /* Refused by cause, never clamped; the settings in force unchanged. */
    assert_int_equal(set_by_name("stepdir.microsteps", 0.0f), PMSTEP_ERR_STEPDIR_MICROSTEPS);
    assert_int_equal(set_by_name("stepdir.microsteps", 257.0f), PMSTEP_ERR_STEPDIR_MICROSTEPS);
    assert_int_equal(set_by_name("stepdir.diag_mode", 2.0f), PMSTEP_ERR_STEPDIR_DIAG_MODE);
    assert_int_equal(set_by_name("stepdir.following_error_limit_full_steps", 0.0f), PMSTEP_ERR_STEPDIR_LIMIT);
    assert_int_equal(set_by_name("stepdir.following_error_limit_full_steps", -0.5f), PMSTEP_ERR_STEPDIR_LIMIT);
    assert_int_equal(set_by_name("stepdir.microsteps", 12.5f), 1000 + PMSTEP_CONSOLE_ERR_BAD_VALUE);
    assert_int_equal(set_by_name("stepdir.invert_direction", 2.0f), 1000 + PMSTEP_CONSOLE_ERR_BAD_VALUE);
    assert_int_equal(set_by_name("stepdir.stall_current_A", -0.1f), PMSTEP_ERR_STEPDIR_STALL_CURRENT);
    assert_int_equal(set_by_name("stepdir.stall_current_A", cfg.limits.max_phase_current_A),
                     PMSTEP_ERR_STEPDIR_STALL_CURRENT); /* at the trip a stall would never be found */
    assert_stepdir_settings_equal(&con.stepdir, &defaults_sd);
    /* Accepted: in force at once; the core's configuration untouched. */
    assert_int_equal(set_by_name("stepdir.microsteps", 256.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.microsteps", 1.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.microsteps", 32.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.invert_direction", 1.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.enable_active_high", 1.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.diag_active_high", 0.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.diag_mode", 1.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.following_error_limit_full_steps", 1.5f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.stall_current_A", 0.9f * cfg.limits.max_phase_current_A), PMSTEP_OK);
    assert_memory_equal(&cfg, &before, sizeof cfg);
    assert_true(con.stepdir.stall_current_A == 0.9f * cfg.limits.max_phase_current_A);
    /* the trip may not be lowered to the stall current: refused by the STEP/DIR setting's name */
    assert_int_equal(set_by_name("limits.max_phase_current_A", 0.9f * cfg.limits.max_phase_current_A),
                     PMSTEP_ERR_STEPDIR_STALL_CURRENT);
    assert_memory_equal(&cfg, &before, sizeof cfg);
    assert_int_equal(con.stepdir.microsteps, 32u);
    assert_true(con.stepdir.invert_direction && con.stepdir.enable_active_high && !con.stepdir.diag_active_high);
    assert_int_equal(con.stepdir.diag_mode, PMSTEP_DIAG_PULSE);
    assert_true(con.stepdir.following_error_limit_full_steps == 1.5f);
    /* A motor's record applied: its STEP/DIR settings (the defaults, as motor_record() writes them) in
     * force, then ours again, saved. */
    write_record(b, n, 58u);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), 0);
    assert_stepdir_settings_equal(&con.stepdir, &defaults_sd);
    assert_int_equal(set_by_name("stepdir.microsteps", 32.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.enable_active_high", 1.0f), PMSTEP_OK);
    assert_int_equal(set_by_name("stepdir.diag_mode", 1.0f), PMSTEP_OK);
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_SAVE), PMSTEP_STORE_OK);
    assert_int_equal(boot(), PMSTEP_STORE_OK);
    assert_true(cs.configured);
    assert_int_equal(con.stepdir.microsteps, 32u);
    assert_true(con.stepdir.enable_active_high);
    assert_int_equal(con.stepdir.diag_mode, PMSTEP_DIAG_PULSE);
    assert_true(get_by_name("stepdir.microsteps", &flags) == 32.0f);
    /* Refused while the motor runs, as every setting. */
    assert_int_equal(ack(PMSTEP_CONSOLE_START), PMSTEP_OK);
    step();
    assert_int_equal(set_by_name("stepdir.microsteps", 64.0f), 1000 + PMSTEP_CONSOLE_ERR_NOT_STOPPED);
    assert_int_equal(con.stepdir.microsteps, 32u);
    assert_int_equal(ack(PMSTEP_CONSOLE_STOP), PMSTEP_OK);
    step();
    assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_DEFAULTS), PMSTEP_OK);
    assert_stepdir_settings_equal(&con.stepdir, &defaults_sd);
}

/* The step tracker's settings from the STEP/DIR settings: the designer's with ours over them, the limit
 * in full steps of this motor. */
static void test_stepdir_tracker_settings(void **state)
{
    pmstep_stepdir_settings_t sd = pmstep_console_stepdir_defaults();
    pmstep_stepdir_config_t designed;
    pmstep_stepdir_config_t got;
    const float full_step_rad = 1.5707963f / (float)cfg.motor.pole_pairs;
    (void)state;
    sd.microsteps = 64u;
    sd.invert_direction = true;
    sd.diag_mode = 1u;
    sd.following_error_limit_full_steps = 2.0f;
    assert_int_equal(pmstep_stepdir_design(&cfg, 64u, &designed), PMSTEP_OK);
    assert_int_equal(pmstep_console_stepdir_config(&cfg, &sd, &got), PMSTEP_OK);
    assert_int_equal(got.microsteps, 64u);
    assert_true(got.invert_direction);
    assert_int_equal(got.diag_mode, PMSTEP_DIAG_PULSE);
    assert_float_equal(got.following_error_limit_rad, 2.0f * full_step_rad, 1e-6f * full_step_rad);
    assert_true(got.tracking_bandwidth_rad_s == designed.tracking_bandwidth_rad_s);
    assert_true(got.stop_time_s == designed.stop_time_s);
    assert_int_equal(got.diag_pulse_periods, designed.diag_pulse_periods);
    sd.microsteps = 300u;
    memset(&got, 0xAB, sizeof got);
    designed = got;
    assert_int_equal(pmstep_console_stepdir_config(&cfg, &sd, &got), PMSTEP_ERR_STEPDIR_MICROSTEPS);
    assert_memory_equal(&got, &designed, sizeof got); /* untouched */
    assert_int_equal(pmstep_console_stepdir_validate(NULL), PMSTEP_ERR_NULL_ARGUMENT);
}

/* A record of the firmware before the STEP/DIR settings (another layout) at boot: refused by name, the
 * board's defaults and the default STEP/DIR settings in force, not configured. */
static void test_boot_record_before_stepdir_settings(void **state)
{
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    uint32_t n = motor_record(b, BOARD_ID, 0.02f);
    const pmstep_stepdir_settings_t defaults_sd = pmstep_console_stepdir_defaults();
    uint32_t count;
    const pmstep_console_config_entry_t *t = pmstep_console_config_table(&count);
    uint32_t old = 0u;
    uint32_t layout = 0u;
    uint32_t off;
    reply_t r;
    (void)state;
    while (old < count && !pmstep_console_config_is_stepdir(old)) {
        const uint8_t type = t[old].type;
        layout = pmstep_store_crc32(layout, (const uint8_t *)t[old].name, (uint32_t)strlen(t[old].name) + 1u);
        layout = pmstep_store_crc32(layout, &type, 1u);
        ++old;
    }
    /* The values of the older table, the measured values moved up over the STEP/DIR ones. */
    memmove(&b[32u + 4u * old], &b[32u + 4u * count], 4u * PMSTEP_STORE_MEASURED_VALUES);
    n -= 4u * (count - old);
    memcpy(&b[12], &layout, 4u); /* little-endian host and record */
    b[20] = (uint8_t)old;
    b[21] = 0u;
    memcpy(&b[24], &n, 4u);
    b[16] = 1u; /* sequence 1, as a save writes it */
    {
        const uint32_t crc = pmstep_store_crc32(0u, b, n - 4u);
        memcpy(&b[n - 4u], &crc, 4u);
    }
    assert_int_equal(flash.ops.erase(flash.ops.ctx, 0u), 0);
    for (off = 0; off < ((n + 7u) & ~7u); off += 8u) {
        assert_int_equal(flash.ops.program(flash.ops.ctx, 0u, off, &b[off], 8u), 0);
    }
    con.stepdir.microsteps = 99u; /* whatever the console held before the reset */
    assert_int_equal(boot(), PMSTEP_STORE_ERR_LAYOUT);
    assert_false(cs.configured);
    assert_memory_equal(&cfg, &defaults, sizeof cfg);
    assert_stepdir_settings_equal(&con.stepdir, &defaults_sd);
    send_request(PMSTEP_CONSOLE_CONFIG_STATUS, NULL, 0u);
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(console_test_i16(&r.data[1]), PMSTEP_STORE_ERR_LAYOUT);
    r = request(PMSTEP_CONSOLE_START, NULL, 0u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_START), PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
}

/* A power cut in the middle of a save through the console: after the reset the record saved before
 * is in force. Over every operation of the save. */
static void test_power_cut_in_console_save(void **state)
{
    uint8_t b[PMSTEP_STORE_RECORD_MAX_BYTES];
    const long ops = 1L + (long)((pmstep_store_record_bytes() + 7u) / 8u);
    long cut;
    (void)state;
    for (cut = 1; cut <= ops; ++cut) {
        uint32_t n;
        fake_flash_init(&flash);
        assert_int_equal(boot(), PMSTEP_STORE_EMPTY);
        n = motor_record(b, BOARD_ID, 0.02f);
        write_record(b, n, 58u);
        assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), 0);
        assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_SAVE), PMSTEP_STORE_OK);
        n = motor_record(b, BOARD_ID, 0.03f);
        write_record(b, n, 58u);
        assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_APPLY), 0);
        fake_flash_cut_after(&flash, cut);
        assert_int_equal(ack(PMSTEP_CONSOLE_CONFIG_SAVE), PMSTEP_STORE_ERR_FLASH);
        fake_flash_power_on(&flash);
        assert_int_equal(boot(), PMSTEP_STORE_OK);
        assert_true(cfg.motor.inertia_kgm2 == 0.02f);
    }
}

static void test_no_store_attached(void **state)
{
    reply_t r;
    (void)state;
    pmstep_console_init(&con, "pmstep test");
    send_request(PMSTEP_CONSOLE_CONFIG_STATUS, NULL, 0u);
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_STATUS), PMSTEP_CONSOLE_ERR_NO_STORE);
    send_request(PMSTEP_CONSOLE_CONFIG_SAVE, NULL, 0u);
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(error_code(&r, PMSTEP_CONSOLE_CONFIG_SAVE), PMSTEP_CONSOLE_ERR_NO_STORE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_hello_says_not_configured, setup),
        cmocka_unit_test_setup(test_empty_store_refuses_start, setup),
        cmocka_unit_test_setup(test_status_names_boot_outcome, setup),
        cmocka_unit_test_setup(test_write_apply_save_boot, setup),
        cmocka_unit_test_setup(test_refused_records_change_nothing, setup),
        cmocka_unit_test_setup(test_write_out_of_order_refused, setup),
        cmocka_unit_test_setup(test_not_while_running, setup),
        cmocka_unit_test_setup(test_defaults_and_erase, setup),
        cmocka_unit_test_setup(test_power_cut_in_console_save, setup),
        cmocka_unit_test_setup(test_stepdir_settings_set_saved_and_booted, setup),
        cmocka_unit_test_setup(test_stepdir_tracker_settings, setup),
        cmocka_unit_test_setup(test_boot_record_before_stepdir_settings, setup),
        cmocka_unit_test_setup(test_no_store_attached, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
