/*
 * The STEP/DIR/EN input and the DIAG output of the STM32G431 port (pmstep_stm32g4_step_input_init(),
 * pmstep_stm32g4_step_counter(), _step_enabled(), _set_diag(), EN in the control interrupt) on the
 * behavioural model: TIM4 counting STEP edges by DIR through its input filter (stm32g4_model_tim4.c),
 * the GPIO pulls and the open-drain output, and the control interrupt feeding the count to the core's
 * step tracker (pmstep_stepdir_count()) once a period.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pmstep/pmstep_stepdir.h"
#include "pmstep_console.h"
#include "pmstep_hal_stm32g4.h"
#include "stm32g4_model.h"
#include "stm32g4_regs.h"

#define M stm32g4_model
#define T stm32g4_model_tim4

#define SYSCLK_HZ 170000000u
/* 100 ns at 170 MHz: the default shortest STEP pulse, and the filter the port picks for it. */
#define PULSE_100NS_TICKS 17u
#define FILTER_CODE_100NS 4u  /* f_DTS / 2, N = 6 */
#define FILTER_SPAN_100NS 12u /* 6 samples 2 clocks apart */

static pmstep_stm32g4_config_t board;
static pmstep_config_t motor_config;
static pmstep_t motor;
static pmstep_stepdir_t tracker; /* the core's step count, fed by the control interrupt */
static unsigned hook_periods;

static void count_steps(const pmstep_output_t *out)
{
    (void)out;
    pmstep_stepdir_count(&tracker, pmstep_stm32g4_step_counter());
    hook_periods++;
}

static int setup(void **state)
{
    (void)state;
    stm32g4_model_reset();
    stm32g4_model_flash_erase_all();
    board = pmstep_stm32g4_default_config();
    board.step_input.enabled = true;
    motor_config =
        pmstep_console_app_config(pmstep_stm32g4_period_s(&board), 1u, pmstep_stm32g4_current_sense_range_A(&board),
                                  pmstep_stm32g4_bus_sense_range_V(&board));
    assert_int_equal(pmstep_init(&motor, &motor_config), PMSTEP_OK);
    pmstep_stm32g4_set_after_step(NULL);
    hook_periods = 0u;
    return 0;
}

static void analog_idle(void)
{
    M.analog_counts[0][board.adc1_channel_i_a] = (uint16_t)lroundf(board.i_a_offset_counts);
    M.analog_counts[1][board.adc2_channel_i_b] = (uint16_t)lroundf(board.i_b_offset_counts);
    M.analog_counts[0][board.adc1_channel_bus] = (uint16_t)lroundf(48.0f / board.bus_gain_v_per_count);
}

static void en_pin(bool drive_enabled)
{
    const pmstep_stm32g4_step_input_t *in = &board.step_input;
    stm32g4_model_pin_in(in->enable_pin.port, in->enable_pin.pin, drive_enabled == in->enable_active_high);
}

static void step_level(bool high)
{
    stm32g4_model_pin_in(board.step_input.step_pin.port, board.step_input.step_pin.pin, high);
}

static void dir_level(bool high)
{
    stm32g4_model_pin_in(board.step_input.dir_pin.port, board.step_input.dir_pin.pin, high);
}

/* Clock, port (with the STEP/DIR input) and core up; STEP, DIR low; EN as said. */
static void bring_up(bool enabled)
{
    assert_int_equal(pmstep_stm32g4_clock_init(&board.clock), PMSTEP_STM32G4_OK);
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    step_level(false);
    dir_level(false);
    en_pin(enabled);
    assert_int_equal(pmstep_stm32g4_init(&board, &motor), PMSTEP_STM32G4_OK);
    analog_idle();
}

