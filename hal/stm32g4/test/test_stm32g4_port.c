/*
 * Unit tests of the STM32G431 port on the host, against fake register blocks
 * (STM32G4_FAKE_REGISTERS: every peripheral is a struct in RAM). The wait hook plays
 * the hardware where a driver waits for it: ready flags follow their enables, the
 * clock switch follows its request, calibration ends. The control interrupt runs
 * the real core.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "pmstep_hal_stm32g4.h"
#include "stm32g4_regs.h"

stm32g4_fake_t stm32g4_fake;
static bool hardware_responds; /* false: nothing ever becomes ready */
static unsigned hook_calls;
/* ADEN is set-only on the hardware and later writes carry it as 0; the hook records that the
 * driver set it and waited for ADRDY. */
static bool adc1_enabled_seen;
static bool adc2_enabled_seen;

void stm32g4_fake_wait_hook(void)
{
    hook_calls++;
    if (!hardware_responds) {
        return;
    }
    stm32g4_fake.rcc.CR =
        (stm32g4_fake.rcc.CR & ~RCC_CR_PLLRDY) | ((stm32g4_fake.rcc.CR & RCC_CR_PLLON) ? RCC_CR_PLLRDY : 0u);
    if (stm32g4_fake.rcc.CR & RCC_CR_HSION) {
        stm32g4_fake.rcc.CR |= RCC_CR_HSIRDY;
    }
    stm32g4_fake.rcc.CFGR =
        (stm32g4_fake.rcc.CFGR & ~RCC_CFGR_SWS_MASK) | ((stm32g4_fake.rcc.CFGR & RCC_CFGR_SW_MASK) << RCC_CFGR_SWS_POS);
    stm32g4_fake.adc1.CR &= ~ADC_CR_ADCAL;
    stm32g4_fake.adc2.CR &= ~ADC_CR_ADCAL;
    /* ADRDY only once enabled (a plain-RAM write of ADRDY to clear it would set it here). */
    if (stm32g4_fake.adc1.CR & ADC_CR_ADEN) {
        stm32g4_fake.adc1.ISR |= ADC_ISR_ADRDY;
        adc1_enabled_seen = true;
    } else if (!adc1_enabled_seen) {
        stm32g4_fake.adc1.ISR &= ~ADC_ISR_ADRDY;
    }
    if (stm32g4_fake.adc2.CR & ADC_CR_ADEN) {
        stm32g4_fake.adc2.ISR |= ADC_ISR_ADRDY;
        adc2_enabled_seen = true;
    } else if (!adc2_enabled_seen) {
        stm32g4_fake.adc2.ISR &= ~ADC_ISR_ADRDY;
    }
}

stm32g4_gpio_t *stm32g4_fake_gpio(uint32_t port)
{
    return &stm32g4_fake.gpio[port];
}

/* LPUART data registers as plain RAM: RDR as it is, TDR keeps the last byte. */
uint32_t stm32g4_fake_lpuart_rdr(void)
{
    return stm32g4_fake.lpuart1.RDR;
}

void stm32g4_fake_lpuart_tdr(uint32_t byte)
{
    stm32g4_fake.lpuart1.TDR = byte;
}

static pmstep_stm32g4_config_t board;
static pmstep_config_t motor_config;
static pmstep_t motor;

#define ARR_20KHZ 4250u /* 170 MHz / (2 x 20 kHz) */

/* Reset values that matter (RM0440): ADC CR DEEPPWD = 1, CFGR JQDIS = 1; TIM1 AF1 BKINE = 1;
 * HSI on and ready; GPIO MODER all analog except PA13..15. */
static void reset_registers(void)
{
    memset(&stm32g4_fake, 0, sizeof stm32g4_fake);
    stm32g4_fake.rcc.CR = RCC_CR_HSION | RCC_CR_HSIRDY;
    stm32g4_fake.rcc.CFGR = 1u; /* SW = SWS = HSI16 */
    stm32g4_fake.adc1.CR = ADC_CR_DEEPPWD;
    stm32g4_fake.adc2.CR = ADC_CR_DEEPPWD;
    stm32g4_fake.adc1.CFGR = ADC_CFGR_JQDIS;
    stm32g4_fake.adc2.CFGR = ADC_CFGR_JQDIS;
    stm32g4_fake.tim1.AF1 = TIM_AF1_BKINE;
    {
        unsigned p;
        for (p = 0; p < STM32G4_GPIO_PORTS; ++p) {
            stm32g4_fake.gpio[p].MODER = 0xFFFFFFFFu;
        }
    }
    stm32g4_fake.gpio[0].MODER = 0xABFFFFFFu;
}

static int setup(void **state)
{
    (void)state;
    reset_registers();
    hardware_responds = true;
    hook_calls = 0;
    adc1_enabled_seen = false;
    adc2_enabled_seen = false;
    board = pmstep_stm32g4_default_config();
    motor_config = pmstep_paper_config();
    motor_config.timing.period_s = pmstep_stm32g4_period_s(&board);
    motor_config.timing.computational_delay_periods = 1u;
    motor_config.limits.current_sense_range_A = pmstep_stm32g4_current_sense_range_A(&board);
    motor_config.limits.bus_sense_range_V = pmstep_stm32g4_bus_sense_range_V(&board);
    assert_int_equal(pmstep_init(&motor, &motor_config), PMSTEP_OK);
    return 0;
}

/* The fault input (PC6, active low) released: pin high. */
static void fault_input(bool asserted)
{
    if (asserted) {
        stm32g4_fake.gpio[2].IDR &= ~STM32G4_BIT(6);
    } else {
        stm32g4_fake.gpio[2].IDR |= STM32G4_BIT(6);
    }
}

/* ADC samples as the hardware would leave them in the injected data registers. */
static void adc_samples(uint32_t i_a_counts, uint32_t bus_counts, uint32_t i_b_counts)
{
    stm32g4_fake.adc1.JDR[0] = i_a_counts;
    stm32g4_fake.adc1.JDR[1] = bus_counts;
    stm32g4_fake.adc2.JDR[0] = i_b_counts;
    stm32g4_fake.adc1.ISR |= ADC_ISR_JEOC | ADC_ISR_JEOS;
}

