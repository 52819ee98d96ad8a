/*
 * Behavioural model of TIM1 (see stm32g4_model.h): its time base, the output compare and the
 * complementary outputs with their dead time, the break input and TRGO2. Every rule names the
 * section of ST RM0440 (Rev 8) it follows, chapter 28 "Advanced-control timers (TIM1/TIM8/TIM20)".
 */
#include "stm32g4_model.h"

#include "pmstep_hal_stm32g4.h"

#define M stm32g4_model
#define TIM (&stm32g4_fake.tim1)

/* TIMx_CR1 DIR (bit 4, stm32g4_regs.h); CR2 OISx at 8 + 2(x-1), OISxN at 9 + 2(x-1); CCER CCxP at 4(x-1) + 1,
 * CCxNP at 4(x-1) + 3; CCMR OCxM[3] at bit 16 (+8); MMS2 code 0010 = update. */
#define MMS2_UPDATE 2u

/* ---------------------------------------------------------------------------
 * TIM1 software writes (§28.6.5 TIMx_SR: flags cleared by writing 0, writing 1 has no
 * effect; §28.6.6 TIMx_EGR UG; §28.3.17/§28.6.20: MOE cannot be set while a break is active).
 * ------------------------------------------------------------------------- */
static void update_event(bool by_ug);
static void break_update(void);

void stm32g4_model_tim1_sync(void)
{
    if (TIM->SR != M.sr) {
        M.sr &= TIM->SR;
    }
    if ((TIM->EGR & TIM_EGR_UG) != 0u) {
        TIM->EGR = 0u;
        update_event(true);
    }
    break_update();
    TIM->SR = M.sr;
}

/* ---------------------------------------------------------------------------
 * TIM1 time base.
 * ------------------------------------------------------------------------- */
static uint32_t ccr_preload(unsigned ch)
{
    switch (ch) {
    case 0: return TIM->CCR1;
    case 1: return TIM->CCR2;
    case 2: return TIM->CCR3;
    case 3: return TIM->CCR4;
    case 4: return TIM->CCR5 & 0xFFFFFu;
    default: return TIM->CCR6;
    }
}

/* OCxPE of channel ch (0-based): CCMR1 ch 0/1, CCMR2 ch 2/3, CCMR3 ch 4/5 (§28.6.7, §28.6.9, §28.6.23). */
static uint32_t ccmr_field(unsigned ch)
{
    const uint32_t reg = ch < 2u ? TIM->CCMR1 : (ch < 4u ? TIM->CCMR2 : TIM->CCMR3);
    const uint32_t shift = (ch % 2u) * 8u;
    return ((reg >> shift) & 0xFFu) | (((reg >> (16u + shift)) & 1u) << 8);
}

static uint32_t oc_mode(unsigned ch)
{
    const uint32_t f = ccmr_field(ch);
    return ((f >> 4) & 7u) | (((f >> 8) & 1u) << 3);
}

/* §28.3.2 "Time-base unit": ARR and CCRx are preloaded when ARPE / OCxPE are set and take
 * their new value at an update event; otherwise writes act at once. §28.3.3 "Repetition
 * counter": REP_CNT is reloaded from RCR at each update event. §28.6.5: UIF is set by an
 * update event, except one from UG while URS = 1. */
static void update_event(bool by_ug)
{
    unsigned ch;
    M.arr_shadow = TIM->ARR & 0xFFFFu;
    for (ch = 0; ch < 6u; ++ch) {
        M.ccr_shadow[ch] = ccr_preload(ch);
    }
    M.rep = TIM->RCR & 0xFFFFu;
    if (by_ug) {
        /* UG re-initialises the counter (§28.6.6): 0 when counting up or centre-aligned. */
        const uint32_t cms = (TIM->CR1 >> TIM_CR1_CMS_POS) & 3u;
        M.cnt = (cms == 0u && (TIM->CR1 & TIM_CR1_DIR) != 0u) ? M.arr_shadow : 0u;
        M.down = false;
        if ((TIM->CR1 & TIM_CR1_URS) == 0u) {
            M.sr |= TIM_SR_UIF;
        }
        if (cms != 0u) {
            /* §28.3.3: in centre-aligned mode with an odd RCR, the update event comes at the
             * overflow when RCR was written before the counter started (at the underflow
             * otherwise): the start from 0 counts as the underflow that precedes it. */
            if (M.rep > 0u) {
                M.rep--;
            }
        }
    } else {
        M.sr |= TIM_SR_UIF;
    }
    M.updates++;
    M.update_pulse = true;
}

