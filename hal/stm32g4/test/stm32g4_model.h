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
 * it differently. Not modelled: prescaler
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
    uint64_t tick;      /**< model time of the trigger edge */
    uint32_t cnt;       /**< TIM1 counter at the trigger */
    bool down;          /**< TIM1 counting down at the trigger */
} stm32g4_model_trigger_t;

typedef struct {
    /* ---- inputs the test drives ---- */
    bool bkin_pin_high;                             /**< electrical level on the TIM1_BKIN pin */
    uint16_t analog_counts[2][ADC_CHANNEL_MAX + 1u]; /**< what ADC1 [0] / ADC2 [1] convert on each channel */
    unsigned aden_guard_polls;  /**< driver polls after ADCAL clears during which an ADEN write is reset */

    /* ---- TIM1 state (RM0440 ch. 28) ---- */
    uint32_t cnt;
    bool down;
    uint32_t rep;               /**< repetition down-counter */
    uint32_t arr_shadow;
    uint32_t ccr_shadow[6];     /**< CCR1..CCR6 active (shadow) values */
    bool ocref[6];              /**< OC1REF..OC6REF */
    bool dt_out[4][2];          /**< dead-time generator outputs (OCx, OCxN before the output stage) */
    uint32_t dt_wait[4][2];     /**< ticks left before a pending rising edge passes */
    bool oc[4];                 /**< TIM1_CHx pin levels */
    bool ocn[4];                /**< TIM1_CHxN pin levels */
    bool trgo2;                 /**< TRGO2 level */
    bool update_pulse;          /**< an update event happened this tick */
    bool break_active;
    uint32_t sr;                /**< TIM1_SR as the hardware holds it */
    uint64_t updates;           /**< update events since reset */
    uint64_t tick;

    /* ---- ADC1/ADC2 state (RM0440 ch. 21) ---- */
    struct {
        uint32_t isr;           /**< ADC_ISR as the hardware holds it */
        uint32_t cr_rs;         /**< the set-only/hardware-cleared CR bits as the hardware holds them */
        unsigned cal_polls;     /**< polls until the calibration ends (0: not calibrating) */
        unsigned guard;         /**< polls left during which ADEN is reset by the calibration logic */
        bool calibrated;
        bool trgo2_prev;
        bool busy;
        unsigned rank;
        uint32_t ticks_left;
        unsigned triggers;
        unsigned sequences;     /**< JEOS raised */
        stm32g4_model_trigger_t log[STM32G4_MODEL_LOG];
    } adc[2];

    /* ---- GPIO ---- */
    stm32g4_gpio_t gpio_seen[STM32G4_GPIO_PORTS]; /**< register values the model last accepted */
    unsigned unclocked_writes;  /**< writes to a GPIO port whose clock was off (lost) */

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

/** Queues @p n bytes for LPUART1's receiver (RXNE while any is left); the transmitter takes every
 *  byte at once (TXE always set) into uart_tx. Line timing is not modelled. */
void stm32g4_model_uart_send(const uint8_t *data, uint32_t n);

/** Drives an input pin's level (IDR), port 0 = A; accepted whatever the port's clock. */
void stm32g4_model_pin_in(unsigned port, unsigned pin, bool high);

/** The level an output pin of a GPIO port drives (ODR after BSRR), port 0 = A. */
bool stm32g4_model_pin_out(unsigned port, unsigned pin);

#ifdef __cplusplus
}
#endif

#endif /* STM32G4_MODEL_H */
