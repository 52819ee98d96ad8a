/**
 * @file pmstep_hal_stm32g4.h
 * @brief STM32G431 port of the HAL contract (pmstep_hal.h): Cortex-M4F at 170 MHz,
 *        TIM1 centre-aligned PWM on two H-bridges (one channel per half-bridge,
 *        complementary outputs with dead time, break input), ADC1/ADC2 injected
 *        conversions triggered by TIM1 at the carrier peak, the ADC interrupt
 *        running read -> pmstep_step() -> apply, a bridge-enable output and a
 *        fault input. Register-level, no vendor library (see stm32g4_regs.h).
 *
 * Phase a is the H-bridge between half-bridges a+ (TIM1_CH1/CH1N) and a- (CH2/CH2N),
 * phase b the one between b+ (CH3/CH3N) and b- (CH4/CH4N):
 *     u_a = (d_a+ - d_a-) V_bus,   u_b = (d_b+ - d_b-) V_bus,
 * with the duty d of a half-bridge the fraction of the period its high side is on.
 *
 * Timing: TIM1 counts up and down (centre-aligned mode 1), so the carrier period is
 * 2 ARR / f_TIM1. Channel 5 (internal) makes TRGO2 rise at the counter peak (one timer
 * tick before it, at CNT = ARR - 1), the
 * centre of the interval where every low side conducts; ADC1 (i_a, then the bus)
 * and ADC2 (i_b) convert on that edge; ADC1's end of injected sequence interrupts.
 * The interrupt writes the duties into preloaded compare registers that take
 * effect at the next update event, one period after the samples: configure the
 * core with computational_delay_periods = 1.
 */
#ifndef PMSTEP_HAL_STM32G4_H
#define PMSTEP_HAL_STM32G4_H

#include <stdbool.h>
#include <stdint.h>

#include "pmstep_hal.h"
#include "pmstep_store.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Status of the port's set-up calls and of the stored configuration's flash (pmstep_stm32g4_store_flash(),
 *  -15 .. -28; the FLASH_SR flags named as in RM0440 §3.7.5): 0 = ok, negative = one named cause. */
