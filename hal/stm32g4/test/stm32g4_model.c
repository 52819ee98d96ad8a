/*
 * Behavioural model of the STM32G431 peripherals the port uses (see stm32g4_model.h).
 * Every rule names the section of ST RM0440 (Rev 8) it follows; chapter 28 is
 * "Advanced-control timers (TIM1/TIM8/TIM20)", chapter 21 "Analog-to-digital converters
 * (ADC)", chapter 3 "Embedded flash memory", chapter 7 "Reset and clock control",
 * chapter 9 "General-purpose I/Os". TIM1 is in stm32g4_model_tim1.c, TIM4 in stm32g4_model_tim4.c,
 * the flash controller in stm32g4_model_flash.c.
 */
#include "stm32g4_model.h"

#include <string.h>

#include "pmstep_hal_stm32g4.h"

stm32g4_fake_t stm32g4_fake;
stm32g4_model_t stm32g4_model;

#define M stm32g4_model
#define TIM (&stm32g4_fake.tim1)

#define ADC_CLOCK_DIVIDER 4u /* CKMODE = 11: HCLK / 4; TIM1 runs at HCLK here */

/* ---------------------------------------------------------------------------
 * Reset values: the register descriptions of RM0440 (§7.4, §6.4, §3.7.1, §9.4.1, §28.6,
 * §21.7.3, §21.7.4). Only the values the port depends on are set; the rest reset to 0.
 * ------------------------------------------------------------------------- */
void stm32g4_model_reset(void)
{
    unsigned p;
    memset(&stm32g4_fake, 0, sizeof stm32g4_fake);
    memset(&M, 0, sizeof M);
    stm32g4_fake.rcc.CR = RCC_CR_HSION | RCC_CR_HSIRDY; /* HSI16 on and ready */
    stm32g4_fake.rcc.CFGR = 0x5u;                       /* SW = SWS = HSI16 */
    stm32g4_fake.pwr.CR1 = PWR_CR1_VOS_RANGE1;
    stm32g4_fake.pwr.CR5 = PWR_CR5_R1MODE;                    /* range 1 normal mode */
    stm32g4_fake.flash.ACR = FLASH_ACR_ICEN | FLASH_ACR_DCEN; /* LATENCY 0 */
    for (p = 0; p < STM32G4_GPIO_PORTS; ++p) {
        stm32g4_fake.gpio[p].MODER = 0xFFFFFFFFu; /* analog */
    }
    stm32g4_fake.gpio[0].MODER = 0xABFFFFFFu; /* PA13..15 debug */
    stm32g4_fake.gpio[1].MODER = 0xFFFFFEBFu; /* PB3, PB4 debug */
    memcpy(M.gpio_seen, stm32g4_fake.gpio, sizeof M.gpio_seen);
    stm32g4_fake.tim1.AF1 = TIM_AF1_BKINE; /* BKIN pin connected */
    stm32g4_fake.adc1.CR = ADC_CR_DEEPPWD;
    stm32g4_fake.adc2.CR = ADC_CR_DEEPPWD;
    stm32g4_fake.adc1.CFGR = ADC_CFGR_JQDIS;
    stm32g4_fake.adc2.CFGR = ADC_CFGR_JQDIS;
    stm32g4_fake.adc1.ISR = STM32G4_MODEL_ISR_MARK;
    stm32g4_fake.adc2.ISR = STM32G4_MODEL_ISR_MARK;
    M.bkin_pin_high = true;
    M.aden_guard_polls = 1u;
    stm32g4_model_flash_reset(); /* the controller; the flash array keeps its contents */
    stm32g4_model_tim4_reset();
}

static stm32g4_adc_t *adc_block(unsigned a)
{
    return a == 0u ? &stm32g4_fake.adc1 : &stm32g4_fake.adc2;
}

/* ---------------------------------------------------------------------------
 * GPIO (§9.3.1, §9.4.7): a port's registers only take writes while its clock is on
 * (RCC_AHB2ENR GPIOxEN, §7.4.15: "when the peripheral clock is not active, the peripheral
 * registers read or write access is not supported"); BSRR sets/resets ODR bits, the set
 * wins when both are written.
 * ------------------------------------------------------------------------- */
