/*
 * STM32G431 firmware image: the paper's controller on the board described by
 * pmstep_stm32g4_default_config() (a NUCLEO-G431RB with a dual full-bridge stage), driven
 * from the console on LPUART1 (the ST-LINK virtual COM port, 115200 8N1; protocol in
 * firmware/console/include/pmstep_console.h, host tool tools/pmstep_console.py).
 *
 * After reset: clock to 170 MHz, TIM1, the ADCs and the gate-driver pins with the bridge
 * off, the console's UART; the motor waits in IDLE for a start command. The control step
 * runs in the ADC interrupt every 50 us; this main loop receives and parses commands,
 * applies each one at a period boundary (the control interrupt held off for the few
 * microseconds it takes, never inside a step), and sends replies and telemetry. The
 * control interrupt has no console code in it. The application itself is app.c.
 */
#include "app.h"

volatile int32_t app_status; /* for a debugger: 0, or the failing step's status */

static void halt(int32_t status)
{
    app_status = status;
    for (;;) {
        __asm volatile("wfi");
    }
}

int main(void)
{
    const int32_t st = pmstep_app_init();
    if (st != 0) {
        halt(st);
    }
    for (;;) {
        pmstep_app_poll();
    }
}
