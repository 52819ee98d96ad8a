/*
 * The STM32G431 application built in STEP/DIR mode (app.c with PMSTEP_STM32G4_STEPDIR=1) on the
 * behavioural model: the port's STEP/DIR input set up at boot, the step count read by the control
 * interrupt every period, EN starting the drive and releasing it (bridge off, IDLE, no fault
 * latched), DIAG deasserted while the core is IDLE without a fault; the STEP/DIR settings from the
 * stored record at boot and from the console at once.
 * (The default build, without the mode, is checked in test_stm32g4_model.c.)
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "app.h"
#include "pmstep_console.h"
#include "pmstep_hal_stm32g4.h"
#include "stm32g4_model.h"
#include "stm32g4_regs.h"
#include "model_console_host.h"

#define M stm32g4_model

static pmstep_stm32g4_config_t board;

/* The ADC counts of a bus voltage on the board's divider. */
static uint16_t bus_counts(float bus_V)
{
    return (uint16_t)(bus_V / board.bus_gain_v_per_count + board.bus_offset_counts + 0.5f);
}

static int setup(void **state)
{
    (void)state;
    stm32g4_model_reset();
    stm32g4_model_flash_erase_all();
    board = pmstep_stm32g4_default_config(); /* the pins the application uses */
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    M.analog_counts[0][board.adc1_channel_i_a] = 2048u;
    M.analog_counts[1][board.adc2_channel_i_b] = 2048u;
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(48.0f);
    return 0;
}

static void pulses(uint32_t n, bool dir_high)
{
    const pmstep_stm32g4_pin_t step = board.step_input.step_pin;
    const pmstep_stm32g4_pin_t dir = board.step_input.dir_pin;
    uint32_t k;
    stm32g4_model_pin_in(dir.port, dir.pin, dir_high);
    stm32g4_model_run(40u);
    for (k = 0; k < n; ++k) {
        stm32g4_model_pin_in(step.port, step.pin, true);
        stm32g4_model_run(34u); /* 200 ns high, 200 ns low: 2.5 MHz */
        stm32g4_model_pin_in(step.port, step.pin, false);
        stm32g4_model_run(34u);
    }
}

static void test_app_counts_steps_each_period(void **state)
{
    const uint32_t period_ticks = 2u * pmstep_stm32g4_pwm_arr(170000000u, board.pwm_frequency_Hz);
    (void)state;
    stm32g4_model_pin_in(board.step_input.enable_pin.port, board.step_input.enable_pin.pin, false); /* enabled */
    assert_int_equal(pmstep_app_init(), 0);
    /* The mode is on: TIM4 counting in clock plus direction x1. */
    assert_true((stm32g4_fake.rcc.APB1ENR1 & RCC_APB1ENR1_TIM4EN) != 0u);
    assert_int_equal(stm32g4_fake.tim4.SMCR & TIM_SMCR_SMS_MASK, TIM_SMCR_SMS_CLOCK_DIR_X1);
    assert_true((stm32g4_fake.tim4.CR1 & TIM_CR1_CEN) != 0u);
    /* 3000 steps forward over about 24 periods, 500 back: the control interrupt's count follows. */
    pulses(3000u, true);
    stm32g4_model_run(period_ticks);
    assert_true(M.adc_irqs > 20u);
    assert_int_equal(pmstep_app_step_count(), 3000);
    pulses(500u, false);
    stm32g4_model_run(period_ticks);
    assert_int_equal(pmstep_app_step_count(), 2500);
    /* IDLE, no fault: DIAG (active high, open drain) pulled low; the bridge off. */
    assert_true(stm32g4_model_pin_drives_low(board.step_input.diag_pin.port, board.step_input.diag_pin.pin));
    assert_false(pmstep_stm32g4_bridge_on());
}

