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

#include "app.h"
#include "pmstep_console.h"
#include "pmstep_hal_stm32g4.h"
#include "stm32g4_model.h"
#include "stm32g4_regs.h"
#include "model_console_host.h"

#define M stm32g4_model

static pmstep_stm32g4_config_t board;
static pmstep_config_t motor_config;
static pmstep_t motor;

static int setup(void **state)
{
    (void)state;
    stm32g4_model_reset();
    stm32g4_model_flash_erase_all(); /* a fresh part: no stored configuration */
    board = pmstep_stm32g4_default_config();
    motor_config =
        pmstep_console_app_config(pmstep_stm32g4_period_s(&board), 1u, pmstep_stm32g4_current_sense_range_A(&board),
                                  pmstep_stm32g4_bus_sense_range_V(&board));
    assert_int_equal(pmstep_init(&motor, &motor_config), PMSTEP_OK);
    return 0;
}

static uint32_t arr_of_board(void)
{
    return pmstep_stm32g4_pwm_arr(pmstep_stm32g4_sysclk_Hz(&board.clock), board.pwm_frequency_Hz);
}

static uint16_t bus_counts(float bus_V)
{
    return (uint16_t)lroundf(bus_V / board.bus_gain_v_per_count + board.bus_offset_counts);
}

/* The analog inputs: currents in A, bus in V, as the ADC channels of the board convert them. */
static void analog(float i_a, float i_b, float bus_V)
{
    M.analog_counts[0][board.adc1_channel_i_a] =
        (uint16_t)lroundf(i_a / board.i_a_gain_a_per_count + board.i_a_offset_counts);
    M.analog_counts[1][board.adc2_channel_i_b] =
        (uint16_t)lroundf(i_b / board.i_b_gain_a_per_count + board.i_b_offset_counts);
    M.analog_counts[0][board.adc1_channel_bus] = bus_counts(bus_V);
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
                const uint32_t hz = pmstep_stm32g4_sysclk_Hz(&c);
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
    {0u, 2u, "VCP TX (LPUART1_TX)"},
    {0u, 3u, "VCP RX (LPUART1_RX)"},
    {0u, 13u, "SWDIO"},
    {0u, 14u, "SWCLK"},
    {5u, 0u, "HSE OSC_IN"},
    {5u, 1u, "HSE OSC_OUT"},
    {2u, 14u, "LSE OSC32_IN"},
    {2u, 15u, "LSE OSC32_OUT"},
    {6u, 10u, "NRST"},
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

/* ===========================================================================
 * The model's rules, each against a small TIM1/ADC set-up written register by register.
 * ========================================================================= */

#define CCMR_PWM1 ((6u << 4) | (1u << 3))
#define CCMR_PWM2 ((7u << 4) | (1u << 3))

/* TIM1 with @p cms (0 edge-aligned, 1 centre-aligned 1), ARR, RCR, CH1 in @p ccmr1 with CCR1,
 * preloads on, UG, counter started. */
static void tim_raw(uint32_t cms, uint32_t arr, uint32_t rcr, uint32_t ccmr1, uint32_t ccr1)
{
    stm32g4_tim_t *tim = &stm32g4_fake.tim1;
    tim->CR1 = (cms << TIM_CR1_CMS_POS) | TIM_CR1_ARPE | TIM_CR1_URS;
    tim->ARR = arr;
    tim->RCR = rcr;
    tim->CCMR1 = ccmr1;
    tim->CCR1 = ccr1;
    tim->CCER = TIM_CCER_CCE(1u) | TIM_CCER_CCNE(1u);
    tim->EGR = TIM_EGR_UG;
    stm32g4_model_sync();
    tim->CR1 |= TIM_CR1_CEN;
}

/* §28.3.2: edge-aligned up 0..ARR, down ARR..0; §28.3.3: one update per RCR + 1 over/underflows. */
static void test_model_edge_aligned_counter_and_repetition(void **state)
{
    uint32_t k;
    (void)state;
    tim_raw(0u, 9u, 2u, CCMR_PWM1, 4u);
    for (k = 1u; k <= 10u; ++k) {
        stm32g4_model_run(1u);
        assert_int_equal(M.cnt, k % 10u);
    }
    assert_int_equal(M.updates, 1u); /* UG only: the first overflow leaves REP_CNT at 1 */
    stm32g4_model_run(30u * 10u - 10u);
    assert_int_equal(M.updates, 1u + 10u); /* 30 overflows, RCR = 2: 10 updates */
    /* Down-counting: ARR, ARR-1, .., 0, ARR. */
    stm32g4_model_reset();
    tim_raw(0u, 9u, 0u, CCMR_PWM1, 4u);
    stm32g4_fake.tim1.CR1 = (stm32g4_fake.tim1.CR1 & ~TIM_CR1_CEN) | STM32G4_BIT(4); /* DIR */
    stm32g4_fake.tim1.EGR = TIM_EGR_UG; /* counting down, UG loads ARR into the counter */
    stm32g4_model_sync();
    stm32g4_fake.tim1.CR1 |= TIM_CR1_CEN;
    M.updates = 1u;
    assert_int_equal(M.cnt, 9u);
    stm32g4_model_run(9u);
    assert_int_equal(M.cnt, 0u);
    stm32g4_model_run(1u);
    assert_int_equal(M.cnt, 9u);
    assert_int_equal(M.updates, 2u); /* UG, then the underflow */
}

/* §28.3.2 centre-aligned: 0..ARR-1 up, ARR..1 down; §28.3.3: RCR = 0 updates at every over-
 * and underflow, odd RCR written before the start at the overflow (the peak). */
static void test_model_centre_aligned_counter_and_repetition(void **state)
{
    uint32_t k;
    (void)state;
    tim_raw(1u, 8u, 0u, CCMR_PWM1, 4u);
    for (k = 1u; k <= 16u; ++k) {
        stm32g4_model_run(1u);
        if (k < 8u) {
            assert_int_equal(M.cnt, k);
            assert_false(M.down);
        } else if (k < 16u) {
            assert_int_equal(M.cnt, 16u - k);
            assert_true(M.down);
        } else {
            assert_int_equal(M.cnt, 0u);
            assert_false(M.down);
        }
    }
    assert_int_equal(M.updates, 1u + 2u);
    stm32g4_model_reset();
    tim_raw(1u, 8u, 1u, CCMR_PWM1, 4u);
    stm32g4_model_run(8u);
    assert_int_equal(M.cnt, 8u);
    assert_int_equal(M.updates, 2u); /* UG + the first peak */
    stm32g4_model_run(8u);
    assert_int_equal(M.updates, 2u); /* no update at the valley */
    stm32g4_model_run(8u);
    assert_int_equal(M.updates, 3u); /* the next peak */
}

/* High ticks of OC1REF over @p ticks. */
static unsigned ref_high_ticks(uint32_t ticks)
{
    unsigned high = 0u;
    uint32_t k;
    for (k = 0; k < ticks; ++k) {
        stm32g4_model_run(1u);
        high += M.ocref[0] ? 1u : 0u;
    }
    return high;
}

/* §28.3.11 PWM modes 1 and 2: duty CCR/ARR in centre-aligned mode; CCR = 0 gives 0 % and
 * CCR >= ARR 100 % (mode 1), mode 2 the complement; edge-aligned CCR/(ARR+1), CCR > ARR 100 %. */
static void test_model_pwm_modes_and_limits(void **state)
{
    static const uint32_t ccr[] = {0u, 1u, 4u, 7u, 8u, 9u, 1000u};
    unsigned k;
    (void)state;
    for (k = 0; k < sizeof ccr / sizeof ccr[0]; ++k) {
        const uint32_t expect = 2u * (ccr[k] < 8u ? ccr[k] : 8u);
        stm32g4_model_reset();
        tim_raw(1u, 8u, 0u, CCMR_PWM1, ccr[k]);
        stm32g4_model_run(16u); /* one period to settle */
        assert_int_equal(ref_high_ticks(16u * 4u), 4u * expect);
        stm32g4_model_reset();
        tim_raw(1u, 8u, 0u, CCMR_PWM2, ccr[k]);
        stm32g4_model_run(16u);
        assert_int_equal(ref_high_ticks(16u * 4u), 4u * (16u - expect));
        stm32g4_model_reset();
        tim_raw(0u, 8u, 0u, CCMR_PWM1, ccr[k]);
        stm32g4_model_run(9u);
        assert_int_equal(ref_high_ticks(9u * 4u), 4u * (ccr[k] < 9u ? ccr[k] : 9u));
    }
    /* The old channel-5 set-up: PWM mode 2 with CCR = ARR in centre-aligned mode never rises. */
    stm32g4_model_reset();
    tim_raw(1u, 8u, 0u, CCMR_PWM2, 8u);
    assert_int_equal(ref_high_ticks(16u * 4u), 0u);
    /* With CCR = ARR - 1 it is high for the two ticks around the peak. */
    stm32g4_model_reset();
    tim_raw(1u, 8u, 0u, CCMR_PWM2, 7u);
    assert_int_equal(ref_high_ticks(16u * 4u), 2u * 4u);
}

/* §28.3.16 dead time: each output's rising edge delayed by DTG ticks, never both on; the
 * generator codes of §28.6.20 agree with the port's own conversion. */
static void test_model_complementary_outputs_dead_time(void **state)
{
    uint32_t dtg;
    unsigned on_h = 0u;
    unsigned on_l = 0u;
    unsigned k;
    (void)state;
    for (dtg = 0u; dtg <= 255u; ++dtg) {
        assert_int_equal((uint64_t)stm32g4_model_dead_time_ticks(dtg) * 1000000000u / 170000000u,
                         pmstep_stm32g4_dtg_to_ns((uint8_t)dtg, 170000000u));
    }
    tim_raw(1u, 100u, 0u, CCMR_PWM1, 30u);
    stm32g4_fake.tim1.BDTR = 5u | TIM_BDTR_MOE; /* 5 ticks */
    stm32g4_model_run(200u);
    for (k = 0; k < 200u; ++k) {
        stm32g4_model_run(1u);
        assert_false(M.oc[0] && M.ocn[0]);
        on_h += M.oc[0] ? 1u : 0u;
        on_l += M.ocn[0] ? 1u : 0u;
    }
    assert_int_equal(on_h, 60u - 5u);        /* 2 CCR ticks of OC1REF, rising edge 5 later */
    assert_int_equal(on_l, 200u - 60u - 5u); /* the complement, rising edge 5 later */
    /* A pulse shorter than the dead time disappears. */
    stm32g4_fake.tim1.CCR1 = 2u;
    stm32g4_model_run(400u);
    on_h = 0u;
    for (k = 0; k < 200u; ++k) {
        stm32g4_model_run(1u);
        on_h += M.oc[0] ? 1u : 0u;
    }
    assert_int_equal(on_h, 0u);
}

/* §28.3.17 break: MOE cleared at once, outputs to their idle levels, BIF set, MOE cannot be set
 * while the break is active and stays cleared after it (AOE = 0). */
static void test_model_break(void **state)
{
    stm32g4_tim_t *tim = &stm32g4_fake.tim1;
    (void)state;
    tim_raw(1u, 100u, 0u, CCMR_PWM1, 50u);
    tim->CR2 = STM32G4_BIT(9); /* OIS1N = 1: CH1N idles high, CH1 low */
    tim->BDTR = 5u | TIM_BDTR_OSSI | TIM_BDTR_OSSR | TIM_BDTR_BKE | TIM_BDTR_MOE; /* active low */
    stm32g4_model_run(300u);
    assert_true(M.oc[0] || M.ocn[0]);
    M.bkin_pin_high = false;
    stm32g4_model_run(1u);
    assert_int_equal(tim->BDTR & TIM_BDTR_MOE, 0u);
    assert_true(tim->SR & TIM_SR_BIF);
    assert_false(M.oc[0]);
    assert_true(M.ocn[0]);
    tim->BDTR |= TIM_BDTR_MOE; /* refused while active */
    stm32g4_model_run(1u);
    assert_int_equal(tim->BDTR & TIM_BDTR_MOE, 0u);
    M.bkin_pin_high = true;
    stm32g4_model_run(10u);
    assert_int_equal(tim->BDTR & TIM_BDTR_MOE, 0u); /* AOE = 0 */
    tim->SR = ~TIM_SR_BIF;
    stm32g4_model_run(1u);
    assert_int_equal(tim->SR & TIM_SR_BIF, 0u);
    tim->BDTR |= TIM_BDTR_MOE;
    stm32g4_model_run(300u);
    assert_true(tim->BDTR & TIM_BDTR_MOE);
    /* BKP = 1: active high; AF1.BKINP inverts the pin. */
    tim->BDTR |= TIM_BDTR_BKP;
    stm32g4_model_run(1u);
    assert_int_equal(tim->BDTR & TIM_BDTR_MOE, 0u); /* pin high = active */
    tim->AF1 |= TIM_AF1_BKINP;
    tim->SR = 0u;
    tim->BDTR |= TIM_BDTR_MOE;
    stm32g4_model_run(1u);
    assert_true(tim->BDTR & TIM_BDTR_MOE);
}

/* ADC1 injected rank 1 on channel 1, trigger TIM1_TRGO2 on @p edge (1 rising, 2 falling, 3 both). */
static void adc_raw(uint32_t edge, bool interrupt)
{
    stm32g4_adc_t *adc = &stm32g4_fake.adc1;
    adc->CR = ADC_CR_ADVREGEN;
    adc->CR = ADC_CR_ADVREGEN | ADC_CR_ADEN;
    stm32g4_model_sync();
    adc->JSQR =
        (ADC12_JEXTSEL_TIM1_TRGO2 << ADC_JSQR_JEXTSEL_POS) | (edge << ADC_JSQR_JEXTEN_POS) | (1u << ADC_JSQR_JSQ1_POS);
    adc->IER = interrupt ? ADC_IER_JEOSIE : 0u;
    adc->CR = ADC_CR_ADVREGEN | ADC_CR_JADSTART;
    stm32g4_model_sync();
    stm32g4_fake.nvic.ISER[0] = STM32G4_BIT(STM32G4_IRQ_ADC1_2);
    M.analog_counts[0][1] = 1234u;
}

/* §28.6.2 MMS2 (update / OC5REFC) and §21.4.18 trigger edges: the sample point moves with the
 * edge; §21.4.21 JEOS and its interrupt; JDR holds the conversion. */
static void test_model_trgo2_and_adc_edges(void **state)
{
    stm32g4_tim_t *tim = &stm32g4_fake.tim1;
    (void)state;
    /* TRGO2 = update (RCR = 1, peaks): rising edge at each peak. */
    tim_raw(1u, 100u, 1u, CCMR_PWM1, 50u);
    tim->CR2 = 2u << TIM_CR2_MMS2_POS;
    adc_raw(1u, true);
    stm32g4_model_run(200u * 10u);
    assert_int_equal(M.adc[0].triggers, 10u);
    assert_int_equal(M.adc[0].log[0].cnt, 100u); /* the update at the peak */
    assert_int_equal(M.adc[0].sequences, 10u);
    assert_int_equal(M.adc_irqs, 10u); /* the handler cleared JEOS each time */
    assert_int_equal(stm32g4_fake.adc1.JDR[0], 1234u);
    /* TRGO2 = OC5REF, CH5 PWM mode 1 with CCR5 = 20: rising at the valley side, falling at CNT 20. */
    stm32g4_model_reset();
    tim_raw(1u, 100u, 1u, CCMR_PWM1, 50u);
    tim->CCMR3 = CCMR_PWM1;
    tim->CCR5 = 20u;
    tim->EGR = TIM_EGR_UG;
    tim->CR2 = TIM_CR2_MMS2_OC5REFC << TIM_CR2_MMS2_POS;
    adc_raw(2u, false); /* falling edge, no interrupt */
    stm32g4_model_run(200u * 10u);
    assert_int_equal(M.adc[0].triggers, 10u);
    assert_int_equal(M.adc[0].log[1].cnt, 20u);
    assert_false(M.adc[0].log[1].down);
    assert_int_equal(M.adc_irqs, 0u);
    assert_true(stm32g4_fake.adc1.ISR & ADC_ISR_JEOS); /* raised, not cleared */
    stm32g4_model_reset();
    tim_raw(1u, 100u, 1u, CCMR_PWM1, 50u);
    tim->CCMR3 = CCMR_PWM1;
    tim->CCR5 = 40u; /* high for 80 ticks, longer than one conversion (60 ticks) */
    tim->EGR = TIM_EGR_UG;
    tim->CR2 = TIM_CR2_MMS2_OC5REFC << TIM_CR2_MMS2_POS;
    adc_raw(3u, false); /* both edges */
    stm32g4_model_run(200u * 10u);
    assert_int_equal(M.adc[0].triggers, 20u);
    /* Not armed (JADSTART = 0): no conversion. */
    stm32g4_model_reset();
    tim_raw(1u, 100u, 1u, CCMR_PWM1, 50u);
    tim->CR2 = 2u << TIM_CR2_MMS2_POS;
    stm32g4_fake.adc1.JSQR = (ADC12_JEXTSEL_TIM1_TRGO2 << ADC_JSQR_JEXTSEL_POS) | (1u << ADC_JSQR_JEXTEN_POS);
    stm32g4_model_run(200u * 10u);
    assert_int_equal(M.adc[0].triggers, 0u);
}

/* §3.3.3 Table 9, both regulator modes (ST's LL thresholds). */
static void test_model_flash_table(void **state)
{
    (void)state;
    assert_int_equal(stm32g4_model_flash_min_latency(30000000u, false), 0u);
    assert_int_equal(stm32g4_model_flash_min_latency(30000001u, false), 1u);
    assert_int_equal(stm32g4_model_flash_min_latency(60000001u, false), 2u);
    assert_int_equal(stm32g4_model_flash_min_latency(90000001u, false), 3u);
    assert_int_equal(stm32g4_model_flash_min_latency(120000001u, false), 4u);
    assert_int_equal(stm32g4_model_flash_min_latency(150000000u, false), 4u);
    assert_int_equal(stm32g4_model_flash_min_latency(34000000u, true), 0u);
    assert_int_equal(stm32g4_model_flash_min_latency(34000001u, true), 1u);
    assert_int_equal(stm32g4_model_flash_min_latency(136000001u, true), 4u);
    assert_int_equal(stm32g4_model_flash_min_latency(170000000u, true), 4u);
    /* Normal mode above 150 MHz is out of specification whatever the latency. */
    stm32g4_fake.pwr.CR5 = PWR_CR5_R1MODE;
    stm32g4_fake.flash.ACR = 15u;
    assert_false(stm32g4_model_flash_ok(160000000u));
}

/* ===========================================================================
 * The port on the model: N carrier periods with the real core in the interrupt.
 * ========================================================================= */

/* Counts, per half-bridge, the ticks of OCxREF and of the pins over one carrier period. */
typedef struct {
    unsigned ref[4];
    unsigned hi[4];
    unsigned lo[4];
    bool shoot_through;
} window_t;

/* The analog inputs of sample k: a bus that moves between 40 and 56 V, small currents. */
static void sample_inputs(unsigned k)
{
    analog(0.8f * sinf(0.21f * (float)k), 2.0f + 0.5f * cosf(0.13f * (float)k), 48.0f + 8.0f * sinf(0.37f * (float)k));
}

/* One carrier period from its update event (the peak) to the next trigger (one tick before
 * the next peak), 2 ARR ticks; the inputs of sample @p next are applied at the valley. */
static void run_window(uint32_t arr, window_t *w, unsigned next)
{
    uint32_t t;
    unsigned ch;
    memset(w, 0, sizeof *w);
    for (t = 0; t < 2u * arr; ++t) {
        if (t == arr) {
            sample_inputs(next);
        }
        stm32g4_model_run(1u);
        for (ch = 0; ch < 4u; ++ch) {
            w->ref[ch] += M.ocref[ch] ? 1u : 0u;
            w->hi[ch] += M.oc[ch] ? 1u : 0u;
            w->lo[ch] += M.ocn[ch] ? 1u : 0u;
            w->shoot_through = w->shoot_through || (M.oc[ch] && M.ocn[ch]);
        }
    }
}

/* The port from reset to the first carrier peak minus two ticks (just before the first trigger). */
static uint32_t start_carrier(void)
{
    const uint32_t arr = arr_of_board();
    bring_up();
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    pmstep_stm32g4_start();
    stm32g4_model_run(arr - 2u);
    return arr;
}

/* Duties equal to the commanded voltages over the measured bus, one period after the samples
 * they were computed from; dead time on every edge; never both switches of a leg on. */
static void test_port_duties_follow_commanded_voltages(void **state)
{
    const unsigned periods = 60u;
    pmstep_t twin;
    uint32_t arr;
    uint32_t dt;
    unsigned expect_ccr[4] = {0u, 0u, 0u, 0u};
    float expect_u[2] = {0.0f, 0.0f};
    float expect_bus = 0.0f;
    bool have_expect = false;
    unsigned checked = 0u;
    unsigned k;
    (void)state;
    assert_int_equal(pmstep_init(&twin, &motor_config), PMSTEP_OK);
    assert_int_equal(pmstep_start(&twin), PMSTEP_OK);
    arr = start_carrier();
    dt = stm32g4_model_dead_time_ticks(stm32g4_fake.tim1.BDTR & TIM_BDTR_DTG_MASK);
    sample_inputs(0u);
    stm32g4_model_run(1u); /* the trigger of sample 0 (CNT = ARR - 1) */
    for (k = 0; k < periods; ++k) {
        pmstep_meas_t meas;
        pmstep_output_t out;
        window_t w;
        unsigned ch;
        /* What the core must command for sample k (the twin gets the same numbers). */
        meas.i_a_A = pmstep_stm32g4_counts_to_si(M.analog_counts[0][board.adc1_channel_i_a], board.i_a_offset_counts,
                                                 board.i_a_gain_a_per_count);
        meas.i_b_A = pmstep_stm32g4_counts_to_si(M.analog_counts[1][board.adc2_channel_i_b], board.i_b_offset_counts,
                                                 board.i_b_gain_a_per_count);
        meas.bus_voltage_V = pmstep_stm32g4_counts_to_si(M.analog_counts[0][board.adc1_channel_bus],
                                                         board.bus_offset_counts, board.bus_gain_v_per_count);
        meas.load_torque_Nm = 0.0f;
        meas.phase_voltage_a_V = 0.0f; /* not sensed on this board */
        meas.phase_voltage_b_V = 0.0f;
        pmstep_step(&twin, &meas, &out);
        /* This period carries the duties of sample k - 1 (loaded at its update event); the
         * interrupt of sample k writes the next ones during it. */
        run_window(arr, &w, k + 1u);
        assert_int_equal(M.cnt, arr - 1u);
        assert_false(M.down);
        assert_false(w.shoot_through);
        if (have_expect) {
            checked++;
            for (ch = 0; ch < 4u; ++ch) {
                assert_int_equal(w.ref[ch], 2u * expect_ccr[ch]);
                if (2u * expect_ccr[ch] > dt && 2u * (arr - expect_ccr[ch]) > dt) {
                    assert_int_equal(w.hi[ch], 2u * expect_ccr[ch] - dt);
                    assert_int_equal(w.lo[ch], 2u * (arr - expect_ccr[ch]) - dt);
                }
            }
            /* u = (d+ - d-) V_bus to within one count of each compare value. */
            assert_float_equal(((float)w.ref[0] - (float)w.ref[1]) / (2.0f * (float)arr) * expect_bus, expect_u[0],
                               2.0f * expect_bus / (float)arr);
            assert_float_equal(((float)w.ref[2] - (float)w.ref[3]) / (2.0f * (float)arr) * expect_bus, expect_u[1],
                               2.0f * expect_bus / (float)arr);
        }
        {
            float dp;
            float dm;
            pmstep_stm32g4_duties(out.u_a_V, meas.bus_voltage_V, board.duty_min, board.duty_max, &dp, &dm);
            expect_ccr[0] = pmstep_stm32g4_duty_to_ccr(dp, arr);
            expect_ccr[1] = pmstep_stm32g4_duty_to_ccr(dm, arr);
            pmstep_stm32g4_duties(out.u_b_V, meas.bus_voltage_V, board.duty_min, board.duty_max, &dp, &dm);
            expect_ccr[2] = pmstep_stm32g4_duty_to_ccr(dp, arr);
            expect_ccr[3] = pmstep_stm32g4_duty_to_ccr(dm, arr);
            expect_u[0] = out.u_a_V;
            expect_u[1] = out.u_b_V;
            expect_bus = meas.bus_voltage_V;
            have_expect = out.bridge_enable;
        }
    }
    assert_true(checked >= periods - 2u); /* every period with the bridge on after the first */
    assert_int_equal(M.adc_irqs, periods);
    assert_true(pmstep_stm32g4_bridge_on());
}

/* All four legs off: every switch off (the port's idle levels are 0). */
static bool all_switches_off(void)
{
    unsigned ch;
    for (ch = 0; ch < 4u; ++ch) {
        if (M.oc[ch] || M.ocn[ch]) {
            return false;
        }
    }
    return true;
}

/* A break: all switches off in the same tick, MOE cleared, the port's fault latched and the
 * core stopped; the bridge stays off for the following periods and until a new start. */
static void test_port_break_turns_bridge_off(void **state)
{
    uint32_t arr;
    (void)state;
    arr = start_carrier();
    stm32g4_model_run(10u * 2u * arr);
    assert_true(pmstep_stm32g4_bridge_on());
    assert_false(all_switches_off());
    M.bkin_pin_high = false; /* active low */
    stm32g4_model_run(1u);
    assert_true(all_switches_off());
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_int_equal(M.brk_irqs, 1u);
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_BREAK);
    assert_false(pmstep_stm32g4_bridge_on());
    assert_false(stm32g4_model_pin_out(board.enable_pin.port, board.enable_pin.pin) == board.enable_active_high);
    {
        const unsigned irqs = M.adc_irqs;
        uint32_t t;
        for (t = 0; t < 10u * 2u * arr; ++t) {
            stm32g4_model_run(1u);
            assert_true(all_switches_off());
        }
        assert_int_equal(M.adc_irqs, irqs + 10u); /* the control period goes on, bridge off */
    }
    M.bkin_pin_high = true;
    stm32g4_model_run(1u);
    assert_true(pmstep_stm32g4_clear_fault());
    stm32g4_model_run(4u * 2u * arr);
    assert_true(all_switches_off()); /* the core was stopped: no restart by itself */
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    stm32g4_model_run(4u * 2u * arr);
    assert_true(pmstep_stm32g4_bridge_on());
    assert_false(all_switches_off());
}

