/*
 * GPIO of the STM32G431 port (RM0440 §9.4): the pins' modes, pulls, output types and alternate
 * functions, and the bridge's pins at start-up (stm32g4_gpio.h for the other drivers' pins).
 */
#include "stm32g4_gpio.h"

#include <stddef.h>

#include "stm32g4_regs.h"

bool stm32g4_pin_valid(const pmstep_stm32g4_pin_t *p)
{
    return p->port < STM32G4_GPIO_PORTS && p->pin < 16u && p->af < 16u;
}

void stm32g4_port_clock_on(uint8_t port)
{
    STM32G4_RCC->AHB2ENR |= STM32G4_BIT(RCC_AHB2ENR_GPIOAEN_POS + port);
    (void)STM32G4_RCC->AHB2ENR; /* the enable takes effect before the port is written */
}

void stm32g4_pin_configure_type(const pmstep_stm32g4_pin_t *p, uint32_t mode, uint32_t pull, bool open_drain)
{
    stm32g4_gpio_t *gpio;
    const uint32_t shift2 = 2u * p->pin;
    stm32g4_port_clock_on(p->port);
    gpio = STM32G4_GPIO(p->port);
    if (mode == GPIO_MODE_AF) {
        const uint32_t shift4 = 4u * (p->pin % 8u);
        gpio->AFR[p->pin / 8u] = (gpio->AFR[p->pin / 8u] & ~(0xFu << shift4)) | ((uint32_t)p->af << shift4);
        gpio->OSPEEDR = (gpio->OSPEEDR & ~(3u << shift2)) | (GPIO_SPEED_VERY_HIGH << shift2);
    }
    if (open_drain) {
        gpio->OTYPER |= STM32G4_BIT(p->pin);
    } else {
        gpio->OTYPER &= ~STM32G4_BIT(p->pin);
    }
    gpio->PUPDR = (gpio->PUPDR & ~(3u << shift2)) | (pull << shift2);
    gpio->MODER = (gpio->MODER & ~(3u << shift2)) | (mode << shift2);
}

void stm32g4_pin_configure(const pmstep_stm32g4_pin_t *p, uint32_t mode, uint32_t pull)
{
    stm32g4_pin_configure_type(p, mode, pull, false);
}

/* Drives the enable pin to its inactive level (driver off). */
static void enable_pin_off(const pmstep_stm32g4_config_t *cfg)
{
    stm32g4_gpio_t *const gpio = STM32G4_GPIO(cfg->enable_pin.port);
    gpio->BSRR = cfg->enable_active_high ? STM32G4_BIT(16u + cfg->enable_pin.pin) : STM32G4_BIT(cfg->enable_pin.pin);
}

pmstep_stm32g4_status_t pmstep_stm32g4_gpio_init(const pmstep_stm32g4_config_t *cfg)
{
    unsigned k;
    if (cfg == NULL) {
        return PMSTEP_STM32G4_ERR_NULL_ARGUMENT;
    }
    for (k = 0; k < 4u; ++k) {
        if (!stm32g4_pin_valid(&cfg->pwm_high[k]) || !stm32g4_pin_valid(&cfg->pwm_low[k])) {
            return PMSTEP_STM32G4_ERR_PIN;
        }
    }
    for (k = 0; k < 3u; ++k) {
        if (!stm32g4_pin_valid(&cfg->adc_pins[k])) {
            return PMSTEP_STM32G4_ERR_PIN;
        }
    }
    if (!stm32g4_pin_valid(&cfg->break_input) || !stm32g4_pin_valid(&cfg->enable_pin)
        || !stm32g4_pin_valid(&cfg->fault_pin)) {
        return PMSTEP_STM32G4_ERR_PIN;
    }
    /* Enable output first, at its off level, so the driver never sees a floating enable: the
     * port's clock on, the off level in ODR, then the pin made an output. */
    stm32g4_port_clock_on(cfg->enable_pin.port);
    enable_pin_off(cfg);
    stm32g4_pin_configure(&cfg->enable_pin, GPIO_MODE_OUTPUT, 0u);
    stm32g4_pin_configure(&cfg->fault_pin, GPIO_MODE_INPUT, cfg->fault_active_high ? GPIO_PULL_DOWN : GPIO_PULL_UP);
    for (k = 0; k < 4u; ++k) {
        stm32g4_pin_configure(&cfg->pwm_high[k], GPIO_MODE_AF, GPIO_PULL_DOWN);
        stm32g4_pin_configure(&cfg->pwm_low[k], GPIO_MODE_AF, GPIO_PULL_DOWN);
    }
    stm32g4_pin_configure(&cfg->break_input, GPIO_MODE_AF, cfg->break_active_high ? GPIO_PULL_DOWN : GPIO_PULL_UP);
    for (k = 0; k < 3u; ++k) {
        stm32g4_pin_configure(&cfg->adc_pins[k], GPIO_MODE_ANALOG, 0u);
    }
    return PMSTEP_STM32G4_OK;
}
