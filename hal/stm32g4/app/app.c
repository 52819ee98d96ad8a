/*
 * The STM32G431 application (see main.c and app.h): the port, the stored configuration, the core
 * and the console, and one turn of the main loop. The control step itself runs in the port's ADC
 * interrupt.
 */
#include "app.h"

#include "pmstep_console.h"
#include "pmstep_hal_stm32g4.h"
#include "stm32g4_regs.h"

#ifndef PMSTEP_VERSION_TEXT
#define PMSTEP_VERSION_TEXT "0.0.0"
#endif

/* STEP/DIR mode (a build with -DPMSTEP_STM32G4_STEPDIR=1, CMake option PMSTEP_STM32G4_STEPDIR): the
 * port's STEP/DIR/EN input and DIAG output enabled; EN starts and releases the drive (follow_enable());
 * in RUN the position loop follows the step count. Its settings (microsteps, DIR's sense, EN's and DIAG's polarities, DIAG's mode, the following-error
 * limit) are the console's stepdir.* values, stored with the configuration. Off by default: the
 * drive is commanded from the console only, and STEP pulses move nothing. */
#ifndef PMSTEP_STM32G4_STEPDIR
#define PMSTEP_STM32G4_STEPDIR 0
#endif
#if PMSTEP_STM32G4_STEPDIR
#include "pmstep/pmstep_stepdir.h"
#endif

static pmstep_t motor;
static pmstep_config_t motor_config;  /* must outlive the instance */
static pmstep_stm32g4_config_t board; /* must outlive the port */
static pmstep_console_t console;
static pmstep_store_t store;                 /* the port's two flash pages (stm32g4_flash.c) */
static pmstep_console_store_t console_store; /* the configuration in force, as the console serves it */
static pmstep_position_t position;           /* sensorless position control on the same instance */
static pmstep_position_output_t position_out;
#if PMSTEP_STM32G4_STEPDIR
static pmstep_stepdir_t stepdir; /* the step count, fed by the control interrupt */
static bool stepdir_was_tracked; /* RUN at the last period: following starts on entering RUN */
static bool en_was_enabled;      /* EN at the last period: its edges start and release the drive */
#endif
static uint32_t uart_errors;
static uint8_t tx[64];
static uint32_t tx_len;
static uint32_t tx_pos;

/* Milliseconds and control periods since start, from the DWT cycle counter the port runs (the
 * main loop polls it far more often than it wraps, every 25 s at 170 MHz). 32-bit arithmetic. */
static struct {
    uint32_t last;
    uint32_t cycles_per_ms;
    uint32_t cycles_per_period;
    uint32_t rem_ms;
    uint32_t rem_period;
    uint32_t ms;
    uint32_t periods;
} clk;

static void clock_update(void)
{
    const uint32_t now = STM32G4_DWT->CYCCNT;
    const uint32_t d = now - clk.last;
    clk.last = now;
    clk.rem_ms += d;
    clk.ms += clk.rem_ms / clk.cycles_per_ms;
    clk.rem_ms %= clk.cycles_per_ms;
    clk.rem_period += d;
    clk.periods += clk.rem_period / clk.cycles_per_period;
    clk.rem_period %= clk.cycles_per_period;
}

#if PMSTEP_STM32G4_STEPDIR
/* The step tracker for the configuration and STEP/DIR settings in force (the console may have changed
 * them since boot), at the counter's present value: nothing counted yet. */
static pmstep_status_t stepdir_start(void)
{
    pmstep_stepdir_config_t sd;
    pmstep_status_t st = pmstep_console_stepdir_config(&motor_config, &console.stepdir, &sd);
    if (st == PMSTEP_OK) {
        st = pmstep_stepdir_init(&stepdir, &sd, motor_config.motor.pole_pairs, motor_config.timing.period_s,
                                 (uint16_t)pmstep_stm32g4_step_counter());
    }
    return st;
}

/* EN as a TMC driver's, between two steps (the core's calls land at this period boundary):
 * - asserted (an edge, or asserted at boot): a configured drive that is IDLE starts - the alignments
 *   (its commissioning), then RUN following the steps; what was counted while disabled is dropped;
 * - released: the port has the bridge off and the core stopped (IDLE) from this period on, as it
 *   gates every period EN reads disabled; a fault latched meanwhile is cleared (the core's, and the
 *   port's once its input is released), so the drive waits in IDLE, DIAG deasserted, for EN again.
 * Edges only: a console STOP, or a fault, with EN held asserted stays so until EN is toggled (or the
 * console starts it). Not while a calibration runs (it drives the core itself). */