/* Counts of the default board for a bus of @p bus_V volts. */
static uint32_t bus_counts(float bus_V)
{
    return (uint32_t)lroundf(bus_V / board.bus_gain_v_per_count);
}

static bool enable_pin_set_last(void)
{
    /* PB5: the last BSRR write decides; bit 5 sets, bit 21 resets. */
    return (stm32g4_fake.gpio[1].BSRR & STM32G4_BIT(5)) != 0u && (stm32g4_fake.gpio[1].BSRR & STM32G4_BIT(21)) == 0u;
}

static bool enable_pin_reset_last(void)
{
    return (stm32g4_fake.gpio[1].BSRR & STM32G4_BIT(21)) != 0u && (stm32g4_fake.gpio[1].BSRR & STM32G4_BIT(5)) == 0u;
}

static void port_up(void)
{
    fault_input(false);
    assert_int_equal(pmstep_stm32g4_init(&board, &motor), PMSTEP_STM32G4_OK);
}

/* ---- pure functions ---- */

static void test_counts_to_si(void **state)
{
    (void)state;
    /* Default board: 3.3 V / 4096 per count, 0.1 V/A around 2048 counts; bus 1:20. */
    assert_float_equal(pmstep_stm32g4_counts_to_si(2048u, 2048.0f, board.i_a_gain_a_per_count), 0.0f, 0.0f);
    assert_float_equal(pmstep_stm32g4_counts_to_si(2048u + 124u, 2048.0f, board.i_a_gain_a_per_count),
                       124.0f * 3.3f / 4096.0f / 0.1f, 1e-6f); /* 0.999 A */
    assert_float_equal(pmstep_stm32g4_counts_to_si(0u, 2048.0f, board.i_a_gain_a_per_count), -16.5f, 1e-5f);
    assert_float_equal(pmstep_stm32g4_counts_to_si(4095u, 0.0f, board.bus_gain_v_per_count),
                       4095.0f * 3.3f / 4096.0f * 20.0f, 1e-4f); /* 65.98 V full scale */
    assert_float_equal(pmstep_stm32g4_counts_to_si(100u, 10.0f, 0.5f), 45.0f, 0.0f);
    assert_float_equal(pmstep_stm32g4_counts_to_si(0u, 10.0f, -2.0f), 20.0f, 0.0f); /* sign in the gain */
}

static void test_duties(void **state)
{
    float dp;
    float dm;
    (void)state;
    pmstep_stm32g4_duties(0.0f, 48.0f, 0.0f, 1.0f, &dp, &dm);
    assert_float_equal(dp, 0.5f, 0.0f);
    assert_float_equal(dm, 0.5f, 0.0f);
    pmstep_stm32g4_duties(12.0f, 48.0f, 0.0f, 1.0f, &dp, &dm);
    assert_float_equal(dp, 0.625f, 0.0f);
    assert_float_equal(dm, 0.375f, 0.0f);
    assert_float_equal((dp - dm) * 48.0f, 12.0f, 0.0f); /* u = (d+ - d-) V_bus */
    pmstep_stm32g4_duties(-24.0f, 48.0f, 0.0f, 1.0f, &dp, &dm);
    assert_float_equal(dp, 0.25f, 0.0f);
    assert_float_equal(dm, 0.75f, 0.0f);
    pmstep_stm32g4_duties(48.0f, 48.0f, 0.0f, 1.0f, &dp, &dm); /* full bus */
    assert_float_equal(dp, 1.0f, 0.0f);
    assert_float_equal(dm, 0.0f, 0.0f);
    pmstep_stm32g4_duties(100.0f, 48.0f, 0.0f, 1.0f, &dp, &dm); /* beyond: clamped */
    assert_float_equal(dp, 1.0f, 0.0f);
    assert_float_equal(dm, 0.0f, 0.0f);
    pmstep_stm32g4_duties(48.0f, 48.0f, 0.02f, 0.98f, &dp, &dm); /* bootstrap limits */
    assert_float_equal(dp, 0.98f, 0.0f);
    assert_float_equal(dm, 0.02f, 0.0f);
    pmstep_stm32g4_duties(10.0f, 0.0f, 0.0f, 1.0f, &dp, &dm); /* no bus: zero volts */
    assert_float_equal(dp, 0.5f, 0.0f);
    assert_float_equal(dm, 0.5f, 0.0f);
    pmstep_stm32g4_duties(10.0f, NAN, 0.0f, 1.0f, &dp, &dm);
    assert_float_equal(dp, 0.5f, 0.0f);
    assert_float_equal(dm, 0.5f, 0.0f);
    pmstep_stm32g4_duties(NAN, 48.0f, 0.0f, 1.0f, &dp, &dm);
    assert_float_equal(dp, 0.5f, 0.0f);
    assert_float_equal(dm, 0.5f, 0.0f);

    assert_int_equal(pmstep_stm32g4_duty_to_ccr(0.5f, ARR_20KHZ), 2125u);
    assert_int_equal(pmstep_stm32g4_duty_to_ccr(0.625f, ARR_20KHZ), 2656u); /* 2656.25 */
    assert_int_equal(pmstep_stm32g4_duty_to_ccr(1.0f, ARR_20KHZ), ARR_20KHZ);
    assert_int_equal(pmstep_stm32g4_duty_to_ccr(0.0f, ARR_20KHZ), 0u);
    assert_int_equal(pmstep_stm32g4_duty_to_ccr(1.5f, ARR_20KHZ), ARR_20KHZ);
    assert_int_equal(pmstep_stm32g4_duty_to_ccr(-0.5f, ARR_20KHZ), 0u);
}