typedef enum {
    PMSTEP_STM32G4_OK = 0,
    PMSTEP_STM32G4_ERR_NULL_ARGUMENT = -1,
    PMSTEP_STM32G4_ERR_CLOCK_CONFIG = -2,   /**< PLL factors out of range, or SYSCLK above 170 MHz */
    PMSTEP_STM32G4_ERR_CLOCK_TIMEOUT = -3,  /**< PLL lock, regulator or clock switch did not complete */
    PMSTEP_STM32G4_ERR_PWM_FREQUENCY = -4,  /**< the carrier frequency gives ARR outside 2..65535 */
    PMSTEP_STM32G4_ERR_DEAD_TIME = -5,      /**< dead time longer than TIM1 can insert */
    PMSTEP_STM32G4_ERR_DUTY_RANGE = -6,     /**< duty_min/duty_max not 0 <= min < max <= 1 */
    PMSTEP_STM32G4_ERR_ADC_CONFIG = -7,     /**< channel or sample-time code out of range */
    PMSTEP_STM32G4_ERR_ADC_TIMEOUT = -8,    /**< ADC calibration or enable did not complete */
    PMSTEP_STM32G4_ERR_PIN = -9,            /**< a pin's port, number or alternate function out of range */
    PMSTEP_STM32G4_ERR_PIN_CONFLICT = -10,  /**< two functions on one pin */
    PMSTEP_STM32G4_ERR_PIN_RESERVED = -11,  /**< a pin the board itself uses (VCP, SWD, crystal..) given another function */
    PMSTEP_STM32G4_ERR_UART_CONFIG = -12,   /**< console baud rate outside what LPUART1 can make from its clock */
    PMSTEP_STM32G4_ERR_UNMEASURED_INPUT = -13, /**< the core's configuration reads an input this board does not
                                                   measure: phase voltages (inverter.phase_voltage_sensing) or
                                                   the load torque (known_load_mode) */
    PMSTEP_STM32G4_ERR_SENSE_RANGE = -14,   /**< the core's configuration claims a measurement range (limits.
                                                 current_sense_range_A, bus_sense_range_V) beyond what this board's
                                                 ADC reads (pmstep_stm32g4_current_sense_range_A(), _bus_) */
    PMSTEP_STM32G4_ERR_FLASH_RANGE = -15,   /**< a slot other than 0 or 1, bytes beyond the slot, or a program not
                                                 in whole double words (8-byte offset and length) */
    PMSTEP_STM32G4_ERR_FLASH_LOCKED = -16,  /**< FLASH_CR still locked after the key sequence (a wrong key written
                                                 earlier locks it until the next reset) */
    PMSTEP_STM32G4_ERR_FLASH_TIMEOUT = -17, /**< FLASH_SR.BSY did not clear */
    PMSTEP_STM32G4_ERR_FLASH_PROGERR = -18, /**< programming a double word that was not erased */
    PMSTEP_STM32G4_ERR_FLASH_WRPERR = -19,  /**< the page is write-protected (option bytes WRP, PCROP) */
    PMSTEP_STM32G4_ERR_FLASH_PGAERR = -20,  /**< program alignment: the two words not in one double word */
    PMSTEP_STM32G4_ERR_FLASH_SIZERR = -21,  /**< a program write that was not a 32-bit word */
    PMSTEP_STM32G4_ERR_FLASH_PGSERR = -22,  /**< programming sequence: a write without PG, an erase with PG, or an
                                                 operation started while an error flag was set */
    PMSTEP_STM32G4_ERR_FLASH_MISERR = -23,  /**< fast programming data miss (fast programming is not used) */
    PMSTEP_STM32G4_ERR_FLASH_FASTERR = -24, /**< fast programming error (fast programming is not used) */
    PMSTEP_STM32G4_ERR_FLASH_OPERR = -25,   /**< an operation failed (reported with ERRIE only, not used) */
    PMSTEP_STM32G4_ERR_FLASH_RDERR = -26,   /**< a PCROP read error (reported with RDERRIE only, not used) */
    PMSTEP_STM32G4_ERR_FLASH_OPTVERR = -27, /**< the option bytes failed their check at load */
    PMSTEP_STM32G4_ERR_FLASH_ECC = -28,     /**< a read met an uncorrectable ECC error (two or more bits wrong in a
                                                 double word: one cut short by a power loss) */
    PMSTEP_STM32G4_ERR_STEP_MICROSTEPS = -29, /**< STEP/DIR input: microsteps per full step not within 1..256 */
    PMSTEP_STM32G4_ERR_STEP_PULSE = -30,    /**< STEP/DIR input: the shortest STEP pulse is under 3 timer clocks
                                                 (18 ns at 170 MHz), shorter than TIM4's input stage sees for sure */
    PMSTEP_STM32G4_ERR_STEP_PIN = -31       /**< STEP/DIR input: STEP not on a TIM4_CH2 pin or DIR not on a TIM4_CH1 pin
                                                 with its alternate function (PB7/PA12, PB6/PA11) */
} pmstep_stm32g4_status_t;

/** Why the port holds the bridge off, independently of the core. */
typedef enum {
    PMSTEP_STM32G4_FAULT_NONE = 0,
    PMSTEP_STM32G4_FAULT_INPUT = 1, /**< the gate driver's fault input was asserted */
    PMSTEP_STM32G4_FAULT_BREAK = 2  /**< TIM1 break: the outputs were cut by hardware */
} pmstep_stm32g4_fault_t;

/** A pin: port 0 = GPIOA .. 6 = GPIOG, pin 0..15, alternate function 0..15 (when used). */
typedef struct {
    uint8_t port;
    uint8_t pin;
    uint8_t af;
} pmstep_stm32g4_pin_t;