static void follow_enable(void)
{
    const bool enabled = pmstep_stm32g4_step_enabled();
    if (enabled && !en_was_enabled) {
        if (console_store.configured && !console.calibrating && pmstep_get_mode(&motor) == PMSTEP_MODE_IDLE
            && pmstep_stm32g4_fault() == PMSTEP_STM32G4_FAULT_NONE) {
            (void)stepdir_start();
            (void)pmstep_start(&motor);
        }
    } else if (!enabled && en_was_enabled && !console.calibrating) {
        if (pmstep_get_mode(&motor) == PMSTEP_MODE_FAULT) {
            (void)pmstep_clear_fault(&motor);
        }
        (void)pmstep_stm32g4_clear_fault();
    }
    en_was_enabled = enabled;
}

/* Once a period, after the step: the count (TIM4 read once), the position loop, EN's edges, then
 * following from the period RUN begins (the reference starts where the motor is: no jump), and DIAG. */
static void after_step(const pmstep_output_t *out)
{
    pmstep_stepdir_count(&stepdir, pmstep_stm32g4_step_counter());
    pmstep_position_update(&position, out, &position_out);
    pmstep_console_home_period(&console, out, &position_out);
    follow_enable();
    if (position_out.tracked && !stepdir_was_tracked && stepdir_start() == PMSTEP_OK) {
        (void)pmstep_position_follow_steps(&position, &stepdir);
    }
    stepdir_was_tracked = position_out.tracked;
    pmstep_stm32g4_set_diag(pmstep_stepdir_diag(&stepdir, out->mode, position_out.position_rad, position_out.tracked));
}

/* The STEP/DIR settings in force onto the port's input (the control interrupt held): EN's and DIAG's
 * polarities at once; the microsteps, DIR's sense, DIAG's mode and limit when following next starts. */
static void stepdir_settings_to_port(void)
{
    const pmstep_stepdir_settings_t *s = &console.stepdir;
    board.step_input.microsteps = s->microsteps;
    if (s->enable_active_high != board.step_input.enable_active_high
        || s->diag_active_high != board.step_input.diag_active_high) {
        pmstep_stm32g4_step_polarity(&board, s->enable_active_high, s->diag_active_high);
        en_was_enabled = pmstep_stm32g4_step_enabled(); /* a new polarity is no edge: EN starts nothing */
    }
}
#else
/* In the control interrupt, after each step: the turn count and, every N-th period, the position
 * loop (pmstep_position.h). */
static void after_step(const pmstep_output_t *out)
{
    pmstep_position_update(&position, out, &position_out);
    pmstep_console_home_period(&console, out, &position_out); /* a HOME under way */
}
#endif

static void snapshot(pmstep_console_snapshot_t *snap)
{
    snap->period = clk.periods - 1u; /* the period that just ended (counted from the timer's start) */
    pmstep_stm32g4_last_period(&snap->out, &snap->meas, &snap->port_fault);
}