/* EN left open: it reads disabled (pull-up, active low), and so does the port. */
static void test_app_en_open_reads_disabled(void **state)
{
    (void)state;
    stm32g4_model_pin_float(board.step_input.enable_pin.port, board.step_input.enable_pin.pin);
    assert_int_equal(pmstep_app_init(), 0);
    assert_false(pmstep_stm32g4_step_enabled());
    stm32g4_model_pin_in(board.step_input.enable_pin.port, board.step_input.enable_pin.pin, false);
    assert_true(pmstep_stm32g4_step_enabled());
}

/* ---- the console on the model's LPUART1, periods between the main loop's turns ---- */

static uint32_t uart_cursor; /* frames in M.uart_tx before this are read */

/* @p periods carrier periods, the main loop turning four times per period. */
static void app_run(unsigned periods)
{
    const uint32_t arr = pmstep_stm32g4_pwm_arr(170000000u, board.pwm_frequency_Hz);
    unsigned k;
    for (k = 0; k < 4u * periods; ++k) {
        stm32g4_model_run(arr / 2u);
        pmstep_app_poll();
    }
}

/* SET_CONFIG by name over the UART: @return the ACK's status (an error reply fails the test). */
static int16_t console_set(uint8_t seq, const char *name, float value)
{
    uint8_t d[64];
    const uint32_t k = (uint32_t)strlen(name);
    int n;
    d[0] = 0xFFu;
    memcpy(&d[1], &value, 4u);
    memcpy(&d[5], name, k);
    model_host_send(PMSTEP_CONSOLE_SET_CONFIG, seq, d, 5u + k);
    app_run(2u);
    n = model_host_receive(&uart_cursor, PMSTEP_CONSOLE_SET_CONFIG | 0x80u, d);
    assert_int_equal(n, 6);
    return (int16_t)(d[0] | (d[1] << 8));
}

/* A record of the paper's motor for this board with STEP/DIR settings @p sd, saved in the model's flash
 * through the port's driver. */
static void store_record(const pmstep_stepdir_settings_t *sd)
{
    pmstep_store_t store;
    pmstep_store_record_t rec;
    memset(&rec, 0, sizeof rec);
    rec.config =
        pmstep_console_app_config(pmstep_stm32g4_period_s(&board), 1u, pmstep_stm32g4_current_sense_range_A(&board),
                                  pmstep_stm32g4_bus_sense_range_V(&board));
    rec.stepdir = *sd;
    assert_int_equal(pmstep_store_init(&store, pmstep_stm32g4_store_flash(), pmstep_stm32g4_board_id()),
                     PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_save(&store, &rec, true), PMSTEP_STORE_OK);
}

/* The stored STEP/DIR settings on the pins from boot (EN active high: pulled down, an open line
 * disabled; DIAG active low: released while deasserted); the console's changes at once. */
static void test_app_stepdir_settings_stored_and_set(void **state)
{
    const pmstep_stm32g4_pin_t en = board.step_input.enable_pin;
    const pmstep_stm32g4_pin_t diag = board.step_input.diag_pin;
    pmstep_stepdir_settings_t sd = pmstep_console_stepdir_defaults();
    (void)state;
    sd.enable_active_high = true;
    sd.diag_active_high = false;
    sd.microsteps = 32u;
    store_record(&sd);
    stm32g4_model_reset(); /* a power cycle: the flash keeps it */
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(48.0f);
    stm32g4_model_pin_float(en.port, en.pin);
    assert_int_equal(pmstep_app_init(), 0);
    uart_cursor = 0u;
    assert_false(pmstep_stm32g4_step_enabled()); /* pulled down: disabled */
    stm32g4_model_pin_in(en.port, en.pin, true);
    assert_true(pmstep_stm32g4_step_enabled());
    stm32g4_model_pin_in(en.port, en.pin, false);
    assert_false(pmstep_stm32g4_step_enabled());
    app_run(3u);
    assert_false(stm32g4_model_pin_drives_low(diag.port, diag.pin)); /* deasserted, active low: released */
    /* The console: EN back to active low, DIAG to active high, in force at the boundary. */
    assert_int_equal(console_set(1u, "stepdir.enable_active_high", 0.0f), PMSTEP_OK);
    stm32g4_model_pin_float(en.port, en.pin);
    assert_false(pmstep_stm32g4_step_enabled()); /* pulled up now: disabled */
    stm32g4_model_pin_in(en.port, en.pin, false);
    assert_true(pmstep_stm32g4_step_enabled());
    stm32g4_model_pin_in(en.port, en.pin, true);
    assert_int_equal(console_set(2u, "stepdir.diag_active_high", 1.0f), PMSTEP_OK);
    app_run(2u);
    assert_true(stm32g4_model_pin_drives_low(diag.port, diag.pin)); /* deasserted, active high: pulled low */
    /* Out of range: refused by name, nothing changed. */
    assert_int_equal(console_set(3u, "stepdir.microsteps", 512.0f), PMSTEP_ERR_STEPDIR_MICROSTEPS);
}

