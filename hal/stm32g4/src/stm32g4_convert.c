/* Pure functions of the STM32G4 port: unit conversions, duty mapping, timer and clock
 * arithmetic. No register access, so the host tests call them directly. */
#include <stddef.h>

#include "pmstep_hal_stm32g4.h"

#define HSI16_HZ 16000000u
#define SYSCLK_MAX_HZ 170000000u

float pmstep_stm32g4_counts_to_si(uint32_t counts, float offset_counts, float gain_per_count)
{
    return ((float)counts - offset_counts) * gain_per_count;
}

static float clamp(float x, float lo, float hi)
{
    return x < lo ? lo : (x > hi ? hi : x);
}

void pmstep_stm32g4_duties(float u_V, float bus_V, float duty_min, float duty_max, float *d_plus, float *d_minus)
{
    float half_ratio;
    if (!(bus_V > 0.0f) || u_V != u_V) { /* no bus, NaN bus or NaN voltage: zero volts */
        *d_plus = clamp(0.5f, duty_min, duty_max);
        *d_minus = *d_plus;
        return;
    }
    half_ratio = 0.5f * (u_V / bus_V);
    *d_plus = clamp(0.5f + half_ratio, duty_min, duty_max);
    *d_minus = clamp(0.5f - half_ratio, duty_min, duty_max);
}

uint32_t pmstep_stm32g4_duty_to_ccr(float duty, uint32_t arr)
{
    const float counts = duty * (float)arr + 0.5f;
    if (!(counts > 0.0f)) {
        return 0u;
    }
    if (counts >= (float)arr) {
        return arr;
    }
    return (uint32_t)counts;
}

pmstep_stm32g4_status_t pmstep_stm32g4_dead_time_dtg(uint32_t dead_time_ns, uint32_t tim_clock_Hz, uint8_t *dtg)
{
    /* Timer clock periods needed, rounded up so the dead time is at least the one asked for. */
    const uint64_t ticks = ((uint64_t)dead_time_ns * tim_clock_Hz + 999999999u) / 1000000000u;
    if (dtg == NULL || tim_clock_Hz == 0u) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    if (ticks <= 127u) {
        *dtg = (uint8_t)ticks;
    } else if (ticks <= 2u * (64u + 63u)) {
        *dtg = (uint8_t)(0x80u | (uint32_t)((ticks + 1u) / 2u - 64u));
    } else if (ticks <= 8u * (32u + 31u)) {
        *dtg = (uint8_t)(0xC0u | (uint32_t)((ticks + 7u) / 8u - 32u));
    } else if (ticks <= 16u * (32u + 31u)) {
        *dtg = (uint8_t)(0xE0u | (uint32_t)((ticks + 15u) / 16u - 32u));
    } else {
        return PMSTEP_STM32G4_ERR_DEAD_TIME;
    }
    return PMSTEP_STM32G4_OK;
}

uint32_t pmstep_stm32g4_dtg_to_ns(uint8_t dtg, uint32_t tim_clock_Hz)
{
    uint64_t ticks;
    if ((dtg & 0x80u) == 0u) {
        ticks = dtg;
    } else if ((dtg & 0xC0u) == 0x80u) {
        ticks = 2u * (64u + (dtg & 0x3Fu));
    } else if ((dtg & 0xE0u) == 0xC0u) {
        ticks = 8u * (32u + (dtg & 0x1Fu));
    } else {
        ticks = 16u * (32u + (dtg & 0x1Fu));
    }
    return tim_clock_Hz == 0u ? 0u : (uint32_t)(ticks * 1000000000u / tim_clock_Hz);
}