/**
 * STEP/DIR/EN input and DIAG output, as a TMC stepper driver has them (a drop-in for one: the
 * controller's step generator, e.g. Klipper or Marlin, drives the motor). Off by default.
 *
 * STEP and DIR go to TIM4 in encoder mode "clock plus direction, x1" (RM0440 §29.4, SMS = 1011):
 * STEP on TIM4_CH2 (tim_ti2, counted on its rising edges), DIR on TIM4_CH1 (tim_ti1, up while
 * high). The counter is the step count, 16 bits wrapping at 0xFFFF; the control interrupt reads it
 * once a period (pmstep_stm32g4_step_counter(), for pmstep_stepdir_count()). Both inputs pass the
 * same digital filter (TIMx_CCMR1 ICxF), chosen from step_min_pulse_ns (pmstep_stm32g4_step_filter()):
 * a STEP high or low time of that length always passes, a glitch much shorter never does; DIR is
 * delayed as much as STEP, so the controller's DIR-to-STEP set-up time is kept.
 *
 * EN (a GPIO input, pulled to its disabled level) gates the bridge: while it reads disabled the
 * bridge is off by the port's one path (MOE = 0, gate-driver enable off, duties 50 %) and the core
 * stopped, as for a port fault but without latching one. Starting the drive on EN's assertion, and
 * clearing a fault on its release, is the application's (app.c), from pmstep_stm32g4_step_enabled(). DIAG (an open-drain GPIO output, with
 * the pin's pull-up) is driven from pmstep_stepdir_diag() through pmstep_stm32g4_set_diag().
 */
typedef struct {
    bool enabled;                      /**< false: none of these pins is touched, no timer runs, EN gates nothing */
    pmstep_stm32g4_pin_t step_pin;     /**< TIM4_CH2: PB7 (AF2) or PA12 (AF10) */
    pmstep_stm32g4_pin_t dir_pin;      /**< TIM4_CH1: PB6 (AF2) or PA11 (AF10) */
    pmstep_stm32g4_pin_t enable_pin;   /**< EN, GPIO input */
    bool enable_active_high;           /**< false: the drive is enabled while EN is low (a TMC driver's EN) */
    pmstep_stm32g4_pin_t diag_pin;     /**< DIAG, open-drain GPIO output */
    bool diag_active_high;             /**< true: DIAG released (pulled high) while asserted (a TMC2209's DIAG) */
    uint32_t microsteps;               /**< microsteps per full step, 1..256 (the controller's setting) */
    uint32_t step_min_pulse_ns;        /**< the shortest STEP high or low time the controller makes */
} pmstep_stm32g4_step_input_t;

/** One use of a pin: what it does on the drive, the MCU signal (with an ADC channel number
 *  appended when @p channel is not 0), and the pin. */
typedef struct {
    const char *function;   /**< e.g. "phase a+ high side" */
    const char *signal;     /**< e.g. "TIM1_CH1", "ADC1_IN" (then channel), "GPIO output" */
    uint8_t channel;        /**< ADC channel of an analog input, 0 otherwise */
    pmstep_stm32g4_pin_t pin;
} pmstep_stm32g4_pin_use_t;

/** A controller board: the pins it uses itself (and what for), which a drive may use only for
 *  the same signal (the console on the virtual COM port) or not at all. */
typedef struct {
    const char *name;
    const pmstep_stm32g4_pin_use_t *reserved;
    uint32_t reserved_count;
} pmstep_stm32g4_board_t;

/** NUCLEO-G431RB (MB1367, user manual UM2505): ST-LINK virtual COM port on LPUART1 PA2/PA3,
 *  SWD PA13/PA14, SWO PB3, LD2 on PA5, B1 on PC13, HSE crystal PF0/PF1, LSE crystal PC14/PC15,
 *  BOOT0 on PB8, NRST on PG10. */
extern const pmstep_stm32g4_board_t pmstep_stm32g4_board_nucleo_g431rb;

/** Clock tree: HSI16 -> PLL; SYSCLK = 16 MHz / pll_m * pll_n / pll_r (HCLK = PCLK1 = PCLK2 = SYSCLK). */
typedef struct {
    uint32_t pll_m; /**< 1..16 (VCO input 2.66..16 MHz) */
    uint32_t pll_n; /**< 8..127 (VCO output 96..344 MHz) */
    uint32_t pll_r; /**< 2, 4, 6 or 8 */
} pmstep_stm32g4_clock_t;

