/**
 * @file app.h
 * @brief The STM32G431 application: the port, the core and the console (main.c runs it; the
 *        host tests run it against the behavioural model of the peripherals).
 */
#ifndef PMSTEP_STM32G4_APP_H
#define PMSTEP_STM32G4_APP_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Clock to 170 MHz, the stored configuration (the newest record of the flash's two pages,
 * pmstep_console_store_boot(); with none, or one refused, the board's configuration and the drive
 * not configured: START is refused until a record is written or CALIBRATE runs), the core (the
 * port's period, one period of delay), the port (bridge off, motor IDLE), position control
 * (pmstep_position, updated in the control interrupt after each step, its commands on the console),
 * the console on LPUART1 with the stored configuration attached (CONFIG_* requests; saves at a period
 * boundary, bridge off), then TIM1 started.
 * @return 0, or the failing step's status: a pmstep_stm32g4_status_t, -100 + a pmstep_status_t (pmstep_init),
 *         -200 + a pmstep_status_t (pmstep_position_init), or -300 + a pmstep_store_status_t (pmstep_store_init).
 */
int32_t pmstep_app_init(void);

/** One turn of the main loop: receive, apply a waiting command at a period boundary, telemetry,
 *  transmit. Never waits. */
void pmstep_app_poll(void);

/** Receive errors of the console's UART (overrun, framing, noise) since init. */
uint32_t pmstep_app_uart_errors(void);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_STM32G4_APP_H */
