/*
 * Board pin maps as data: the NUCLEO-G431RB's own pins, the default drive (that board with
 * a dual full-bridge power stage), and the check that a configuration gives each pin one
 * function and keeps off the board's pins. Signals per pin: STM32G431RB pin data (ST's
 * STM32_open_pin_data, LQFP64); alternate-function numbers: datasheet DS12589.
 */
#include <stddef.h>

#include "pmstep_hal_stm32g4.h"

#define PA 0u
#define PB 1u
#define PC 2u
#define PF 5u
#define PG 6u

static const pmstep_stm32g4_pin_use_t nucleo_g431rb_pins[] = {
    {"ST-LINK virtual COM port TX", "LPUART1_TX", 0u, {PA, 2u, 12u}},
    {"ST-LINK virtual COM port RX", "LPUART1_RX", 0u, {PA, 3u, 12u}},
    {"LD2 user LED", "LD2", 0u, {PA, 5u, 0u}},
    {"SWDIO", "SYS_JTMS-SWDIO", 0u, {PA, 13u, 0u}},
    {"SWCLK", "SYS_JTCK-SWCLK", 0u, {PA, 14u, 0u}},
    {"SWO", "SYS_JTDO-SWO", 0u, {PB, 3u, 0u}},
    {"BOOT0", "BOOT0", 0u, {PB, 8u, 0u}},
    {"B1 user button", "B1", 0u, {PC, 13u, 0u}},
    {"LSE crystal", "RCC_OSC32_IN", 0u, {PC, 14u, 0u}},
    {"LSE crystal", "RCC_OSC32_OUT", 0u, {PC, 15u, 0u}},
    {"HSE crystal", "RCC_OSC_IN", 0u, {PF, 0u, 0u}},
    {"HSE crystal", "RCC_OSC_OUT", 0u, {PF, 1u, 0u}},
    {"NRST", "NRST", 0u, {PG, 10u, 0u}},
};

const pmstep_stm32g4_board_t pmstep_stm32g4_board_nucleo_g431rb = {
    "NUCLEO-G431RB", nucleo_g431rb_pins, (uint32_t)(sizeof nucleo_g431rb_pins / sizeof nucleo_g431rb_pins[0])};

