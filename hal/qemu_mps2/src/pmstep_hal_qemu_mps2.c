/*
 * HAL contract on QEMU mps2-an386: sample and output blocks in RAM, a control
 * interrupt pended by software, SysTick around the step (see the header).
 *
 * System registers used (ARMv7-M Architecture Reference Manual, ARM DDI 0403E):
 *   SysTick  SYST_CSR 0xE000E010, SYST_RVR 0xE000E014, SYST_CVR 0xE000E018 (B3.3.2)
 *   NVIC     ISER0 0xE000E100, IPR 0xE000E400 (one byte per line), STIR 0xE000EF00 (B3.4.3)
 */
#include "pmstep_hal_qemu_mps2.h"

#include <stddef.h>

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYST_CSR_ENABLE (1u << 0)
#define SYST_CSR_CLKSOURCE_CPU (1u << 2)
#define SYST_MASK 0x00FFFFFFu /* 24-bit down counter */

#define NVIC_ISER ((volatile uint32_t *)0xE000E100u)
#define NVIC_IPR ((volatile uint8_t *)0xE000E400u)
#define NVIC_STIR (*(volatile uint32_t *)0xE000EF00u)

static struct {
    pmstep_t *inst;
    pmstep_meas_t samples;  /* "ADC": written by the harness before the interrupt */
    pmstep_output_t output; /* "PWM": written by pmstep_hal_apply_output() */
    pmstep_output_t scratch;
    volatile uint32_t periods;
    mps2_pil_cost_t cost;
} port;

void pmstep_hal_read_measurements(pmstep_meas_t *meas)
{
    *meas = port.samples;
}

void pmstep_hal_apply_output(const pmstep_output_t *out)
{
    port.output = *out;
}

/* The bracket's own cost: a call with pmstep_step()'s arguments to a function that does nothing. */
__attribute__((noinline)) static void empty_step(pmstep_t *inst, const pmstep_meas_t *meas, pmstep_output_t *out)
{
    (void)inst;
    (void)meas;
    (void)out;
    __asm volatile("" ::: "memory");
}

static uint32_t elapsed(uint32_t before, uint32_t after)
{
    return (before - after) & SYST_MASK;
}

#define STACK_PAINT 0x5AC3A55Cu
#define STACK_PAINT_WORDS (MPS2_PIL_STACK_PAINT_BYTES / 4u)

/* Paints the words below @p sp; the step then runs with its frame starting at @p sp. */
static void paint_stack(uintptr_t sp)
{
    volatile uint32_t *w = (volatile uint32_t *)(sp - MPS2_PIL_STACK_PAINT_BYTES);
    uint32_t k;
    for (k = 0; k < STACK_PAINT_WORDS; ++k) {
        w[k] = STACK_PAINT;
    }
}

/* Bytes below @p sp written since paint_stack(sp). */
static uint32_t stack_used(uintptr_t sp)
{
    const volatile uint32_t *w = (const volatile uint32_t *)(sp - MPS2_PIL_STACK_PAINT_BYTES);
    uint32_t k;
    for (k = 0; k < STACK_PAINT_WORDS; ++k) {
        if (w[k] != STACK_PAINT) {
            return (STACK_PAINT_WORDS - k) * 4u;
        }
    }
    return 0u;
}

void MPS2_PIL_CONTROL_IRQHandler(void)
{
    pmstep_meas_t meas;
    uint32_t t0;
    uint32_t t1;
    uint32_t t2;
    uint32_t t3;
    unsigned mode;

    uintptr_t sp;
    uint32_t stack;

    pmstep_hal_read_measurements(&meas);
    t0 = SYST_CVR;
    empty_step(port.inst, &meas, &port.scratch);
    t1 = SYST_CVR;
    __asm volatile("mov %0, sp" : "=r"(sp)); /* the step's frame starts here */
    paint_stack(sp);
    t2 = SYST_CVR;
    pmstep_step(port.inst, &meas, &port.output);
    t3 = SYST_CVR;
    stack = stack_used(sp);
    pmstep_hal_apply_output(&port.output);

    mode = (unsigned)port.output.mode;
    if (mode < MPS2_PIL_MODES) {
        port.cost.steps[mode]++;
        port.cost.empty_ticks[mode] += elapsed(t0, t1);
        port.cost.step_ticks[mode] += elapsed(t2, t3);
        if (stack > port.cost.stack_max_bytes[mode]) {
            port.cost.stack_max_bytes[mode] = stack;
        }
    }
    port.periods = port.periods + 1u;
}

void mps2_pil_init(pmstep_t *inst)
{
    const pmstep_output_t zero_output = {0};
    port.inst = inst;
    port.output = zero_output;
    port.periods = 0u;
    {
        const mps2_pil_cost_t zero_cost = {{0}, {0}, {0}, {0}};
        port.cost = zero_cost;
    }
    SYST_CSR = 0u;
    SYST_RVR = SYST_MASK;
    SYST_CVR = 0u;
    SYST_CSR = SYST_CSR_ENABLE | SYST_CSR_CLKSOURCE_CPU;
    NVIC_IPR[MPS2_PIL_CONTROL_IRQ] = 0x40u;
    NVIC_ISER[MPS2_PIL_CONTROL_IRQ / 32u] = 1u << (MPS2_PIL_CONTROL_IRQ % 32u);
    __asm volatile("cpsie i" ::: "memory");
}

void mps2_pil_control_period(const pmstep_meas_t *samples, pmstep_output_t *out)
{
    const uint32_t before = port.periods;
    port.samples = *samples;
    __asm volatile("dsb" ::: "memory");
    NVIC_STIR = MPS2_PIL_CONTROL_IRQ;
    __asm volatile("dsb\n\tisb" ::: "memory");
    while (port.periods == before) { /* taken at the ISB above; the loop only guards */
        __asm volatile("" ::: "memory");
    }
    *out = port.output;
}

const mps2_pil_cost_t *mps2_pil_cost(void)
{
    return &port.cost;
}

uint32_t mps2_pil_calibrate(uint32_t iterations)
{
    uint32_t before;
    uint32_t after;
    uint32_t n = iterations;
    before = SYST_CVR;
    __asm volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
    after = SYST_CVR;
    return elapsed(before, after);
}

double mps2_pil_instructions_per_tick(uint32_t iterations)
{
    const uint32_t ticks = mps2_pil_calibrate(iterations);
    return ticks == 0u ? 0.0 : 2.0 * (double)iterations / (double)ticks;
}
