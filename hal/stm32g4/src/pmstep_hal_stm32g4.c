/*
 * The HAL contract on the STM32G431: the ADC interrupt reads the injected samples,
 * runs pmstep_step() and writes the duties; the bridge goes off (TIM1 MOE = 0,
 * driver enable inactive, duties 50 %) when the core says so, when the gate
 * driver's fault input is asserted, or on a TIM1 break. A port fault also stops the
 * core (pmstep_stop), so it re-aligns after a restart instead of integrating
 * voltages that were never applied.
 */
#include <stddef.h>

#include "pmstep_hal_stm32g4.h"
#include "stm32g4_regs.h"

static struct {
    const pmstep_stm32g4_config_t *cfg;
    pmstep_t *inst;
    uint32_t arr;
    float bus_voltage_V; /* this period's sample, for the duties */
    pmstep_output_t out;
    volatile pmstep_stm32g4_fault_t fault;
    volatile bool step_disabled; /* the STEP/DIR input's EN read disabled at this period's start */
    volatile bool bridge_on;
    volatile uint32_t isr_cycles_max;
    pmstep_stm32g4_after_step_t after_step;
} port;

static bool fault_input_asserted(void)
{
    const pmstep_stm32g4_config_t *cfg = port.cfg;
    const bool high = (STM32G4_GPIO(cfg->fault_pin.port)->IDR & STM32G4_BIT(cfg->fault_pin.pin)) != 0u;
    return high == cfg->fault_active_high;
}

/* EN of the STEP/DIR input (true when the input is not enabled: nothing gates the bridge). */
static bool step_enable_asserted(void)
{
    const pmstep_stm32g4_step_input_t *in = &port.cfg->step_input;
    bool high;
    if (!in->enabled) {
        return true;
    }
    high = (STM32G4_GPIO(in->enable_pin.port)->IDR & STM32G4_BIT(in->enable_pin.pin)) != 0u;
    return high == in->enable_active_high;
}

static void enable_pin(bool on)
{
    const pmstep_stm32g4_config_t *cfg = port.cfg;
    const bool level = on == cfg->enable_active_high;
    STM32G4_GPIO(cfg->enable_pin.port)->BSRR =
        level ? STM32G4_BIT(cfg->enable_pin.pin) : STM32G4_BIT(16u + cfg->enable_pin.pin);
}

static void bridge_off(void)
{
    stm32g4_tim_t *const tim = STM32G4_TIM1;
    tim->BDTR &= ~TIM_BDTR_MOE; /* outputs to their idle (off) levels at once */
    enable_pin(false);
    tim->CCR1 = port.arr / 2u;
    tim->CCR2 = port.arr / 2u;
    tim->CCR3 = port.arr / 2u;
    tim->CCR4 = port.arr / 2u;
    port.bridge_on = false;
}

static void bridge_on(void)
{
    enable_pin(true);
    STM32G4_TIM1->BDTR |= TIM_BDTR_MOE;
    port.bridge_on = true;
}

static void latch_fault(pmstep_stm32g4_fault_t fault)
{
    if (port.fault == PMSTEP_STM32G4_FAULT_NONE) {
        port.fault = fault;
    }
    bridge_off();
}

void pmstep_hal_read_measurements(pmstep_meas_t *meas)
{
    const pmstep_stm32g4_config_t *cfg = port.cfg;
    meas->i_a_A = pmstep_stm32g4_counts_to_si(STM32G4_ADC1->JDR[0], cfg->i_a_offset_counts, cfg->i_a_gain_a_per_count);
    meas->bus_voltage_V =
        pmstep_stm32g4_counts_to_si(STM32G4_ADC1->JDR[1], cfg->bus_offset_counts, cfg->bus_gain_v_per_count);
    meas->i_b_A = pmstep_stm32g4_counts_to_si(STM32G4_ADC2->JDR[0], cfg->i_b_offset_counts, cfg->i_b_gain_a_per_count);
    meas->load_torque_Nm = 0.0f;    /* no torque sensor on this board (known_load_mode refused at init) */
    meas->phase_voltage_a_V = 0.0f; /* no phase-voltage sensing (refused at init) */
    meas->phase_voltage_b_V = 0.0f;
    port.bus_voltage_V = meas->bus_voltage_V;
    port.step_disabled = !step_enable_asserted();
    if (fault_input_asserted()) {
        latch_fault(PMSTEP_STM32G4_FAULT_INPUT);
    }
}

