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

static void send_request(uint8_t type, const void *data, uint32_t n)
{
    console_test_send(&con, type, ++seq, data, n);
}

static unsigned replies(reply_t *r, unsigned max)
{
    return console_test_take_replies(&con, r, max);
}

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
        cmocka_unit_test_setup(test_no_store_attached, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
