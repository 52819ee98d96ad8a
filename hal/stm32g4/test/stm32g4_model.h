/**
 * @file stm32g4_model.h
 * @brief Behavioural model of the STM32G431 peripherals the port drives, for host tests:
 *        TIM1 (counter, repetition counter, PWM modes 1 and 2, complementary outputs with
 *        dead time, break, TRGO2), the ADC1/ADC2 injected trigger and conversions, the
 *        ADC enable/calibration handshake, the clock tree's ready flags, the flash latency
 *        table and GPIO clock gating.
 *
 * The port's drivers write the fake register blocks (stm32g4_fake, STM32G4_FAKE_REGISTERS);
 * the model reads those registers as the hardware would and writes back what the hardware
 * would show. Time advances in TIM1 kernel clock ticks (TIM1 runs at SYSCLK here), by
 * stm32g4_model_run(); interrupts that are pending and enabled in the NVIC run the port's
 * handlers at the tick they become pending (the CPU time of a handler is not modelled).
 *
 * Each rule in stm32g4_model.c cites the section of the reference manual (ST RM0440,
 * "STM32G4 Series advanced Arm-based 32-bit MCUs") it models, numbered as in the revision the
 * port's register header follows (Rev 8), with the section's title where other revisions number
 * it differently. The flash controller and the flash array are modelled in stm32g4_model_flash.c
 * (see "Flash" below), TIM4 as the STEP/DIR counter in stm32g4_model_tim4.c (see "TIM4"). Not modelled: prescaler
 * other than 0, input capture, break filter and break 2, OCxREF clear, combined/asymmetric
 * PWM modes, the injected queue (JQDIS = 1 is assumed), regular conversions.
 */
#ifndef STM32G4_MODEL_H
#define STM32G4_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#include "stm32g4_regs.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A reserved bit of ADC_ISR the model keeps at 1 so that it sees every software write
 *  (flags are write-1-to-clear: a write of the value already there must still clear them). */
#define STM32G4_MODEL_ISR_MARK STM32G4_BIT(31)

/** Up to this many injected conversions are logged per ADC. */
#define STM32G4_MODEL_LOG 4096u

typedef struct {
    uint64_t tick; /**< model time of the trigger edge */
    uint32_t cnt;  /**< TIM1 counter at the trigger */
    bool down;     /**< TIM1 counting down at the trigger */
} stm32g4_model_trigger_t;

typedef struct {
    /* ---- inputs the test drives ---- */
    bool bkin_pin_high;                              /**< electrical level on the TIM1_BKIN pin */
    uint16_t analog_counts[2][ADC_CHANNEL_MAX + 1u]; /**< what ADC1 [0] / ADC2 [1] convert on each channel */
    unsigned aden_guard_polls; /**< driver polls after ADCAL clears during which an ADEN write is reset */

    /* ---- TIM1 state (RM0440 ch. 28) ---- */
    uint32_t cnt;
    bool down;
    uint32_t rep; /**< repetition down-counter */
    uint32_t arr_shadow;
    uint32_t ccr_shadow[6]; /**< CCR1..CCR6 active (shadow) values */
    bool ocref[6];          /**< OC1REF..OC6REF */
    bool dt_out[4][2];      /**< dead-time generator outputs (OCx, OCxN before the output stage) */
    uint32_t dt_wait[4][2]; /**< ticks left before a pending rising edge passes */
    bool oc[4];             /**< TIM1_CHx pin levels */
    bool ocn[4];            /**< TIM1_CHxN pin levels */
    bool trgo2;             /**< TRGO2 level */
    bool update_pulse;      /**< an update event happened this tick */
    bool break_active;
    uint32_t sr;      /**< TIM1_SR as the hardware holds it */
    uint64_t updates; /**< update events since reset */
    uint64_t tick;

    /* ---- ADC1/ADC2 state (RM0440 ch. 21) ---- */
    struct {
        uint32_t isr;       /**< ADC_ISR as the hardware holds it */
        uint32_t cr_rs;     /**< the set-only/hardware-cleared CR bits as the hardware holds them */
        unsigned cal_polls; /**< polls until the calibration ends (0: not calibrating) */
        unsigned guard;     /**< polls left during which ADEN is reset by the calibration logic */
        bool calibrated;
        bool trgo2_prev;
        bool busy;
        unsigned rank;
        uint32_t ticks_left;
        unsigned triggers;
        unsigned sequences; /**< JEOS raised */
        stm32g4_model_trigger_t log[STM32G4_MODEL_LOG];
    } adc[2];

    /* ---- GPIO ---- */
    stm32g4_gpio_t gpio_seen[STM32G4_GPIO_PORTS]; /**< register values the model last accepted */
    uint32_t gpio_floating[STM32G4_GPIO_PORTS];   /**< inputs nobody drives: IDR reads the pin's pull */
    unsigned unclocked_writes;                    /**< writes to a GPIO port whose clock was off (lost) */

    /* ---- LPUART1 (the console): bytes from the host, bytes sent ---- */
    uint8_t uart_rx[4096];
    uint32_t uart_rx_head;
    uint32_t uart_rx_len;
    uint8_t uart_tx[16384];
    uint32_t uart_tx_len;

    /* ---- interrupts taken ---- */
    unsigned adc_irqs;
    unsigned brk_irqs;
} stm32g4_model_t;