static void test_dead_time(void **state)
{
    uint8_t dtg = 0;
    (void)state;
    /* t_DTS = 1/170 MHz = 5.88 ns */
    assert_int_equal(pmstep_stm32g4_dead_time_dtg(500u, 170000000u, &dtg), PMSTEP_STM32G4_OK);
    assert_int_equal(dtg, 85u); /* 85 x 5.88 ns = 500 ns */
    assert_int_equal(pmstep_stm32g4_dtg_to_ns(dtg, 170000000u), 500u);
    assert_int_equal(pmstep_stm32g4_dead_time_dtg(1000u, 170000000u, &dtg), PMSTEP_STM32G4_OK);
    assert_int_equal(dtg, 0x80u | 21u); /* (64 + 21) x 2 t = 170 t = 1000 ns */
    assert_int_equal(pmstep_stm32g4_dtg_to_ns(dtg, 170000000u), 1000u);
    assert_int_equal(pmstep_stm32g4_dead_time_dtg(2000u, 170000000u, &dtg), PMSTEP_STM32G4_OK);
    assert_int_equal(dtg, 0xC0u | 11u); /* 340 t -> (32 + 11) x 8 t = 344 t */
    assert_true(pmstep_stm32g4_dtg_to_ns(dtg, 170000000u) >= 2000u);
    assert_int_equal(pmstep_stm32g4_dead_time_dtg(5000u, 170000000u, &dtg), PMSTEP_STM32G4_OK);
    assert_int_equal(dtg, 0xE0u | 22u); /* 850 t -> (32 + 22) x 16 t = 864 t */
    assert_true(pmstep_stm32g4_dtg_to_ns(dtg, 170000000u) >= 5000u);
    assert_int_equal(pmstep_stm32g4_dead_time_dtg(0u, 170000000u, &dtg), PMSTEP_STM32G4_OK);
    assert_int_equal(dtg, 0u);
    /* Longest: 1008 t = 5.93 us */
    assert_int_equal(pmstep_stm32g4_dead_time_dtg(5929u, 170000000u, &dtg), PMSTEP_STM32G4_OK);
    assert_int_equal(dtg, 0xFFu);
    assert_int_equal(pmstep_stm32g4_dead_time_dtg(6000u, 170000000u, &dtg), PMSTEP_STM32G4_ERR_DEAD_TIME);
    /* Never shorter than asked, over the whole range. */
    {
        uint32_t ns;
        for (ns = 0u; ns <= 5900u; ns += 7u) {
            assert_int_equal(pmstep_stm32g4_dead_time_dtg(ns, 170000000u, &dtg), PMSTEP_STM32G4_OK);
            assert_true(pmstep_stm32g4_dtg_to_ns(dtg, 170000000u) + 1u >= ns);
        }
    }
}

static void test_clock_arithmetic(void **state)
{
    const pmstep_stm32g4_clock_t c170 = {4u, 85u, 2u};
    const pmstep_stm32g4_clock_t too_fast = {4u, 90u, 2u}; /* 180 MHz */
    const pmstep_stm32g4_clock_t bad_r = {4u, 85u, 3u};
    const pmstep_stm32g4_clock_t vco_low = {4u, 20u, 2u}; /* VCO 80 MHz */
    (void)state;
    assert_int_equal(pmstep_stm32g4_sysclk_Hz(&c170), 170000000u);
    assert_int_equal(pmstep_stm32g4_sysclk_Hz(&too_fast), 0u);
    assert_int_equal(pmstep_stm32g4_sysclk_Hz(&bad_r), 0u);
    assert_int_equal(pmstep_stm32g4_sysclk_Hz(&vco_low), 0u);
    assert_int_equal(pmstep_stm32g4_flash_latency(170000000u), 4u);
    assert_int_equal(pmstep_stm32g4_flash_latency(151000000u), 4u);
    assert_int_equal(pmstep_stm32g4_flash_latency_mode(34000000u, true), 0u);
    assert_int_equal(pmstep_stm32g4_flash_latency_mode(34000001u, true), 1u);
    /* At or below 150 MHz the port runs range 1 normal mode: 30 MHz per wait state. */
    assert_int_equal(pmstep_stm32g4_flash_latency(150000000u), 4u);
    assert_int_equal(pmstep_stm32g4_flash_latency(64000000u), 2u);
    assert_int_equal(pmstep_stm32g4_flash_latency(30000000u), 0u);
    assert_int_equal(pmstep_stm32g4_flash_latency(30000001u), 1u);
    assert_int_equal(pmstep_stm32g4_flash_latency_mode(64000000u, true), 1u);
    assert_int_equal(pmstep_stm32g4_flash_latency_mode(150000000u, true), 4u);
    assert_int_equal(pmstep_stm32g4_pwm_arr(170000000u, 20000u), ARR_20KHZ);
    assert_int_equal(pmstep_stm32g4_pwm_arr(170000000u, 10000u), 8500u);
    assert_int_equal(pmstep_stm32g4_pwm_arr(170000000u, 40000u), 2125u);
    assert_int_equal(pmstep_stm32g4_pwm_arr(170000000u, 1000u), 0u); /* ARR 85000 > 65535 */
    assert_float_equal(pmstep_stm32g4_period_s(&board), 50e-6f, 1e-12f);
}

/* ---- drivers against the fake registers ---- */

static void test_clock_init(void **state)
{
    stm32g4_rcc_t *rcc = &stm32g4_fake.rcc;
    (void)state;
    assert_int_equal(pmstep_stm32g4_clock_init(&board.clock), PMSTEP_STM32G4_OK);
    /* PLL: HSI16 / 4 x 85 / 2, R output on */
    assert_int_equal(rcc->PLLCFGR, 2u | (3u << 4) | (85u << 8) | (0u << 25) | (1u << 24));
    assert_true(rcc->CR & RCC_CR_PLLON);
    assert_int_equal(rcc->CFGR & RCC_CFGR_SW_MASK, 3u);   /* SYSCLK = PLL */
    assert_int_equal(rcc->CFGR & RCC_CFGR_HPRE_MASK, 0u); /* HCLK = SYSCLK in the end */
    assert_int_equal(rcc->CFGR & (RCC_CFGR_PPRE1_MASK | RCC_CFGR_PPRE2_MASK), 0u);
    assert_int_equal(stm32g4_fake.flash.ACR & FLASH_ACR_LATENCY_MASK, 4u); /* 4 wait states at 170 MHz */
    assert_true(stm32g4_fake.flash.ACR & FLASH_ACR_PRFTEN);
    assert_true(stm32g4_fake.flash.ACR & FLASH_ACR_ICEN);
    assert_true(stm32g4_fake.flash.ACR & FLASH_ACR_DCEN);
    assert_int_equal(stm32g4_fake.pwr.CR5 & PWR_CR5_R1MODE, 0u); /* range 1 boost */
    assert_int_equal(stm32g4_fake.pwr.CR1 & PWR_CR1_VOS_MASK, PWR_CR1_VOS_RANGE1);
    assert_true(rcc->APB1ENR1 & RCC_APB1ENR1_PWREN);
}