/* @p n STEP pulses, @p high_ticks high then @p low_ticks low each (timer clocks at 170 MHz). */
static void pulses(uint32_t n, uint32_t high_ticks, uint32_t low_ticks)
{
    uint32_t k;
    for (k = 0; k < n; ++k) {
        step_level(true);
        stm32g4_model_run(high_ticks);
        step_level(false);
        stm32g4_model_run(low_ticks);
    }
}

static uint32_t period_ticks(void)
{
    return 2u * pmstep_stm32g4_pwm_arr(SYSCLK_HZ, board.pwm_frequency_Hz);
}

/* ---- the filter code from the shortest pulse ---- */

static void test_filter_from_min_pulse(void **state)
{
    uint8_t icf = 99u;
    uint8_t k;
    (void)state;
    /* 100 ns = 17 clocks: the longest span that leaves 2 clocks of margin is 12 (code 0100). */
    assert_int_equal(pmstep_stm32g4_step_filter(100u, SYSCLK_HZ, &icf), PMSTEP_STM32G4_OK);
    assert_int_equal(icf, FILTER_CODE_100NS);
    assert_int_equal(pmstep_stm32g4_step_filter_ticks(icf), FILTER_SPAN_100NS);
    /* 1 us = 170 clocks: span 160 (code 1101, 5 samples 32 clocks apart); 2.5 us and more: the last code. */
    assert_int_equal(pmstep_stm32g4_step_filter(1000u, SYSCLK_HZ, &icf), PMSTEP_STM32G4_OK);
    assert_int_equal(icf, 13u);
    assert_int_equal(pmstep_stm32g4_step_filter(2500u, SYSCLK_HZ, &icf), PMSTEP_STM32G4_OK);
    assert_int_equal(icf, 15u);
    assert_int_equal(pmstep_stm32g4_step_filter_ticks(15u), 256u);
    /* 18 ns = 3 clocks: no filter; 17 ns = 2 clocks: refused. */
    assert_int_equal(pmstep_stm32g4_step_filter(18u, SYSCLK_HZ, &icf), PMSTEP_STM32G4_OK);
    assert_int_equal(icf, 0u);
    assert_int_equal(pmstep_stm32g4_step_filter(17u, SYSCLK_HZ, &icf), PMSTEP_STM32G4_ERR_STEP_PULSE);
    assert_int_equal(pmstep_stm32g4_step_filter(100u, SYSCLK_HZ, NULL), PMSTEP_STM32G4_ERR_NULL_ARGUMENT);
    /* Every pulse length from 3 clocks up: the chosen span plus the margin fits in it, and the next
     * code's would not. */
    for (k = 0u; k < 16u; ++k) {
        assert_true(k == 0u
                    || pmstep_stm32g4_step_filter_ticks(k) > pmstep_stm32g4_step_filter_ticks((uint8_t)(k - 1u)));
    }
    {
        uint32_t ns;
        for (ns = 18u; ns < 2000u; ++ns) {
            const uint32_t ticks = (uint32_t)((uint64_t)ns * SYSCLK_HZ / 1000000000u);
            assert_int_equal(pmstep_stm32g4_step_filter(ns, SYSCLK_HZ, &icf), PMSTEP_STM32G4_OK);
            assert_true(pmstep_stm32g4_step_filter_ticks(icf) + 2u <= ticks);
            assert_true(icf == 15u || pmstep_stm32g4_step_filter_ticks((uint8_t)(icf + 1u)) + 2u > ticks);
        }
    }
}

/* ---- the registers the driver leaves ---- */

