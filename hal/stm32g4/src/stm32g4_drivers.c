/*
 * Register drivers of the STM32G431 port: clock tree, TIM1 PWM, the STEP/DIR input, ADC1/ADC2,
 * LPUART1 (the pins: stm32g4_gpio.c).
 * Every wait on the hardware is bounded and returns a timeout status.
 * Register and bit references: stm32g4_regs.h (RM0440 Rev 8).
 */
#include <stddef.h>

#include "pmstep_hal_stm32g4.h"
#include "stm32g4_gpio.h"
#include "stm32g4_regs.h"

/* Iterations of a wait loop before giving up: far above any documented delay. */
#define WAIT_LIMIT 1000000u

static bool wait_set(volatile uint32_t *reg, uint32_t mask, uint32_t value)
{
    uint32_t n;
    for (n = 0; n < WAIT_LIMIT; ++n) {
        STM32G4_WAIT_HOOK(); /* nothing on the target; the host tests' hardware model */
        if ((*reg & mask) == value) {
            return true;
        }
    }
    return false;
}

/* Busy wait of at least @p cycles CPU cycles (each turn takes more than one cycle). */
static void delay_cycles(uint32_t cycles)
{
    volatile uint32_t n;
    for (n = 0; n < cycles; ++n) {
    }
}