static void test_clock_init_timeout_and_config(void **state)
{
    const pmstep_stm32g4_clock_t too_fast = {4u, 90u, 2u};
    (void)state;
    hardware_responds = false; /* the PLL never locks */
    stm32g4_fake.rcc.CR = RCC_CR_HSION | RCC_CR_HSIRDY;
    assert_int_equal(pmstep_stm32g4_clock_init(&board.clock), PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT);
    assert_true(hook_calls >= 1000000u);                            /* it waited, boundedly */
    assert_int_equal(stm32g4_fake.rcc.CFGR & RCC_CFGR_SW_MASK, 1u); /* never switched to a dead PLL */
    assert_int_equal(pmstep_stm32g4_clock_init(&too_fast), PMSTEP_STM32G4_ERR_CLOCK_CONFIG);
    assert_int_equal(pmstep_stm32g4_clock_init(NULL), PMSTEP_STM32G4_ERR_NULL_ARGUMENT);
}

static void test_pwm_init(void **state)
{
    stm32g4_tim_t *tim = &stm32g4_fake.tim1;
    const uint32_t pwm1 = (6u << 4) | (1u << 3);
    (void)state;
    assert_int_equal(pmstep_stm32g4_pwm_init(&board, 170000000u), PMSTEP_STM32G4_OK);
    assert_true(stm32g4_fake.rcc.APB2ENR & RCC_APB2ENR_TIM1EN);
    assert_int_equal(tim->CR1 & TIM_CR1_CEN, 0u);                /* not running yet */
    assert_int_equal(tim->CR1 & (3u << 5), TIM_CR1_CMS_CENTER1); /* centre-aligned */
    assert_true(tim->CR1 & TIM_CR1_ARPE);
    assert_int_equal(tim->PSC, 0u);
    assert_int_equal(tim->ARR, ARR_20KHZ);               /* 20 kHz at 170 MHz */
    assert_int_equal(tim->RCR, 1u);                      /* one update per period */
    assert_int_equal(tim->CCMR1, pwm1 | (pwm1 << 8));    /* CH1, CH2 PWM mode 1, preload */
    assert_int_equal(tim->CCMR2, pwm1 | (pwm1 << 8));    /* CH3, CH4 */
    assert_int_equal(tim->CCMR3, (7u << 4) | (1u << 3)); /* CH5 PWM mode 2: trigger at peak */
    assert_int_equal(tim->CCR5, ARR_20KHZ - 1u);         /* reached on the up slope */
    assert_int_equal(tim->CCR1, ARR_20KHZ / 2u);         /* 0 V until the first step */
    assert_int_equal(tim->CCR4, ARR_20KHZ / 2u);
    assert_int_equal(tim->CCER, 0x5555u | TIM_CCER_CC5E);                     /* CHx and CHxN of 1..4, active high */
    assert_int_equal((tim->CR2 & TIM_CR2_MMS2_MASK) >> TIM_CR2_MMS2_POS, 8u); /* TRGO2 = OC5REFC */
    assert_int_equal(tim->CR2 & 0xFF00u, 0u);                                 /* idle levels: all off */
    assert_int_equal(tim->BDTR & TIM_BDTR_DTG_MASK, 85u);                     /* 500 ns */
    assert_true(tim->BDTR & TIM_BDTR_BKE);
    assert_int_equal(tim->BDTR & TIM_BDTR_BKP, 0u); /* break active low */
    assert_true(tim->BDTR & TIM_BDTR_OSSI);
    assert_true(tim->BDTR & TIM_BDTR_OSSR);
    assert_int_equal(tim->BDTR & TIM_BDTR_MOE, 0u); /* bridge off */
    assert_int_equal(tim->BDTR & TIM_BDTR_AOE, 0u);
    assert_int_equal((tim->BDTR >> 16) & 0xFu, 4u); /* break filter */
    assert_true(tim->AF1 & TIM_AF1_BKINE);
    assert_true(tim->DIER & TIM_DIER_BIE);
    assert_true(tim->EGR & TIM_EGR_UG);

    board.pwm_frequency_Hz = 10000u;
    assert_int_equal(pmstep_stm32g4_pwm_init(&board, 170000000u), PMSTEP_STM32G4_OK);
    assert_int_equal(tim->ARR, 8500u);
    board.pwm_frequency_Hz = 1000u;
    assert_int_equal(pmstep_stm32g4_pwm_init(&board, 170000000u), PMSTEP_STM32G4_ERR_PWM_FREQUENCY);
    board.pwm_frequency_Hz = 20000u;
    board.dead_time_ns = 10000u;
    assert_int_equal(pmstep_stm32g4_pwm_init(&board, 170000000u), PMSTEP_STM32G4_ERR_DEAD_TIME);
    board.dead_time_ns = 500u;
    board.duty_min = 0.6f;
    board.duty_max = 0.4f;
    assert_int_equal(pmstep_stm32g4_pwm_init(&board, 170000000u), PMSTEP_STM32G4_ERR_DUTY_RANGE);
}

static void test_adc_init(void **state)
{
    stm32g4_adc_t *adc1 = &stm32g4_fake.adc1;
    stm32g4_adc_t *adc2 = &stm32g4_fake.adc2;
    const uint32_t trigger = (8u << 2) | (1u << 7); /* TIM1_TRGO2, rising edge */
    (void)state;
    assert_int_equal(pmstep_stm32g4_adc_init(&board), PMSTEP_STM32G4_OK);
    assert_true(stm32g4_fake.rcc.AHB2ENR & RCC_AHB2ENR_ADC12EN);
    assert_int_equal(stm32g4_fake.adc12.CCR & ADC_CCR_CKMODE_MASK, ADC_CCR_CKMODE_HCLK_DIV4);
    assert_int_equal(adc1->CR & ADC_CR_DEEPPWD, 0u);
    assert_true(adc1->CR & ADC_CR_ADVREGEN);
    assert_true(adc1_enabled_seen); /* enabled, and ADRDY awaited */
    assert_true(adc2_enabled_seen);
    assert_int_equal(adc1->CR & ADC_CR_ADCALDIF, 0u); /* single-ended calibration */
    assert_true(adc1->CR & ADC_CR_JADSTART);
    assert_true(adc2->CR & ADC_CR_JADSTART);
    /* ADC1: 2 conversions, i_a (ch 1) then bus (ch 6); ADC2: i_b (ch 2) */
    assert_int_equal(adc1->JSQR, 1u | trigger | (1u << 9) | (6u << 15));
    assert_int_equal(adc2->JSQR, 0u | trigger | (2u << 9));
    assert_int_equal(adc1->SMPR1, (2u << 3) | (2u << 18));
    assert_int_equal(adc2->SMPR1, 2u << 6);
    assert_int_equal(adc1->IER, ADC_IER_JEOSIE);
    assert_int_equal(adc2->IER, 0u);

    reset_registers();
    hardware_responds = false; /* calibration never ends */
    assert_int_equal(pmstep_stm32g4_adc_init(&board), PMSTEP_STM32G4_ERR_ADC_TIMEOUT);
    board.adc1_channel_bus = 19u;
    assert_int_equal(pmstep_stm32g4_adc_init(&board), PMSTEP_STM32G4_ERR_ADC_CONFIG);
}