typedef struct {
    pmstep_stm32g4_clock_t clock;

    /* PWM */
    uint32_t pwm_frequency_Hz;        /**< carrier (= control) frequency, e.g. 20000 */
    uint32_t dead_time_ns;            /**< inserted between complementary outputs */
    float duty_min;                   /**< per half-bridge, e.g. 0 (bootstrap drivers may need > 0) */
    float duty_max;                   /**< per half-bridge, e.g. 1 (bootstrap drivers may need < 1) */
    pmstep_stm32g4_pin_t pwm_high[4]; /**< TIM1_CH1..CH4: a+, a-, b+, b- high sides */
    pmstep_stm32g4_pin_t pwm_low[4];  /**< TIM1_CH1N..CH4N: the low sides */
    pmstep_stm32g4_pin_t break_input; /**< TIM1_BKIN */
    bool break_active_high;
    uint8_t break_filter;             /**< BKF code 0..15 */

    /* ADC: ADC1 injected rank 1 = i_a, rank 2 = bus; ADC2 injected rank 1 = i_b */
    uint8_t adc1_channel_i_a;
    uint8_t adc1_channel_bus;
    uint8_t adc2_channel_i_b;
    uint8_t adc_sample_time;          /**< SMP code 0..7 for the three channels */
    pmstep_stm32g4_pin_t adc_pins[3]; /**< i_a, bus, i_b inputs (set to analog) */
    float i_a_offset_counts;          /**< counts at 0 A */
    float i_a_gain_a_per_count;       /**< A per count (sign included) */
    float i_b_offset_counts;
    float i_b_gain_a_per_count;
    float bus_offset_counts;          /**< counts at 0 V */
    float bus_gain_v_per_count;       /**< V per count */

    /* GPIO */
    pmstep_stm32g4_pin_t enable_pin;  /**< gate driver enable (push-pull output) */
    bool enable_active_high;
    pmstep_stm32g4_pin_t fault_pin;   /**< gate driver fault (input with pull-up when active low) */
    bool fault_active_high;

    /* Console: LPUART1, 8N1 */
    pmstep_stm32g4_pin_t console_tx;  /**< LPUART1_TX */
    pmstep_stm32g4_pin_t console_rx;  /**< LPUART1_RX */
    uint32_t console_baud;            /**< e.g. 115200 */

    /* STEP/DIR/EN input and DIAG output on TIM4 and three GPIOs (step_input.enabled: off by default) */
    pmstep_stm32g4_step_input_t step_input;

    /** The controller board whose own pins the drive must keep off (NULL: none checked). */
    const pmstep_stm32g4_board_t *board;
} pmstep_stm32g4_config_t;

/** The most pins a configuration uses (the STEP/DIR input's four included). */
#define PMSTEP_STM32G4_PIN_USES_MAX 20u

/** Every pin @p cfg uses, with its function, into @p out (up to @p max). @return the count
 *  (16 for a complete configuration, 20 with the STEP/DIR input enabled), or 0 if @p cfg is NULL. */
uint32_t pmstep_stm32g4_pin_map(const pmstep_stm32g4_config_t *cfg, pmstep_stm32g4_pin_use_t *out, uint32_t max);

/**
 * Checks the pin map of @p cfg: every pin in range, one function per pin, and the board's
 * own pins (cfg->board) used only for the signal the board gives them.
 * @retval PMSTEP_STM32G4_OK
 * @retval PMSTEP_STM32G4_ERR_NULL_ARGUMENT
 * @retval PMSTEP_STM32G4_ERR_PIN           a port, pin or alternate function out of range
 * @retval PMSTEP_STM32G4_ERR_PIN_CONFLICT  two functions on one pin
 * @retval PMSTEP_STM32G4_ERR_PIN_RESERVED  a board pin given another function
 */