pmstep_stm32g4_config_t pmstep_stm32g4_default_config(void)
{
    /* 12-bit ADC, 3.3 V reference: 3.3/4096 V per count. */
    const float volts_per_count = 3.3f / 4096.0f;
    pmstep_stm32g4_config_t c;
    c.clock.pll_m = 4u;  /* 16 MHz / 4 = 4 MHz */
    c.clock.pll_n = 85u; /* x 85 = 340 MHz VCO */
    c.clock.pll_r = 2u;  /* / 2 = 170 MHz */
    c.pwm_frequency_Hz = 20000u;
    c.dead_time_ns = 500u;
    c.duty_min = 0.0f;
    c.duty_max = 1.0f;
    /* The dual full-bridge stage: phase a between legs a+ and a-, phase b between b+ and b-. */
    c.pwm_high[0] = (pmstep_stm32g4_pin_t){PA, 8u, 6u};   /* TIM1_CH1  AF6: a+ */
    c.pwm_high[1] = (pmstep_stm32g4_pin_t){PA, 9u, 6u};   /* TIM1_CH2  AF6: a- */
    c.pwm_high[2] = (pmstep_stm32g4_pin_t){PA, 10u, 6u};  /* TIM1_CH3  AF6: b+ */
    c.pwm_high[3] = (pmstep_stm32g4_pin_t){PA, 11u, 11u}; /* TIM1_CH4  AF11: b- */
    c.pwm_low[0] = (pmstep_stm32g4_pin_t){PA, 7u, 6u};    /* TIM1_CH1N AF6 */
    c.pwm_low[1] = (pmstep_stm32g4_pin_t){PB, 0u, 6u};    /* TIM1_CH2N AF6 */
    c.pwm_low[2] = (pmstep_stm32g4_pin_t){PB, 1u, 6u};    /* TIM1_CH3N AF6 */
    c.pwm_low[3] = (pmstep_stm32g4_pin_t){PC, 5u, 6u};    /* TIM1_CH4N AF6 */
    c.break_input = (pmstep_stm32g4_pin_t){PA, 6u, 6u};   /* TIM1_BKIN AF6 */
    c.break_active_high = false;
    c.break_filter = 4u;
    c.adc1_channel_i_a = 1u; /* PA0 ADC1_IN1 */
    c.adc1_channel_bus = 6u; /* PC0 ADC1_IN6 (PA2/PA3 are the NUCLEO's virtual COM port) */
    c.adc2_channel_i_b = 2u; /* PA1 ADC2_IN2 */
    c.adc_sample_time = 2u;  /* 12.5 ADC clock cycles */
    c.adc_pins[0] = (pmstep_stm32g4_pin_t){PA, 0u, 0u};
    c.adc_pins[1] = (pmstep_stm32g4_pin_t){PC, 0u, 0u};
    c.adc_pins[2] = (pmstep_stm32g4_pin_t){PA, 1u, 0u};
    /* Current sensors: 0.1 V/A around 1.65 V. Bus: 1:20 divider. */
    c.i_a_offset_counts = 2048.0f;
    c.i_a_gain_a_per_count = volts_per_count / 0.1f;
    c.i_b_offset_counts = 2048.0f;
    c.i_b_gain_a_per_count = volts_per_count / 0.1f;
    c.bus_offset_counts = 0.0f;
    c.bus_gain_v_per_count = volts_per_count * 20.0f;
    c.enable_pin = (pmstep_stm32g4_pin_t){PB, 5u, 0u};
    c.enable_active_high = true;
    c.fault_pin = (pmstep_stm32g4_pin_t){PC, 6u, 0u}; /* open-drain nFAULT */
    c.fault_active_high = false;
    c.console_tx = (pmstep_stm32g4_pin_t){PA, 2u, 12u}; /* LPUART1_TX AF12: the ST-LINK VCP */
    c.console_rx = (pmstep_stm32g4_pin_t){PA, 3u, 12u}; /* LPUART1_RX AF12 */
    c.console_baud = 115200u;
    /* STEP/DIR input, off unless the application enables it: TIM4 on PB6/PB7 (AF2, DS12589), EN and
     * DIAG on PC8/PC9, free on the NUCLEO and away from the power stage's pins. Polarities of a
     * TMC2209: EN enables while low, DIAG high when asserted. */
    c.step_input.enabled = false;
    c.step_input.step_pin = (pmstep_stm32g4_pin_t){PB, 7u, 2u}; /* TIM4_CH2 AF2 */
    c.step_input.dir_pin = (pmstep_stm32g4_pin_t){PB, 6u, 2u};  /* TIM4_CH1 AF2 */
    c.step_input.enable_pin = (pmstep_stm32g4_pin_t){PC, 8u, 0u};
    c.step_input.enable_active_high = false;
    c.step_input.diag_pin = (pmstep_stm32g4_pin_t){PC, 9u, 0u};
    c.step_input.diag_active_high = true;
    c.step_input.microsteps = 16u;
    c.step_input.step_min_pulse_ns = PMSTEP_STM32G4_STEP_MIN_PULSE_NS;
    c.board = &pmstep_stm32g4_board_nucleo_g431rb;
    return c;
}