extern stm32g4_model_t stm32g4_model;

/** Registers to their reset values (RM0440 register descriptions), model state cleared. */
void stm32g4_model_reset(void);

/** Applies the software writes since the last call (set-only bits, flags, BSRR, UG). */
void stm32g4_model_sync(void);

/** Runs @p ticks TIM1 clock ticks, taking interrupts as they become pending. */
void stm32g4_model_run(uint64_t ticks);

/** Minimum flash wait states for @p hclk_Hz (RM0440 §3.3.3, Table 9), range 1 boost or normal. */
uint32_t stm32g4_model_flash_min_latency(uint32_t hclk_Hz, bool boost);

/** Whether the flash (with LATENCY, R1MODE as written) can run at @p hclk_Hz. */
bool stm32g4_model_flash_ok(uint32_t hclk_Hz);

/** Dead time in TIM1 clock ticks of a DTG code (RM0440 §28.6.20, CKD = 0). */
uint32_t stm32g4_model_dead_time_ticks(uint32_t dtg);

/** TIM1 after software wrote its registers (stm32g4_model_sync() calls it): SR flags cleared by
 *  writing 0, UG's update event, the break (stm32g4_model_tim1.c). */
void stm32g4_model_tim1_sync(void);

/** One TIM1 clock tick (stm32g4_model_run() gives it each tick): the break, the counter, OCxREF,
 *  the outputs with their dead time, TRGO2. */
void stm32g4_model_tim1_tick(void);

/** Queues @p n bytes for LPUART1's receiver (RXNE while any is left); the transmitter takes every
 *  byte at once (TXE always set) into uart_tx. Line timing is not modelled. */
void stm32g4_model_uart_send(const uint8_t *data, uint32_t n);

/** Drives an input pin's level (IDR), port 0 = A; accepted whatever the port's clock. */
void stm32g4_model_pin_in(unsigned port, unsigned pin, bool high);

/** The level an output pin of a GPIO port drives (ODR after BSRR), port 0 = A. */
bool stm32g4_model_pin_out(unsigned port, unsigned pin);

/** Leaves an input pin undriven (a line left open): IDR reads its pull, 0 without one, until
 *  stm32g4_model_pin_in() drives it again. */
void stm32g4_model_pin_float(unsigned port, unsigned pin);

/** Whether an output pin drives its line high (push-pull with a 1; never an open-drain pin). */
bool stm32g4_model_pin_drives_high(unsigned port, unsigned pin);

/** Whether an output pin pulls its line low (a 0 in ODR, push-pull or open drain). */
bool stm32g4_model_pin_drives_low(unsigned port, unsigned pin);

/** The line's level: an input's IDR; an output's drive; a released open-drain line high if the pin's
 *  pull-up or @p external_pull_up holds it (low otherwise: floating, read as low here). */