static void gpio_sync(void)
{
    unsigned p;
    for (p = 0; p < STM32G4_GPIO_PORTS; ++p) {
        stm32g4_gpio_t *g = &stm32g4_fake.gpio[p];
        const bool clocked = (stm32g4_fake.rcc.AHB2ENR & STM32G4_BIT(RCC_AHB2ENR_GPIOAEN_POS + p)) != 0u;
        if (!clocked) {
            if (memcmp(g, &M.gpio_seen[p], sizeof *g) != 0) {
                M.unclocked_writes++;
                memcpy(g, &M.gpio_seen[p], sizeof *g); /* the write is lost */
            }
            continue;
        }
        if (g->BSRR != 0u) {
            g->ODR = (g->ODR & ~(g->BSRR >> 16)) | (g->BSRR & 0xFFFFu);
            g->BSRR = 0u;
        }
        if (g->BRR != 0u) {
            g->ODR &= ~(g->BRR & 0xFFFFu);
            g->BRR = 0u;
        }
        /* §9.3.1, §9.3.9: an input nobody drives reads its pull (up 1, down 0; none: 0 here). */
        if (M.gpio_floating[p] != 0u) {
            unsigned pin;
            for (pin = 0; pin < 16u; ++pin) {
                if ((M.gpio_floating[p] & STM32G4_BIT(pin)) != 0u) {
                    const uint32_t pull = (g->PUPDR >> (2u * pin)) & 3u;
                    g->IDR = pull == GPIO_PULL_UP ? (g->IDR | STM32G4_BIT(pin)) : (g->IDR & ~STM32G4_BIT(pin));
                }
            }
        }
        memcpy(&M.gpio_seen[p], g, sizeof *g);
    }
}

stm32g4_gpio_t *stm32g4_fake_gpio(uint32_t port)
{
    gpio_sync();
    return &stm32g4_fake.gpio[port];
}

void stm32g4_model_pin_in(unsigned port, unsigned pin, bool high)
{
    M.gpio_floating[port] &= ~STM32G4_BIT(pin);
    gpio_sync();
    if (high) {
        stm32g4_fake.gpio[port].IDR |= STM32G4_BIT(pin);
    } else {
        stm32g4_fake.gpio[port].IDR &= ~STM32G4_BIT(pin);
    }
    M.gpio_seen[port].IDR = stm32g4_fake.gpio[port].IDR;
}

bool stm32g4_model_pin_out(unsigned port, unsigned pin)
{
    gpio_sync();
    return (stm32g4_fake.gpio[port].ODR & STM32G4_BIT(pin)) != 0u;
}

void stm32g4_model_pin_float(unsigned port, unsigned pin)
{
    M.gpio_floating[port] |= STM32G4_BIT(pin);
    gpio_sync();
}

/* §9.3.7, §9.4.1, §9.4.2: an output pin (MODER 01) drives ODR push-pull (OTYPER 0); open drain
 * (OTYPER 1) drives a 0 and lets the line go for a 1: then a pull-up (the pin's own, PUPDR 01, or
 * one outside) takes it high, and with none it floats. */
bool stm32g4_model_pin_drives_high(unsigned port, unsigned pin)
{
    const stm32g4_gpio_t *g;
    gpio_sync();
    g = &stm32g4_fake.gpio[port];
    return ((g->MODER >> (2u * pin)) & 3u) == GPIO_MODE_OUTPUT && (g->OTYPER & STM32G4_BIT(pin)) == 0u
           && (g->ODR & STM32G4_BIT(pin)) != 0u;
}

bool stm32g4_model_pin_drives_low(unsigned port, unsigned pin)
{
    const stm32g4_gpio_t *g;
    gpio_sync();
    g = &stm32g4_fake.gpio[port];
    return ((g->MODER >> (2u * pin)) & 3u) == GPIO_MODE_OUTPUT && (g->ODR & STM32G4_BIT(pin)) == 0u;
}