pmstep_stm32g4_status_t pmstep_stm32g4_check_pins(const pmstep_stm32g4_config_t *cfg);

/**
 * The default drive: a NUCLEO-G431RB with a dual full-bridge power stage (pin map in
 * stm32g4_board.c; check it against your stage's schematic), 20 kHz, 500 ns dead time,
 * 12-bit ADC with a 3.3 V reference, current sensors of 0.1 V/A centred at 1.65 V, bus
 * divider 1:20, console on LPUART1 (the ST-LINK virtual COM port) at 115200 8N1.
 */
pmstep_stm32g4_config_t pmstep_stm32g4_default_config(void);

/* ---- pure functions (no register access; unit-tested on the host) ---- */

/** Physical value from an ADC sample: (counts - offset) * gain. */
float pmstep_stm32g4_counts_to_si(uint32_t counts, float offset_counts, float gain_per_count);

/**
 * Duties of the two half-bridges of one H-bridge for the voltage @p u_V across it,
 * against the measured bus: d+ = 1/2 + u/(2 V_bus), d- = 1/2 - u/(2 V_bus), each
 * clamped to [duty_min, duty_max]. A bus that is not positive (or NaN) or a NaN
 * voltage gives 1/2 and 1/2 (zero volts).
 */
void pmstep_stm32g4_duties(float u_V, float bus_V, float duty_min, float duty_max, float *d_plus, float *d_minus);

/** Compare value for a duty: round(duty * arr), within 0..arr. */
uint32_t pmstep_stm32g4_duty_to_ccr(float duty, uint32_t arr);

/**
 * TIM1 BDTR.DTG for at least @p dead_time_ns with the timer clock @p tim_clock_Hz
 * (t_DTS = 1/f_TIM, CKD = 0), by the four ranges of RM0440 §28.6.20:
 * DTG[7]=0: n t; 10x: (64+x) 2t; 110x: (32+x) 8t; 111x: (32+x) 16t.
 * @return PMSTEP_STM32G4_OK or PMSTEP_STM32G4_ERR_DEAD_TIME.
 */
pmstep_stm32g4_status_t pmstep_stm32g4_dead_time_dtg(uint32_t dead_time_ns, uint32_t tim_clock_Hz, uint8_t *dtg);

/** Dead time (ns, rounded down) that a DTG code gives at @p tim_clock_Hz. */
uint32_t pmstep_stm32g4_dtg_to_ns(uint8_t dtg, uint32_t tim_clock_Hz);

/** SYSCLK (Hz) of a clock configuration, or 0 when it is out of range. */
uint32_t pmstep_stm32g4_sysclk_Hz(const pmstep_stm32g4_clock_t *clock);

/** Flash wait states for @p hclk_Hz in range 1 boost mode (@p boost) or normal mode
 *  (RM0440 §3.3.3, Table 9: 34 MHz resp. 30 MHz per wait state). */
uint32_t pmstep_stm32g4_flash_latency_mode(uint32_t hclk_Hz, bool boost);

/** Flash wait states for @p hclk_Hz in the regulator mode the port uses at that clock: boost
 *  above 150 MHz, normal mode at or below. */
uint32_t pmstep_stm32g4_flash_latency(uint32_t hclk_Hz);

/** TIM1 ARR for a centre-aligned carrier: round(f_TIM / (2 f_pwm)); 0 when outside 2..65535. */
uint32_t pmstep_stm32g4_pwm_arr(uint32_t tim_clock_Hz, uint32_t pwm_frequency_Hz);

/** The shortest STEP pulse the default configuration expects (ns): a TMC2209's minimum STEP high and
 *  low time t_SH, t_SL (100 ns), and Klipper's step_pulse_duration for TMC drivers. */
#define PMSTEP_STM32G4_STEP_MIN_PULSE_NS 100u

