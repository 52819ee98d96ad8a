/*
 * Behavioural model of TIM4 as the STEP/DIR counter (see stm32g4_model.h, "TIM4"). Each rule names
 * the section of ST RM0440 it follows, chapter 29 "General-purpose timers (TIM2/TIM3/TIM4/TIM5)":
 * §29.4 "Input filter" and "Encoder interface mode" ("Clock plus direction encoder mode"), §29.5
 * the registers; §7.4.17 RCC_APB1ENR1; §9.4 the GPIO registers (the pin's alternate function).
 */
#include <string.h>

#include "stm32g4_model.h"

stm32g4_model_tim4_t stm32g4_model_tim4;

#define T stm32g4_model_tim4
#define TIM (&stm32g4_fake.tim4)

/* §29.5.7 ICxF with CKD = 00 (f_DTS = f_CK_INT): the sampling period in clocks and N. CKD = 01 and
 * 10 double and quadruple f_DTS's period for the codes from 0100. */
static const uint32_t filter_period[16] = {1u, 1u, 1u, 1u, 2u, 2u, 4u, 4u, 8u, 8u, 16u, 16u, 16u, 32u, 32u, 32u};
static const uint32_t filter_n[16] = {1u, 2u, 4u, 8u, 6u, 8u, 6u, 8u, 6u, 8u, 5u, 6u, 8u, 5u, 6u, 8u};

void stm32g4_model_tim4_reset(void)
{
    memset(&T, 0, sizeof T);
    /* §29.5: every TIM4 register resets to 0 but ARR (0xFFFF for a 16-bit timer, §29.5.14). */
    TIM->ARR = 0xFFFFu;
}

/* A pin's input to the timer: its IDR bit while it is in alternate function @p af (§9.4.1 MODER 10,
 * §9.4.9/§9.4.10 AFRL/AFRH); the timer sees 0 from a pin in any other function. */
static bool pin_in_af(unsigned port, unsigned pin, uint32_t af)
{
    const stm32g4_gpio_t *g = &stm32g4_fake.gpio[port];
    const bool is_af = ((g->MODER >> (2u * pin)) & 3u) == GPIO_MODE_AF;
    const bool that_af = ((g->AFR[pin / 8u] >> (4u * (pin % 8u))) & 0xFu) == af;
    return is_af && that_af && (g->IDR & STM32G4_BIT(pin)) != 0u;
}

/* tim_ti1 = TIM4_CH1 (PB6 AF2, PA11 AF10), tim_ti2 = TIM4_CH2 (PB7 AF2, PA12 AF10), with TISEL = 0
 * (§29.5.25: 0000 selects the TIMx_CHx pin; the model has no other source). */
static bool ti_raw(unsigned channel)
{
    const uint32_t sel = channel == 0u ? (TIM->TISEL & TIM_TISEL_TI1SEL_MASK) : (TIM->TISEL & TIM_TISEL_TI2SEL_MASK);
    if (sel != 0u) {
        return false;
    }
    return channel == 0u ? (pin_in_af(1u, 6u, 2u) || pin_in_af(0u, 11u, 10u))
                         : (pin_in_af(1u, 7u, 2u) || pin_in_af(0u, 12u, 10u));
}

/* §29.4 "Input filter": the input is sampled at f_SAMPLING; the filtered signal takes a new level
 * after N consecutive samples at it. A pulse shorter than (N - 1) sampling periods never passes; one
 * of N periods or more always does. */
static void filter_tick(unsigned channel, uint64_t tick)
{
    const uint32_t icf = (TIM->CCMR1 >> (channel == 0u ? TIM_CCMR1_IC1F_POS : TIM_CCMR1_IC2F_POS)) & TIM_CCMR_ICF_MASK;
    const uint32_t ckd = (TIM->CR1 & TIM_CR1_CKD_MASK) >> TIM_CR1_CKD_POS;
    const uint32_t period = icf >= 4u ? filter_period[icf] << (ckd < 3u ? ckd : 0u) : filter_period[icf];
    bool level;
    if (tick % period != 0u) {
        return;
    }
    level = ti_raw(channel);
    if (level == T.ti_filtered[channel]) {
        T.ti_run[channel] = 0u;
        return;
    }
    if (++T.ti_run[channel] >= filter_n[icf]) {
        T.ti_filtered[channel] = level;
        T.ti_run[channel] = 0u;
        if (channel == 1u) {
            T.filtered_edges++;
        }
    }
}

