/*
 * The STM32G431 port against the behavioural model of its peripherals (stm32g4_model.h):
 * what the hardware does with what the drivers write. The port's init runs against the
 * model, then whole carrier periods run tick by tick with the real core in the interrupt.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "pmstep_hal_stm32g4.h"
#include "stm32g4_model.h"
#include "stm32g4_regs.h"

#define M stm32g4_model

static pmstep_stm32g4_config_t board;
static pmstep_config_t motor_config;
static pmstep_t motor;

static int setup(void **state)
{
    (void)state;
    stm32g4_model_reset();
    board = pmstep_stm32g4_default_config();
    motor_config = pmstep_paper_config();
    motor_config.period_s = pmstep_stm32g4_period_s(&board);
    motor_config.computational_delay_periods = 1u;
    assert_int_equal(pmstep_init(&motor, &motor_config), PMSTEP_OK);
    return 0;
}

static uint32_t arr_of_board(void)
{
    return pmstep_stm32g4_pwm_arr(pmstep_stm32g4_sysclk_hz(&board.clock), board.pwm_frequency_hz);
}

static uint16_t bus_counts(float bus_v)
{
    return (uint16_t)lroundf(bus_v / board.bus_gain_v_per_count + board.bus_offset_counts);
}

/* The analog inputs: currents in A, bus in V, as the ADC channels of the board convert them. */
static void analog(float i_a, float i_b, float bus_v)
{
    M.analog_counts[0][board.adc1_channel_i_a] = (uint16_t)lroundf(i_a / board.i_a_gain_a_per_count + board.i_a_offset_counts);
    M.analog_counts[1][board.adc2_channel_i_b] = (uint16_t)lroundf(i_b / board.i_b_gain_a_per_count + board.i_b_offset_counts);
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(bus_v);
}

/* Clock, port and core up; the fault input released; the counter not yet started. */
static void bring_up(void)
{
    assert_int_equal(pmstep_stm32g4_clock_init(&board.clock), PMSTEP_STM32G4_OK);
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    assert_int_equal(pmstep_stm32g4_init(&board, &motor), PMSTEP_STM32G4_OK);
    analog(0.0f, 0.0f, 48.0f);
}

/* ---- defect 1: the ADC trigger of the control interrupt ---- */

/* Ticks from the trigger to the carrier peak (CNT = ARR): + before, - after. */
static int32_t to_peak(const stm32g4_model_trigger_t *t, uint32_t arr)
{
    return t->down ? (int32_t)t->cnt - (int32_t)arr : (int32_t)arr - (int32_t)t->cnt;
}

static void test_one_injected_conversion_per_period(void **state)
{
    const unsigned periods = 40u;
    uint32_t arr;
    unsigned k;
    (void)state;
    bring_up();
    arr = arr_of_board();
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    pmstep_stm32g4_start();
    stm32g4_model_run((uint64_t)periods * 2u * arr);
    /* Exactly one injected sequence per carrier period on each ADC, and one interrupt. */
    assert_int_equal(M.adc[0].triggers, periods);
    assert_int_equal(M.adc[1].triggers, periods);
    assert_int_equal(M.adc[0].sequences, periods);
    assert_int_equal(M.adc_irqs, periods);
    for (k = 0; k < periods; ++k) {
        const stm32g4_model_trigger_t *t1 = &M.adc[0].log[k];
        const stm32g4_model_trigger_t *t2 = &M.adc[1].log[k];
        /* At the carrier peak (the centre of the low-side conduction), to one timer tick. */
        assert_true(abs(to_peak(t1, arr)) <= 1);
        assert_int_equal(t1->tick, t2->tick); /* i_a and i_b sampled together */
        if (k > 0u) {
            assert_int_equal(t1->tick - M.adc[0].log[k - 1u].tick, 2u * arr);
        }
    }
    assert_true(pmstep_stm32g4_bridge_on());
}

/* ---- defect 2: flash wait states for every clock the port accepts ---- */

static void test_flash_latency_every_pll_setting(void **state)
{
    unsigned accepted = 0u;
    unsigned too_few = 0u;
    uint32_t m;
    uint32_t n;
    uint32_t r;
    (void)state;
    for (m = 1u; m <= 16u; ++m) {
        for (n = 8u; n <= 127u; ++n) {
            for (r = 2u; r <= 8u; r += 2u) {
                const pmstep_stm32g4_clock_t c = {m, n, r};
                const uint32_t hz = pmstep_stm32g4_sysclk_hz(&c);
                if (hz == 0u) {
                    continue;
                }
                accepted++;
                stm32g4_model_reset();
                assert_int_equal(pmstep_stm32g4_clock_init(&c), PMSTEP_STM32G4_OK);
                if (!stm32g4_model_flash_ok(hz)) {
                    too_few++;
                }
            }
        }
    }
    assert_int_equal(accepted, 1292u);
    assert_int_equal(too_few, 0u);
}

/* ---- defect 3: ADEN right after the calibration ---- */