uint32_t pmstep_stm32g4_pin_map(const pmstep_stm32g4_config_t *cfg, pmstep_stm32g4_pin_use_t *out, uint32_t max)
{
    static const char *const high_fn[4] = {"phase a+ high side", "phase a- high side", "phase b+ high side",
                                           "phase b- high side"};
    static const char *const low_fn[4] = {"phase a+ low side", "phase a- low side", "phase b+ low side",
                                          "phase b- low side"};
    static const char *const high_sig[4] = {"TIM1_CH1", "TIM1_CH2", "TIM1_CH3", "TIM1_CH4"};
    static const char *const low_sig[4] = {"TIM1_CH1N", "TIM1_CH2N", "TIM1_CH3N", "TIM1_CH4N"};
    pmstep_stm32g4_pin_use_t all[PMSTEP_STM32G4_PIN_USES_MAX];
    uint32_t n = 0u;
    uint32_t k;
    if (cfg == NULL) {
        return 0u;
    }
    for (k = 0; k < 4u; ++k) {
        all[n++] = (pmstep_stm32g4_pin_use_t){high_fn[k], high_sig[k], 0u, cfg->pwm_high[k]};
        all[n++] = (pmstep_stm32g4_pin_use_t){low_fn[k], low_sig[k], 0u, cfg->pwm_low[k]};
    }
    all[n++] = (pmstep_stm32g4_pin_use_t){"break input (overcurrent comparator)", "TIM1_BKIN", 0u, cfg->break_input};
    all[n++] = (pmstep_stm32g4_pin_use_t){"phase a current sensor", "ADC1_IN", cfg->adc1_channel_i_a, cfg->adc_pins[0]};
    all[n++] = (pmstep_stm32g4_pin_use_t){"bus voltage divider", "ADC1_IN", cfg->adc1_channel_bus, cfg->adc_pins[1]};
    all[n++] = (pmstep_stm32g4_pin_use_t){"phase b current sensor", "ADC2_IN", cfg->adc2_channel_i_b, cfg->adc_pins[2]};
    all[n++] = (pmstep_stm32g4_pin_use_t){"gate driver enable", "GPIO output", 0u, cfg->enable_pin};
    all[n++] = (pmstep_stm32g4_pin_use_t){"gate driver fault", "GPIO input", 0u, cfg->fault_pin};
    all[n++] = (pmstep_stm32g4_pin_use_t){"console TX", "LPUART1_TX", 0u, cfg->console_tx};
    all[n++] = (pmstep_stm32g4_pin_use_t){"console RX", "LPUART1_RX", 0u, cfg->console_rx};
    if (cfg->step_input.enabled) {
        all[n++] = (pmstep_stm32g4_pin_use_t){"STEP input", "TIM4_CH2", 0u, cfg->step_input.step_pin};
        all[n++] = (pmstep_stm32g4_pin_use_t){"DIR input", "TIM4_CH1", 0u, cfg->step_input.dir_pin};
        all[n++] = (pmstep_stm32g4_pin_use_t){"EN input (bridge gate)", "GPIO input", 0u, cfg->step_input.enable_pin};
        all[n++] = (pmstep_stm32g4_pin_use_t){"DIAG output", "GPIO open drain", 0u, cfg->step_input.diag_pin};
    }
    for (k = 0; k < n && k < max && out != NULL; ++k) {
        out[k] = all[k];
    }
    return n;
}

static bool same_pin(const pmstep_stm32g4_pin_t *a, const pmstep_stm32g4_pin_t *b)
{
    return a->port == b->port && a->pin == b->pin;
}

static bool same_text(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        ++a;
        ++b;
    }
    return *a == *b;
}

pmstep_stm32g4_status_t pmstep_stm32g4_check_pins(const pmstep_stm32g4_config_t *cfg)
{
    pmstep_stm32g4_pin_use_t map[PMSTEP_STM32G4_PIN_USES_MAX];
    uint32_t n;
    uint32_t i;
    uint32_t j;
    if (cfg == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    n = pmstep_stm32g4_pin_map(cfg, map, PMSTEP_STM32G4_PIN_USES_MAX);
    for (i = 0; i < n; ++i) {
        if (map[i].pin.port >= 7u || map[i].pin.pin >= 16u || map[i].pin.af >= 16u) {
            return PMSTEP_STM32G4_ERR_PIN;
        }
    }
    for (i = 0; i < n; ++i) {
        for (j = i + 1u; j < n; ++j) {
            if (same_pin(&map[i].pin, &map[j].pin)) {
                return PMSTEP_STM32G4_ERR_PIN_CONFLICT;
            }
        }
    }
    if (cfg->board != NULL) {
        for (i = 0; i < n; ++i) {
            for (j = 0; j < cfg->board->reserved_count; ++j) {
                const pmstep_stm32g4_pin_use_t *r = &cfg->board->reserved[j];
                if (same_pin(&map[i].pin, &r->pin) && !same_text(map[i].signal, r->signal)) {
                    return PMSTEP_STM32G4_ERR_PIN_RESERVED;
                }
            }
        }
    }
    return PMSTEP_STM32G4_OK;
}