static void test_init_sets_timer_and_pins(void **state)
{
    const stm32g4_tim_t *tim = &stm32g4_fake.tim4;
    const stm32g4_gpio_t *pb = &stm32g4_fake.gpio[1];
    const stm32g4_gpio_t *pc = &stm32g4_fake.gpio[2];
    (void)state;
    bring_up(true);
    assert_true((stm32g4_fake.rcc.APB1ENR1 & RCC_APB1ENR1_TIM4EN) != 0u);
    /* Encoder mode clock plus direction x1: SMS = 1011 at bits 16, 2:0 (RM0440 §29.5.3). */
    assert_int_equal(tim->SMCR & TIM_SMCR_SMS_MASK, STM32G4_BIT(16) | 3u);
    /* IC1 on TI1, IC2 on TI2, the 100 ns filter on both; no inversion; the whole 16 bits; counting. */
    assert_int_equal(tim->CCMR1, 0x4141u);
    assert_int_equal(tim->CCER, 0u);
    assert_int_equal(tim->ARR, 0xFFFFu);
    assert_int_equal(tim->PSC, 0u);
    assert_true((tim->CR1 & TIM_CR1_CEN) != 0u);
    assert_int_equal(tim->CR1 & TIM_CR1_CKD_MASK, 0u);
    /* PB6 (DIR), PB7 (STEP): AF2, pulled down. */
    assert_int_equal((pb->MODER >> 12) & 0xFu, 0xAu);
    assert_int_equal((pb->AFR[0] >> 24) & 0xFFu, 0x22u);
    assert_int_equal((pb->PUPDR >> 12) & 0xFu, 0xAu);
    /* PC8 (EN, active low): input with pull-up; PC9 (DIAG): open-drain output with pull-up, and
     * deasserted (active high: pulled low). */
    assert_int_equal((pc->MODER >> 16) & 3u, GPIO_MODE_INPUT);
    assert_int_equal((pc->PUPDR >> 16) & 3u, GPIO_PULL_UP);
    assert_int_equal((pc->MODER >> 18) & 3u, GPIO_MODE_OUTPUT);
    assert_true((pc->OTYPER & STM32G4_BIT(9)) != 0u);
    assert_int_equal((pc->PUPDR >> 18) & 3u, GPIO_PULL_UP);
    assert_true(stm32g4_model_pin_drives_low(2u, 9u));
    /* Nothing on the pins yet: nothing counted. */
    stm32g4_model_run(1000u);
    assert_int_equal(pmstep_stm32g4_step_counter(), 0u);
    assert_int_equal(M.unclocked_writes, 0u);
}

/* ---- counting ---- */

/* 70 000 pulses at 5 MHz (100 ns high, 100 ns low), the control interrupt reading the counter every
 * period: the core's count is exact across the 16-bit wrap. Then a direction reversal. */
static void test_high_rate_across_wrap(void **state)
{
    const uint32_t n_up = 70000u;
    const uint32_t n_down = 1000u;
    (void)state;
    bring_up(true);
    {
        pmstep_stepdir_config_t sdc;
        assert_int_equal(pmstep_stepdir_design(&motor_config, board.step_input.microsteps, &sdc), PMSTEP_OK);
        assert_int_equal(pmstep_stepdir_init(&tracker, &sdc, motor_config.motor.pole_pairs,
                                             pmstep_stm32g4_period_s(&board), (uint16_t)pmstep_stm32g4_step_counter()),
                         PMSTEP_OK);
    }
    pmstep_stm32g4_set_after_step(count_steps);
    pmstep_stm32g4_start();
    dir_level(true);
    stm32g4_model_run(100u);
    pulses(n_up, PULSE_100NS_TICKS, PULSE_100NS_TICKS);
    stm32g4_model_run(period_ticks()); /* one more control period reads the last of them */
    /* 250 steps a period, over 280 periods: the counter went once round. */
    assert_true(hook_periods > 270u);
    assert_int_equal(T.wraps, 1u);
    assert_int_equal(pmstep_stm32g4_step_counter(), n_up - 65536u);
    assert_int_equal(tracker.steps, (int32_t)n_up);
    assert_int_equal(T.counted_up, n_up);
    assert_true((stm32g4_fake.tim4.CR1 & TIM_CR1_DIR) == 0u);

    /* DIR low (changed while STEP is low, 100 ns before the next rising edge): counting down, and
     * back below the wrap. */
    dir_level(false);
    stm32g4_model_run(PULSE_100NS_TICKS);
    pulses(n_down, PULSE_100NS_TICKS, PULSE_100NS_TICKS);
    stm32g4_model_run(period_ticks());
    assert_int_equal(tracker.steps, (int32_t)(n_up - n_down));
    assert_int_equal(T.counted_down, n_down);
    assert_true((stm32g4_fake.tim4.CR1 & TIM_CR1_DIR) != 0u);
    /* Down through 0: from 4464 less 5000 steps. */
    pulses(5000u, PULSE_100NS_TICKS, PULSE_100NS_TICKS);
    stm32g4_model_run(period_ticks());
    assert_int_equal(T.wraps, 2u);
    assert_int_equal(tracker.steps, (int32_t)(n_up - n_down - 5000u));
    assert_int_equal(pmstep_stm32g4_step_counter(), 65536u + n_up - 65536u - n_down - 5000u);
}