/**
 * TIMx_CCMR1 ICxF for the STEP/DIR inputs at @p tim_clock_Hz (CKD = 0, f_DTS = f_CK_INT): the longest
 * filter (N samples at f_SAMPLING, RM0440 §29.5.7) whose span N / f_SAMPLING is at most the shortest
 * pulse less 2 clocks (the input synchroniser's uncertainty), so that every pulse of @p min_pulse_ns
 * passes. 100 ns at 170 MHz: 17 clocks, code 0100 (6 samples at 85 MHz, 12 clocks = 71 ns).
 * @retval PMSTEP_STM32G4_OK, PMSTEP_STM32G4_ERR_NULL_ARGUMENT
 * @retval PMSTEP_STM32G4_ERR_STEP_PULSE  the pulse spans fewer than 3 clocks
 */
pmstep_stm32g4_status_t pmstep_stm32g4_step_filter(uint32_t min_pulse_ns, uint32_t tim_clock_Hz, uint8_t *icf);

/** The span of filter code @p icf in timer clocks (N times the sampling period; CKD = 0): a level
 *  held this long always passes, one held at most (N - 1) sampling periods never does. */
uint32_t pmstep_stm32g4_step_filter_ticks(uint8_t icf);

/** Text for a status code. */
const char *pmstep_stm32g4_status_str(pmstep_stm32g4_status_t status);

/* ---- drivers (register access) ---- */

/** Clock tree to SYSCLK (170 MHz with the default config): boost mode, flash latency, PLL. */
pmstep_stm32g4_status_t pmstep_stm32g4_clock_init(const pmstep_stm32g4_clock_t *clock);

/** GPIO: TIM1 pins, break input, ADC inputs (analog), enable output (driver off), fault input. */
pmstep_stm32g4_status_t pmstep_stm32g4_gpio_init(const pmstep_stm32g4_config_t *cfg);

/** TIM1: centre-aligned PWM, dead time, break, ADC trigger; outputs off (MOE = 0), counter stopped. */
pmstep_stm32g4_status_t pmstep_stm32g4_pwm_init(const pmstep_stm32g4_config_t *cfg, uint32_t tim_clock_Hz);

/**
 * The STEP/DIR input (cfg->step_input; nothing when not enabled): checks it, then the EN input (pulled
 * to its disabled level), the DIAG output (open drain, deasserted), the STEP and DIR pins (TIM4_CH2,
 * TIM4_CH1, pulled down) and TIM4 in encoder mode clock plus direction x1, ARR = 0xFFFF, the filter
 * of step_min_pulse_ns, CNT = 0, counting (CEN = 1). pmstep_stm32g4_init() calls it.
 * @retval PMSTEP_STM32G4_OK, PMSTEP_STM32G4_ERR_NULL_ARGUMENT, PMSTEP_STM32G4_ERR_PIN
 * @retval PMSTEP_STM32G4_ERR_STEP_MICROSTEPS, PMSTEP_STM32G4_ERR_STEP_PULSE, PMSTEP_STM32G4_ERR_STEP_PIN
 */
pmstep_stm32g4_status_t pmstep_stm32g4_step_input_init(const pmstep_stm32g4_config_t *cfg, uint32_t tim_clock_Hz);

/**
 * Sets the STEP/DIR input's EN and DIAG polarities of @p cfg (the configuration the port runs on) to
 * @p enable_active_high and @p diag_active_high, and when the input is enabled and set up, its pins
 * to match at once: EN pulled to its disabled level, DIAG deasserted (the next period drives it).
 * From the main loop with the control interrupt held (pmstep_stm32g4_hold_control()).
 */
void pmstep_stm32g4_step_polarity(pmstep_stm32g4_config_t *cfg, bool enable_active_high, bool diag_active_high);

/** ADC1/ADC2: power-up, calibration, injected sequences on TIM1_TRGO2, JEOS interrupt of ADC1. */
pmstep_stm32g4_status_t pmstep_stm32g4_adc_init(const pmstep_stm32g4_config_t *cfg);