/* ---- clock tree: RM0440 §7.2.6 (PLL), §6.1.5 (range 1 boost), §3.3.3 (flash latency) ---- */
pmstep_stm32g4_status_t pmstep_stm32g4_clock_init(const pmstep_stm32g4_clock_t *clock)
{
    stm32g4_rcc_t *const rcc = STM32G4_RCC;
    stm32g4_pwr_t *const pwr = STM32G4_PWR;
    stm32g4_flash_t *const flash = STM32G4_FLASH;
    const uint32_t sysclk_Hz = pmstep_stm32g4_sysclk_Hz(clock);
    uint32_t latency;
    uint32_t reg;

    if (clock == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    if (sysclk_Hz == 0u) {
        return PMSTEP_STM32G4_ERR_CLOCK_CONFIG;
    }
    /* Boost mode only above 150 MHz; the wait states follow the mode (RM0440 §3.3.3, Table 9). */
    latency = pmstep_stm32g4_flash_latency_mode(sysclk_Hz, sysclk_Hz > 150000000u);

    /* Voltage range 1; boost mode (R1MODE = 0) above 150 MHz, with HCLK = SYSCLK / 2 while
     * switching (the sequence of RM0440 §6.1.5). */
    rcc->APB1ENR1 |= RCC_APB1ENR1_PWREN;
    (void)rcc->APB1ENR1; /* the enable takes effect before PWR is written */
    pwr->CR1 = (pwr->CR1 & ~PWR_CR1_VOS_MASK) | PWR_CR1_VOS_RANGE1;
    if (!wait_set(&pwr->SR2, PWR_SR2_VOSF, 0u)) {
        return PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT;
    }
    rcc->CFGR = (rcc->CFGR & ~RCC_CFGR_HPRE_MASK) | (RCC_CFGR_HPRE_DIV2 << RCC_CFGR_HPRE_POS);
    if (sysclk_Hz > 150000000u) {
        pwr->CR5 &= ~PWR_CR5_R1MODE;
    } else {
        pwr->CR5 |= PWR_CR5_R1MODE;
    }

    /* Flash wait states before the clock rises; prefetch and caches on. */
    flash->ACR = (flash->ACR & ~FLASH_ACR_LATENCY_MASK) | latency | FLASH_ACR_PRFTEN | FLASH_ACR_ICEN | FLASH_ACR_DCEN;
    if (!wait_set(&flash->ACR, FLASH_ACR_LATENCY_MASK, latency)) {
        return PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT;
    }

    /* HSI16 (on after reset) -> PLL; the PLL is configured while off. */
    rcc->CR |= RCC_CR_HSION;
    if (!wait_set(&rcc->CR, RCC_CR_HSIRDY, RCC_CR_HSIRDY)) {
        return PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT;
    }
    rcc->CR &= ~RCC_CR_PLLON;
    if (!wait_set(&rcc->CR, RCC_CR_PLLRDY, 0u)) {
        return PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT;
    }
    reg = RCC_PLLCFGR_PLLSRC_HSI16 | ((clock->pll_m - 1u) << RCC_PLLCFGR_PLLM_POS)
          | (clock->pll_n << RCC_PLLCFGR_PLLN_POS) | ((clock->pll_r / 2u - 1u) << RCC_PLLCFGR_PLLR_POS)
          | RCC_PLLCFGR_PLLREN;
    rcc->PLLCFGR = reg;
    rcc->CR |= RCC_CR_PLLON;
    if (!wait_set(&rcc->CR, RCC_CR_PLLRDY, RCC_CR_PLLRDY)) {
        return PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT;
    }

    /* Switch SYSCLK to the PLL, wait at least 1 us, then HCLK = SYSCLK, PCLK1 = PCLK2 = HCLK
     * (so TIM1 runs at SYSCLK). */
    rcc->CFGR = (rcc->CFGR & ~RCC_CFGR_SW_MASK) | (RCC_CFGR_SW_PLL << RCC_CFGR_SW_POS);
    if (!wait_set(&rcc->CFGR, RCC_CFGR_SWS_MASK, RCC_CFGR_SW_PLL << RCC_CFGR_SWS_POS)) {
        return PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT;
    }
    delay_cycles(200u);
    rcc->CFGR = (rcc->CFGR & ~(RCC_CFGR_HPRE_MASK | RCC_CFGR_PPRE1_MASK | RCC_CFGR_PPRE2_MASK))
                | (RCC_CFGR_HPRE_DIV1 << RCC_CFGR_HPRE_POS);
    return PMSTEP_STM32G4_OK;
}

/* ---- TIM1: RM0440 §28.3 (functional description), §28.6 (registers) ---- */
pmstep_stm32g4_status_t pmstep_stm32g4_pwm_init(const pmstep_stm32g4_config_t *cfg, uint32_t tim_clock_Hz)
{
    stm32g4_tim_t *const tim = STM32G4_TIM1;
    const uint32_t pwm_channel = (TIM_OCM_PWM1 << TIM_CCMR_OCM_POS) | TIM_CCMR_OCPE;
    uint32_t arr;
    uint8_t dtg;
    pmstep_stm32g4_status_t st;
    unsigned k;

    if (cfg == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    if (!(cfg->duty_min >= 0.0f && cfg->duty_max <= 1.0f && cfg->duty_min < cfg->duty_max)) {
        return PMSTEP_STM32G4_ERR_DUTY_RANGE;
    }
    arr = pmstep_stm32g4_pwm_arr(tim_clock_Hz, cfg->pwm_frequency_Hz);
    if (arr == 0u) {
        return PMSTEP_STM32G4_ERR_PWM_FREQUENCY;
    }
    st = pmstep_stm32g4_dead_time_dtg(cfg->dead_time_ns, tim_clock_Hz, &dtg);
    if (st != PMSTEP_STM32G4_OK) {
        return st;
    }
    if (cfg->break_filter > 15u) {
        return PMSTEP_STM32G4_ERR_PIN;
    }

    STM32G4_RCC->APB2ENR |= RCC_APB2ENR_TIM1EN;
    (void)STM32G4_RCC->APB2ENR;

    tim->CR1 = 0u; /* counter stopped while configuring */
    tim->BDTR = 0u;
    /* Centre-aligned mode 1, ARR preloaded; an update only from counter events (URS). */
    tim->CR1 = TIM_CR1_CMS_CENTER1 | TIM_CR1_ARPE | TIM_CR1_URS;
    tim->PSC = 0u;
    tim->ARR = arr;
    /* One update event per carrier period. RCR written before the counter starts: the update
     * (and the compare-preload transfer) happens at the overflow, the counter peak
     * (RM0440 §28.3.3 "Repetition counter"). */
    tim->RCR = 1u;
    /* CH1..CH4: PWM mode 1 (high side on while CNT < CCR), compare preload. CH5: PWM mode 2
     * (inactive while CNT < CCR5 counting up, active while CNT > CCR5 counting down) with
     * CCR5 = ARR - 1: in centre-aligned mode the counter runs 0..ARR-1 up and ARR..1 down, so
     * OC5REF is high for CNT = ARR-1 (up) and CNT = ARR (down) and rises one timer tick before
     * the peak. (CCR5 = ARR would never be reached counting up nor exceeded counting down.) */
    tim->CCMR1 = (pwm_channel << TIM_CCMR_OC_LOW_POS) | (pwm_channel << TIM_CCMR_OC_HIGH_POS);
    tim->CCMR2 = (pwm_channel << TIM_CCMR_OC_LOW_POS) | (pwm_channel << TIM_CCMR_OC_HIGH_POS);
    tim->CCMR3 = ((TIM_OCM_PWM2 << TIM_CCMR_OCM_POS) | TIM_CCMR_OCPE) << TIM_CCMR_OC_LOW_POS;
    tim->CCR1 = arr / 2u;
    tim->CCR2 = arr / 2u;
    tim->CCR3 = arr / 2u;
    tim->CCR4 = arr / 2u;
    tim->CCR5 = arr - 1u;
    {
        uint32_t ccer = TIM_CCER_CC5E;
        for (k = 1u; k <= 4u; ++k) {
            ccer |= TIM_CCER_CCE(k) | TIM_CCER_CCNE(k); /* both outputs, active high */
        }
        tim->CCER = ccer;
    }
    /* TRGO2 = OC5REFC: the ADC trigger. Idle levels (OISx, OISxN) 0: every switch off when MOE = 0. */
    tim->CR2 = TIM_CR2_MMS2_OC5REFC << TIM_CR2_MMS2_POS;
    /* Break: BKIN pin enabled (AF1.BKINE, not inverted), filter, polarity in BDTR.BKP. Off state
     * (OSSI, OSSR): outputs driven to their idle levels rather than released. MOE = 0: the bridge
     * stays off until the port turns it on; AOE = 0: after a break only software turns it on. */
    tim->AF1 = (tim->AF1 & ~TIM_AF1_BKINP) | TIM_AF1_BKINE;
    tim->BDTR = (uint32_t)dtg | TIM_BDTR_OSSI | TIM_BDTR_OSSR | TIM_BDTR_BKE
                | (cfg->break_active_high ? TIM_BDTR_BKP : 0u) | ((uint32_t)cfg->break_filter << TIM_BDTR_BKF_POS);
    /* Load PSC, ARR, RCR and the compare values now; clear the flags this sets. */
    tim->EGR = TIM_EGR_UG;
    tim->SR = 0u;
    tim->DIER = TIM_DIER_BIE;
    return PMSTEP_STM32G4_OK;
}

/* ---- STEP/DIR input: TIM4 in encoder mode, RM0440 chapter 29 "General-purpose timers (TIM2/TIM3/
 * TIM4/TIM5)": §29.4 "Encoder interface mode" (clock plus direction), §29.4 "Input filter"
 * (TIMx_CCMR1 ICxF), registers §29.5 ----
 *
 * Why the encoder mode "clock plus direction" (SMS = 1011) rather than external clock mode 1 with
 * DIR on TIMx_CR1.DIR: in external clock mode the direction is a register bit software must copy
 * from the DIR pin, late by an interrupt's latency, so a STEP edge right after a DIR change counts
 * the wrong way; in the encoder mode the timer takes each STEP edge's direction from the DIR pin's
 * level (tim_ti1fp1) at that edge, in hardware, with DIR and STEP through the same filter. x1
 * counts each STEP pulse once (x2, SMS = 1010, would count both edges: a TMC driver's "dedge").
 * Timers with the mode on the STM32G431: TIM1, TIM8, TIM2, TIM3, TIM4; TIM1 makes the PWM, TIM2 and
 * TIM3's channel pins are the ADC inputs, the break input and the gate-driver enable here, TIM8 is
 * kept for a second axis: TIM4 on PB6/PB7. */
static bool tim4_channel_pin(const pmstep_stm32g4_pin_t *p, uint8_t channel)
{
    /* DS12589 alternate functions: TIM4_CH1 on PB6 (AF2) and PA11 (AF10), TIM4_CH2 on PB7 (AF2) and
     * PA12 (AF10) (the LQFP64 has no PD12/PD13). */
    const uint8_t port_a = 0u;
    const uint8_t port_b = 1u;
    const uint8_t pin_b = channel == 1u ? 6u : 7u;
    const uint8_t pin_a = channel == 1u ? 11u : 12u;
    return (p->port == port_b && p->pin == pin_b && p->af == 2u)
           || (p->port == port_a && p->pin == pin_a && p->af == 10u);
}

pmstep_stm32g4_status_t pmstep_stm32g4_step_input_init(const pmstep_stm32g4_config_t *cfg, uint32_t tim_clock_Hz)
{
    stm32g4_tim_t *const tim = STM32G4_TIM4;
    const pmstep_stm32g4_step_input_t *in;
    pmstep_stm32g4_status_t st;
    uint8_t icf;
    if (cfg == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    in = &cfg->step_input;
    if (!in->enabled) {
        return PMSTEP_STM32G4_OK;
    }
    if (in->microsteps < 1u || in->microsteps > 256u) {
        return PMSTEP_STM32G4_ERR_STEP_MICROSTEPS;
    }
    st = pmstep_stm32g4_step_filter(in->step_min_pulse_ns, tim_clock_Hz, &icf);
    if (st != PMSTEP_STM32G4_OK) {
        return st;
    }
    if (!stm32g4_pin_valid(&in->step_pin) || !stm32g4_pin_valid(&in->dir_pin) || !stm32g4_pin_valid(&in->enable_pin)
        || !stm32g4_pin_valid(&in->diag_pin)) {
        return PMSTEP_STM32G4_ERR_PIN;
    }
    if (!tim4_channel_pin(&in->step_pin, 2u) || !tim4_channel_pin(&in->dir_pin, 1u)) {
        return PMSTEP_STM32G4_ERR_STEP_PIN;
    }

    /* EN: an input pulled to its disabled level, so an open line keeps the bridge off. */
    stm32g4_pin_configure(&in->enable_pin, GPIO_MODE_INPUT, in->enable_active_high ? GPIO_PULL_DOWN : GPIO_PULL_UP);
    /* DIAG: deasserted in ODR first (active high: pulled low; active low: released), then an
     * open-drain output with the pin's pull-up (a line nobody else pulls reads high). */
    stm32g4_port_clock_on(in->diag_pin.port);
    STM32G4_GPIO(in->diag_pin.port)->BSRR =
        in->diag_active_high ? STM32G4_BIT(16u + in->diag_pin.pin) : STM32G4_BIT(in->diag_pin.pin);
    stm32g4_pin_configure_type(&in->diag_pin, GPIO_MODE_OUTPUT, GPIO_PULL_UP, true);
    /* STEP and DIR: TIM4's inputs, pulled down (an open STEP line counts nothing). */
    stm32g4_pin_configure(&in->step_pin, GPIO_MODE_AF, GPIO_PULL_DOWN);
    stm32g4_pin_configure(&in->dir_pin, GPIO_MODE_AF, GPIO_PULL_DOWN);

    STM32G4_RCC->APB1ENR1 |= RCC_APB1ENR1_TIM4EN; /* §7.4.17; TIM4 runs at PCLK1 = SYSCLK */
    (void)STM32G4_RCC->APB1ENR1;
    tim->CR1 = 0u;  /* counter stopped; CKD = 00: t_DTS = t_CK_INT, the filter's base (§29.5.1) */
    tim->SMCR = 0u; /* slave mode off while the inputs are set up (§29.5.3) */
    tim->DIER = 0u; /* no interrupt: the count is read each control period */
    /* CC1P = CC2P = 0 (§29.5.11): counts up while DIR is high, on STEP's rising edges; CCxNP = 0 as
     * the encoder mode wants; CCxE = 0, no capture. */
    tim->CCER = 0u;
    /* IC1 on tim_ti1 (DIR), IC2 on tim_ti2 (STEP), the same filter on both so DIR keeps its set-up
     * time to STEP (§29.5.7); input prescalers 0. */
    tim->CCMR1 = (TIM_CCMR_CCS_INPUT_TI << TIM_CCMR1_CC1S_POS) | ((uint32_t)icf << TIM_CCMR1_IC1F_POS)
                 | (TIM_CCMR_CCS_INPUT_TI << TIM_CCMR1_CC2S_POS) | ((uint32_t)icf << TIM_CCMR1_IC2F_POS);
    tim->TISEL = 0u; /* tim_ti1, tim_ti2 from the TIM4_CH1, TIM4_CH2 pins (§29.5.25) */
    tim->PSC = 0u;
    tim->ARR = 0xFFFFu;    /* the whole 16 bits: the count wraps 0xFFFF <-> 0, which the core unwraps */
    tim->EGR = TIM_EGR_UG; /* PSC and ARR loaded, the counter to 0 (§29.5.6) */
    tim->SR = 0u;
    tim->CNT = 0u;
    tim->SMCR = TIM_SMCR_SMS_CLOCK_DIR_X1; /* §29.5.3 SMS = 1011 */
    tim->CR1 = TIM_CR1_CEN;
    return PMSTEP_STM32G4_OK;
}

void pmstep_stm32g4_step_polarity(pmstep_stm32g4_config_t *cfg, bool enable_active_high, bool diag_active_high)
{
    pmstep_stm32g4_step_input_t *in;
    if (cfg == NULL) {
        return;
    }
    in = &cfg->step_input;
    in->enable_active_high = enable_active_high;
    in->diag_active_high = diag_active_high;
    if (!in->enabled) {
        return;
    }
    /* As at set-up: EN pulled to its (new) disabled level, DIAG deasserted at its (new) level. */
    stm32g4_pin_configure(&in->enable_pin, GPIO_MODE_INPUT, enable_active_high ? GPIO_PULL_DOWN : GPIO_PULL_UP);
    STM32G4_GPIO(in->diag_pin.port)->BSRR =
        diag_active_high ? STM32G4_BIT(16u + in->diag_pin.pin) : STM32G4_BIT(in->diag_pin.pin);
}

/* ---- ADC1/ADC2: RM0440 §21.4.6 (regulator), §21.4.8 (calibration), §21.4.9 (enable),
 * §21.4.21 (injected conversions) ---- */
static void adc_cr_set(stm32g4_adc_t *adc, uint32_t bits)
{
    adc->CR = (adc->CR & ~ADC_CR_RS_BITS) | bits;
}

static void adc_sample_time(stm32g4_adc_t *adc, uint32_t channel, uint32_t code)
{
    if (channel < 10u) {
        adc->SMPR1 = (adc->SMPR1 & ~(7u << (3u * channel))) | (code << (3u * channel));
    } else {
        adc->SMPR2 = (adc->SMPR2 & ~(7u << (3u * (channel - 10u)))) | (code << (3u * (channel - 10u)));
    }
}

static bool adc_calibrate_and_enable(stm32g4_adc_t *adc)
{
    adc->CR = (adc->CR & ~(ADC_CR_RS_BITS | ADC_CR_ADCALDIF)); /* single-ended calibration */
    adc_cr_set(adc, ADC_CR_ADCAL);
    if (!wait_set(&adc->CR, ADC_CR_ADCAL, 0u)) {
        return false;
    }
    adc->ISR = ADC_ISR_ADRDY;
    /* ADEN set less than 4 ADC clock cycles after ADCAL clears is reset by the calibration
     * logic: set it again until ADRDY (ST's HAL does the same, stm32g4xx_hal_adc.c). */
    {
        uint32_t n;
        for (n = 0; n < WAIT_LIMIT; ++n) {
            if ((adc->CR & ADC_CR_ADEN) == 0u) {
                adc_cr_set(adc, ADC_CR_ADEN);
            }
            STM32G4_WAIT_HOOK();
            if ((adc->ISR & ADC_ISR_ADRDY) != 0u) {
                adc->ISR = ADC_ISR_ADRDY;
                return true;
            }
        }
    }
    return false;
}

pmstep_stm32g4_status_t pmstep_stm32g4_adc_init(const pmstep_stm32g4_config_t *cfg)
{
    stm32g4_adc_t *const adc1 = STM32G4_ADC1;
    stm32g4_adc_t *const adc2 = STM32G4_ADC2;
    const uint32_t trigger =
        (ADC12_JEXTSEL_TIM1_TRGO2 << ADC_JSQR_JEXTSEL_POS) | (ADC_JSQR_JEXTEN_RISING << ADC_JSQR_JEXTEN_POS);

    if (cfg == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    if (cfg->adc1_channel_i_a < 1u || cfg->adc1_channel_i_a > ADC_CHANNEL_MAX || cfg->adc1_channel_bus < 1u
        || cfg->adc1_channel_bus > ADC_CHANNEL_MAX || cfg->adc2_channel_i_b < 1u
        || cfg->adc2_channel_i_b > ADC_CHANNEL_MAX || cfg->adc_sample_time > 7u) {
        return PMSTEP_STM32G4_ERR_ADC_CONFIG;
    }
    STM32G4_RCC->AHB2ENR |= RCC_AHB2ENR_ADC12EN;
    (void)STM32G4_RCC->AHB2ENR;
    STM32G4_ADC12->CCR = (STM32G4_ADC12->CCR & ~ADC_CCR_CKMODE_MASK) | ADC_CCR_CKMODE_HCLK_DIV4;

    /* Out of deep power-down, regulator on, t_ADCVREG_STUP = 20 us (DS12589): 4000 turns of
     * the delay loop are more than 3400 cycles at 170 MHz. */
    adc1->CR = adc1->CR & ~(ADC_CR_RS_BITS | ADC_CR_DEEPPWD);
    adc2->CR = adc2->CR & ~(ADC_CR_RS_BITS | ADC_CR_DEEPPWD);
    adc_cr_set(adc1, ADC_CR_ADVREGEN);
    adc_cr_set(adc2, ADC_CR_ADVREGEN);
    delay_cycles(4000u);
    if (!adc_calibrate_and_enable(adc1) || !adc_calibrate_and_enable(adc2)) {
        return PMSTEP_STM32G4_ERR_ADC_TIMEOUT;
    }

    adc_sample_time(adc1, cfg->adc1_channel_i_a, cfg->adc_sample_time);
    adc_sample_time(adc1, cfg->adc1_channel_bus, cfg->adc_sample_time);
    adc_sample_time(adc2, cfg->adc2_channel_i_b, cfg->adc_sample_time);
    /* ADC1: i_a then the bus; ADC2: i_b, on the same TIM1_TRGO2 edge (i_a and i_b together). */
    adc1->JSQR = (1u << ADC_JSQR_JL_POS) | trigger | ((uint32_t)cfg->adc1_channel_i_a << ADC_JSQR_JSQ1_POS)
                 | ((uint32_t)cfg->adc1_channel_bus << ADC_JSQR_JSQ2_POS);
    adc2->JSQR = (0u << ADC_JSQR_JL_POS) | trigger | ((uint32_t)cfg->adc2_channel_i_b << ADC_JSQR_JSQ1_POS);
    adc1->ISR = ADC_ISR_JEOC | ADC_ISR_JEOS;
    adc2->ISR = ADC_ISR_JEOC | ADC_ISR_JEOS;
    adc1->IER = ADC_IER_JEOSIE;
    /* Armed: each trigger converts the injected sequence. */
    adc_cr_set(adc1, ADC_CR_JADSTART);
    adc_cr_set(adc2, ADC_CR_JADSTART);
    return PMSTEP_STM32G4_OK;
}

/* ---- LPUART1, the console: RM0440 §38.4 (baud rate 256 f_ck / BRR, f_ck within 3..4096 x the
 * baud rate), §38.7 (registers). 8 data bits, no parity, 1 stop bit (the reset values of CR1
 * and CR2), no FIFO, polled from the main loop. ---- */
uint32_t pmstep_stm32g4_lpuart_brr(uint32_t clock_hz, uint32_t baud)
{
    uint64_t brr;
    if (baud == 0u || (uint64_t)clock_hz < 3u * (uint64_t)baud || (uint64_t)clock_hz > 4096u * (uint64_t)baud) {
        return 0u;
    }
    brr = (256u * (uint64_t)clock_hz + baud / 2u) / baud;
    return (brr < LPUART_BRR_MIN || brr > LPUART_BRR_MAX) ? 0u : (uint32_t)brr;
}

pmstep_stm32g4_status_t pmstep_stm32g4_lpuart_init(const pmstep_stm32g4_config_t *cfg, uint32_t pclk1_hz)
{
    stm32g4_lpuart_t *const u = STM32G4_LPUART1;
    uint32_t brr;
    if (cfg == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    brr = pmstep_stm32g4_lpuart_brr(pclk1_hz, cfg->console_baud);
    if (brr == 0u) {
        return PMSTEP_STM32G4_ERR_UART_CONFIG;
    }
    if (!stm32g4_pin_valid(&cfg->console_tx) || !stm32g4_pin_valid(&cfg->console_rx)) {
        return PMSTEP_STM32G4_ERR_PIN;
    }
    STM32G4_RCC->CCIPR &= ~RCC_CCIPR_LPUART1SEL_MASK; /* kernel clock PCLK1 */
    STM32G4_RCC->APB1ENR2 |= RCC_APB1ENR2_LPUART1EN;
    (void)STM32G4_RCC->APB1ENR2;
    u->CR1 = 0u; /* UE = 0 while BRR is written */
    u->PRESC = 0u;
    u->BRR = brr;
    u->CR1 = LPUART_CR1_UE | LPUART_CR1_RE | LPUART_CR1_TE;
    stm32g4_pin_configure(&cfg->console_tx, GPIO_MODE_AF, 0u);
    stm32g4_pin_configure(&cfg->console_rx, GPIO_MODE_AF, GPIO_PULL_UP); /* idle high when unconnected */
    return PMSTEP_STM32G4_OK;
}

uint32_t pmstep_stm32g4_lpuart_read(uint8_t *data, uint32_t max, uint32_t *errors)
{
    stm32g4_lpuart_t *const u = STM32G4_LPUART1;
    uint32_t n = 0u;
    const uint32_t isr = u->ISR;
    if ((isr & LPUART_ISR_ERRORS) != 0u) { /* overrun, framing, noise, parity: counted, cleared */
        u->ICR = isr & LPUART_ISR_ERRORS;
        if (errors != NULL) {
            ++*errors;
        }
    }
    while (n < max && (u->ISR & LPUART_ISR_RXNE) != 0u) {
        data[n++] = (uint8_t)(STM32G4_LPUART_READ_RDR(u) & 0xFFu);
    }
    return n;
}

uint32_t pmstep_stm32g4_lpuart_write(const uint8_t *data, uint32_t n)
{
    stm32g4_lpuart_t *const u = STM32G4_LPUART1;
    uint32_t k = 0u;
    while (k < n && (u->ISR & LPUART_ISR_TXE) != 0u) {
        STM32G4_LPUART_WRITE_TDR(u, data[k]);
        ++k;
    }
    return k;
}