/* DIR reversed every few pulses, each change 24 ns (4 clocks, above a TMC2209's 20 ns set-up) before
 * a STEP rising edge: the filter delays DIR as much as STEP, so every pulse counts its own way. */
static void test_direction_reversals(void **state)
{
    unsigned r;
    (void)state;
    bring_up(true);
    for (r = 0; r < 200u; ++r) {
        uint32_t k;
        for (k = 0; k < 5u; ++k) {
            const bool up = k < 3u; /* +3, -2 */
            stm32g4_model_run(PULSE_100NS_TICKS - 4u);
            dir_level(up);
            stm32g4_model_run(4u);
            step_level(true);
            stm32g4_model_run(PULSE_100NS_TICKS);
            step_level(false);
        }
    }
    stm32g4_model_run(100u);
    assert_int_equal(T.counted_up, 600u);
    assert_int_equal(T.counted_down, 400u);
    assert_int_equal(pmstep_stm32g4_step_counter(), 200u);
}

/* The filter as a minimum width: with the 100 ns setting (6 samples 2 clocks apart), a pulse of 10
 * clocks (59 ns, 5 sampling periods) never counts, whatever its phase to the sampling; one of 12
 * clocks (71 ns) and one of 100 ns always do. Glitches on a held STEP (a short low) do not count. */
static void test_short_pulse_rejected(void **state)
{
    uint32_t phase;
    uint32_t counted;
    (void)state;
    bring_up(true);
    dir_level(true);
    stm32g4_model_run(50u);
    for (phase = 0; phase < 4u; ++phase) {
        stm32g4_model_run(phase);
        pulses(10u, 10u, 40u);
    }
    assert_int_equal(pmstep_stm32g4_step_counter(), 0u);
    assert_int_equal(T.filtered_edges, 0u);
    for (phase = 0; phase < 4u; ++phase) {
        stm32g4_model_run(phase);
        pulses(10u, FILTER_SPAN_100NS, 40u);
    }
    assert_int_equal(pmstep_stm32g4_step_counter(), 40u);
    for (phase = 0; phase < 4u; ++phase) {
        stm32g4_model_run(phase);
        pulses(10u, PULSE_100NS_TICKS, PULSE_100NS_TICKS);
    }
    assert_int_equal(pmstep_stm32g4_step_counter(), 80u);
    /* STEP held high with 10-clock drops: one rising edge only. */
    counted = pmstep_stm32g4_step_counter();
    step_level(true);
    stm32g4_model_run(40u);
    for (phase = 0; phase < 20u; ++phase) {
        step_level(false);
        stm32g4_model_run(10u);
        step_level(true);
        stm32g4_model_run(40u + phase % 2u);
    }
    step_level(false);
    stm32g4_model_run(40u);
    assert_int_equal(pmstep_stm32g4_step_counter(), counted + 1u);
}

