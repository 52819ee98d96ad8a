/*
 * Unit tests of the simulation images' STEP/DIR requests (SIM_STEPS, SIM_FOLLOW_STEPS, SIM_STEPDIR) and
 * the emulated step counter: their refusal where the input is not attached, the lengths and BUSY, the
 * counter read as a port reads its timer (every edge counted through the 16-bit wrap, both ways), and
 * following through the mailbox at the period boundary. RUN is given to the position library as the
 * core's output would give it (mode RUN, the estimate's c-hat, s-hat), as in console.position.
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
static pmstep_stepdir_t stepdir;
static pmstep_console_snapshot_t snap;

typedef console_test_reply_t reply_t;

static int setup(void **state)
{
    pmstep_position_config_t gains;
    (void)state;
    pmstep_console_init(&con, "pmstep test");
    cfg = pmstep_console_app_config(50e-6f, 1u, 16.5f, 66.0f);
    assert_int_equal(pmstep_init(&motor, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_position_design(&cfg, &gains), PMSTEP_OK);
    assert_int_equal(pmstep_position_init(&position, &motor, &gains), PMSTEP_OK);
    memset(&stepdir, 0, sizeof stepdir);
    memset(&snap, 0, sizeof snap);
    snap.period = 99u;
    return 0;
}

/* A simulation image with position control and the STEP/DIR input attached. */
static void attach_all(void)
{
    pmstep_console_attach_simulation(&con);
    pmstep_console_attach_position(&con, &position);
    assert_int_equal(pmstep_console_attach_sim_stepdir(&con, &stepdir, &cfg), PMSTEP_OK);
}

/* The one frame the console transmitted. */
static reply_t one_reply(void)
{
    reply_t r;
    assert_int_equal(console_test_take_replies(&con, &r, 1u), 1u);
    return r;
}

static void expect_error(uint8_t type, uint8_t code)
{
    const reply_t r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_ERROR_FRAME);
    assert_int_equal(r.n, 2u);
    assert_int_equal(r.data[0], type);
    assert_int_equal(r.data[1], code);
}

/* An ACK to @p type: its status. */
static int16_t expect_ack(uint8_t type)
{
    const reply_t r = one_reply();
    assert_int_equal(r.type, type | 0x80u);
    assert_int_equal(r.n, 6u);
    return console_test_i16(r.data);
}

/* @p n periods of the same @p edges each. */
static void queue_steps(int8_t edges, uint32_t n)
{
    int8_t data[PMSTEP_CONSOLE_SIM_STEPS_MAX];
    uint32_t k;
    for (k = 0; k < n; ++k) {
        data[k] = edges;
    }
    console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPS, 1u, data, n);
    assert_int_equal(expect_ack(PMSTEP_CONSOLE_SIM_STEPS), 0);
}

/* One period as the image runs it after the core's step: the counter read, the position update (the
 * estimate at electrical angle @p angle, in RUN if @p run), DIAG. */
static void period(double angle, bool run)
{
    pmstep_output_t out;
    pmstep_position_output_t pos_out;
    memset(&out, 0, sizeof out);
    out.mode = run ? PMSTEP_MODE_RUN : PMSTEP_MODE_IDLE;
    out.cos_hat = (float)cos(angle);
    out.sin_hat = (float)sin(angle);
    pmstep_stepdir_count(&stepdir, pmstep_console_sim_steps_period(&con));
    pmstep_position_update(&position, &out, &pos_out);
    (void)pmstep_stepdir_diag(&stepdir, out.mode, pos_out.position_rad, pos_out.tracked);
    snap.period++;
}

/* SIM_STEPDIR through the mailbox. */
static reply_t read_stepdir(void)
{
    reply_t r;
    console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPDIR, 7u, NULL, 0u);
    assert_true(pmstep_console_pending(&con));
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_SIM_STEPDIR | 0x80u);
    assert_int_equal(r.seq, 7u);
    assert_int_equal(r.n, 23u);
    return r;
}

static int32_t i32_at(const uint8_t *p) { return (int32_t)console_test_u32(p); }

/* A hardware image, and a simulation image without the input: all three refused, counted, nothing
 * attached without simulation or position control. */