uint32_t pmstep_stm32g4_sysclk_Hz(const pmstep_stm32g4_clock_t *clock)
{
    uint32_t vco_in_Hz;
    uint32_t vco_out_Hz;
    uint32_t sysclk_Hz;
    if (clock == NULL || clock->pll_m < 1u || clock->pll_m > 16u || clock->pll_n < 8u || clock->pll_n > 127u
        || (clock->pll_r != 2u && clock->pll_r != 4u && clock->pll_r != 6u && clock->pll_r != 8u)) {
        return 0u;
    }
    /* PLL input 2.66..16 MHz, VCO 96..344 MHz (datasheet DS12589, PLL characteristics). */
    vco_in_Hz = HSI16_HZ / clock->pll_m;
    vco_out_Hz = vco_in_Hz * clock->pll_n;
    sysclk_Hz = vco_out_Hz / clock->pll_r;
    if (vco_in_Hz < 2660000u || vco_out_Hz < 96000000u || vco_out_Hz > 344000000u || sysclk_Hz > SYSCLK_MAX_HZ) {
        return 0u;
    }
    return sysclk_Hz;
}

uint32_t pmstep_stm32g4_flash_latency_mode(uint32_t hclk_Hz, bool boost)
{
    /* RM0440 §3.3.3, Table 9: one wait state per 34 MHz in range 1 boost mode, per 30 MHz in
     * range 1 normal mode (the thresholds of ST's LL utilities, UTILS_SCALE1_LATENCYn_FREQ). */
    const uint32_t per_wait_state_hz = boost ? 34000000u : 30000000u;
    return hclk_Hz == 0u ? 0u : (hclk_Hz - 1u) / per_wait_state_hz;
}

uint32_t pmstep_stm32g4_flash_latency(uint32_t hclk_Hz)
{
    return pmstep_stm32g4_flash_latency_mode(hclk_Hz, hclk_Hz > 150000000u);
}

uint32_t pmstep_stm32g4_pwm_arr(uint32_t tim_clock_Hz, uint32_t pwm_frequency_Hz)
{
    uint64_t arr;
    if (pwm_frequency_Hz == 0u) {
        return 0u;
    }
    arr = ((uint64_t)tim_clock_Hz + pwm_frequency_Hz) / (2u * (uint64_t)pwm_frequency_Hz);
    return (arr < 2u || arr > 65535u) ? 0u : (uint32_t)arr;
}

/* TIMx_CCMR1 ICxF (RM0440 §29.5.7) with CKD = 0: sampling period in timer clocks and samples N. */
static const uint8_t filter_period_ticks[16] = {1u, 1u, 1u, 1u, 2u, 2u, 4u, 4u, 8u, 8u, 16u, 16u, 16u, 32u, 32u, 32u};
static const uint8_t filter_samples[16] = {1u, 2u, 4u, 8u, 6u, 8u, 6u, 8u, 6u, 8u, 5u, 6u, 8u, 5u, 6u, 8u};
#define STEP_SYNC_MARGIN_TICKS 2u /* the input synchroniser: an edge is seen up to 2 clocks late */

uint32_t pmstep_stm32g4_step_filter_ticks(uint8_t icf)
{
    const uint32_t k = icf & 0xFu;
    return (uint32_t)filter_period_ticks[k] * (uint32_t)filter_samples[k];
}