bool stm32g4_model_pin_level(unsigned port, unsigned pin, bool external_pull_up)
{
    const stm32g4_gpio_t *g;
    gpio_sync();
    g = &stm32g4_fake.gpio[port];
    if (((g->MODER >> (2u * pin)) & 3u) != GPIO_MODE_OUTPUT) {
        return (g->IDR & STM32G4_BIT(pin)) != 0u;
    }
    if (stm32g4_model_pin_drives_high(port, pin)) {
        return true;
    }
    if (stm32g4_model_pin_drives_low(port, pin)) {
        return false;
    }
    return external_pull_up || ((g->PUPDR >> (2u * pin)) & 3u) == GPIO_PULL_UP; /* released */
}

/* ---------------------------------------------------------------------------
 * Flash latency: §3.3.3 "Read access latency", Table 9 "Number of wait states according
 * to CPU clock (HCLK) frequency": range 1 boost mode one wait state per 34 MHz up to
 * 170 MHz; range 1 normal mode one per 30 MHz up to 150 MHz (the same thresholds as ST's
 * LL utilities). Boost mode is R1MODE = 0 (PWR_CR5, §6.4.18).
 * ------------------------------------------------------------------------- */
uint32_t stm32g4_model_flash_min_latency(uint32_t hclk_Hz, bool boost)
{
    const uint32_t step = boost ? 34000000u : 30000000u;
    return hclk_Hz == 0u ? 0u : (hclk_Hz - 1u) / step;
}

bool stm32g4_model_flash_ok(uint32_t hclk_Hz)
{
    const bool boost = (stm32g4_fake.pwr.CR5 & PWR_CR5_R1MODE) == 0u;
    const uint32_t latency = stm32g4_fake.flash.ACR & FLASH_ACR_LATENCY_MASK;
    if (hclk_Hz > (boost ? 170000000u : 150000000u)) {
        return false; /* range 1 normal mode is limited to 150 MHz (§6.1.5) */
    }
    return latency >= stm32g4_model_flash_min_latency(hclk_Hz, boost);
}

/* ---------------------------------------------------------------------------
 * Clock tree ready flags (§7.2.3, §7.2.4, §7.4.1, §7.4.3): HSIRDY follows HSION, PLLRDY
 * follows PLLON, SWS follows SW (the PLL only once it is ready); the regulator settles
 * (PWR_SR2 VOSF = 0, §6.4.12). One driver poll is enough time for each.
 * ------------------------------------------------------------------------- */
static void clock_poll(void)
{
    stm32g4_rcc_t *rcc = &stm32g4_fake.rcc;
    uint32_t sw;
    rcc->CR = (rcc->CR & ~(RCC_CR_HSIRDY | RCC_CR_PLLRDY)) | ((rcc->CR & RCC_CR_HSION) ? RCC_CR_HSIRDY : 0u)
              | ((rcc->CR & RCC_CR_PLLON) ? RCC_CR_PLLRDY : 0u);
    sw = (rcc->CFGR & RCC_CFGR_SW_MASK) >> RCC_CFGR_SW_POS;
    if (sw != RCC_CFGR_SW_PLL || (rcc->CR & RCC_CR_PLLRDY) != 0u) {
        rcc->CFGR = (rcc->CFGR & ~RCC_CFGR_SWS_MASK) | (sw << RCC_CFGR_SWS_POS);
    }
    stm32g4_fake.pwr.SR2 &= ~PWR_SR2_VOSF;
}

/* ---------------------------------------------------------------------------
 * ADC control (§21.4.6 "ADC deep-power-down mode and voltage regulator", §21.4.8
 * "Calibration", §21.4.9 "ADC on-off control", §21.7.3 ADC_CR): ADCAL, ADEN, JADSTART are
 * set by software and cleared by hardware (writing 0 has no effect); calibration and enable
 * need the regulator (ADVREGEN = 1, DEEPPWD = 0); ADEN set while ADCAL = 1 is ignored, and an
 * ADEN set less than 4 ADC clock cycles after ADCAL clears is reset by the calibration logic
 * (ST's HAL, stm32g4xx_hal_adc.c, ADC_Enable) - here: during the first aden_guard_polls driver
 * polls after the calibration ends; ADRDY follows a successful enable. ADC_ISR flags are
 * cleared by writing 1 (§21.7.1).
 * ------------------------------------------------------------------------- */