/* A firmware fault (over-current latched by the core): the interrupt that sees it turns every
 * switch off, and they stay off. */
static void test_port_firmware_fault_turns_bridge_off(void **state)
{
    uint32_t arr;
    unsigned irqs;
    uint32_t t;
    (void)state;
    arr = start_carrier();
    stm32g4_model_run(10u * 2u * arr);
    assert_false(all_switches_off());
    analog(16.0f, 0.0f, 48.0f); /* above the paper's 15 A limit */
    irqs = M.adc_irqs;
    while (M.adc_irqs == irqs) {
        stm32g4_model_run(1u);
    }
    stm32g4_model_run(1u); /* the tick after the interrupt */
    assert_true(all_switches_off());
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_NONE); /* the core's fault */
    analog(0.0f, 0.0f, 48.0f);
    for (t = 0; t < 10u * 2u * arr; ++t) {
        stm32g4_model_run(1u);
        assert_true(all_switches_off()); /* latched in the core until cleared */
    }
}

/* ===========================================================================
 * The application (app.c: port, core and console on LPUART1) on the model: commands as bytes
 * on the UART, periods running between the main loop's turns.
 * ========================================================================= */

static uint32_t uart_cursor; /* frames in M.uart_tx before this are read */

/* @p periods carrier periods, the main loop turning four times per period. */
static void app_run(uint32_t arr, unsigned periods)
{
    unsigned k;
    for (k = 0; k < 4u * periods; ++k) {
        stm32g4_model_run(arr / 2u);
        pmstep_app_poll();
    }
}