static void test_refused_without_the_input(void **state)
{
    const int8_t edges[2] = {1, -1};
    unsigned round;
    (void)state;
    for (round = 0; round < 2u; ++round) {
        console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPS, 1u, edges, 2u);
        expect_error(PMSTEP_CONSOLE_SIM_STEPS, PMSTEP_CONSOLE_ERR_NOT_SUPPORTED);
        console_test_send(&con, PMSTEP_CONSOLE_SIM_FOLLOW_STEPS, 2u, NULL, 0u);
        expect_error(PMSTEP_CONSOLE_SIM_FOLLOW_STEPS, PMSTEP_CONSOLE_ERR_NOT_SUPPORTED);
        console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPDIR, 3u, NULL, 0u);
        expect_error(PMSTEP_CONSOLE_SIM_STEPDIR, PMSTEP_CONSOLE_ERR_NOT_SUPPORTED);
        assert_int_equal(pmstep_console_attach_sim_stepdir(&con, &stepdir, &cfg), PMSTEP_ERR_NULL_ARGUMENT);
        pmstep_console_attach_simulation(&con); /* the second round: simulation, no position control */
    }
    assert_null(con.sim_stepdir);
    assert_int_equal(con.count.rx_error_replies, 6u);
    assert_false(pmstep_console_pending(&con));
}

/* SIM_STEPS: 1 to 60 periods; BUSY while edges of the last one remain or a SIM_ADVANCE runs. */
static void test_steps_lengths_and_busy(void **state)
{
    int8_t data[PMSTEP_CONSOLE_SIM_STEPS_MAX + 1u];
    const uint32_t periods = 5u;
    uint32_t k;
    (void)state;
    memset(data, 1, sizeof data);
    attach_all();
    console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPS, 1u, NULL, 0u);
    expect_error(PMSTEP_CONSOLE_SIM_STEPS, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPS, 1u, data, PMSTEP_CONSOLE_SIM_STEPS_MAX + 1u);
    expect_error(PMSTEP_CONSOLE_SIM_STEPS, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    console_test_send(&con, PMSTEP_CONSOLE_SIM_FOLLOW_STEPS, 1u, data, 1u);
    expect_error(PMSTEP_CONSOLE_SIM_FOLLOW_STEPS, PMSTEP_CONSOLE_ERR_BAD_LENGTH);
    console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPDIR, 1u, data, 4u);
    expect_error(PMSTEP_CONSOLE_SIM_STEPDIR, PMSTEP_CONSOLE_ERR_BAD_LENGTH);

    queue_steps(3, PMSTEP_CONSOLE_SIM_STEPS_MAX);
    console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPS, 2u, data, 1u);
    expect_error(PMSTEP_CONSOLE_SIM_STEPS, PMSTEP_CONSOLE_ERR_BUSY); /* the first's edges not out yet */
    for (k = 0; k < PMSTEP_CONSOLE_SIM_STEPS_MAX; ++k) {
        assert_int_equal(pmstep_console_sim_steps_period(&con), (uint16_t)(3u * (k + 1u)));
    }
    assert_int_equal(pmstep_console_sim_steps_period(&con), 3u * PMSTEP_CONSOLE_SIM_STEPS_MAX); /* none left */

    console_test_send(&con, PMSTEP_CONSOLE_SIM_ADVANCE, 3u, &periods, 4u);
    assert_int_equal(pmstep_console_advance_request(&con), periods);
    console_test_send(&con, PMSTEP_CONSOLE_SIM_STEPS, 4u, data, 1u);
    expect_error(PMSTEP_CONSOLE_SIM_STEPS, PMSTEP_CONSOLE_ERR_BUSY); /* periods under way */
    pmstep_console_advance_done(&con, 105u);
    (void)one_reply();
    queue_steps(-2, 1u);
    assert_int_equal(pmstep_console_sim_steps_period(&con), 3u * PMSTEP_CONSOLE_SIM_STEPS_MAX - 2u);
    assert_int_equal(con.count.rx_error_replies, 6u);
}

/* Bursts of up to 127 edges a period, forward through two turns of the counter and back across its
 * wrap: the input counts every edge; SIM_STEPDIR reports the count, the edges, the counter. */