bool stm32g4_model_pin_level(unsigned port, unsigned pin, bool external_pull_up);

/* ---------------------------------------------------------------------------
 * TIM4 (stm32g4_model_tim4.c): the STEP/DIR counter, from RM0440 chapter 29 "General-purpose timers
 * (TIM2/TIM3/TIM4/TIM5)". Its inputs are the pins the test drives with stm32g4_model_pin_in(): tim_ti1
 * from TIM4_CH1 (PB6 AF2 or PA11 AF10), tim_ti2 from TIM4_CH2 (PB7 AF2 or PA12 AF10), each only
 * while the pin is in that alternate function (0 otherwise). Modelled: the input filter (ICxF, CKD),
 * the polarity (CCxP), the encoder modes clock plus direction x2 and x1 (SMS 1010, 1011) and the
 * internal clock (SMS 0000, PSC 0), CEN, ARR wrap both ways with UIF, UG, CNT written by software,
 * CR1.DIR. Not modelled: the other slave and encoder modes (no count), the prescalers, captures,
 * compare outputs, TISEL other than 0 (no input), the index, interrupts and DMA.
 * ------------------------------------------------------------------------- */

typedef struct {
    uint32_t cnt;         /**< the counter (what CNT reads) */
    uint32_t cnt_written; /**< CNT as the model last left it: another value is a software write */
    uint32_t sr;          /**< TIM4_SR as the hardware holds it */
    bool ti_filtered[2];  /**< tim_ti1, tim_ti2 after the filter (before the polarity) */
    uint32_t ti_run[2];   /**< consecutive samples at the other level */
    bool ti2fp2_prev;     /**< tim_ti2fp2 at the last tick */
    uint64_t counted_up;  /**< counts up and down since the reset */
    uint64_t counted_down;
    uint64_t wraps;          /**< overflows and underflows */
    uint64_t filtered_edges; /**< STEP edges the filter passed (both directions of the level) */
} stm32g4_model_tim4_t;

extern stm32g4_model_tim4_t stm32g4_model_tim4;

/** TIM4's registers and state to their reset values (stm32g4_model_reset() calls it). */
void stm32g4_model_tim4_reset(void);

/** One TIM4 clock tick (stm32g4_model_run() gives it each tick: TIM4 runs at PCLK1 = SYSCLK). */
void stm32g4_model_tim4_tick(void);

/* ---------------------------------------------------------------------------
 * Flash (stm32g4_model_flash.c): the FLASH controller's key, status, control and ECC registers
 * and the 128 KiB main array with its ECC state per double word, from RM0440 chapter 3. The
 * driver's register writes with side effects and every access to the array come through
 * stm32g4_fake_flash_reg_write(), stm32g4_fake_flash_read32() and _write32() (stm32g4_regs.h).
 * The array lives outside stm32g4_model_reset(): a reset is a power cycle of the chip, and the
 * flash keeps its contents (stm32g4_model_flash_erase_all() gives a fresh part).
 * ------------------------------------------------------------------------- */

/** 64-bit program time t_PROG, 81.7 us typical (DS12589 "Flash memory characteristics"), in
 *  ticks of 170 MHz (13 889). */
#define STM32G4_MODEL_FLASH_PROGRAM_TICKS 13889u
/** Page (2 KiB) erase time t_ERASE, 22.02 ms typical (DS12589), in ticks of 170 MHz. */
#define STM32G4_MODEL_FLASH_ERASE_TICKS 3743400u
/** Model ticks per second (the ticks are SYSCLK cycles at 170 MHz). */
#define STM32G4_MODEL_TICKS_PER_S 170000000u
/** Double words per page. */
#define STM32G4_MODEL_FLASH_PAGE_DW (STM32G4_FLASH_PAGE_BYTES / STM32G4_FLASH_DOUBLE_WORD_BYTES)

