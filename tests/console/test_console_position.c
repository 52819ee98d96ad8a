/*
 * Unit tests of the console's position requests (MOVE_TO, HOLD, GET_POSITION, SET_POSITION_ZERO):
 * their parsing and encoding, the error replies (wrong length, non-finite value, no position
 * control attached) and the replies through the mailbox at the period boundary. RUN is given to
 * the position library as the core's output would give it (mode RUN, the estimate's c-hat, s-hat),
 * as in unit.test_position.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "pmstep_console.h"
#include "console_test_frame.h"

static pmstep_console_t con;
static pmstep_config_t cfg;
static pmstep_t motor;
static pmstep_position_t position;
static pmstep_console_snapshot_t snap;

static int setup(void **state)
{
    pmstep_position_config_t gains;
    (void)state;
    pmstep_console_init(&con, "pmstep test");
    cfg = pmstep_console_app_config(50e-6f, 1u, 16.5f, 66.0f);
    assert_int_equal(pmstep_init(&motor, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_position_design(&cfg, &gains), PMSTEP_OK);
    assert_int_equal(pmstep_position_init(&position, &motor, &gains), PMSTEP_OK);
    memset(&snap, 0, sizeof snap);
    snap.period = 99u;
    return 0;
}

static void request(uint8_t type, uint8_t seq, const void *data, uint32_t n)
{
    uint8_t buf[80];
    pmstep_console_receive(&con, buf, console_test_frame(buf, type, seq, data, n), 0u);
}

typedef console_test_reply_t reply_t;

/* The one frame the console transmitted. */
static reply_t one_reply(void)
{
    uint8_t tx[PMSTEP_CONSOLE_TX_BYTES];
    const uint32_t n = pmstep_console_transmit(&con, tx, sizeof tx);
    reply_t r;
    assert_int_equal(console_test_replies(tx, n, &r, 1u), 1u);
    return r;
}

static int16_t status_of(const reply_t *r) { return console_test_i16(r->data); }

static void expect_error(uint8_t type, uint8_t code)
{
    const reply_t r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_ERROR_FRAME);
    assert_int_equal(r.n, 2u);
    assert_int_equal(r.data[0], type);
    assert_int_equal(r.data[1], code);
    assert_false(pmstep_console_pending(&con));
}

/* The position library sees RUN with the estimate at electrical angle @p angle. */
static void run_period(double angle)
{
    pmstep_output_t out;
    pmstep_position_output_t pos_out;
    memset(&out, 0, sizeof out);
    out.mode = PMSTEP_MODE_RUN;
    out.cos_hat = (float)cos(angle);
    out.sin_hat = (float)sin(angle);
    pmstep_position_update(&position, &out, &pos_out);
    snap.period++;
}

/* An image in speed mode: every position request gets PMSTEP_CONSOLE_ERR_NO_POSITION, counted. */
static void test_no_position_instance(void **state)
{
    const float move[3] = {1.0f, 2.0f, 20.0f};
    (void)state;
    request(PMSTEP_CONSOLE_MOVE_TO, 1u, move, 12u);
    expect_error(PMSTEP_CONSOLE_MOVE_TO, PMSTEP_CONSOLE_ERR_NO_POSITION);
    request(PMSTEP_CONSOLE_HOLD, 2u, NULL, 0u);
    expect_error(PMSTEP_CONSOLE_HOLD, PMSTEP_CONSOLE_ERR_NO_POSITION);
    request(PMSTEP_CONSOLE_GET_POSITION, 3u, NULL, 0u);
    expect_error(PMSTEP_CONSOLE_GET_POSITION, PMSTEP_CONSOLE_ERR_NO_POSITION);
    request(PMSTEP_CONSOLE_SET_POSITION_ZERO, 4u, NULL, 0u);
    expect_error(PMSTEP_CONSOLE_SET_POSITION_ZERO, PMSTEP_CONSOLE_ERR_NO_POSITION);
    assert_int_equal(con.count.rx_error_replies, 4u);
    assert_int_equal(con.count.rx_frames, 4u);
}