/* A few turns of the main loop, no period ending (a reply may take more than one turn to send). */
static void turns(void)
{
    unsigned k;
    for (k = 0; k < 8u; ++k) {
        pmstep_app_poll();
    }
}

/* HELLO's flags (pmstep_console.h): 1 a stored configuration attached, 2 a motor configured. */
#define HELLO_STORE 1u
#define HELLO_CONFIGURED 2u

/* A record of @p cfg saved in the flash (through the port's driver, on the model's flash), as a
 * configuration written over the console and saved would leave it. */
static void store_record(const pmstep_config_t *cfg)
{
    pmstep_store_t store;
    pmstep_store_record_t rec;
    memset(&rec, 0, sizeof rec);
    rec.config = *cfg;
    rec.stepdir = pmstep_console_stepdir_defaults();
    assert_int_equal(pmstep_store_init(&store, pmstep_stm32g4_store_flash(), pmstep_stm32g4_board_id()),
                     PMSTEP_STORE_OK);
    assert_int_equal(pmstep_store_save(&store, &rec, true), PMSTEP_STORE_OK);
}

/* HELLO: its text and flags. */
static void check_hello(uint8_t seq, uint8_t flags)
{
    uint8_t d[64];
    int n;
    model_host_send(PMSTEP_CONSOLE_HELLO, seq, NULL, 0u);
    turns();
    n = model_host_receive(&uart_cursor, 0x81u, d);
    assert_true(n > 4);
    assert_int_equal(d[2], PMSTEP_STORE_FORMAT_VERSION);
    assert_int_equal(d[3], flags);
    assert_memory_equal(&d[4], "pmstep " PMSTEP_VERSION_TEXT " stm32g431",
                        strlen("pmstep  stm32g431") + strlen(PMSTEP_VERSION_TEXT));
}