typedef struct {
    /* ---- inputs the test drives (stm32g4_model_reset() sets them to the values said) ---- */
    uint32_t poll_ticks;   /**< ticks one driver poll of FLASH_SR lasts, while the flash is busy (170: 1 us) */
    uint32_t cut_at_step;  /**< the power is cut in the middle of this program or erase step, counted
                                   from 1 since the reset (0: no cut) */
    uint32_t cut_erase_dw; /**< an erase cut short has erased this many double words of its page
                                   before the cut (STM32G4_MODEL_FLASH_PAGE_DW / 2) */
    uint32_t inject_step;  /**< this program or erase step ends with inject_flags and changes nothing (0: none) */
    uint32_t inject_flags; /**< FLASH_SR error flags of the injected failure (FLASH_SR_PROGERR) */
    bool stuck_busy;       /**< an operation once started never ends (BSY stays set) */

    /* ---- the controller (RM0440 §3.3.5 .. §3.3.7) ---- */
    uint32_t sr;       /**< FLASH_SR's flags as the hardware holds them (BSY apart) */
    unsigned key_step; /**< 1: KEY1 written, KEY2 expected */
    bool key_error;    /**< a wrong key sequence: FLASH_CR locked until the reset */
    bool latched;      /**< the first word of a double word is latched */
    uint32_t latch_addr;
    uint32_t latch_word;
    unsigned op;         /**< the operation running: 0 none, 1 page erase, 2 program */
    uint32_t op_index;   /**< its page, or its double word's index in the array */
    uint32_t op_data[2]; /**< the double word being programmed */
    uint64_t op_left;    /**< ticks until it ends */
    bool powered;        /**< false from a power cut until the reset */

    /* ---- counted since the reset ---- */
    uint32_t steps;         /**< program and erase steps started (the power cut's count) */
    uint32_t erases;        /**< page erases completed */
    uint32_t programs;      /**< double words programmed */
    uint64_t busy_ticks;    /**< ticks with BSY set */
    uint32_t bus_errors;    /**< wrong-key bus errors (the hardware raises a hard fault) */
    uint32_t nmis;          /**< NMIs raised by ECCD */
    uint32_t nmis_fatal;    /**< of those, the ones the port's handler did not take (the CPU would hang) */
    uint32_t dcache_resets; /**< FLASH_ACR.DCRST written 1 while the data cache was disabled */
    uint32_t stalled_reads; /**< array reads that waited for a running operation */
} stm32g4_model_flash_t;

extern stm32g4_model_flash_t stm32g4_model_flash;

/** The controller to its reset state (FLASH_CR locked, no flag; stm32g4_model_reset() calls it);
 *  the array is kept, as through a power cycle. */
void stm32g4_model_flash_reset(void);

/** A fresh part: every byte of the array 0xFF, no double word with an ECC error. */
void stm32g4_model_flash_erase_all(void);

/** The array's byte at @p addr (0x0800 0000 ..), for a test to look at without a CPU read. */
const uint8_t *stm32g4_model_flash_bytes(uint32_t addr);

/** Makes the double word at @p addr read with an uncorrectable ECC error (until erased). */
void stm32g4_model_flash_set_ecc_error(uint32_t addr);

/** Whether the double word at @p addr reads with an uncorrectable ECC error. */
bool stm32g4_model_flash_ecc_error(uint32_t addr);

/** A CPU write of @p bytes (1, 2 or 4) to the flash memory at @p addr (the driver's word writes
 *  come through stm32g4_fake_flash_write32()). */
void stm32g4_model_flash_write(uint32_t addr, uint32_t value, uint32_t bytes);

/** A CPU 32-bit read of the flash memory at @p addr (waits for a running operation, records and
 *  raises an ECC double error). */
uint32_t stm32g4_model_flash_read(uint32_t addr);

/** Whether an operation runs (FLASH_SR.BSY). */
bool stm32g4_model_flash_busy(void);

/** @p ticks of time for the flash (stm32g4_model_run() gives it each tick). */
void stm32g4_model_flash_advance(uint64_t ticks);

/** One driver poll of FLASH_SR (the wait hook calls it): poll_ticks of time for the flash. */
void stm32g4_model_flash_poll(void);

#ifdef __cplusplus
}
#endif

#endif /* STM32G4_MODEL_H */