/**
 * The whole port for @p inst (initialised; its configuration must use computational_delay_periods = 1
 * and period_s = pmstep_stm32g4_period_s(), and read neither phase voltages nor a load torque:
 * PMSTEP_STM32G4_ERR_UNMEASURED_INPUT, nor claim measurement ranges beyond the board's:
 * PMSTEP_STM32G4_ERR_SENSE_RANGE, before any register is touched): GPIO, TIM1, ADC, the STEP/DIR
 * input when enabled (pmstep_stm32g4_step_input_init()), interrupts; bridge off.
 * Call after pmstep_stm32g4_clock_init() with the same @p cfg, which must outlive the port.
 */
pmstep_stm32g4_status_t pmstep_stm32g4_init(const pmstep_stm32g4_config_t *cfg, pmstep_t *inst);

/** Control period (s) that TIM1 runs at: 2 ARR / f_TIM1. 0 if the configuration is invalid. */
float pmstep_stm32g4_period_s(const pmstep_stm32g4_config_t *cfg);

/** The phase currents the ADC reads (A): +/- the smaller distance from either phase's offset to an
 *  end code (0 or 4095), times its gain. What the core's limits.current_sense_range_A may be at most. */
float pmstep_stm32g4_current_sense_range_A(const pmstep_stm32g4_config_t *cfg);

/** The bus voltage the ADC reads at its last code (V). What limits.bus_sense_range_V may be at most. */
float pmstep_stm32g4_bus_sense_range_V(const pmstep_stm32g4_config_t *cfg);

/** Work run in the control interrupt after each step, with its output (e.g. position control's
 *  pmstep_position_update()). */
typedef void (*pmstep_stm32g4_after_step_t)(const pmstep_output_t *out);

/** Sets the work run after each step (NULL: none); call before pmstep_stm32g4_start(). */
void pmstep_stm32g4_set_after_step(pmstep_stm32g4_after_step_t hook);

/** Starts the TIM1 counter: from here on the ADC interrupt runs every period. */
void pmstep_stm32g4_start(void);

/** The port's own fault (bridge held off while not NONE). */
pmstep_stm32g4_fault_t pmstep_stm32g4_fault(void);

/** Clears the port's fault if the fault input is no longer asserted. @return true if cleared. */
bool pmstep_stm32g4_clear_fault(void);

/** Whether the port has the bridge switching (MOE set and driver enabled). */
bool pmstep_stm32g4_bridge_on(void);

/** The STEP/DIR input's counter (TIM4_CNT, 16 bits): read it once a period in the control interrupt
 *  (the after-step hook) for pmstep_stepdir_count(). 0 when the input is not enabled. */
uint32_t pmstep_stm32g4_step_counter(void);

/** Whether EN reads enabled (always true when the STEP/DIR input is not enabled: nothing gates). */
bool pmstep_stm32g4_step_enabled(void);

/** Drives DIAG (open drain): @p asserted at diag_active_high's level. Nothing when the input is off. */
void pmstep_stm32g4_set_diag(bool asserted);

/** Longest control interrupt so far, in CPU cycles (DWT cycle counter). */
uint32_t pmstep_stm32g4_isr_cycles_max(void);

/** LPUART BRR for @p baud from the kernel clock @p clock_hz (RM0440 §38.4), 0 if out of range. */
uint32_t pmstep_stm32g4_lpuart_brr(uint32_t clock_hz, uint32_t baud);

/** LPUART1 at cfg->console_baud 8N1 from PCLK1 = @p pclk1_hz, on the console pins. */
pmstep_stm32g4_status_t pmstep_stm32g4_lpuart_init(const pmstep_stm32g4_config_t *cfg, uint32_t pclk1_hz);

/** Takes up to @p max received bytes, never waits; a receive error adds one to @p errors. */
uint32_t pmstep_stm32g4_lpuart_read(uint8_t *data, uint32_t max, uint32_t *errors);

/** Sends as many of @p n bytes as the transmitter takes now, never waits. @return that count. */
uint32_t pmstep_stm32g4_lpuart_write(const uint8_t *data, uint32_t n);

/** Holds the control interrupt off (main loop, for a period boundary: never for long). */
void pmstep_stm32g4_hold_control(void);

/** Lets the control interrupt run again (a period that ended meanwhile runs now). */
void pmstep_stm32g4_release_control(void);