/* The last period's output as the control interrupt left it. */
static pmstep_output_t last_out(void)
{
    pmstep_output_t out;
    pmstep_meas_t meas;
    uint8_t port_fault;
    pmstep_stm32g4_last_period(&out, &meas, &port_fault);
    return out;
}

static void en(bool enabled) /* EN active low, as the defaults have it */
{
    stm32g4_model_pin_in(board.step_input.enable_pin.port, board.step_input.enable_pin.pin, !enabled);
}

/* A configured drive (the paper's motor from the flash), booted with EN released. */
static void boot_configured(void)
{
    const pmstep_stepdir_settings_t sd = pmstep_console_stepdir_defaults();
    store_record(&sd);
    stm32g4_model_reset();
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    M.analog_counts[0][board.adc1_channel_i_a] = 2048u;
    M.analog_counts[1][board.adc2_channel_i_b] = 2048u;
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(48.0f);
    en(false);
    assert_int_equal(pmstep_app_init(), 0);
    uart_cursor = 0u;
}

/* EN as a TMC driver's: asserted, the drive starts (alignment first); released, the bridge off and the
 * drive IDLE with no fault; asserted again, it starts again. What was counted while disabled is dropped
 * when EN starts the drive, so following never replays it. */
static void test_app_en_starts_and_stops_the_drive(void **state)
{
    const pmstep_stm32g4_pin_t diag = board.step_input.diag_pin;
    pmstep_output_t out;
    (void)state;
    boot_configured();
    app_run(5u);
    out = last_out();
    assert_int_equal(out.mode, PMSTEP_MODE_IDLE);
    assert_false(pmstep_stm32g4_bridge_on());
    pulses(100u, true); /* steps while disabled: counted, moving nothing */
    app_run(2u);
    assert_int_equal(pmstep_app_step_count(), 100);
    assert_int_equal(last_out().mode, PMSTEP_MODE_IDLE);
    /* Asserted: the alignment starts at the next period, the bridge on; the count starts from 0 here. */
    en(true);
    app_run(3u);
    out = last_out();
    assert_int_equal(out.mode, PMSTEP_MODE_S_ALIGN);
    assert_true(out.bridge_enable);
    assert_true(pmstep_stm32g4_bridge_on());
    assert_int_equal(pmstep_app_step_count(), 0);
    assert_true(stm32g4_model_pin_drives_low(diag.port, diag.pin)); /* no fault: DIAG deasserted */
    /* Released: the bridge off at once, the drive IDLE, nothing latched. */
    en(false);
    app_run(2u);
    out = last_out();
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(out.mode, PMSTEP_MODE_IDLE);
    assert_int_equal(out.fault, PMSTEP_FAULT_NONE);
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_NONE);
    assert_true(stm32g4_model_pin_drives_low(diag.port, diag.pin));
    app_run(20u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_IDLE); /* stays so while EN is released */
    assert_false(pmstep_stm32g4_bridge_on());
    /* Asserted again: it starts again. */
    en(true);
    app_run(3u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_S_ALIGN);
    assert_true(pmstep_stm32g4_bridge_on());
}