static void test_wrong_length_and_non_finite(void **state)
{
    const float bad[4] = {1.0f, NAN, 20.0f, 0.0f};
    const float inf_jerk[4] = {1.0f, 2.0f, 20.0f, INFINITY};
    const float inf_target[3] = {-INFINITY, 2.0f, 20.0f};
    const float hold_nan = NAN;
    const uint8_t junk[8] = {0u};
    (void)state;
    pmstep_console_attach_position(&con, &position);
    request(PMSTEP_CONSOLE_MOVE_TO, 1u, junk, 8u);
    expect_error(PMSTEP_CONSOLE_MOVE_TO, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    request(PMSTEP_CONSOLE_MOVE_TO, 1u, junk, 0u);
    expect_error(PMSTEP_CONSOLE_MOVE_TO, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    request(PMSTEP_CONSOLE_HOLD, 2u, junk, 2u);
    expect_error(PMSTEP_CONSOLE_HOLD, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    request(PMSTEP_CONSOLE_GET_POSITION, 3u, junk, 4u);
    expect_error(PMSTEP_CONSOLE_GET_POSITION, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    request(PMSTEP_CONSOLE_SET_POSITION_ZERO, 4u, junk, 1u);
    expect_error(PMSTEP_CONSOLE_SET_POSITION_ZERO, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    request(PMSTEP_CONSOLE_MOVE_TO, 5u, bad, 16u);
    expect_error(PMSTEP_CONSOLE_MOVE_TO, PMSTEP_CONSOLE_ERR_BAD_VALUE);
    request(PMSTEP_CONSOLE_MOVE_TO, 6u, inf_jerk, 16u);
    expect_error(PMSTEP_CONSOLE_MOVE_TO, PMSTEP_CONSOLE_ERR_BAD_VALUE);
    request(PMSTEP_CONSOLE_MOVE_TO, 7u, inf_target, 12u);
    expect_error(PMSTEP_CONSOLE_MOVE_TO, PMSTEP_CONSOLE_ERR_BAD_VALUE);
    request(PMSTEP_CONSOLE_HOLD, 8u, &hold_nan, 4u);
    expect_error(PMSTEP_CONSOLE_HOLD, PMSTEP_CONSOLE_ERR_BAD_VALUE);
    assert_int_equal(con.count.rx_error_replies, 9u);
    assert_int_equal(con.count.commands_applied, 0u);
}

/* Through the mailbox: the core's refusal before RUN, then a move, the read-back, a new zero, a hold. */
static void test_requests_at_the_boundary(void **state)
{
    const float move[3] = {0.5f, 2.0f, 20.0f};
    const float bad_limit[4] = {0.5f, -2.0f, 20.0f, 0.0f};
    const double angle = 7.0; /* electrical rad: 7/p mechanical */
    reply_t r;
    (void)state;
    pmstep_console_attach_position(&con, &position);
    request(PMSTEP_CONSOLE_GET_POSITION, 1u, NULL, 0u);
    assert_true(pmstep_console_pending(&con));
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_GET_POSITION | 0x80u);
    assert_int_equal(r.seq, 1u);
    assert_int_equal(r.n, 19u);
    assert_int_equal(status_of(&r), PMSTEP_ERR_BAD_MODE); /* not in RUN: no estimate */
    assert_int_equal(r.data[18], 0u);
    request(PMSTEP_CONSOLE_MOVE_TO, 2u, move, 12u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_MOVE_TO | 0x80u);
    assert_int_equal(status_of(&r), PMSTEP_ERR_BAD_MODE);

    run_period(0.0); /* RUN's first period, then the estimate turns to 7 rad */
    run_period(3.5);
    run_period(angle);
    request(PMSTEP_CONSOLE_GET_POSITION, 3u, NULL, 0u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(status_of(&r), PMSTEP_OK);
    assert_int_equal(r.data[2] | (r.data[3] << 8), 102u); /* the period the values are from */
    assert_float_equal(console_test_f32(&r.data[6]), (float)(angle / (double)cfg.motor.pole_pairs), 1e-5f);
    assert_float_equal(console_test_f32(&r.data[10]), console_test_f32(&r.data[6]),
                       0.0f); /* speed mode: theta* = theta-hat */
    assert_float_equal(console_test_f32(&r.data[14]), 0.0f, 0.0f);
    assert_int_equal(r.data[18], PMSTEP_CONSOLE_POSITION_TRACKED);

    request(PMSTEP_CONSOLE_MOVE_TO, 4u, bad_limit, 16u); /* finite, but the core refuses it */
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(status_of(&r), PMSTEP_ERR_BAD_COMMAND_VALUE);
    request(PMSTEP_CONSOLE_MOVE_TO, 5u, move, 12u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_MOVE_TO | 0x80u);
    assert_int_equal(status_of(&r), PMSTEP_OK);
    assert_true(position.out.position_mode);
    assert_float_equal(position.motion.target, 0.5f, 0.0f);
    run_period(angle);
    request(PMSTEP_CONSOLE_GET_POSITION, 6u, NULL, 0u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(status_of(&r), PMSTEP_OK);
    assert_int_equal(r.data[18],
                     PMSTEP_CONSOLE_POSITION_TRACKED | PMSTEP_CONSOLE_POSITION_MODE | PMSTEP_CONSOLE_POSITION_MOVING);
    assert_float_equal(console_test_f32(&r.data[14]), console_test_f32(&r.data[10]) - console_test_f32(&r.data[6]),
                       0.0f);

    request(PMSTEP_CONSOLE_SET_POSITION_ZERO, 7u, NULL, 0u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_SET_POSITION_ZERO | 0x80u);
    assert_int_equal(status_of(&r), PMSTEP_OK);
    request(PMSTEP_CONSOLE_GET_POSITION, 8u, NULL, 0u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_float_equal(console_test_f32(&r.data[6]), 0.0f, 1e-6f);
    /* the target moved with it; the estimate it moved by is within the atan2 polynomial's 1.2e-5/p rad */
    assert_float_equal(position.motion.target, (float)(0.5 - angle / (double)cfg.motor.pole_pairs), 3e-6f);

    request(PMSTEP_CONSOLE_HOLD, 9u, NULL, 0u); /* in position mode: the move's limits */
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_HOLD | 0x80u);
    assert_int_equal(status_of(&r), PMSTEP_OK);
    assert_int_equal(con.count.commands_applied, 9u);
    assert_int_equal(con.count.rx_error_replies, 0u);
}

/* The HOME_STATUS reply: status, period, state, found by, stop, position. */
static reply_t home_status(uint8_t seq)
{
    reply_t r;
    request(PMSTEP_CONSOLE_HOME_STATUS, seq, NULL, 0u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_HOME_STATUS | 0x80u);
    assert_int_equal(r.n, 16u);
    return r;
}

/* HOME and HOME_STATUS: lengths and values checked at parsing, the core's refusals by code, a homing
 * started on the designer's settings with the request's, run by pmstep_console_home_period() and ended
 * (aborted) when RUN ends. */
static void test_home(void **state)
{
    const float toward_plus[3] = {1.0f, 0.5f, 2.0f};
    const float with_current[4] = {-1.0f, 0.0f, 2.0f, 0.25f};
    const float no_direction[3] = {0.0f, 0.5f, 2.0f};
    const float no_travel[3] = {1.0f, 0.5f, 0.0f};
    const float nan_speed[3] = {1.0f, NAN, 2.0f};
    pmstep_homing_config_t designed;
    pmstep_output_t out;
    pmstep_position_output_t pos_out;
    reply_t r;
    (void)state;
    assert_int_equal(pmstep_homing_design(&cfg, &designed), PMSTEP_OK);
    request(PMSTEP_CONSOLE_HOME, 1u, toward_plus, 12u);
    expect_error(PMSTEP_CONSOLE_HOME, PMSTEP_CONSOLE_ERR_NO_POSITION);
    pmstep_console_attach_position(&con, &position);
    request(PMSTEP_CONSOLE_HOME, 2u, toward_plus, 8u);
    expect_error(PMSTEP_CONSOLE_HOME, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    request(PMSTEP_CONSOLE_HOME, 3u, nan_speed, 12u);
    expect_error(PMSTEP_CONSOLE_HOME, PMSTEP_CONSOLE_ERR_BAD_VALUE);
    request(PMSTEP_CONSOLE_HOME_STATUS, 4u, toward_plus, 4u);
    expect_error(PMSTEP_CONSOLE_HOME_STATUS, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    r = home_status(5u);
    assert_int_equal(status_of(&r), PMSTEP_OK);
    assert_int_equal(r.data[6], PMSTEP_HOMING_IDLE);
    request(PMSTEP_CONSOLE_HOME, 6u, toward_plus, 12u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(status_of(&r), PMSTEP_ERR_BAD_MODE); /* not tracked */
    run_period(0.0);
    request(PMSTEP_CONSOLE_HOME, 7u, no_direction, 12u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    assert_int_equal(status_of((r = one_reply(), &r)), PMSTEP_ERR_HOMING);
    request(PMSTEP_CONSOLE_HOME, 8u, no_travel, 12u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    assert_int_equal(status_of((r = one_reply(), &r)), PMSTEP_ERR_HOMING);
    assert_int_equal(con.homing.state, PMSTEP_HOMING_IDLE);
    /* toward -, the designer's speed, a stall current of 0.25 A */
    request(PMSTEP_CONSOLE_HOME, 9u, with_current, 16u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_HOME | 0x80u);
    assert_int_equal(status_of(&r), PMSTEP_OK);
    assert_int_equal(con.homing.state, PMSTEP_HOMING_SEEKING);
    assert_true(con.homing.direction == -1.0f);
    assert_true(con.homing.cfg.speed_rad_s == designed.speed_rad_s);
    assert_true(con.homing.cfg.max_travel_rad == 2.0f);
    assert_true(con.homing.cfg.stall_current_A == 0.25f);
    assert_true(position.out.position_mode);
    assert_float_equal(position.motion.target, -2.0f, 1e-6f);
    r = home_status(10u);
    assert_int_equal(r.data[6], PMSTEP_HOMING_SEEKING);
    assert_float_equal(console_test_f32(&r.data[12]), 0.0f, 1e-6f); /* theta-hat */
    /* the image's period: the homing sees RUN end and is aborted */
    memset(&out, 0, sizeof out);
    out.mode = PMSTEP_MODE_FAULT;
    pmstep_position_update(&position, &out, &pos_out);
    pmstep_console_home_period(&con, &out, &pos_out);
    r = home_status(11u);
    assert_int_equal(r.data[6], PMSTEP_HOMING_ABORTED);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_no_position_instance, setup),
        cmocka_unit_test_setup(test_wrong_length_and_non_finite, setup),
        cmocka_unit_test_setup(test_requests_at_the_boundary, setup),
        cmocka_unit_test_setup(test_home, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