/**
 * The last period as the control interrupt left it, read between periods (call between
 * pmstep_stm32g4_hold_control() and _release_control()): the step's output, the samples
 * converted again from the ADC data registers, the port's fault.
 */
void pmstep_stm32g4_last_period(pmstep_output_t *out, pmstep_meas_t *meas, uint8_t *port_fault);

/* ---- stored configuration: the flash (stm32g4_flash.c) ---- */

/** The two slots of the stored configuration: the last two pages of the STM32G431xB's flash,
 *  page 62 (slot 0) and page 63 (slot 1), which the linker script keeps free of code and data. */
#define PMSTEP_STM32G4_STORE_ADDR 0x0801F000u
#define PMSTEP_STM32G4_STORE_FIRST_PAGE 62u
#define PMSTEP_STM32G4_STORE_SLOTS 2u

/** The text whose CRC-32 is the board id (pmstep_stm32g4_board_id()): the controller board, its power
 *  stage and sensing as pmstep_stm32g4_default_config() describes them. A port for another board
 *  or sensing names it otherwise, so that a record made for one is refused by the other
 *  (PMSTEP_STORE_ERR_BOARD). */
#define PMSTEP_STM32G4_BOARD_NAME "pmstep stm32g431 NUCLEO-G431RB dual full-bridge 0.1V/A 1:20"

/**
 * The flash the stored configuration (pmstep_store.h) lives in on this port: slots of one page
 * (2 KiB) each at PMSTEP_STM32G4_STORE_ADDR. Each operation unlocks FLASH_CR, clears error flags
 * left from before, runs, waits for BSY with a bound and locks FLASH_CR again; it returns 0 or a
 * negative pmstep_stm32g4_status_t:
 *   erase:   a page erase (RM0440 §3.3.6); 22 ms typical (DS12589), the CPU stalls on any flash read
 *            meanwhile (a single bank); then the data cache is reset.
 *   program: double words (§3.3.7 standard programming, 82 us each typical), each checked.
 *   read:    PMSTEP_STM32G4_ERR_FLASH_ECC if a double word read has an uncorrectable ECC error
 *            (FLASH_ECCR.ECCD with its address in the slots; the NMI it raises is taken by
 *            pmstep_stm32g4_flash_ecc_nmi()).
 * Codes: _RANGE, _LOCKED, _TIMEOUT, one per FLASH_SR error flag (_PROGERR .. _OPTVERR), _ECC.
 * Main loop only (never from an interrupt), bridge off: the store's caller sees to that.
 */
const pmstep_store_flash_t *pmstep_stm32g4_store_flash(void);

/** The board id of the stored configuration's records: CRC-32 (ISO-HDLC, pmstep_store_crc32()) of the
 *  bytes of PMSTEP_STM32G4_BOARD_NAME, without its NUL. */
uint32_t pmstep_stm32g4_board_id(void);

/**
 * The NMI's flash part (NMI_Handler calls it first): a double ECC error (FLASH_ECCR.ECCD) of a read
 * inside the stored configuration's pages is the store's to report: ECCD is cleared, the error
 * counted for the read in progress (which then returns PMSTEP_STM32G4_ERR_FLASH_ECC), and the
 * handler returns. @return true if it was such an error; false for any other cause (an ECC error in
 * code or constants, in the system flash, or not a flash error at all): the NMI stays fatal.
 */
bool pmstep_stm32g4_flash_ecc_nmi(void);

/** Double ECC errors in the stored configuration's pages since reset (taken by the NMI or seen by a read). */
uint32_t pmstep_stm32g4_flash_ecc_errors(void);

/** ADC1 and ADC2 interrupt: the control period. */
void ADC1_2_IRQHandler(void);

/** TIM1 break interrupt: latches PMSTEP_STM32G4_FAULT_BREAK. */
void TIM1_BRK_TIM15_IRQHandler(void);

#ifdef __cplusplus
}
#endif

#endif /* PMSTEP_HAL_STM32G4_H */