/* A fresh part: the application boots with the board's configuration, not configured; START is
 * refused (error reply NOT_CONFIGURED) and the bridge stays off. */
static void test_app_boots_unconfigured_with_empty_flash(void **state)
{
    const uint32_t arr = arr_of_board();
    uint8_t d[64];
    int n;
    (void)state;
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    analog(0.0f, 0.0f, 48.0f);
    assert_int_equal(pmstep_app_init(), 0);
    assert_int_equal(stm32g4_model_flash.steps, 0u); /* booting only reads the flash */
    /* The default build has no STEP/DIR mode: TIM4 never clocked, its pins and EN/DIAG's untouched
     * (analog, their reset state), STEP pulses count nothing. */
    assert_int_equal(stm32g4_fake.rcc.APB1ENR1 & RCC_APB1ENR1_TIM4EN, 0u);
    assert_int_equal((stm32g4_fake.gpio[board.step_input.step_pin.port].MODER >> (2u * board.step_input.step_pin.pin))
                         & 3u,
                     GPIO_MODE_ANALOG);
    assert_int_equal(
        (stm32g4_fake.gpio[board.step_input.enable_pin.port].MODER >> (2u * board.step_input.enable_pin.pin)) & 3u,
        GPIO_MODE_ANALOG);
    stm32g4_model_pin_in(board.step_input.step_pin.port, board.step_input.step_pin.pin, true);
    stm32g4_model_run(100u);
    stm32g4_model_pin_in(board.step_input.step_pin.port, board.step_input.step_pin.pin, false);
    stm32g4_model_run(100u);
    assert_int_equal(stm32g4_fake.tim4.CNT, 0u);
    assert_int_equal(pmstep_app_step_count(), 0);
    uart_cursor = 0u;
    check_hello(1u, HELLO_STORE);
    model_host_send(PMSTEP_CONSOLE_START, 2u, NULL, 0u);
    turns();
    app_run(arr, 2u);
    n = model_host_receive(&uart_cursor, PMSTEP_CONSOLE_ERROR_FRAME, d);
    assert_int_equal(n, 2);
    assert_int_equal(d[0], PMSTEP_CONSOLE_START);
    assert_int_equal(d[1], PMSTEP_CONSOLE_ERR_NOT_CONFIGURED);
    app_run(arr, 20u);
    assert_false(pmstep_stm32g4_bridge_on());
    model_host_send(PMSTEP_CONSOLE_GET_STATUS, 3u, NULL, 0u);
    turns();
    n = model_host_receive(&uart_cursor, 0x87u, d);
    assert_int_equal(n, 60);
    assert_int_equal(d[4], PMSTEP_MODE_IDLE);
}