/* CEN gates the count; the count is kept while stopped. */
static void test_cen_gates_counting(void **state)
{
    (void)state;
    bring_up(true);
    dir_level(true);
    stm32g4_model_run(50u);
    pulses(25u, PULSE_100NS_TICKS, PULSE_100NS_TICKS);
    assert_int_equal(pmstep_stm32g4_step_counter(), 25u);
    stm32g4_fake.tim4.CR1 &= ~TIM_CR1_CEN;
    pulses(25u, PULSE_100NS_TICKS, PULSE_100NS_TICKS);
    assert_int_equal(pmstep_stm32g4_step_counter(), 25u);
    stm32g4_fake.tim4.CR1 |= TIM_CR1_CEN;
    pulses(5u, PULSE_100NS_TICKS, PULSE_100NS_TICKS);
    assert_int_equal(pmstep_stm32g4_step_counter(), 30u);
}

/* Not enabled (the default): TIM4 never clocked, its pins left alone, STEP pulses count nothing, and
 * EN gates nothing: the console-commanded drive as before. */
static void test_off_by_default(void **state)
{
    (void)state;
    board.step_input.enabled = false;
    bring_up(false);
    assert_int_equal(stm32g4_fake.rcc.APB1ENR1 & RCC_APB1ENR1_TIM4EN, 0u);
    assert_int_equal((stm32g4_fake.gpio[1].MODER >> 12) & 0xFu, 0xFu); /* PB6, PB7 analog (reset) */
    assert_int_equal((stm32g4_fake.gpio[2].MODER >> 16) & 0xFu, 0xFu); /* PC8, PC9 analog */
    pulses(20u, PULSE_100NS_TICKS, PULSE_100NS_TICKS);
    assert_int_equal(pmstep_stm32g4_step_counter(), 0u);
    assert_int_equal(stm32g4_fake.tim4.CNT, 0u);
    assert_true(pmstep_stm32g4_step_enabled());
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    pmstep_stm32g4_start();
    stm32g4_model_run(4u * period_ticks());
    assert_true(pmstep_stm32g4_bridge_on());
}

/* ---- EN gating the bridge ---- */

static void check_en_gating(bool active_high)
{
    const pmstep_stm32g4_pin_t en = board.step_input.enable_pin;
    board.step_input.enable_active_high = active_high;
    bring_up(false);
    /* Disabled at start: START is followed by a stop at the next period, the bridge never on. */
    assert_false(pmstep_stm32g4_step_enabled());
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    pmstep_stm32g4_start();
    stm32g4_model_run(4u * period_ticks());
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(motor.mode, PMSTEP_MODE_IDLE);
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    /* Enabled: START, the bridge switches. */
    en_pin(true);
    assert_true(pmstep_stm32g4_step_enabled());
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    stm32g4_model_run(4u * period_ticks());
    assert_true(pmstep_stm32g4_bridge_on());
    assert_true((stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE) != 0u);
    assert_true(stm32g4_model_pin_out(board.enable_pin.port, board.enable_pin.pin) == board.enable_active_high);
    /* Disabled: off within a period by the one path (MOE = 0, gate driver disabled, 50 % duties),
     * the core stopped, no port fault latched. */
    en_pin(false);
    stm32g4_model_run(period_ticks() + 10u);
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_true(stm32g4_model_pin_out(board.enable_pin.port, board.enable_pin.pin) != board.enable_active_high);
    assert_int_equal(stm32g4_fake.tim1.CCR1, stm32g4_fake.tim1.ARR / 2u);
    assert_int_equal(stm32g4_fake.tim1.CCR4, stm32g4_fake.tim1.ARR / 2u);
    assert_int_equal(motor.mode, PMSTEP_MODE_IDLE);
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_NONE);
    /* An open EN line reads disabled (the pin's pull). */
    stm32g4_model_pin_float(en.port, en.pin);
    assert_false(pmstep_stm32g4_step_enabled());
    en_pin(true);
    assert_true(pmstep_stm32g4_step_enabled());
    stm32g4_model_pin_float(en.port, en.pin);
    assert_false(pmstep_stm32g4_step_enabled());
}