void pmstep_hal_apply_output(const pmstep_output_t *out)
{
    const pmstep_stm32g4_config_t *cfg = port.cfg;
    stm32g4_tim_t *const tim = STM32G4_TIM1;
    float d_plus;
    float d_minus;
    if (port.fault != PMSTEP_STM32G4_FAULT_NONE || port.step_disabled || !out->bridge_enable) {
        bridge_off(); /* the one way off, for EN too: never one bridge on and one off */
        return;
    }
    /* Preloaded: these take effect at the next update event (the next carrier peak). */
    pmstep_stm32g4_duties(out->u_a_V, port.bus_voltage_V, cfg->duty_min, cfg->duty_max, &d_plus, &d_minus);
    tim->CCR1 = pmstep_stm32g4_duty_to_ccr(d_plus, port.arr);
    tim->CCR2 = pmstep_stm32g4_duty_to_ccr(d_minus, port.arr);
    pmstep_stm32g4_duties(out->u_b_V, port.bus_voltage_V, cfg->duty_min, cfg->duty_max, &d_plus, &d_minus);
    tim->CCR3 = pmstep_stm32g4_duty_to_ccr(d_plus, port.arr);
    tim->CCR4 = pmstep_stm32g4_duty_to_ccr(d_minus, port.arr);
    if (!port.bridge_on) {
        bridge_on();
    }
}

/* The core stops (IDLE) after a port fault or while EN holds the bridge off, unless it is already off. */
static void stop_core_on_port_fault(void)
{
    if ((port.fault != PMSTEP_STM32G4_FAULT_NONE || port.step_disabled) && port.out.mode != PMSTEP_MODE_IDLE
        && port.out.mode != PMSTEP_MODE_FAULT) {
        (void)pmstep_stop(port.inst);
        port.out.mode = PMSTEP_MODE_IDLE;
    }
}

void ADC1_2_IRQHandler(void)
{
    const uint32_t start = STM32G4_DWT->CYCCNT;
    uint32_t cycles;
    STM32G4_ADC1->ISR = ADC_ISR_JEOC | ADC_ISR_JEOS; /* write 1 to clear */
    if (port.inst == NULL) {
        return;
    }
    pmstep_hal_control_period(port.inst, &port.out);
    stop_core_on_port_fault();
    if (port.after_step != NULL) {
        port.after_step(&port.out);
    }
    cycles = STM32G4_DWT->CYCCNT - start;
    if (cycles > port.isr_cycles_max) {
        port.isr_cycles_max = cycles;
    }
}

void TIM1_BRK_TIM15_IRQHandler(void)
{
    stm32g4_tim_t *const tim = STM32G4_TIM1;
    if ((tim->SR & TIM_SR_BIF) != 0u) {
        tim->SR = ~TIM_SR_BIF;      /* write 0 to clear */
        tim->DIER &= ~TIM_DIER_BIE; /* the flag comes back while the input stays active */
        latch_fault(PMSTEP_STM32G4_FAULT_BREAK);
        if (port.inst != NULL) {
            stop_core_on_port_fault();
        }
    }
}

pmstep_stm32g4_fault_t pmstep_stm32g4_fault(void)
{
    return port.fault;
}

bool pmstep_stm32g4_clear_fault(void)
{
    stm32g4_tim_t *const tim = STM32G4_TIM1;
    if (port.cfg == NULL || fault_input_asserted()) {
        return false;
    }
    tim->SR = ~TIM_SR_BIF;
    if ((tim->SR & TIM_SR_BIF) != 0u) { /* break input still active */
        return false;
    }
    port.fault = PMSTEP_STM32G4_FAULT_NONE;
    tim->DIER |= TIM_DIER_BIE;
    return true;
}

bool pmstep_stm32g4_bridge_on(void)
{
    return port.bridge_on;
}

uint32_t pmstep_stm32g4_step_counter(void)
{
    if (port.cfg == NULL || !port.cfg->step_input.enabled) {
        return 0u;
    }
    return STM32G4_TIM4->CNT & 0xFFFFu;
}

