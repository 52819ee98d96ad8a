/*
 * STM32G431 firmware image: the paper's controller on the board described by
 * pmstep_stm32g4_default_config(). After reset it sets the clock to 170 MHz, brings
 * up TIM1, the ADCs and the gate driver pins with the bridge off, starts the
 * strategy (s-alignment, c-alignment, then the adaptive controller with a 10 rad/s
 * set-point) and sleeps; everything else happens in the ADC interrupt, every
 * 50 us. A real application replaces the fixed start and set-point by its commands.
 */
#include "pmstep_hal_stm32g4.h"

static pmstep_t motor;
static pmstep_config_t motor_config;       /* must outlive the instance */
static pmstep_stm32g4_config_t board;      /* must outlive the port */
volatile int32_t app_status;               /* for a debugger: 0, or the failing step's status */

static void halt(int32_t status)
{
    app_status = status;
    for (;;) {
        __asm volatile("wfi");
    }
}

int main(void)
{
    pmstep_status_t st;
    pmstep_stm32g4_status_t port_st;

    board = pmstep_stm32g4_default_config();
    port_st = pmstep_stm32g4_clock_init(&board.clock);
    if (port_st != PMSTEP_STM32G4_OK) {
        halt((int32_t)port_st);
    }
    motor_config = pmstep_paper_config();
    motor_config.timing.period_s = pmstep_stm32g4_period_s(&board); /* 50 us at 20 kHz */
    motor_config.timing.computational_delay_periods = 1u;          /* duties load at the next carrier peak */
    st = pmstep_init(&motor, &motor_config);
    if (st != PMSTEP_OK) {
        halt(-100 + (int32_t)st);
    }
    port_st = pmstep_stm32g4_init(&board, &motor);
    if (port_st != PMSTEP_STM32G4_OK) {
        halt((int32_t)port_st);
    }
    (void)pmstep_set_speed_target(&motor, 10.0f, 50.0f);
    (void)pmstep_start(&motor);
    pmstep_stm32g4_start();
    for (;;) {
        __asm volatile("wfi");
    }
}