pmstep_stm32g4_status_t pmstep_stm32g4_step_filter(uint32_t min_pulse_ns, uint32_t tim_clock_Hz, uint8_t *icf)
{
    uint64_t pulse_ticks;
    uint8_t k;
    if (icf == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    pulse_ticks = (uint64_t)min_pulse_ns * tim_clock_Hz / 1000000000u;
    if (pulse_ticks < 1u + STEP_SYNC_MARGIN_TICKS) {
        return PMSTEP_STM32G4_ERR_STEP_PULSE;
    }
    /* The spans grow with the code: the last one that fits. */
    *icf = 0u;
    for (k = 1u; k < 16u; ++k) {
        if ((uint64_t)pmstep_stm32g4_step_filter_ticks(k) + STEP_SYNC_MARGIN_TICKS <= pulse_ticks) {
            *icf = k;
        }
    }
    return PMSTEP_STM32G4_OK;
}

const char *pmstep_stm32g4_status_str(pmstep_stm32g4_status_t status)
{
    switch (status) {
    case PMSTEP_STM32G4_OK:
        return "ok";
    case PMSTEP_STM32G4_ERR_NULL_ARGUMENT:
        return "null argument";
    case PMSTEP_STM32G4_ERR_CLOCK_CONFIG:
        return "PLL factors out of range or SYSCLK above 170 MHz";
    case PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT:
        return "PLL lock, regulator or clock switch timed out";
    case PMSTEP_STM32G4_ERR_PWM_FREQUENCY:
        return "PWM frequency gives TIM1 ARR outside 2..65535";
    case PMSTEP_STM32G4_ERR_DEAD_TIME:
        return "dead time longer than TIM1 can insert";
    case PMSTEP_STM32G4_ERR_DUTY_RANGE:
        return "duty range must be 0 <= duty_min < duty_max <= 1";
    case PMSTEP_STM32G4_ERR_ADC_CONFIG:
        return "ADC channel or sample time out of range";
    case PMSTEP_STM32G4_ERR_ADC_TIMEOUT:
        return "ADC calibration or enable timed out";
    case PMSTEP_STM32G4_ERR_PIN:
        return "pin port, number or alternate function out of range";
    case PMSTEP_STM32G4_ERR_PIN_CONFLICT:
        return "two functions on one pin";
    case PMSTEP_STM32G4_ERR_PIN_RESERVED:
        return "a pin the board itself uses is given another function";
    case PMSTEP_STM32G4_ERR_UART_CONFIG:
        return "console baud rate out of LPUART1's range";
    case PMSTEP_STM32G4_ERR_UNMEASURED_INPUT:
        return "the core reads phase voltages or a load torque, which this board does not measure";
    case PMSTEP_STM32G4_ERR_SENSE_RANGE:
        return "the core's measurement ranges exceed what this board's ADC reads";
    case PMSTEP_STM32G4_ERR_FLASH_RANGE:
        return "flash slot, offset or length out of range";
    case PMSTEP_STM32G4_ERR_FLASH_LOCKED:
        return "flash control register stayed locked (a wrong key locks it until reset)";
    case PMSTEP_STM32G4_ERR_FLASH_TIMEOUT:
        return "flash operation timed out (BSY stayed set)";
    case PMSTEP_STM32G4_ERR_FLASH_PROGERR:
        return "flash PROGERR: double word not erased before programming";
    case PMSTEP_STM32G4_ERR_FLASH_WRPERR:
        return "flash WRPERR: page write-protected";
    case PMSTEP_STM32G4_ERR_FLASH_PGAERR:
        return "flash PGAERR: program alignment";
    case PMSTEP_STM32G4_ERR_FLASH_SIZERR:
        return "flash SIZERR: program write not a word";
    case PMSTEP_STM32G4_ERR_FLASH_PGSERR:
        return "flash PGSERR: programming sequence";
    case PMSTEP_STM32G4_ERR_FLASH_MISERR:
        return "flash MISERR: fast programming data miss";
    case PMSTEP_STM32G4_ERR_FLASH_FASTERR:
        return "flash FASTERR: fast programming error";
    case PMSTEP_STM32G4_ERR_FLASH_OPERR:
        return "flash OPERR: operation error";
    case PMSTEP_STM32G4_ERR_FLASH_RDERR:
        return "flash RDERR: PCROP read error";
    case PMSTEP_STM32G4_ERR_FLASH_OPTVERR:
        return "flash OPTVERR: option bytes invalid";
    case PMSTEP_STM32G4_ERR_FLASH_ECC:
        return "flash uncorrectable ECC error on read";
    case PMSTEP_STM32G4_ERR_STEP_MICROSTEPS:
        return "STEP/DIR microsteps per full step not within 1..256";
    case PMSTEP_STM32G4_ERR_STEP_PULSE:
        return "STEP/DIR minimum pulse shorter than 3 timer clocks";
    case PMSTEP_STM32G4_ERR_STEP_PIN:
        return "STEP not on a TIM4_CH2 pin or DIR not on a TIM4_CH1 pin";
    }
    return "unknown status";
}