static void adc_sync(unsigned a)
{
    stm32g4_adc_t *adc = adc_block(a);
    const uint32_t written = adc->CR;
    const uint32_t req = written & ADC_CR_RS_BITS & ~M.adc[a].cr_rs;
    const bool regulator = (written & ADC_CR_ADVREGEN) != 0u && (written & ADC_CR_DEEPPWD) == 0u;
    if ((adc->ISR & STM32G4_MODEL_ISR_MARK) == 0u) { /* software wrote ISR (before this CR write) */
        M.adc[a].isr &= ~adc->ISR;
    }
    if ((req & ADC_CR_ADCAL) != 0u && regulator && (M.adc[a].cr_rs & ADC_CR_ADEN) == 0u) {
        M.adc[a].cr_rs |= ADC_CR_ADCAL;
        M.adc[a].cal_polls = 3u;
    }
    if ((req & ADC_CR_ADEN) != 0u && regulator && (M.adc[a].cr_rs & ADC_CR_ADCAL) == 0u) {
        if (M.adc[a].guard == 0u) {
            M.adc[a].cr_rs |= ADC_CR_ADEN;
            M.adc[a].isr |= ADC_ISR_ADRDY;
        } /* else: reset by the calibration logic */
    }
    if ((req & ADC_CR_JADSTART) != 0u && (M.adc[a].cr_rs & ADC_CR_ADEN) != 0u) {
        M.adc[a].cr_rs |= ADC_CR_JADSTART;
    }
    if ((req & ADC_CR_ADDIS) != 0u) {
        M.adc[a].cr_rs &= ~(ADC_CR_ADEN | ADC_CR_JADSTART);
        M.adc[a].isr &= ~ADC_ISR_ADRDY;
    }
    adc->CR = (written & ~ADC_CR_RS_BITS) | M.adc[a].cr_rs;
    adc->ISR = M.adc[a].isr | STM32G4_MODEL_ISR_MARK;
}

static void adc_poll(unsigned a)
{
    if (M.adc[a].cal_polls > 0u) {
        if (--M.adc[a].cal_polls == 0u) {
            M.adc[a].cr_rs &= ~ADC_CR_ADCAL;
            M.adc[a].calibrated = true;
            M.adc[a].guard = M.aden_guard_polls;
        }
    } else if (M.adc[a].guard > 0u) {
        M.adc[a].guard--;
    }
    adc_block(a)->CR = (adc_block(a)->CR & ~ADC_CR_RS_BITS) | M.adc[a].cr_rs;
}

/* ---------------------------------------------------------------------------
 * LPUART1 (§38.7.8, §38.7.10, §38.7.11): RXNE while received data waits in RDR, cleared by
 * reading RDR; TXE when TDR can take a byte. The NVIC's ICER (ARMv7-M B3.4.4) clears enables.
 * The DWT cycle counter counts CPU cycles (ARMv7-M C1.8.8): one per TIM1 tick here.
 * ------------------------------------------------------------------------- */
static void uart_status(void)
{
    stm32g4_fake.lpuart1.ISR = (stm32g4_fake.lpuart1.ISR & ~LPUART_ISR_RXNE) | LPUART_ISR_TXE
                               | (M.uart_rx_head < M.uart_rx_len ? LPUART_ISR_RXNE : 0u);
    if (M.uart_rx_head < M.uart_rx_len) {
        stm32g4_fake.lpuart1.RDR = M.uart_rx[M.uart_rx_head];
    }
}

void stm32g4_model_uart_send(const uint8_t *data, uint32_t n)
{
    uint32_t k;
    if (M.uart_rx_head == M.uart_rx_len) {
        M.uart_rx_head = 0u;
        M.uart_rx_len = 0u;
    }
    for (k = 0; k < n && M.uart_rx_len < sizeof M.uart_rx; ++k) {
        M.uart_rx[M.uart_rx_len++] = data[k];
    }
    uart_status();
}