/* A fault with EN asserted latches (DIAG asserted) and stays latched while EN stays asserted; releasing
 * EN clears it (the drive IDLE, DIAG deasserted), and asserting EN starts the drive again. */
static void test_app_en_release_clears_a_fault(void **state)
{
    const pmstep_stm32g4_pin_t diag = board.step_input.diag_pin;
    pmstep_output_t out;
    (void)state;
    boot_configured();
    en(true);
    app_run(3u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_S_ALIGN);
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(20.0f); /* below the 30 V minimum */
    app_run(5u);
    out = last_out();
    assert_int_equal(out.mode, PMSTEP_MODE_FAULT);
    assert_int_equal(out.fault, PMSTEP_FAULT_BUS_UNDERVOLTAGE);
    assert_false(pmstep_stm32g4_bridge_on());
    assert_false(stm32g4_model_pin_drives_low(diag.port, diag.pin)); /* asserted (active high): released */
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(48.0f);
    app_run(20u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_FAULT); /* EN held asserted: latched */
    en(false);
    app_run(2u);
    out = last_out();
    assert_int_equal(out.mode, PMSTEP_MODE_IDLE);
    assert_int_equal(out.fault, PMSTEP_FAULT_NONE);
    assert_true(stm32g4_model_pin_drives_low(diag.port, diag.pin));
    en(true);
    app_run(3u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_S_ALIGN);
    assert_true(pmstep_stm32g4_bridge_on());
}

/* Only EN's edges: a console STOP with EN held asserted stays stopped; EN asserted on a drive with no
 * motor configured starts nothing. */
static void test_app_en_edges_only(void **state)
{
    uint8_t d[64];
    (void)state;
    boot_configured();
    en(true);
    app_run(3u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_S_ALIGN);
    model_host_send(PMSTEP_CONSOLE_STOP, 1u, NULL, 0u);
    app_run(2u);
    assert_int_equal(model_host_receive(&uart_cursor, PMSTEP_CONSOLE_STOP | 0x80u, d), 6);
    app_run(20u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_IDLE);
    assert_false(pmstep_stm32g4_bridge_on());
    /* No motor configured (an empty flash): EN asserted at boot and after starts nothing. */
    stm32g4_model_reset();
    stm32g4_model_flash_erase_all();
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(48.0f);
    en(true);
    assert_int_equal(pmstep_app_init(), 0);
    app_run(5u);
    en(false);
    app_run(2u);
    en(true);
    app_run(5u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_IDLE);
    assert_false(pmstep_stm32g4_bridge_on());
}

/* A configured drive powered up with EN already asserted starts by itself. */
static void test_app_en_asserted_at_boot_starts(void **state)
{
    const pmstep_stepdir_settings_t sd = pmstep_console_stepdir_defaults();
    (void)state;
    store_record(&sd);
    stm32g4_model_reset();
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    M.analog_counts[0][board.adc1_channel_i_a] = 2048u;
    M.analog_counts[1][board.adc2_channel_i_b] = 2048u;
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(48.0f);
    en(true);
    assert_int_equal(pmstep_app_init(), 0);
    app_run(3u);
    assert_int_equal(last_out().mode, PMSTEP_MODE_S_ALIGN);
    assert_true(pmstep_stm32g4_bridge_on());
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_app_counts_steps_each_period, setup),
        cmocka_unit_test_setup(test_app_en_open_reads_disabled, setup),
        cmocka_unit_test_setup(test_app_stepdir_settings_stored_and_set, setup),
        cmocka_unit_test_setup(test_app_en_starts_and_stops_the_drive, setup),
        cmocka_unit_test_setup(test_app_en_release_clears_a_fault, setup),
        cmocka_unit_test_setup(test_app_en_edges_only, setup),
        cmocka_unit_test_setup(test_app_en_asserted_at_boot_starts, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