static void test_every_edge_counted_through_the_wrap(void **state)
{
    int32_t sum = 0;
    uint32_t k;
    reply_t r;
    (void)state;
    attach_all();
    for (k = 0; k < 20u; ++k) { /* 20 x 60 x 127 = 152400 */
        uint32_t p;
        queue_steps(127, PMSTEP_CONSOLE_SIM_STEPS_MAX);
        for (p = 0; p < PMSTEP_CONSOLE_SIM_STEPS_MAX; ++p) {
            period(0.0, false);
        }
        sum += 127 * (int32_t)PMSTEP_CONSOLE_SIM_STEPS_MAX;
        assert_int_equal(stepdir.steps, sum);
    }
    for (k = 0; k < 3u; ++k) { /* back 3 x 60 x 128 = 23040, across 2 x 65536 */
        uint32_t p;
        queue_steps(-128, PMSTEP_CONSOLE_SIM_STEPS_MAX);
        for (p = 0; p < PMSTEP_CONSOLE_SIM_STEPS_MAX; ++p) {
            period(0.0, false);
        }
        sum -= 128 * (int32_t)PMSTEP_CONSOLE_SIM_STEPS_MAX;
    }
    period(0.0, false); /* a period without edges */
    assert_int_equal(sum, 129360);
    assert_int_equal(stepdir.steps, sum);
    r = read_stepdir();
    assert_int_equal(console_test_u32(&r.data[0]), snap.period);
    assert_int_equal(i32_at(&r.data[4]), sum);                                /* the input's count */
    assert_int_equal(i32_at(&r.data[8]), sum);                                /* the counter's edges */
    assert_int_equal(r.data[12] | (r.data[13] << 8), (uint32_t)sum % 65536u); /* the counter */
    assert_int_equal(r.data[14], 0u);                                         /* not following */
    assert_float_equal(console_test_f32(&r.data[15]), (float)sum * stepdir.rad_per_microstep, 1e-2f);
    assert_float_equal(console_test_f32(&r.data[19]), 0.0f, 0.0f);
}

/* SIM_FOLLOW_STEPS: refused before RUN with the input unchanged; in RUN the input starts afresh at
 * the counter and the loop follows it from the next period. */
static void test_follow_at_the_boundary(void **state)
{
    const double q = 2.0 * 3.14159265358979 / (4.0 * (double)cfg.motor.pole_pairs * 16.0); /* 16 microsteps */
    uint32_t k;
    reply_t r;
    (void)state;
    attach_all();
    queue_steps(100, 10u);
    for (k = 0; k < 10u; ++k) {
        period(0.0, false);
    }
    console_test_send(&con, PMSTEP_CONSOLE_SIM_FOLLOW_STEPS, 1u, NULL, 0u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    assert_int_equal(expect_ack(PMSTEP_CONSOLE_SIM_FOLLOW_STEPS), PMSTEP_ERR_BAD_MODE); /* not tracked */
    assert_int_equal(stepdir.steps, 1000);
    assert_false(stepdir.following);

    period(0.0, true); /* RUN: tracked */
    console_test_send(&con, PMSTEP_CONSOLE_SIM_FOLLOW_STEPS, 2u, NULL, 0u);
    pmstep_console_boundary(&con, &motor, &cfg, &snap);
    r = one_reply();
    assert_int_equal(r.type, PMSTEP_CONSOLE_SIM_FOLLOW_STEPS | 0x80u);
    assert_int_equal(console_test_i16(r.data), PMSTEP_OK);
    assert_int_equal(console_test_u32(&r.data[2]), snap.period + 1u); /* the next period */
    assert_int_equal(stepdir.steps, 0);                               /* afresh: the bursts dropped */
    assert_int_equal(stepdir.last_counter, 1000u);
    assert_true(stepdir.following);
    assert_true(position.out.position_mode);
    assert_ptr_equal(position.steps, &stepdir);

    queue_steps(1, 40u);
    for (k = 0; k < 40u; ++k) {
        period(0.0, true); /* the estimate stays: the count runs ahead of it */
    }
    r = read_stepdir();
    assert_int_equal(i32_at(&r.data[4]), 40);
    assert_int_equal(i32_at(&r.data[8]), 1040);
    assert_int_equal(r.data[14] & (PMSTEP_CONSOLE_SIM_STEPDIR_FOLLOWING | PMSTEP_CONSOLE_SIM_STEPDIR_MOVING),
                     PMSTEP_CONSOLE_SIM_STEPDIR_FOLLOWING | PMSTEP_CONSOLE_SIM_STEPDIR_MOVING);
    assert_float_equal(console_test_f32(&r.data[15]), (float)(40.0 * q), 1e-5f); /* from the start's 0 */
    /* the following error: the count's position at the last update less that update's theta-hat (0) */
    assert_float_equal(console_test_f32(&r.data[19]), (float)((double)stepdir.steps_at_update * q), 1e-5f);
    assert_true(console_test_f32(&r.data[19]) > 0.0f);
    assert_int_equal(con.count.rx_error_replies, 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_refused_without_the_input, setup),
        cmocka_unit_test_setup(test_steps_lengths_and_busy, setup),
        cmocka_unit_test_setup(test_every_edge_counted_through_the_wrap, setup),
        cmocka_unit_test_setup(test_follow_at_the_boundary, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