uint32_t stm32g4_fake_lpuart_rdr(void)
{
    uint32_t b = stm32g4_fake.lpuart1.RDR;
    if (M.uart_rx_head < M.uart_rx_len) {
        b = M.uart_rx[M.uart_rx_head++];
    }
    uart_status();
    return b;
}

void stm32g4_fake_lpuart_tdr(uint32_t byte)
{
    if ((stm32g4_fake.lpuart1.CR1 & (LPUART_CR1_UE | LPUART_CR1_TE)) == (LPUART_CR1_UE | LPUART_CR1_TE)
        && (stm32g4_fake.rcc.APB1ENR2 & RCC_APB1ENR2_LPUART1EN) != 0u && M.uart_tx_len < sizeof M.uart_tx) {
        M.uart_tx[M.uart_tx_len++] = (uint8_t)byte;
    }
}

/* The model takes interrupts only between the application's turns (never inside one), so a
 * line held off with ICER and enabled again with ISER within a turn needs no modelling; ICER
 * writes are consumed (the tests check the enables the turn leaves behind). */
static void nvic_sync(void)
{
    unsigned i;
    for (i = 0; i < 8u; ++i) {
        stm32g4_fake.nvic.ICER[i] = 0u;
    }
}

void stm32g4_model_sync(void)
{
    nvic_sync();
    uart_status();
    gpio_sync();
    adc_sync(0u);
    adc_sync(1u);
    stm32g4_model_tim1_sync();
}

/* The driver's bounded wait loops call this once per poll. While the flash is busy only the flash
 * driver polls (the main loop waits in it, the control interrupt held off): only the flash advances. */
void stm32g4_fake_wait_hook(void)
{
    if (stm32g4_model_flash_busy()) {
        stm32g4_model_flash_poll();
        return;
    }
    stm32g4_model_sync();
    clock_poll();
    adc_poll(0u);
    adc_poll(1u);
}

/* ---------------------------------------------------------------------------
 * ADC injected conversions: §21.4.18 "Conversion on external trigger and trigger polarity"
 * (JEXTEN 01 rising, 10 falling, 11 both edges of the trigger selected by JEXTSEL; for
 * ADC1/ADC2 JEXTSEL 8 is TIM1_TRGO2, Table 164), §21.4.21 "Injected channels" (with
 * JADSTART = 1 each trigger converts JL + 1 ranks, data in JDRy, JEOC after each, JEOS after
 * the last), §21.4.12 "Channel-wise programmable sampling time" (t_conv = SMP + 12.5 ADC
 * cycles), §21.7.2 ADC_IER (JEOSIE: interrupt on JEOS). A trigger while a sequence runs is
 * ignored. The queue (JQDIS = 0) is not modelled.
 * ------------------------------------------------------------------------- */
static const uint32_t smp_half_cycles[8] = {5u, 13u, 25u, 49u, 95u, 185u, 495u, 1281u};

static uint32_t jsqr_channel(uint32_t jsqr, unsigned rank)
{
    return (jsqr >> (ADC_JSQR_JSQ1_POS + 6u * rank)) & 0x1Fu;
}

static uint32_t conversion_ticks(stm32g4_adc_t *adc, uint32_t channel)
{
    const uint32_t code =
        channel < 10u ? (adc->SMPR1 >> (3u * channel)) & 7u : (adc->SMPR2 >> (3u * (channel - 10u))) & 7u;
    return (smp_half_cycles[code] + 25u) * ADC_CLOCK_DIVIDER / 2u;
}

