/*
 * The STM32G431 application built in STEP/DIR mode (app.c with PMSTEP_STM32G4_STEPDIR=1) on the
 * behavioural model: the port's STEP/DIR input set up at boot, the step count read by the control
 * interrupt every period, EN keeping the bridge off, DIAG deasserted while the core is IDLE without
 * a fault. (The default build, without the mode, is checked in test_stm32g4_model.c.)
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "app.h"
#include "pmstep_hal_stm32g4.h"
#include "stm32g4_model.h"
#include "stm32g4_regs.h"

#define M stm32g4_model

static pmstep_stm32g4_config_t board;

static int setup(void **state)
{
    (void)state;
    stm32g4_model_reset();
    stm32g4_model_flash_erase_all();
    board = pmstep_stm32g4_default_config(); /* the pins the application uses */
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    M.analog_counts[0][board.adc1_channel_i_a] = 2048u;
    M.analog_counts[1][board.adc2_channel_i_b] = 2048u;
    M.analog_counts[0][board.adc1_channel_bus] = 745u; /* 48 V */
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_app_counts_steps_each_period, setup),
        cmocka_unit_test_setup(test_app_en_open_reads_disabled, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