static void test_en_active_low_gates_bridge(void **state)
{
    (void)state;
    check_en_gating(false);
}

static void test_en_active_high_gates_bridge(void **state)
{
    (void)state;
    check_en_gating(true);
}

/* ---- DIAG ---- */

static void check_diag(bool active_high)
{
    const pmstep_stm32g4_pin_t d = board.step_input.diag_pin;
    board.step_input.diag_active_high = active_high;
    bring_up(true);
    /* Deasserted after init. */
    assert_true(stm32g4_model_pin_level(d.port, d.pin, false) == !active_high);
    pmstep_stm32g4_set_diag(true);
    assert_true(stm32g4_model_pin_level(d.port, d.pin, false) == active_high);
    assert_true(stm32g4_model_pin_drives_low(d.port, d.pin) == !active_high);
    pmstep_stm32g4_set_diag(false);
    assert_true(stm32g4_model_pin_level(d.port, d.pin, false) == !active_high);
    assert_true(stm32g4_model_pin_drives_low(d.port, d.pin) == active_high);
    /* Open drain: the pin never drives the line high, whatever the state. */
    pmstep_stm32g4_set_diag(true);
    assert_false(stm32g4_model_pin_drives_high(d.port, d.pin));
    pmstep_stm32g4_set_diag(false);
    assert_false(stm32g4_model_pin_drives_high(d.port, d.pin));
}

static void test_diag_active_high(void **state)
{
    (void)state;
    check_diag(true);
}

static void test_diag_active_low(void **state)
{
    (void)state;
    check_diag(false);
}

/* ---- settings refused, by name, before TIM4 is touched ---- */

static void expect_refused(pmstep_stm32g4_status_t expected)
{
    assert_int_equal(pmstep_stm32g4_clock_init(&board.clock), PMSTEP_STM32G4_OK);
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    assert_int_equal(pmstep_stm32g4_init(&board, &motor), expected);
    assert_int_equal(stm32g4_fake.rcc.APB1ENR1 & RCC_APB1ENR1_TIM4EN, 0u);
    stm32g4_model_reset();
    board = pmstep_stm32g4_default_config();
    board.step_input.enabled = true;
}