static void test_gpio_init(void **state)
{
    stm32g4_gpio_t *gpioa = &stm32g4_fake.gpio[0];
    stm32g4_gpio_t *gpiob = &stm32g4_fake.gpio[1];
    stm32g4_gpio_t *gpioc = &stm32g4_fake.gpio[2];
    (void)state;
    assert_int_equal(pmstep_stm32g4_gpio_init(&board), PMSTEP_STM32G4_OK);
    assert_int_equal((gpioa->MODER >> (2u * 8u)) & 3u, GPIO_MODE_AF);     /* PA8 TIM1_CH1 */
    assert_int_equal((gpioa->AFR[1] >> 0) & 0xFu, 6u);                    /* AF6 */
    assert_int_equal((gpioa->AFR[1] >> 12) & 0xFu, 11u);                  /* PA11 AF11 */
    assert_int_equal((gpioa->AFR[0] >> 28) & 0xFu, 6u);                   /* PA7 TIM1_CH1N AF6 */
    assert_int_equal((gpioc->AFR[0] >> 20) & 0xFu, 6u);                   /* PC5 TIM1_CH4N AF6 */
    assert_int_equal((gpioa->MODER >> (2u * 6u)) & 3u, GPIO_MODE_AF);     /* PA6 BKIN */
    assert_int_equal((gpioa->PUPDR >> (2u * 6u)) & 3u, GPIO_PULL_UP);     /* active low break */
    assert_int_equal((gpioa->MODER >> 0) & 3u, GPIO_MODE_ANALOG);         /* PA0 i_a */
    assert_int_equal((gpiob->MODER >> (2u * 5u)) & 3u, GPIO_MODE_OUTPUT); /* PB5 enable */
    assert_true(enable_pin_reset_last());                                 /* driver off */
    assert_int_equal((gpioc->MODER >> (2u * 6u)) & 3u, GPIO_MODE_INPUT);  /* PC6 fault */
    assert_int_equal((gpioc->PUPDR >> (2u * 6u)) & 3u, GPIO_PULL_UP);
    assert_int_equal((gpioa->MODER >> (2u * 13u)) & 3u, 2u); /* SWD pins untouched */
    board.fault_pin.pin = 16u;
    assert_int_equal(pmstep_stm32g4_gpio_init(&board), PMSTEP_STM32G4_ERR_PIN);
}

static void test_port_init(void **state)
{
    (void)state;
    port_up();
    assert_int_equal(stm32g4_fake.nvic.ISER[0] & (1u << 18), 1u << 18); /* ADC1_2 */
    assert_int_equal(stm32g4_fake.nvic.ISER[0] & (1u << 24), 1u << 24); /* TIM1_BRK */
    assert_true(stm32g4_fake.nvic.IPR[24] < stm32g4_fake.nvic.IPR[18]); /* break first */
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_true(stm32g4_fake.dwt.CTRL & DWT_CTRL_CYCCNTENA);
    pmstep_stm32g4_start();
    assert_true(stm32g4_fake.tim1.CR1 & TIM_CR1_CEN);
}

/* The interrupt in IDLE: measurements converted, bridge stays off. */
static void test_isr_idle_keeps_bridge_off(void **state)
{
    (void)state;
    port_up();
    adc_samples(2048u, bus_counts(48.0f), 2048u);
    ADC1_2_IRQHandler();
    assert_int_equal(stm32g4_fake.adc1.ISR, ADC_ISR_JEOC | ADC_ISR_JEOS); /* flags written to clear */
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_int_equal(stm32g4_fake.tim1.CCR1, ARR_20KHZ / 2u);
}

/* s-alignment (3): u_a = 0, u_b = u_cs = 24 V on a 48 V bus -> b+ at 75 %, b- at 25 %. */
static void test_isr_s_alignment_duties(void **state)
{
    (void)state;
    port_up();
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    adc_samples(2048u, bus_counts(48.0f), 2048u);
    ADC1_2_IRQHandler();
    assert_true(pmstep_stm32g4_bridge_on());
    assert_true(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE);
    assert_true(enable_pin_set_last());
    {
        /* The core limits to the sampled bus, which is 48 V to within one count. */
        const float bus = pmstep_stm32g4_counts_to_si(bus_counts(48.0f), 0.0f, board.bus_gain_v_per_count);
        const float d_b = 0.5f + 0.5f * 24.0f / bus;
        assert_int_equal(stm32g4_fake.tim1.CCR1, ARR_20KHZ / 2u);
        assert_int_equal(stm32g4_fake.tim1.CCR2, ARR_20KHZ / 2u);
        assert_int_equal(stm32g4_fake.tim1.CCR3, pmstep_stm32g4_duty_to_ccr(d_b, ARR_20KHZ));
        assert_int_equal(stm32g4_fake.tim1.CCR4, pmstep_stm32g4_duty_to_ccr(1.0f - d_b, ARR_20KHZ));
        assert_true(stm32g4_fake.tim1.CCR3 >= 3186u && stm32g4_fake.tim1.CCR3 <= 3189u); /* 75 % of 4250 */
    }
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_NONE);
}

