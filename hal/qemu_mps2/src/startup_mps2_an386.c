/*
 * Start-up of the QEMU mps2-an386 port: vector table and reset handler.
 *
 * The reset handler gives the FPU full access (CPACR.CP10/CP11 = 0b11, ARMv7-M
 * Architecture Reference Manual, B3.2.20) before any floating-point instruction,
 * then enters newlib's rdimon crt0 (_start), which takes the stack and heap from
 * the semihosting SYS_HEAPINFO call, clears .bss, fetches argv with SYS_GET_CMDLINE,
 * calls main() and exits through SYS_EXIT with main's status.
 */
#include <stdint.h>

#include "pmstep_hal_qemu_mps2.h"

extern uint32_t __stack_top;
extern void _start(void); /* newlib rdimon crt0 */

void Reset_Handler(void);
void Default_Handler(void);
void NMI_Handler(void) __attribute__((weak, alias("Default_Handler")));
void HardFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void MemManage_Handler(void) __attribute__((weak, alias("Default_Handler")));
void BusFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void UsageFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SVC_Handler(void) __attribute__((weak, alias("Default_Handler")));
void DebugMon_Handler(void) __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));

/* External interrupts: weak, so a port or an application defines the ones it uses. */
#define IRQ_WEAK(n) void Irq##n##_Handler(void) __attribute__((weak, alias("Default_Handler")))
IRQ_WEAK(0);
IRQ_WEAK(1);
IRQ_WEAK(2);
IRQ_WEAK(3);
IRQ_WEAK(4);
IRQ_WEAK(5);
IRQ_WEAK(6);
IRQ_WEAK(7);
IRQ_WEAK(8);
IRQ_WEAK(9);
IRQ_WEAK(10);
IRQ_WEAK(11);
IRQ_WEAK(12);
IRQ_WEAK(13);
IRQ_WEAK(14);
IRQ_WEAK(15);
IRQ_WEAK(16);
IRQ_WEAK(17);
IRQ_WEAK(18);
IRQ_WEAK(19);
IRQ_WEAK(20);
IRQ_WEAK(21);
IRQ_WEAK(22);
IRQ_WEAK(23);
IRQ_WEAK(24);
IRQ_WEAK(25);
IRQ_WEAK(26);
IRQ_WEAK(27);
IRQ_WEAK(28);
IRQ_WEAK(29);
IRQ_WEAK(30);
IRQ_WEAK(31);

typedef void (*vector_t)(void);

/* 16 system entries, then the 32 external interrupts of the AN386 image. */
typedef struct {
    uint32_t *initial_sp;
    vector_t system[15];
    vector_t irq[MPS2_IRQ_COUNT];
} vector_table_t;

__attribute__((section(".isr_vector"), used)) const vector_table_t mps2_vector_table = {
    &__stack_top,
    {Reset_Handler, NMI_Handler, HardFault_Handler, MemManage_Handler, BusFault_Handler, UsageFault_Handler, 0, 0, 0, 0,
     SVC_Handler, DebugMon_Handler, 0, PendSV_Handler, SysTick_Handler},
    {Irq0_Handler,  Irq1_Handler,  Irq2_Handler,  Irq3_Handler,  Irq4_Handler,  Irq5_Handler,  Irq6_Handler,
     Irq7_Handler,  Irq8_Handler,  Irq9_Handler,  Irq10_Handler, Irq11_Handler, Irq12_Handler, Irq13_Handler,
     Irq14_Handler, Irq15_Handler, Irq16_Handler, Irq17_Handler, Irq18_Handler, Irq19_Handler, Irq20_Handler,
     Irq21_Handler, Irq22_Handler, Irq23_Handler, Irq24_Handler, Irq25_Handler, Irq26_Handler, Irq27_Handler,
     Irq28_Handler, Irq29_Handler, Irq30_Handler, Irq31_Handler},
};

void Default_Handler(void)
{
    /* An unexpected exception: stop here (a debugger attached to QEMU's gdbstub sees it). */
    for (;;) {
    }
}

void Reset_Handler(void)
{
    volatile uint32_t *const cpacr = (volatile uint32_t *)0xE000ED88u; /* SCB->CPACR */
    *cpacr |= (0xFu << 20);                                            /* CP10, CP11: full access */
    __asm volatile("dsb\n\tisb" ::: "memory");
    _start();
}