static bool preload_on(unsigned ch)
{
    return (ccmr_field(ch) & TIM_CCMR_OCPE) != 0u;
}

/* §28.3.2 "Counter modes": edge-aligned up counts 0..ARR then overflows to 0; down counts
 * ARR..0 then underflows to ARR; centre-aligned counts 0..ARR-1 up, overflows, ARR..1 down,
 * underflows (CNT = ARR belongs to the down slope, CNT = 0 to the up slope). */
static void counter_tick(void)
{
    const uint32_t cms = (TIM->CR1 >> TIM_CR1_CMS_POS) & 3u;
    bool event = false;
    if ((TIM->CR1 & TIM_CR1_ARPE) == 0u) {
        M.arr_shadow = TIM->ARR & 0xFFFFu;
    }
    if (cms == 0u) {
        M.down = (TIM->CR1 & TIM_CR1_DIR) != 0u;
        if (!M.down) {
            if (M.cnt >= M.arr_shadow) {
                M.cnt = 0u;
                event = true;
            } else {
                M.cnt++;
            }
        } else if (M.cnt == 0u) {
            M.cnt = M.arr_shadow;
            event = true;
        } else {
            M.cnt--;
        }
    } else if (!M.down) {
        M.cnt++;
        if (M.cnt >= M.arr_shadow) {
            M.down = true;
            event = true;
        }
    } else {
        M.cnt--;
        if (M.cnt == 0u) {
            M.down = false;
            event = true;
        }
    }
    TIM->CNT = M.cnt;
    /* §28.3.3: REP_CNT counts down at each overflow/underflow (both in centre-aligned mode);
     * the update event is generated when it is 0, and it is reloaded from RCR. */
    if (event) {
        if (M.rep == 0u) {
            update_event(false);
        } else {
            M.rep--;
        }
    }
}

/* §28.3.11 "PWM mode" (edge- and centre-aligned): PWM mode 1 - in upcounting OCxREF is active
 * while CNT < CCRx, in downcounting inactive while CNT > CCRx else active; PWM mode 2 is the
 * complement. Consequences the tests check: CCRx = 0 gives 0 % in mode 1; CCRx >= ARR gives
 * 100 % in mode 1 in centre-aligned mode (CNT never exceeds ARR). Other modes: 0000 frozen
 * (kept), 0100 forced inactive, 0101 forced active (§28.6.7). */
static void ocref_update(void)
{
    unsigned ch;
    for (ch = 0; ch < 6u; ++ch) {
        const uint32_t ccr = preload_on(ch) ? M.ccr_shadow[ch] : ccr_preload(ch);
        const uint32_t mode = oc_mode(ch);
        bool mode1;
        if (!preload_on(ch)) {
            M.ccr_shadow[ch] = ccr;
        }
        mode1 = M.down ? !(M.cnt > ccr) : (M.cnt < ccr);
        switch (mode) {
        case 6u: M.ocref[ch] = mode1; break;
        case 7u: M.ocref[ch] = !mode1; break;
        case 4u: M.ocref[ch] = false; break;
        case 5u: M.ocref[ch] = true; break;
        default: break;
        }
    }
}

/* §28.3.17 "Using the break function": the break input (BKIN pin, enabled by BKE and
 * AF1.BKINE, polarity BKP in BDTR with AF1.BKINP inverting the pin) clears MOE
 * asynchronously, sets BIF, and keeps MOE cleared while active; with AOE = 0, MOE stays
 * cleared until software sets it again. The break filter is not modelled. */
static void break_update(void)
{
    const bool enabled = (TIM->BDTR & TIM_BDTR_BKE) != 0u && (TIM->AF1 & TIM_AF1_BKINE) != 0u;
    const bool level = M.bkin_pin_high != ((TIM->AF1 & TIM_AF1_BKINP) != 0u);
    const bool active_high = (TIM->BDTR & TIM_BDTR_BKP) != 0u;
    M.break_active = enabled && (level == active_high);
    if (M.break_active) {
        TIM->BDTR &= ~TIM_BDTR_MOE;
        M.sr |= TIM_SR_BIF;
        TIM->SR = M.sr;
    }
}