/* §29.4 "Time-base unit", "Counter modes": counting up from ARR overflows to 0, counting down from
 * 0 underflows to ARR; each sets UIF (§29.5.5). CR1.DIR shows the direction (read-only in encoder
 * mode, §29.5.1). */
static void count(bool up)
{
    const uint32_t arr = TIM->ARR & 0xFFFFu;
    if (up) {
        T.counted_up++;
        if (T.cnt >= arr) {
            T.cnt = 0u;
            T.sr |= TIM_SR_UIF;
            T.wraps++;
        } else {
            T.cnt++;
        }
        TIM->CR1 &= ~TIM_CR1_DIR;
    } else {
        T.counted_down++;
        if (T.cnt == 0u) {
            T.cnt = arr;
            T.sr |= TIM_SR_UIF;
            T.wraps++;
        } else {
            T.cnt--;
        }
        TIM->CR1 |= TIM_CR1_DIR;
    }
}

void stm32g4_model_tim4_tick(void)
{
    const bool clocked = (stm32g4_fake.rcc.APB1ENR1 & RCC_APB1ENR1_TIM4EN) != 0u;
    uint32_t sms;
    bool ti1fp1;
    bool ti2fp2;
    bool ccs_input;
    if (!clocked) {
        return; /* §7.4.17: no clock, no count (the registers keep what they hold) */
    }
    /* Software writes: CNT written (§29.5.12), flags cleared by writing 0 (§29.5.5), UG (§29.5.6:
     * the counter re-initialised, to 0 counting up; UIF unless URS). */
    if ((TIM->CNT & 0xFFFFu) != T.cnt_written) {
        T.cnt = TIM->CNT & 0xFFFFu;
    }
    if (TIM->SR != T.sr) {
        T.sr &= TIM->SR;
    }
    if ((TIM->EGR & TIM_EGR_UG) != 0u) {
        TIM->EGR = 0u;
        T.cnt = 0u;
        if ((TIM->CR1 & TIM_CR1_URS) == 0u) {
            T.sr |= TIM_SR_UIF;
        }
    }

    filter_tick(0u, stm32g4_model.tick);
    filter_tick(1u, stm32g4_model.tick);
    /* §29.5.11: CCxP inverts tim_tixf into tim_tixfpx. The encoder takes tim_ti1fp1 and tim_ti2fp2
     * with IC1 and IC2 mapped on tim_ti1 and tim_ti2 (CC1S = CC2S = 01, §29.4 "Encoder interface
     * mode": the set-up it gives); otherwise the model counts nothing. */
    ti1fp1 = T.ti_filtered[0] != ((TIM->CCER & TIM_CCER_CC1P) != 0u);
    ti2fp2 = T.ti_filtered[1] != ((TIM->CCER & TIM_CCER_CC2P) != 0u);
    ccs_input = ((TIM->CCMR1 >> TIM_CCMR1_CC1S_POS) & TIM_CCMR_CCS_MASK) == TIM_CCMR_CCS_INPUT_TI
                && ((TIM->CCMR1 >> TIM_CCMR1_CC2S_POS) & TIM_CCMR_CCS_MASK) == TIM_CCMR_CCS_INPUT_TI;
    sms = TIM->SMCR & TIM_SMCR_SMS_MASK;

    if ((TIM->CR1 & TIM_CR1_CEN) != 0u) {
        const bool rise = ti2fp2 && !T.ti2fp2_prev;
        const bool edge = ti2fp2 != T.ti2fp2_prev;
        if (sms == 0u) {
            count(true); /* §29.5.3 SMS 0000: the internal clock (PSC = 0 assumed) */
        } else if (sms == TIM_SMCR_SMS_CLOCK_DIR_X1 && ccs_input && rise) {
            count(ti1fp1); /* one count per edge of tim_ti2fp2 (CC2P 0: rising), up while tim_ti1fp1 is high */
        } else if (sms == TIM_SMCR_SMS_CLOCK_DIR_X2 && ccs_input && edge) {
            count(ti1fp1); /* both edges */
        }
    }
    T.ti2fp2_prev = ti2fp2;
    TIM->CNT = T.cnt;
    T.cnt_written = T.cnt;
    TIM->SR = T.sr;
}