int32_t pmstep_app_init(void)
{
    pmstep_status_t st;
    pmstep_stm32g4_status_t port_st;
    pmstep_store_status_t store_st;
    pmstep_config_t defaults;
    uint32_t sysclk_Hz;

    board = pmstep_stm32g4_default_config();
    board.step_input.enabled = PMSTEP_STM32G4_STEPDIR != 0;
    port_st = pmstep_stm32g4_clock_init(&board.clock);
    if (port_st != PMSTEP_STM32G4_OK) {
        return (int32_t)port_st;
    }
    /* The board's own configuration (duties load one period later: one period of delay). Then the
     * newest record of the flash over it, if there is one and it is accepted whole; otherwise the
     * board's, the drive not configured until a record is written or CALIBRATE runs (START refused). */
    defaults =
        pmstep_console_app_config(pmstep_stm32g4_period_s(&board), 1u, pmstep_stm32g4_current_sense_range_A(&board),
                                  pmstep_stm32g4_bus_sense_range_V(&board));
    store_st = pmstep_store_init(&store, pmstep_stm32g4_store_flash(), pmstep_stm32g4_board_id());
    if (store_st != PMSTEP_STORE_OK) {
        return -300 + (int32_t)store_st;
    }
    (void)pmstep_console_store_boot(&console_store, &store, &defaults, &motor_config); /* its cause kept there */
    st = pmstep_init(&motor, &motor_config);
    if (st != PMSTEP_OK) {
        return -100 + (int32_t)st;
    }
    {
        pmstep_position_config_t gains;
        (void)pmstep_position_design(&motor_config, &gains);
        st = pmstep_position_init(&position, &motor, &gains);
        if (st != PMSTEP_OK) {
            return -200 + (int32_t)st;
        }
    }
    pmstep_console_init(&console, "pmstep " PMSTEP_VERSION_TEXT " stm32g431");
    pmstep_console_attach_position(&console, &position);
    pmstep_console_attach_store(&console, &console_store); /* saves at the period boundary, bridge off */
#if PMSTEP_STM32G4_STEPDIR
    /* The stored STEP/DIR settings (or the defaults) onto the input before the port sets it up. */
    board.step_input.microsteps = console.stepdir.microsteps;
    board.step_input.enable_active_high = console.stepdir.enable_active_high;
    board.step_input.diag_active_high = console.stepdir.diag_active_high;
#endif
    port_st = pmstep_stm32g4_init(&board, &motor);
    if (port_st != PMSTEP_STM32G4_OK) {
        return (int32_t)port_st;
    }
#if PMSTEP_STM32G4_STEPDIR
    st = stepdir_start();
    if (st != PMSTEP_OK) {
        return -400 + (int32_t)st;
    }
    stepdir_was_tracked = false;
    en_was_enabled = false; /* EN asserted at boot starts a configured drive */
#endif
    sysclk_Hz = pmstep_stm32g4_sysclk_Hz(&board.clock);
    port_st = pmstep_stm32g4_lpuart_init(&board, sysclk_Hz); /* PCLK1 = SYSCLK */
    if (port_st != PMSTEP_STM32G4_OK) {
        return (int32_t)port_st;
    }
    pmstep_stm32g4_set_after_step(after_step);
    uart_errors = 0u;
    tx_len = 0u;
    tx_pos = 0u;
    clk.cycles_per_period = (uint32_t)((float)sysclk_Hz * pmstep_stm32g4_period_s(&board) + 0.5f); /* 2 ARR */
    clk.cycles_per_ms = sysclk_Hz / 1000u;
    clk.last = STM32G4_DWT->CYCCNT;
    clk.rem_ms = 0u;
    clk.rem_period = 0u;
    clk.ms = 0u;
    clk.periods = 0u;
    pmstep_stm32g4_start();
    return 0;
}

void pmstep_app_poll(void)
{
    uint8_t rx[32];
    const uint32_t n = pmstep_stm32g4_lpuart_read(rx, sizeof rx, &uart_errors);
    pmstep_console_snapshot_t snap;
    clock_update();
    pmstep_console_receive(&console, rx, n, clk.ms);
    if (pmstep_console_pending(&console)
        || (console.decimation != 0u && (int32_t)(clk.periods - 1u - console.next_telemetry) >= 0)) {
        pmstep_stm32g4_hold_control();
        snapshot(&snap);
        if (pmstep_console_pending_command(&console) == PMSTEP_CONSOLE_CLEAR_FAULT) {
            (void)pmstep_stm32g4_clear_fault(); /* the port's latch too (break, driver fault input) */
        }
        pmstep_console_boundary(&console, &motor, &motor_config, &snap);
#if PMSTEP_STM32G4_STEPDIR
        stepdir_settings_to_port();
#endif
        pmstep_stm32g4_release_control();
        pmstep_console_telemetry(&console, &snap);
    }
    if (tx_pos == tx_len) {
        tx_len = pmstep_console_transmit(&console, tx, sizeof tx);
        tx_pos = 0u;
    }
    tx_pos += pmstep_stm32g4_lpuart_write(&tx[tx_pos], tx_len - tx_pos);
}

uint32_t pmstep_app_uart_errors(void)
{
    return uart_errors;
}

int32_t pmstep_app_step_count(void)
{
#if PMSTEP_STM32G4_STEPDIR
    return stepdir.steps;
#else
    return 0;
#endif
}
