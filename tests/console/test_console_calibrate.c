/*
 * Self-commissioning through the console (pmstep_console_calibrate.c) on the SIL's plant: a
 * 17HS4401 preset on the host port (its measurement chain and bridge), the console and the store
 * attached as on the board. CALIBRATE from the rated current alone: the runs advance at the period
 * boundaries, other commands get BUSY meanwhile, and at the end the design is in force, the drive
 * configured and the record saved; STOP cancels (the board's defaults back, not configured); a motor
 * with both phases open fails by name.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "console_test_frame.h"
#include "fake_flash.h"
#include "pmstep_console.h"
#include "pmstep_hal_host.h"
#include "sil/runner.h"
#include "sil/scenario.h"

#ifndef PRESET_17HS4401
#error "PRESET_17HS4401: the path of sil/scenarios/motors/17hs4401.ini"
#endif

static sil_scenario_t sc;
static plant_t plant;
static pmstep_t motor;
static pmstep_config_t cfg;
static pmstep_config_t defaults;
static pmstep_console_t con;
static pmstep_console_snapshot_t snap;
static fake_flash_t flash;
static pmstep_store_t store;
static pmstep_console_store_t cs;
static pmstep_calibrate_t cal;
static uint8_t seq;

typedef console_test_reply_t reply_t;

static void period(void);

/* The board: the preset's drive (period, delay, sensing, dead time); the plant: its motor. */
static void board(sil_fault_config_t faults)
{
    char err[256];
    sil_scenario_paper(&sc);
    assert_int_equal(sil_scenario_load(&sc, PRESET_17HS4401, err, sizeof err), 0);
    sc.faults = faults;
    sc.load.kind = PLANT_LOAD_NONE;
    defaults = sc.controller;
    assert_int_equal(sil_bind_plant(&sc, &plant), 0);
    fake_flash_init(&flash);
    assert_int_equal(pmstep_store_init(&store, &flash.ops, 7u), PMSTEP_STORE_OK);
    assert_int_equal(pmstep_console_store_boot(&cs, &store, &defaults, &cfg), PMSTEP_STORE_EMPTY);
    assert_int_equal(pmstep_init(&motor, &cfg), PMSTEP_OK);
    pmstep_console_init(&con, "pmstep test");
    pmstep_console_attach_store(&con, &cs);
    memset(&cal, 0, sizeof cal);
    pmstep_console_attach_calibration(&con, &cal);
    memset(&snap, 0, sizeof snap);
    snap.period = UINT32_MAX;
    period(); /* the bus measured once, as a board does every period from reset */
}

static int teardown(void **state)
{
    (void)state;
    pmstep_hal_host_release();
    return 0;
}

static void send_request(uint8_t type, const void *data, uint32_t n) { console_test_send(&con, type, ++seq, data, n); }

static unsigned replies(reply_t *r, unsigned max) { return console_test_take_replies(&con, r, max); }

/* One period: the boundary (as the application calls it while the console is pending), then the
 * step on the plant. */
static void period(void)
{
    pmstep_meas_t meas;
    if (pmstep_console_pending(&con)) {
        pmstep_console_boundary(&con, &motor, &cfg, &snap);
    }
    plant.time_s = (double)(snap.period + 1u) * (double)sc.controller.timing.period_s;
    pmstep_hal_read_measurements(&meas);
    pmstep_step(&motor, &meas, &snap.out);
    pmstep_hal_apply_output(&snap.out);
    sil_drive_advance(&plant, pmstep_hal_host_inverter(), (double)sc.controller.timing.period_s, sc.substeps);
    snap.meas = meas;
    snap.period++;
}

static void calibrate_request(float rated_A)
{
    uint8_t d[6];
    const uint16_t p = 50u;
    reply_t r;
    memcpy(d, &rated_A, 4u);
    memcpy(&d[4], &p, 2u);
    send_request(PMSTEP_CONSOLE_CALIBRATE, d, sizeof d);
    period();
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(r.type, PMSTEP_CONSOLE_CALIBRATE | 0x80u);
    assert_int_equal(console_test_i16(r.data), PMSTEP_OK);
}

/* Periods until the console no longer needs the boundary (the calibration over and saved), at most
 * @p seconds; a request of @p busy_type sent once a second meanwhile must get BUSY. */
static void run_calibration(double seconds, uint8_t busy_type)
{
    const uint32_t per_second = (uint32_t)(1.0 / (double)sc.controller.timing.period_s);
    uint32_t k;
    for (k = 0; k < (uint32_t)(seconds * per_second) && con.calibrating; ++k) {
        period();
        if (busy_type != 0u && k % per_second == per_second / 2u) {
            reply_t r;
            send_request(busy_type, NULL, 0u);
            period();
            assert_int_equal(replies(&r, 1), 1u);
            assert_int_equal(r.type, PMSTEP_CONSOLE_ERROR_FRAME);
            assert_int_equal(r.data[1], PMSTEP_CONSOLE_ERR_BUSY);
        }
    }
}