static void test_adc_enable_retried_after_calibration(void **state)
{
    unsigned guard;
    (void)state;
    for (guard = 0u; guard <= 3u; ++guard) {
        stm32g4_model_reset();
        M.aden_guard_polls = guard;
        assert_int_equal(pmstep_stm32g4_clock_init(&board.clock), PMSTEP_STM32G4_OK);
        assert_int_equal(pmstep_stm32g4_adc_init(&board), PMSTEP_STM32G4_OK);
        stm32g4_model_sync();
        assert_true(M.adc[0].calibrated && M.adc[1].calibrated);
        assert_true(M.adc[0].cr_rs & ADC_CR_ADEN);
        assert_true(M.adc[1].cr_rs & ADC_CR_ADEN);
        assert_true(M.adc[0].cr_rs & ADC_CR_JADSTART);
        assert_true(M.adc[1].cr_rs & ADC_CR_JADSTART);
    }
}

/* ---- defect 4: the gate-driver enable is at its off level from the first write ---- */

static void check_enable_off_after_gpio_init(bool active_high)
{
    stm32g4_gpio_t *g;
    stm32g4_model_reset();
    board.enable_active_high = active_high;
    assert_int_equal(pmstep_stm32g4_gpio_init(&board), PMSTEP_STM32G4_OK);
    assert_int_equal(M.unclocked_writes, 0u);
    g = &stm32g4_fake.gpio[board.enable_pin.port];
    assert_int_equal((g->MODER >> (2u * board.enable_pin.pin)) & 3u, GPIO_MODE_OUTPUT);
    /* Driver off: low for an active-high enable, high for an active-low one. */
    assert_int_equal(stm32g4_model_pin_out(board.enable_pin.port, board.enable_pin.pin), !active_high);
}

static void test_enable_pin_written_after_its_clock(void **state)
{
    (void)state;
    check_enable_off_after_gpio_init(true);
    check_enable_off_after_gpio_init(false);
}

/* ---- defect 5: the default board keeps off the NUCLEO-G431RB's own pins ---- */

typedef struct {
    uint8_t port;
    uint8_t pin;
    const char *use;
} board_pin_t;

/* NUCLEO-G431RB (UM2505): ST-LINK virtual COM port on LPUART1 PA2 (TX) / PA3 (RX), SWD on
 * PA13/PA14, the 24 MHz HSE crystal on PF0/PF1, the 32.768 kHz LSE crystal on PC14/PC15,
 * NRST on PG10. */
static const board_pin_t nucleo_reserved[] = {
    {0u, 2u, "VCP TX (LPUART1_TX)"}, {0u, 3u, "VCP RX (LPUART1_RX)"}, {0u, 13u, "SWDIO"},
    {0u, 14u, "SWCLK"},              {5u, 0u, "HSE OSC_IN"},          {5u, 1u, "HSE OSC_OUT"},
    {2u, 14u, "LSE OSC32_IN"},       {2u, 15u, "LSE OSC32_OUT"},      {6u, 10u, "NRST"},
};

/* ADC1 channel of a pin (STM32G431RB pin data, ST STM32_open_pin_data), 0 if none used here. */
static unsigned adc1_channel_of(uint8_t port, uint8_t pin)
{
    if (port == 0u && pin <= 3u) {
        return pin + 1u; /* PA0..PA3: ADC1_IN1..IN4 */
    }
    if (port == 2u && pin <= 3u) {
        return pin + 6u; /* PC0..PC3: ADC1_IN6..IN9 */
    }
    if (port == 1u && pin == 1u) {
        return 12u;
    }
    if (port == 1u && pin == 11u) {
        return 14u;
    }
    if (port == 1u && pin == 12u) {
        return 11u;
    }
    return 0u;
}

static void check_not_reserved(const pmstep_stm32g4_pin_t *p)
{
    unsigned k;
    for (k = 0; k < sizeof nucleo_reserved / sizeof nucleo_reserved[0]; ++k) {
        if (p->port == nucleo_reserved[k].port && p->pin == nucleo_reserved[k].pin) {
            print_error("P%c%u is the NUCLEO's %s\n", 'A' + p->port, p->pin, nucleo_reserved[k].use);
            fail();
        }
    }
}

static void test_default_board_off_nucleo_pins(void **state)
{
    unsigned k;
    (void)state;
    for (k = 0; k < 4u; ++k) {
        check_not_reserved(&board.pwm_high[k]);
        check_not_reserved(&board.pwm_low[k]);
    }
    for (k = 0; k < 3u; ++k) {
        check_not_reserved(&board.adc_pins[k]);
    }
    check_not_reserved(&board.break_input);
    check_not_reserved(&board.enable_pin);
    check_not_reserved(&board.fault_pin);
    /* The bus pin and the ADC1 channel that converts it agree. */
    assert_int_equal(adc1_channel_of(board.adc_pins[1].port, board.adc_pins[1].pin), board.adc1_channel_bus);
    assert_int_equal(adc1_channel_of(board.adc_pins[0].port, board.adc_pins[0].pin), board.adc1_channel_i_a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_one_injected_conversion_per_period, setup),
        cmocka_unit_test_setup(test_flash_latency_every_pll_setting, setup),
        cmocka_unit_test_setup(test_adc_enable_retried_after_calibration, setup),
        cmocka_unit_test_setup(test_enable_pin_written_after_its_clock, setup),
        cmocka_unit_test_setup(test_default_board_off_nucleo_pins, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
