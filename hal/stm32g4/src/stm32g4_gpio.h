/*
 * The pins of the STM32G431 port's drivers (stm32g4_gpio.c, RM0440 §9.4), for the drivers that set
 * up their own (stm32g4_drivers.c: the STEP/DIR input, LPUART1).
 */
#ifndef STM32G4_GPIO_H
#define STM32G4_GPIO_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep_hal_stm32g4.h"

/** Whether @p p names a pin of the device (port A-G, pin 0-15, alternate function 0-15). */
bool stm32g4_pin_valid(const pmstep_stm32g4_pin_t *p);

/** A GPIO port's clock on: its registers take no write before (RM0440 §7.4.15). */
void stm32g4_port_clock_on(uint8_t port);

/** The pin's mode (MODER last, so it takes its function with the rest already set), pull, output
 *  type (§9.4.2 OTYPER: push-pull, or open drain) and alternate function; its port's clock on. */
void stm32g4_pin_configure_type(const pmstep_stm32g4_pin_t *p, uint32_t mode, uint32_t pull, bool open_drain);

/** stm32g4_pin_configure_type() with a push-pull output type. */
void stm32g4_pin_configure(const pmstep_stm32g4_pin_t *p, uint32_t mode, uint32_t pull);

#endif /* STM32G4_GPIO_H */