/* The gate driver's fault input: bridge off at once, core stopped, latched until cleared. */
static void test_fault_input_turns_bridge_off(void **state)
{
    (void)state;
    port_up();
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    adc_samples(2048u, bus_counts(48.0f), 2048u);
    ADC1_2_IRQHandler();
    assert_true(pmstep_stm32g4_bridge_on());

    fault_input(true);
    ADC1_2_IRQHandler();
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_INPUT);
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_true(enable_pin_reset_last());
    assert_int_equal(stm32g4_fake.tim1.CCR3, ARR_20KHZ / 2u);
    {
        pmstep_output_t out;
        const pmstep_meas_t m = {0.0f, 0.0f, 48.0f, 0.0f, 0.0f, 0.0f};
        pmstep_step(&motor, &m, &out);
        assert_int_equal(out.mode, PMSTEP_MODE_IDLE); /* the core was stopped */
    }
    /* Still asserted: cannot clear. Released: cleared, but the bridge stays off until a new start. */
    assert_false(pmstep_stm32g4_clear_fault());
    fault_input(false);
    assert_true(pmstep_stm32g4_clear_fault());
    ADC1_2_IRQHandler();
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    ADC1_2_IRQHandler();
    assert_true(pmstep_stm32g4_bridge_on());
}

/* A fault the core latches (over-current) turns the bridge off through bridge_enable = false. */
static void test_core_fault_turns_bridge_off(void **state)
{
    (void)state;
    port_up();
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    adc_samples(2048u, bus_counts(48.0f), 2048u);
    ADC1_2_IRQHandler();
    assert_true(pmstep_stm32g4_bridge_on());
    adc_samples(4095u, bus_counts(48.0f), 2048u); /* +16.5 A, above the paper's 15 A limit */
    ADC1_2_IRQHandler();
    assert_false(pmstep_stm32g4_bridge_on());
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_true(enable_pin_reset_last());
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_NONE); /* the core's fault, not the port's */
}

/* TIM1 break: latched, interrupt source masked (the flag returns while the input is active). */
static void test_break_interrupt(void **state)
{
    (void)state;
    port_up();
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    adc_samples(2048u, bus_counts(48.0f), 2048u);
    ADC1_2_IRQHandler();
    assert_true(pmstep_stm32g4_bridge_on());
    stm32g4_fake.tim1.SR |= TIM_SR_BIF;
    stm32g4_fake.tim1.BDTR &= ~TIM_BDTR_MOE; /* what the hardware does */
    TIM1_BRK_TIM15_IRQHandler();
    assert_int_equal(pmstep_stm32g4_fault(), PMSTEP_STM32G4_FAULT_BREAK);
    assert_int_equal(stm32g4_fake.tim1.SR & TIM_SR_BIF, 0u);
    assert_int_equal(stm32g4_fake.tim1.DIER & TIM_DIER_BIE, 0u);
    assert_false(pmstep_stm32g4_bridge_on());
    assert_true(enable_pin_reset_last());
    ADC1_2_IRQHandler(); /* stays off while latched */
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_true(pmstep_stm32g4_clear_fault());
    assert_true(stm32g4_fake.tim1.DIER & TIM_DIER_BIE);
}

/* Sampled currents reach the core in amperes: in RUN the core's i_d/i_q come from them. */
static void test_measurements_in_si(void **state)
{
    pmstep_meas_t m;
    (void)state;
    port_up();
    adc_samples(2048u + 248u, bus_counts(24.0f), 2048u - 124u);
    pmstep_hal_read_measurements(&m);
    assert_float_equal(m.i_a_A, 248.0f * board.i_a_gain_a_per_count, 1e-6f); /* 1.998 A */
    assert_float_equal(m.i_b_A, -124.0f * board.i_b_gain_a_per_count, 1e-6f);
    assert_float_equal(m.bus_voltage_V, 24.0f, 0.5f * board.bus_gain_v_per_count);
    assert_float_equal(m.load_torque_Nm, 0.0f, 0.0f);
}

/* ---- pin maps ---- */

/* Signals of the STM32G431RB (LQFP64) pins a drive may use here, from ST's pin data
 * (STM32_open_pin_data, STM32G431R(6-8-B)Tx.xml): the check that each pin of the map can
 * carry the signal the map gives it. */
typedef struct {
    uint8_t port;
    uint8_t pin;
    const char *signals;
} pin_signals_t;

static const pin_signals_t g431rb_signals[] = {
    {0u, 0u, " ADC1_IN1 ADC2_IN1 "},
    {0u, 1u, " ADC1_IN2 ADC2_IN2 "},
    {0u, 2u, " ADC1_IN3 LPUART1_TX "},
    {0u, 3u, " ADC1_IN4 LPUART1_RX "},
    {0u, 6u, " ADC2_IN3 TIM1_BKIN "},
    {0u, 7u, " ADC2_IN4 TIM1_CH1N "},
    {0u, 8u, " TIM1_CH1 "},
    {0u, 9u, " TIM1_CH2 "},
    {0u, 10u, " TIM1_CH3 "},
    {0u, 11u, " TIM1_CH1N TIM1_CH4 "},
    {1u, 0u, " ADC1_IN15 TIM1_CH2N "},
    {1u, 1u, " ADC1_IN12 TIM1_CH3N "},
    {2u, 0u, " ADC1_IN6 ADC2_IN6 TIM1_CH1 LPUART1_RX "},
    {2u, 5u, " ADC2_IN11 TIM1_CH4N "},
    {1u, 5u, " "},
    {2u, 6u, " "},
};

static bool pin_can_carry(const pmstep_stm32g4_pin_use_t *u)
{
    char want[24];
    unsigned k;
    if (u->signal[0] == 'G') { /* plain GPIO: any I/O pin */
        return true;
    }
    if (u->channel != 0u) {
        snprintf(want, sizeof want, " %s%u ", u->signal, (unsigned)u->channel);
    } else {
        snprintf(want, sizeof want, " %s ", u->signal);
    }
    for (k = 0; k < sizeof g431rb_signals / sizeof g431rb_signals[0]; ++k) {
        if (g431rb_signals[k].port == u->pin.port && g431rb_signals[k].pin == u->pin.pin) {
            return strstr(g431rb_signals[k].signals, want) != NULL;
        }
    }
    return false;
}