bool pmstep_stm32g4_step_enabled(void)
{
    return port.cfg == NULL || step_enable_asserted();
}

void pmstep_stm32g4_set_diag(bool asserted)
{
    const pmstep_stm32g4_step_input_t *in;
    if (port.cfg == NULL || !port.cfg->step_input.enabled) {
        return;
    }
    in = &port.cfg->step_input;
    /* Open drain: a 1 in ODR releases the line (the pull-up takes it high), a 0 pulls it low. */
    STM32G4_GPIO(in->diag_pin.port)->BSRR =
        asserted == in->diag_active_high ? STM32G4_BIT(in->diag_pin.pin) : STM32G4_BIT(16u + in->diag_pin.pin);
}

uint32_t pmstep_stm32g4_isr_cycles_max(void)
{
    return port.isr_cycles_max;
}

float pmstep_stm32g4_period_s(const pmstep_stm32g4_config_t *cfg)
{
    uint32_t sysclk_Hz;
    uint32_t arr;
    if (cfg == NULL) {
        return 0.0f;
    }
    sysclk_Hz = pmstep_stm32g4_sysclk_Hz(&cfg->clock);
    arr = pmstep_stm32g4_pwm_arr(sysclk_Hz, cfg->pwm_frequency_Hz);
    return arr == 0u ? 0.0f : (float)(2u * arr) / (float)sysclk_Hz;
}

#define ADC_LAST_CODE 4095.0f /* 12 bits */

static float abs_f(float x)
{
    return x < 0.0f ? -x : x;
}

/* The magnitude a bipolar channel reads before either end code. */
static float bipolar_range(float offset_counts, float gain_per_count)
{
    const float below = offset_counts;
    const float above = ADC_LAST_CODE - offset_counts;
    return (below < above ? below : above) * abs_f(gain_per_count);
}

float pmstep_stm32g4_current_sense_range_A(const pmstep_stm32g4_config_t *cfg)
{
    const float a_A = bipolar_range(cfg->i_a_offset_counts, cfg->i_a_gain_a_per_count);
    const float b_A = bipolar_range(cfg->i_b_offset_counts, cfg->i_b_gain_a_per_count);
    return a_A < b_A ? a_A : b_A;
}

float pmstep_stm32g4_bus_sense_range_V(const pmstep_stm32g4_config_t *cfg)
{
    return (ADC_LAST_CODE - cfg->bus_offset_counts) * abs_f(cfg->bus_gain_v_per_count);
}

static void nvic_enable(uint32_t irq, uint8_t priority)
{
    stm32g4_nvic_t *const nvic = STM32G4_NVIC;
    nvic->IPR[irq] = priority;
    /* Write-one-to-set; the read-modify-write keeps the fake register block of the host tests
     * (plain RAM) showing every enabled line, and changes nothing on the hardware. */
    nvic->ISER[irq / 32u] |= STM32G4_BIT(irq % 32u);
}