static void test_invalid_settings_refused(void **state)
{
    (void)state;
    board.step_input.microsteps = 0u;
    expect_refused(PMSTEP_STM32G4_ERR_STEP_MICROSTEPS);
    board.step_input.microsteps = 257u;
    expect_refused(PMSTEP_STM32G4_ERR_STEP_MICROSTEPS);
    board.step_input.step_min_pulse_ns = 10u;
    expect_refused(PMSTEP_STM32G4_ERR_STEP_PULSE);
    board.step_input.step_pin = (pmstep_stm32g4_pin_t){0u, 12u, 2u}; /* PA12 is TIM4_CH2 on AF10, not AF2 */
    expect_refused(PMSTEP_STM32G4_ERR_STEP_PIN);
    board.step_input.dir_pin = (pmstep_stm32g4_pin_t){1u, 8u, 2u}; /* PB8: no TIM4 channel; BOOT0 on the NUCLEO */
    expect_refused(PMSTEP_STM32G4_ERR_PIN_RESERVED);
    board.step_input.dir_pin = (pmstep_stm32g4_pin_t){1u, 7u, 2u}; /* STEP's pin */
    expect_refused(PMSTEP_STM32G4_ERR_PIN_CONFLICT);
    board.step_input.dir_pin = (pmstep_stm32g4_pin_t){0u, 11u, 10u}; /* TIM4_CH1, but phase b-'s high side */
    expect_refused(PMSTEP_STM32G4_ERR_PIN_CONFLICT);
    board.step_input.enable_pin = (pmstep_stm32g4_pin_t){0u, 2u, 0u}; /* the console's TX */
    expect_refused(PMSTEP_STM32G4_ERR_PIN_CONFLICT);
    board.step_input.diag_pin = (pmstep_stm32g4_pin_t){2u, 13u, 0u}; /* B1 user button */
    expect_refused(PMSTEP_STM32G4_ERR_PIN_RESERVED);
    board.step_input.diag_pin = (pmstep_stm32g4_pin_t){2u, 16u, 0u};
    expect_refused(PMSTEP_STM32G4_ERR_PIN);
    /* The other pins of TIM4 are taken. */
    board.step_input.step_pin = (pmstep_stm32g4_pin_t){0u, 12u, 10u};
    board.step_input.dir_pin = (pmstep_stm32g4_pin_t){1u, 6u, 2u};
    assert_int_equal(pmstep_stm32g4_clock_init(&board.clock), PMSTEP_STM32G4_OK);
    assert_int_equal(pmstep_stm32g4_init(&board, &motor), PMSTEP_STM32G4_OK);
    /* Each code its own text. */
    assert_string_not_equal(pmstep_stm32g4_status_str(PMSTEP_STM32G4_ERR_STEP_MICROSTEPS),
                            pmstep_stm32g4_status_str((pmstep_stm32g4_status_t)1000));
    assert_string_not_equal(pmstep_stm32g4_status_str(PMSTEP_STM32G4_ERR_STEP_PULSE),
                            pmstep_stm32g4_status_str((pmstep_stm32g4_status_t)1000));
    assert_string_not_equal(pmstep_stm32g4_status_str(PMSTEP_STM32G4_ERR_STEP_PIN),
                            pmstep_stm32g4_status_str((pmstep_stm32g4_status_t)1000));
    assert_string_not_equal(pmstep_stm32g4_status_str(PMSTEP_STM32G4_ERR_STEP_PULSE),
                            pmstep_stm32g4_status_str(PMSTEP_STM32G4_ERR_STEP_PIN));
}

/* The pin map names the four pins only when the input is enabled. */
static void test_pin_map(void **state)
{
    pmstep_stm32g4_pin_use_t map[PMSTEP_STM32G4_PIN_USES_MAX];
    uint32_t n;
    (void)state;
    n = pmstep_stm32g4_pin_map(&board, map, PMSTEP_STM32G4_PIN_USES_MAX);
    assert_int_equal(n, 20u);
    assert_string_equal(map[16].signal, "TIM4_CH2");
    assert_int_equal(map[16].pin.port, 1u);
    assert_int_equal(map[16].pin.pin, 7u);
    assert_string_equal(map[17].signal, "TIM4_CH1");
    assert_string_equal(map[19].signal, "GPIO open drain");
    assert_int_equal(pmstep_stm32g4_check_pins(&board), PMSTEP_STM32G4_OK);
    board.step_input.enabled = false;
    assert_int_equal(pmstep_stm32g4_pin_map(&board, map, PMSTEP_STM32G4_PIN_USES_MAX), 16u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_filter_from_min_pulse, setup),
        cmocka_unit_test_setup(test_init_sets_timer_and_pins, setup),
        cmocka_unit_test_setup(test_high_rate_across_wrap, setup),
        cmocka_unit_test_setup(test_direction_reversals, setup),
        cmocka_unit_test_setup(test_short_pulse_rejected, setup),
        cmocka_unit_test_setup(test_cen_gates_counting, setup),
        cmocka_unit_test_setup(test_off_by_default, setup),
        cmocka_unit_test_setup(test_en_active_low_gates_bridge, setup),
        cmocka_unit_test_setup(test_en_active_high_gates_bridge, setup),
        cmocka_unit_test_setup(test_diag_active_high, setup),
        cmocka_unit_test_setup(test_diag_active_low, setup),
        cmocka_unit_test_setup(test_invalid_settings_refused, setup),
        cmocka_unit_test_setup(test_pin_map, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