static void test_pin_map_default_board(void **state)
{
    pmstep_stm32g4_pin_use_t map[18];
    uint32_t n;
    uint32_t i;
    uint32_t j;
    (void)state;
    assert_int_equal(pmstep_stm32g4_check_pins(&board), PMSTEP_STM32G4_OK);
    n = pmstep_stm32g4_pin_map(&board, map, 18u);
    assert_int_equal(n, 16u);
    for (i = 0; i < n; ++i) {
        if (!pin_can_carry(&map[i])) {
            print_error("P%c%u cannot carry %s%u (%s)\n", 'A' + map[i].pin.port, map[i].pin.pin, map[i].signal,
                        map[i].channel, map[i].function);
            fail();
        }
        for (j = i + 1u; j < n; ++j) { /* one pin, one function */
            assert_false(map[i].pin.port == map[j].pin.port && map[i].pin.pin == map[j].pin.pin);
        }
        /* The virtual COM port pins carry the console and nothing else. */
        if (map[i].pin.port == 0u && (map[i].pin.pin == 2u || map[i].pin.pin == 3u)) {
            assert_true(strncmp(map[i].signal, "LPUART1_", 8u) == 0);
        }
    }
    /* The map's ADC channels are the ones the ADC is set up with. */
    assert_int_equal(map[9].channel, board.adc1_channel_i_a);
    assert_int_equal(map[10].channel, board.adc1_channel_bus);
    assert_int_equal(map[11].channel, board.adc2_channel_i_b);
}

static void test_pin_map_conflicts_refused(void **state)
{
    pmstep_stm32g4_config_t c;
    (void)state;
    c = board;
    c.adc_pins[1] = (pmstep_stm32g4_pin_t){0u, 2u, 0u}; /* the old bus input: the VCP's TX */
    c.console_tx = (pmstep_stm32g4_pin_t){2u, 4u, 7u};  /* console moved away, PA2 still the board's */
    assert_int_equal(pmstep_stm32g4_check_pins(&c), PMSTEP_STM32G4_ERR_PIN_RESERVED);
    c = board;
    c.adc_pins[1] = (pmstep_stm32g4_pin_t){0u, 2u, 0u}; /* bus on the console's pin */
    assert_int_equal(pmstep_stm32g4_check_pins(&c), PMSTEP_STM32G4_ERR_PIN_CONFLICT);
    c = board;
    c.enable_pin = c.pwm_high[0]; /* two functions on PA8 */
    assert_int_equal(pmstep_stm32g4_check_pins(&c), PMSTEP_STM32G4_ERR_PIN_CONFLICT);
    c = board;
    c.fault_pin = (pmstep_stm32g4_pin_t){0u, 13u, 0u}; /* SWDIO */
    assert_int_equal(pmstep_stm32g4_check_pins(&c), PMSTEP_STM32G4_ERR_PIN_RESERVED);
    c = board;
    c.enable_pin = (pmstep_stm32g4_pin_t){0u, 5u, 0u}; /* LD2 */
    assert_int_equal(pmstep_stm32g4_check_pins(&c), PMSTEP_STM32G4_ERR_PIN_RESERVED);
    c.board = NULL; /* another controller board: only conflicts are checked */
    assert_int_equal(pmstep_stm32g4_check_pins(&c), PMSTEP_STM32G4_OK);
    c.pwm_low[3].pin = 16u;
    assert_int_equal(pmstep_stm32g4_check_pins(&c), PMSTEP_STM32G4_ERR_PIN);
    assert_int_equal(pmstep_stm32g4_check_pins(NULL), PMSTEP_STM32G4_ERR_NULL_ARGUMENT);
    /* The port refuses to start on a conflicting map, before touching a pin. */
    c = board;
    c.enable_pin = c.pwm_low[0];
    fault_input(false);
    assert_int_equal(pmstep_stm32g4_init(&c, &motor), PMSTEP_STM32G4_ERR_PIN_CONFLICT);
    assert_int_equal(stm32g4_fake.rcc.AHB2ENR, 0u);
}

/* A core that reads an input this board has no sensor for is refused before any register is
 * touched: phase-voltage sensing and known-load mode each. */
static void test_unmeasured_inputs_refused(void **state)
{
    pmstep_config_t cfg = motor_config;
    pmstep_t inst;
    (void)state;
    fault_input(false);
    cfg.inverter.phase_voltage_sensing = true;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_stm32g4_init(&board, &inst), PMSTEP_STM32G4_ERR_UNMEASURED_INPUT);
    cfg.inverter.phase_voltage_sensing = false;
    cfg.known_load_mode = true;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_stm32g4_init(&board, &inst), PMSTEP_STM32G4_ERR_UNMEASURED_INPUT);
    assert_int_equal(stm32g4_fake.rcc.AHB2ENR, 0u);
    assert_int_equal(stm32g4_fake.tim1.BDTR & TIM_BDTR_MOE, 0u);
    assert_string_equal(pmstep_stm32g4_status_str(PMSTEP_STM32G4_ERR_UNMEASURED_INPUT),
                        "the core reads phase voltages or a load torque, which this board does not measure");
    /* The same configuration without them starts. */
    cfg.known_load_mode = false;
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_stm32g4_init(&board, &inst), PMSTEP_STM32G4_OK);
}

/* The measurement ranges follow from the board's offsets and gains (0.1 V/A about 1.65 V: the
 * smaller side, 2047 counts of 3.3/4096/0.1 A; the bus's 1:20 divider at code 4095), and a core
 * that claims more than the board reads is refused before any register is touched: its trips
 * could sit where a saturated reading never reaches them. */
static void test_sense_ranges_beyond_board_refused(void **state)
{
    pmstep_config_t cfg = motor_config;
    pmstep_t inst;
    (void)state;
    fault_input(false);
    assert_float_equal(pmstep_stm32g4_current_sense_range_A(&board), 2047.0f * 3.3f / 4096.0f / 0.1f, 1e-4f);
    assert_float_equal(pmstep_stm32g4_bus_sense_range_V(&board), 4095.0f * 3.3f / 4096.0f * 20.0f, 1e-3f);
    cfg.limits.current_sense_range_A = 16.5f; /* above the board's 16.49 A */
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_stm32g4_init(&board, &inst), PMSTEP_STM32G4_ERR_SENSE_RANGE);
    cfg = motor_config;
    cfg.limits.bus_sense_range_V = 66.0f; /* above the board's 65.98 V */
    assert_int_equal(pmstep_init(&inst, &cfg), PMSTEP_OK);
    assert_int_equal(pmstep_stm32g4_init(&board, &inst), PMSTEP_STM32G4_ERR_SENSE_RANGE);
    assert_int_equal(stm32g4_fake.rcc.AHB2ENR, 0u);
    assert_int_equal(pmstep_stm32g4_init(&board, &motor), PMSTEP_STM32G4_OK);
}