static void calibrates_saves_and_runs(void **state)
{
    const sil_fault_config_t none = {SIL_PHASES_NONE, 0.0, SIL_SENSOR_OK, SIL_PHASES_NONE, 0.0};
    reply_t r;
    pmstep_store_record_t stored;
    (void)state;
    board(none);
    calibrate_request(1.7f);
    run_calibration(20.0, PMSTEP_CONSOLE_START);
    send_request(PMSTEP_CONSOLE_CALIBRATE_STATUS, NULL, 0u);
    assert_int_equal(replies(&r, 1), 1u);
    print_message("calibrate: stage %u status %d runs %u; R %.4g L %.4g k_M %.4g J %.4g F %.4g\n", r.data[0],
                  console_test_i16(&r.data[1]), r.data[4], (double)console_test_f32(&r.data[8]),
                  (double)console_test_f32(&r.data[12]), (double)console_test_f32(&r.data[16]),
                  (double)console_test_f32(&r.data[20]), (double)console_test_f32(&r.data[24]));
    assert_int_equal(r.data[0], PMSTEP_CALIBRATE_DONE);
    assert_int_equal(console_test_i16(&r.data[1]), 0);
    assert_int_equal(console_test_i16(&r.data[6]), PMSTEP_STORE_OK); /* saved */
    /* within 5 % of the plant's R, L, k_M and 10 % of its J */
    assert_true(console_test_f32(&r.data[8]) > 0.95f * 1.5f && console_test_f32(&r.data[8]) < 1.05f * 1.5f);
    assert_true(console_test_f32(&r.data[12]) > 0.95f * 0.0028f && console_test_f32(&r.data[12]) < 1.05f * 0.0028f);
    assert_true(console_test_f32(&r.data[16]) > 0.95f * 0.16638f && console_test_f32(&r.data[16]) < 1.05f * 0.16638f);
    assert_true(console_test_f32(&r.data[20]) > 0.9f * 5.4e-6f && console_test_f32(&r.data[20]) < 1.1f * 5.4e-6f);
    assert_true(cs.configured);
    assert_true(cfg.motor.resistance_Ohm == console_test_f32(&r.data[8]));
    /* the record at the next boot is the design in force */
    assert_int_equal(pmstep_store_load(&store, &defaults, &stored, NULL), PMSTEP_STORE_OK);
    assert_memory_equal(&stored.config.gains, &cfg.gains, sizeof cfg.gains);
    /* and it runs: START, then 40 rad/s */
    {
        const float target[2] = {40.0f, 500.0f};
        uint32_t k;
        send_request(PMSTEP_CONSOLE_START, NULL, 0u);
        period();
        assert_int_equal(replies(&r, 1), 1u);
        assert_int_equal(console_test_i16(r.data), PMSTEP_OK);
        for (k = 0; k < 20000u; ++k) { /* 1 s: alignment, then RUN */
            period();
        }
        send_request(PMSTEP_CONSOLE_SPEED_TARGET, target, sizeof target);
        for (k = 0; k < 20000u; ++k) {
            period();
        }
        (void)replies(&r, 1);
        assert_int_equal(snap.out.mode, PMSTEP_MODE_RUN);
        assert_true(plant.x.omega_rad_s > 38.0 && plant.x.omega_rad_s < 42.0);
    }
}

static void stop_cancels(void **state)
{
    const sil_fault_config_t none = {SIL_PHASES_NONE, 0.0, SIL_SENSOR_OK, SIL_PHASES_NONE, 0.0};
    reply_t r;
    uint32_t k;
    (void)state;
    board(none);
    calibrate_request(1.7f);
    for (k = 0; k < 10000u; ++k) {
        period();
    }
    send_request(PMSTEP_CONSOLE_STOP, NULL, 0u);
    period();
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(r.type, PMSTEP_CONSOLE_STOP | 0x80u);
    assert_false(con.calibrating);
    assert_int_equal(cal.status, PMSTEP_CALIBRATE_ERR_CANCELLED);
    assert_false(cs.configured);
    assert_memory_equal(&cfg, &defaults, sizeof cfg);
    period();
    assert_false(snap.out.bridge_enable);
    assert_int_equal(flash.programs, 0u);
}

static void open_phases_fail_by_name(void **state)
{
    const sil_fault_config_t open = {SIL_PHASES_BOTH, 0.0, SIL_SENSOR_OK, SIL_PHASES_NONE, 0.0};
    (void)state;
    board(open);
    calibrate_request(1.7f);
    run_calibration(20.0, 0u);
    assert_int_equal(cal.stage, PMSTEP_CALIBRATE_FAILED);
    assert_int_equal(cal.status, PMSTEP_CALIBRATE_ERR_NO_MOTOR);
    assert_false(cs.configured);
    assert_int_equal(flash.programs, 0u);
}

static void bad_requests_refused(void **state)
{
    const sil_fault_config_t none = {SIL_PHASES_NONE, 0.0, SIL_SENSOR_OK, SIL_PHASES_NONE, 0.0};
    uint8_t d[6];
    const float bad = -1.0f;
    const uint16_t p = 50u;
    reply_t r;
    (void)state;
    board(none);
    memcpy(d, &bad, 4u);
    memcpy(&d[4], &p, 2u);
    send_request(PMSTEP_CONSOLE_CALIBRATE, d, sizeof d);
    period();
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(console_test_i16(r.data), PMSTEP_CALIBRATE_ERR_REQUEST);
    assert_false(con.calibrating);
    send_request(PMSTEP_CONSOLE_CALIBRATE, d, 5u);
    assert_int_equal(replies(&r, 1), 1u);
    assert_int_equal(r.data[1], PMSTEP_CONSOLE_ERR_BAD_LENGTH);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_teardown(calibrates_saves_and_runs, teardown),
        cmocka_unit_test_teardown(stop_cancels, teardown),
        cmocka_unit_test_teardown(open_phases_fail_by_name, teardown),
        cmocka_unit_test_teardown(bad_requests_refused, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