static void adc_tick(unsigned a)
{
    stm32g4_adc_t *adc = adc_block(a);
    const uint32_t jsqr = adc->JSQR;
    const uint32_t jexten = (jsqr >> ADC_JSQR_JEXTEN_POS) & 3u;
    const uint32_t jextsel = (jsqr >> ADC_JSQR_JEXTSEL_POS) & 0x1Fu;
    const bool armed = (M.adc[a].cr_rs & (ADC_CR_ADEN | ADC_CR_JADSTART)) == (ADC_CR_ADEN | ADC_CR_JADSTART);
    const bool trg = jextsel == ADC12_JEXTSEL_TIM1_TRGO2 && M.trgo2;
    const bool rise = trg && !M.adc[a].trgo2_prev;
    const bool fall = !trg && M.adc[a].trgo2_prev && jextsel == ADC12_JEXTSEL_TIM1_TRGO2;
    M.adc[a].trgo2_prev = trg;
    if (M.adc[a].busy) {
        if (--M.adc[a].ticks_left == 0u) {
            const unsigned r = M.adc[a].rank;
            const uint32_t ch = jsqr_channel(jsqr, r);
            adc->JDR[r] = M.analog_counts[a][ch <= ADC_CHANNEL_MAX ? ch : 0u];
            M.adc[a].isr |= ADC_ISR_JEOC;
            if (r >= (jsqr & 3u)) {
                M.adc[a].isr |= ADC_ISR_JEOS;
                M.adc[a].busy = false;
                M.adc[a].sequences++;
            } else {
                M.adc[a].rank = r + 1u;
                M.adc[a].ticks_left = conversion_ticks(adc, jsqr_channel(jsqr, r + 1u));
            }
            adc->ISR = M.adc[a].isr | STM32G4_MODEL_ISR_MARK;
        }
        return;
    }
    if (armed && ((rise && (jexten & 1u) != 0u) || (fall && (jexten & 2u) != 0u))) {
        stm32g4_model_trigger_t *t = &M.adc[a].log[M.adc[a].triggers % STM32G4_MODEL_LOG];
        t->tick = M.tick;
        t->cnt = M.cnt;
        t->down = M.down;
        M.adc[a].triggers++;
        M.adc[a].busy = true;
        M.adc[a].rank = 0u;
        M.adc[a].ticks_left = conversion_ticks(adc, jsqr_channel(jsqr, 0u));
    }
}

/* ---------------------------------------------------------------------------
 * NVIC (ARMv7-M B3.4): an enabled interrupt line whose source is active runs its handler;
 * ADC1_2 from JEOS & JEOSIE of either ADC, TIM1_BRK from BIF & BIE. The handler must clear
 * the source or it runs again at the next tick.
 * ------------------------------------------------------------------------- */
static bool irq_enabled(uint32_t irq)
{
    return (stm32g4_fake.nvic.ISER[irq / 32u] & STM32G4_BIT(irq % 32u)) != 0u;
}

static void interrupts(void)
{
    unsigned guard;
    for (guard = 0; guard < 4u; ++guard) {
        const bool brk =
            (M.sr & TIM_SR_BIF) != 0u && (TIM->DIER & TIM_DIER_BIE) != 0u && irq_enabled(STM32G4_IRQ_TIM1_BRK_TIM15);
        const bool adc = (((M.adc[0].isr & ADC_ISR_JEOS) != 0u && (stm32g4_fake.adc1.IER & ADC_IER_JEOSIE) != 0u)
                          || ((M.adc[1].isr & ADC_ISR_JEOS) != 0u && (stm32g4_fake.adc2.IER & ADC_IER_JEOSIE) != 0u))
                         && irq_enabled(STM32G4_IRQ_ADC1_2);
        if (brk) { /* higher priority in the port's set-up */
            M.brk_irqs++;
            TIM1_BRK_TIM15_IRQHandler();
        } else if (adc) {
            M.adc_irqs++;
            ADC1_2_IRQHandler();
        } else {
            return;
        }
        stm32g4_model_sync();
    }
}

void stm32g4_model_run(uint64_t ticks)
{
    uint64_t n;
    for (n = 0; n < ticks; ++n) {
        stm32g4_model_sync();
        M.update_pulse = false;
        M.tick++;
        if ((stm32g4_fake.dwt.CTRL & DWT_CTRL_CYCCNTENA) != 0u) {
            stm32g4_fake.dwt.CYCCNT++;
        }
        stm32g4_model_tim1_tick();
        adc_tick(0u);
        adc_tick(1u);
        TIM->SR = M.sr;
        stm32g4_model_tim4_tick();
        stm32g4_model_flash_advance(1u);
        interrupts();
    }
}