/* ---- console UART (LPUART1) and the main loop's access to the last period ---- */

static void test_lpuart(void **state)
{
    stm32g4_lpuart_t *u = &stm32g4_fake.lpuart1;
    uint8_t buf[8];
    uint32_t errors = 0u;
    (void)state;
    /* 256 x 170 MHz / 115200 = 377777.8 -> 377778; limits 3x..4096x the baud rate (RM0440 §38.4). */
    assert_int_equal(pmstep_stm32g4_lpuart_brr(170000000u, 115200u), 377778u);
    assert_int_equal(pmstep_stm32g4_lpuart_brr(170000000u, 921600u), 47222u);
    assert_int_equal(pmstep_stm32g4_lpuart_brr(170000000u, 9600u), 0u);     /* f_ck > 4096 x baud */
    assert_int_equal(pmstep_stm32g4_lpuart_brr(170000000u, 60000000u), 0u); /* f_ck < 3 x baud */
    assert_int_equal(pmstep_stm32g4_lpuart_brr(170000000u, 0u), 0u);
    assert_int_equal(pmstep_stm32g4_lpuart_init(&board, 170000000u), PMSTEP_STM32G4_OK);
    assert_int_equal(u->BRR, 377778u);
    assert_int_equal(u->CR1, LPUART_CR1_UE | LPUART_CR1_RE | LPUART_CR1_TE);
    assert_true(stm32g4_fake.rcc.APB1ENR2 & RCC_APB1ENR2_LPUART1EN);
    assert_int_equal(stm32g4_fake.rcc.CCIPR & RCC_CCIPR_LPUART1SEL_MASK, 0u);
    assert_int_equal((stm32g4_fake.gpio[0].MODER >> 4) & 3u, GPIO_MODE_AF); /* PA2 */
    assert_int_equal((stm32g4_fake.gpio[0].AFR[0] >> 8) & 0xFu, 12u);       /* AF12 */
    assert_int_equal((stm32g4_fake.gpio[0].AFR[0] >> 12) & 0xFu, 12u);      /* PA3 AF12 */
    board.console_baud = 9600u;
    assert_int_equal(pmstep_stm32g4_lpuart_init(&board, 170000000u), PMSTEP_STM32G4_ERR_UART_CONFIG);
    /* Never waits: nothing received, nothing taken; transmitter busy, nothing sent. */
    u->ISR = 0u;
    assert_int_equal(pmstep_stm32g4_lpuart_read(buf, sizeof buf, &errors), 0u);
    assert_int_equal(pmstep_stm32g4_lpuart_write(buf, 4u), 0u);
    u->ISR = LPUART_ISR_TXE;
    assert_int_equal(pmstep_stm32g4_lpuart_write((const uint8_t *)"abcd", 4u), 4u);
    assert_int_equal(u->TDR, 'd');
    u->ISR = 1u << 3; /* overrun */
    (void)pmstep_stm32g4_lpuart_read(buf, sizeof buf, &errors);
    assert_int_equal(errors, 1u);
    assert_int_equal(u->ICR, 1u << 3);
}

static void test_hold_and_last_period(void **state)
{
    pmstep_output_t out;
    pmstep_meas_t meas;
    uint8_t port_fault = 9u;
    (void)state;
    port_up();
    pmstep_stm32g4_hold_control();
    assert_int_equal(stm32g4_fake.nvic.ICER[0], 1u << 18);
    pmstep_stm32g4_release_control();
    assert_true(stm32g4_fake.nvic.ISER[0] & (1u << 18));
    assert_int_equal(pmstep_start(&motor), PMSTEP_OK);
    adc_samples(2048u + 124u, bus_counts(48.0f), 2048u);
    ADC1_2_IRQHandler();
    pmstep_stm32g4_last_period(&out, &meas, &port_fault);
    assert_int_equal(out.mode, PMSTEP_MODE_S_ALIGN);
    assert_float_equal(out.u_b_V, 24.0f, 1e-3f);
    assert_float_equal(meas.i_a_A, 124.0f * board.i_a_gain_a_per_count, 1e-6f);
    assert_float_equal(meas.bus_voltage_V, 48.0f, board.bus_gain_v_per_count);
    assert_int_equal(port_fault, PMSTEP_STM32G4_FAULT_NONE);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_counts_to_si, setup),
        cmocka_unit_test_setup(test_duties, setup),
        cmocka_unit_test_setup(test_dead_time, setup),
        cmocka_unit_test_setup(test_clock_arithmetic, setup),
        cmocka_unit_test_setup(test_clock_init, setup),
        cmocka_unit_test_setup(test_clock_init_timeout_and_config, setup),
        cmocka_unit_test_setup(test_pwm_init, setup),
        cmocka_unit_test_setup(test_adc_init, setup),
        cmocka_unit_test_setup(test_gpio_init, setup),
        cmocka_unit_test_setup(test_port_init, setup),
        cmocka_unit_test_setup(test_isr_idle_keeps_bridge_off, setup),
        cmocka_unit_test_setup(test_isr_s_alignment_duties, setup),
        cmocka_unit_test_setup(test_fault_input_turns_bridge_off, setup),
        cmocka_unit_test_setup(test_core_fault_turns_bridge_off, setup),
        cmocka_unit_test_setup(test_break_interrupt, setup),
        cmocka_unit_test_setup(test_measurements_in_si, setup),
        cmocka_unit_test_setup(test_pin_map_default_board, setup),
        cmocka_unit_test_setup(test_pin_map_conflicts_refused, setup),
        cmocka_unit_test_setup(test_unmeasured_inputs_refused, setup),
        cmocka_unit_test_setup(test_sense_ranges_beyond_board_refused, setup),
        cmocka_unit_test_setup(test_lpuart, setup),
        cmocka_unit_test_setup(test_hold_and_last_period, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