/* §28.3.16 "Complementary outputs and dead-time insertion": from OCxREF the dead-time
 * generator makes OCx = OCxREF with its rising edge delayed by the dead time and OCxN = not
 * OCxREF with its rising edge delayed by the dead time (a pulse shorter than the dead time
 * disappears). Output stage, Table "Output control bits for complementary OCx and OCxN
 * channels with break feature" (§28.6.11): MOE = 1, CCxE = CCxNE = 1: the generator outputs
 * XOR polarity; MOE = 0 with OSSI = 1: the idle levels OISx / OISxN (the intermediate
 * "inactive, then idle after a dead time" step is not modelled; the port's idle levels are
 * the inactive ones). A disabled output (CCxE = 0, MOE = 1, OSSR = 0) reads 0 here. */
uint32_t stm32g4_model_dead_time_ticks(uint32_t dtg)
{
    /* §28.6.20 DTG[7:0], t_DTS = t_CK_INT (CKD = 0). */
    if ((dtg & 0x80u) == 0u) {
        return dtg;
    }
    if ((dtg & 0xC0u) == 0x80u) {
        return (64u + (dtg & 0x3Fu)) * 2u;
    }
    if ((dtg & 0xE0u) == 0xC0u) {
        return (32u + (dtg & 0x1Fu)) * 8u;
    }
    return (32u + (dtg & 0x1Fu)) * 16u;
}

static void outputs_update(void)
{
    const uint32_t dt = stm32g4_model_dead_time_ticks(TIM->BDTR & TIM_BDTR_DTG_MASK);
    const bool moe = (TIM->BDTR & TIM_BDTR_MOE) != 0u;
    unsigned ch;
    for (ch = 0; ch < 4u; ++ch) {
        const bool want[2] = {M.ocref[ch], !M.ocref[ch]};
        unsigned k;
        for (k = 0; k < 2u; ++k) {
            if (!want[k]) {
                M.dt_out[ch][k] = false;
                M.dt_wait[ch][k] = dt;
            } else if (!M.dt_out[ch][k]) {
                if (M.dt_wait[ch][k] == 0u) {
                    M.dt_out[ch][k] = true;
                } else {
                    M.dt_wait[ch][k]--;
                }
            }
        }
        if (moe) {
            const bool e = (TIM->CCER & TIM_CCER_CCE(ch + 1u)) != 0u;
            const bool en = (TIM->CCER & TIM_CCER_CCNE(ch + 1u)) != 0u;
            const bool p = (TIM->CCER & STM32G4_BIT(4u * ch + 1u)) != 0u;
            const bool np = (TIM->CCER & STM32G4_BIT(4u * ch + 3u)) != 0u;
            M.oc[ch] = e && (M.dt_out[ch][0] != p);
            M.ocn[ch] = en && (M.dt_out[ch][1] != np);
        } else {
            const bool ossi = (TIM->BDTR & TIM_BDTR_OSSI) != 0u;
            M.oc[ch] = ossi && (TIM->CR2 & STM32G4_BIT(8u + 2u * ch)) != 0u;
            M.ocn[ch] = ossi && (TIM->CR2 & STM32G4_BIT(9u + 2u * ch)) != 0u;
        }
    }
}

/* §28.3.26 / §28.6.2 TIMx_CR2 MMS2: TRGO2 is the update event (0010) or OC5REFC (1000, OC5REF
 * after the optional clear, which is not used) among others. */
static void trgo2_update(void)
{
    const uint32_t mms2 = (TIM->CR2 & TIM_CR2_MMS2_MASK) >> TIM_CR2_MMS2_POS;
    if (mms2 == TIM_CR2_MMS2_OC5REFC) {
        M.trgo2 = M.ocref[4];
    } else if (mms2 == MMS2_UPDATE) {
        M.trgo2 = M.update_pulse;
    } else {
        M.trgo2 = false;
    }
}

void stm32g4_model_tim1_tick(void)
{
    break_update();
    if ((TIM->CR1 & TIM_CR1_CEN) != 0u) {
        counter_tick();
    }
    ocref_update();
    outputs_update();
    trgo2_update();
}