pmstep_stm32g4_status_t pmstep_stm32g4_init(const pmstep_stm32g4_config_t *cfg, pmstep_t *inst)
{
    uint32_t sysclk_Hz;
    pmstep_stm32g4_status_t st;
    if (cfg == NULL || inst == NULL || inst->cfg == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    if (inst->cfg->inverter.phase_voltage_sensing || inst->cfg->known_load_mode) {
        return PMSTEP_STM32G4_ERR_UNMEASURED_INPUT;
    }
    if (inst->cfg->limits.current_sense_range_A > pmstep_stm32g4_current_sense_range_A(cfg)
        || inst->cfg->limits.bus_sense_range_V > pmstep_stm32g4_bus_sense_range_V(cfg)) {
        return PMSTEP_STM32G4_ERR_SENSE_RANGE;
    }
    sysclk_Hz = pmstep_stm32g4_sysclk_Hz(&cfg->clock);
    if (sysclk_Hz == 0u) {
        return PMSTEP_STM32G4_ERR_CLOCK_CONFIG;
    }
    port.cfg = cfg;
    port.inst = NULL; /* no control period until everything is set up */
    port.fault = PMSTEP_STM32G4_FAULT_NONE;
    port.step_disabled = cfg->step_input.enabled; /* off until the first period reads EN */
    port.bridge_on = false;
    port.isr_cycles_max = 0u;
    port.arr = pmstep_stm32g4_pwm_arr(sysclk_Hz, cfg->pwm_frequency_Hz);

    st = pmstep_stm32g4_check_pins(cfg); /* one function per pin, the board's own pins kept */
    if (st == PMSTEP_STM32G4_OK) {
        st = pmstep_stm32g4_gpio_init(cfg);
    }
    if (st == PMSTEP_STM32G4_OK) {
        st = pmstep_stm32g4_pwm_init(cfg, sysclk_Hz); /* TIM1 runs at PCLK2 = SYSCLK */
    }
    if (st == PMSTEP_STM32G4_OK) {
        st = pmstep_stm32g4_step_input_init(cfg, sysclk_Hz); /* TIM4 runs at PCLK1 = SYSCLK */
    }
    if (st == PMSTEP_STM32G4_OK) {
        st = pmstep_stm32g4_adc_init(cfg);
    }
    if (st != PMSTEP_STM32G4_OK) {
        return st;
    }
    /* Cycle counter for the interrupt's duration (ARMv7-M DWT). */
    STM32G4_DEMCR |= DEMCR_TRCENA;
    STM32G4_DWT->CYCCNT = 0u;
    STM32G4_DWT->CTRL |= DWT_CTRL_CYCCNTENA;
    bridge_off();
    port.inst = inst;
    /* Break above control (lower number = higher priority; 4 priority bits, RM0440 §14.1). */
    nvic_enable(STM32G4_IRQ_TIM1_BRK_TIM15, 0x00u);
    nvic_enable(STM32G4_IRQ_ADC1_2, 0x10u);
    return PMSTEP_STM32G4_OK;
}

void pmstep_stm32g4_set_after_step(pmstep_stm32g4_after_step_t hook)
{
    port.after_step = hook;
}

void pmstep_stm32g4_start(void)
{
    STM32G4_TIM1->CR1 |= TIM_CR1_CEN;
}

void pmstep_stm32g4_hold_control(void)
{
    STM32G4_NVIC->ICER[STM32G4_IRQ_ADC1_2 / 32u] = STM32G4_BIT(STM32G4_IRQ_ADC1_2 % 32u);
#if !defined(STM32G4_FAKE_REGISTERS)
    __asm volatile("dsb\n\tisb" ::: "memory"); /* no control interrupt after this point */
#endif
}

void pmstep_stm32g4_release_control(void)
{
    /* Write-one-to-set; the read-modify-write keeps a fake register block (plain RAM) showing
     * every enabled line, as nvic_enable() does, and changes nothing on the hardware. */
    STM32G4_NVIC->ISER[STM32G4_IRQ_ADC1_2 / 32u] |= STM32G4_BIT(STM32G4_IRQ_ADC1_2 % 32u);
}

void pmstep_stm32g4_last_period(pmstep_output_t *out, pmstep_meas_t *meas, uint8_t *port_fault)
{
    const pmstep_stm32g4_config_t *cfg = port.cfg;
    *out = port.out;
    *port_fault = (uint8_t)port.fault;
    if (cfg == NULL) {
        const pmstep_meas_t zero = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
        *meas = zero;
        return;
    }
    /* The injected data registers hold the last period's samples until the next trigger. */
    meas->i_a_A = pmstep_stm32g4_counts_to_si(STM32G4_ADC1->JDR[0], cfg->i_a_offset_counts, cfg->i_a_gain_a_per_count);
    meas->bus_voltage_V =
        pmstep_stm32g4_counts_to_si(STM32G4_ADC1->JDR[1], cfg->bus_offset_counts, cfg->bus_gain_v_per_count);
    meas->i_b_A = pmstep_stm32g4_counts_to_si(STM32G4_ADC2->JDR[0], cfg->i_b_offset_counts, cfg->i_b_gain_a_per_count);
    meas->load_torque_Nm = 0.0f;
    meas->phase_voltage_a_V = 0.0f;
    meas->phase_voltage_b_V = 0.0f;
}
