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
 * boundary, bridge off), then TIM1 started. Built with PMSTEP_STM32G4_STEPDIR=1 (STEP/DIR mode): the
 * port's STEP/DIR/EN input and DIAG output too (EN gates the bridge), the step count read every
 * period, and from each entry into RUN the position loop following it (pmstep_position_follow_steps();
 * a console move, hold or speed command ends that until the next START); DIAG from
 * pmstep_stepdir_diag().
 * @return 0, or the failing step's status: a pmstep_stm32g4_status_t, -100 + a pmstep_status_t (pmstep_init),
 *         -200 + a pmstep_status_t (pmstep_position_init), -300 + a pmstep_store_status_t (pmstep_store_init),
 *         or -400 + a pmstep_status_t (the STEP/DIR tracker: pmstep_stepdir_design(), _init()).
 */
int32_t pmstep_app_init(void);

/** One turn of the main loop: receive, apply a waiting command at a period boundary, telemetry,
 *  transmit. Never waits. */
void pmstep_app_poll(void);

/** Receive errors of the console's UART (overrun, framing, noise) since init. */
uint32_t pmstep_app_uart_errors(void);

/** Microsteps counted on the STEP/DIR input since the tracker's last start (0 without STEP/DIR mode). */
int32_t pmstep_app_step_count(void);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_STM32G4_APP_H */