static void test_app_console_on_the_model(void **state)
{
    const uint32_t arr = arr_of_board();
    uint8_t d[64];
    int n;
    (void)state;
    store_record(&motor_config); /* the paper's motor, configured from the flash at boot */
    stm32g4_model_reset();       /* a power cycle: the flash keeps it */
    stm32g4_model_pin_in(board.fault_pin.port, board.fault_pin.pin, !board.fault_active_high);
    analog(0.0f, 0.0f, 48.0f);
    assert_int_equal(pmstep_app_init(), 0);
    uart_cursor = 0u;
    /* Hello, answered in the main loop. */
    check_hello(1u, HELLO_STORE | HELLO_CONFIGURED);
    /* IDLE: the bridge stays off while periods run. */
    app_run(arr, 10u);
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(M.adc_irqs, 10u);
    /* Start, telemetry every 10 periods: applied at a boundary, the bridge on. */
    model_host_send(PMSTEP_CONSOLE_START, 2u, NULL, 0u);
    turns();
    n = model_host_receive(&uart_cursor, 0x82u, d);
    assert_int_equal(n, 6);
    assert_int_equal(d[0] | (d[1] << 8), 0);
    assert_true(stm32g4_fake.nvic.ISER[0] & STM32G4_BIT(STM32G4_IRQ_ADC1_2)); /* released again */
    {
        const uint32_t dec = 10u;
        model_host_send(PMSTEP_CONSOLE_TELEMETRY, 3u, &dec, 4u);
    }
    app_run(arr, 50u);
    assert_true(pmstep_stm32g4_bridge_on());
    assert_int_equal(M.adc_irqs, 60u); /* not one period lost to the console */
    {
        unsigned frames = 0;
        uint32_t last = 0;
        const uint32_t save = uart_cursor;
        while ((n = model_host_receive(&uart_cursor, PMSTEP_CONSOLE_TELEMETRY_FRAME, d)) > 0) {
            uint32_t period;
            float bus;
            memcpy(&period, d, 4u);
            memcpy(&bus, &d[6 + 4 * 7], 4u);
            assert_true(frames == 0u || period > last);
            assert_int_equal(d[4], PMSTEP_MODE_S_ALIGN);
            assert_float_equal(bus, 48.0f, board.bus_gain_v_per_count);
            last = period;
            frames++;
        }
        assert_true(frames >= 4u && frames <= 5u); /* every 10 periods over 50 */
        uart_cursor = save;
    }
    /* Status: mode, currents as sampled. */
    model_host_send(PMSTEP_CONSOLE_GET_STATUS, 4u, NULL, 0u);
    turns();
    n = model_host_receive(&uart_cursor, 0x87u, d);
    assert_int_equal(n, 60);
    assert_int_equal(d[4], PMSTEP_MODE_S_ALIGN);
    /* A break: every switch off in the port; the status shows the port's fault. */
    M.bkin_pin_high = false;
    app_run(arr, 2u);
    assert_false(pmstep_stm32g4_bridge_on());
    model_host_send(PMSTEP_CONSOLE_GET_STATUS, 5u, NULL, 0u);
    turns();
    n = model_host_receive(&uart_cursor, 0x87u, d);
    assert_int_equal(d[6], PMSTEP_STM32G4_FAULT_BREAK);
    /* Released, cleared through the console: the port's latch clears too. */
    M.bkin_pin_high = true;
    app_run(arr, 1u);
    model_host_send(PMSTEP_CONSOLE_CLEAR_FAULT, 6u, NULL, 0u);
    turns();
    n = model_host_receive(&uart_cursor, 0x84u, d);
    assert_int_equal(n, 6);
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_NONE);
    /* Garbage on the line: counted, nothing else. */
    {
        const uint8_t junk[5] = {0x00u, 0x13u, 0x37u, 0xFFu, 0x42u};
        uint32_t garbage;
        stm32g4_model_uart_send(junk, sizeof junk);
        turns();
        model_host_send(PMSTEP_CONSOLE_GET_COUNTERS, 7u, NULL, 0u);
        pmstep_app_poll();
        n = model_host_receive(&uart_cursor, 0x8Cu, d);
        assert_int_equal(n, 44);
        memcpy(&garbage, &d[8], 4u);
        assert_int_equal(garbage, 5u);
    }
    assert_int_equal(pmstep_app_uart_errors(), 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_one_injected_conversion_per_period, setup),
        cmocka_unit_test_setup(test_flash_latency_every_pll_setting, setup),
        cmocka_unit_test_setup(test_adc_enable_retried_after_calibration, setup),
        cmocka_unit_test_setup(test_enable_pin_written_after_its_clock, setup),
        cmocka_unit_test_setup(test_default_board_off_nucleo_pins, setup),
        cmocka_unit_test_setup(test_model_edge_aligned_counter_and_repetition, setup),
        cmocka_unit_test_setup(test_model_centre_aligned_counter_and_repetition, setup),
        cmocka_unit_test_setup(test_model_pwm_modes_and_limits, setup),
        cmocka_unit_test_setup(test_model_complementary_outputs_dead_time, setup),
        cmocka_unit_test_setup(test_model_break, setup),
        cmocka_unit_test_setup(test_model_trgo2_and_adc_edges, setup),
        cmocka_unit_test_setup(test_model_flash_table, setup),
        cmocka_unit_test_setup(test_port_duties_follow_commanded_voltages, setup),
        cmocka_unit_test_setup(test_port_break_turns_bridge_off, setup),
        cmocka_unit_test_setup(test_port_firmware_fault_turns_bridge_off, setup),
        cmocka_unit_test_setup(test_app_boots_unconfigured_with_empty_flash, setup),
        cmocka_unit_test_setup(test_app_console_on_the_model, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
