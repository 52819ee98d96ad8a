/*
 * Start-up of the STM32G431: vector table (RM0440 §14.3, Table 97: 16 Cortex-M4
 * system entries, then interrupts 0..101), reset handler (data copy, bss clear,
 * FPU access, VTOR), NMI handler, default handler. The other handlers are weak: the port
 * and the application define the ones they use.
 */
#include <stdbool.h>
#include <stdint.h>

#include "pmstep_hal_stm32g4.h"
#include "stm32g4_regs.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern int main(void);

void Reset_Handler(void);
void Default_Handler(void);
void NMI_Handler(void);
void HardFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void MemManage_Handler(void) __attribute__((weak, alias("Default_Handler")));
void BusFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void UsageFault_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SVC_Handler(void) __attribute__((weak, alias("Default_Handler")));
void DebugMon_Handler(void) __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler(void) __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler(void) __attribute__((weak, alias("Default_Handler")));
void ADC1_2_IRQHandler(void) __attribute__((weak, alias("Default_Handler")));         /* 18 */
void TIM1_BRK_TIM15_IRQHandler(void) __attribute__((weak, alias("Default_Handler"))); /* 24 */

typedef void (*vector_t)(void);

typedef struct {
    uint32_t *initial_sp;
    vector_t system[15];
    vector_t irq[STM32G4_IRQ_COUNT];
} vector_table_t;

#define D Default_Handler
#define D5 D, D, D, D, D
#define D10 D5, D5
__attribute__((section(".isr_vector"), used)) const vector_table_t stm32g431_vector_table = {
    &_estack,
    {Reset_Handler, NMI_Handler, HardFault_Handler, MemManage_Handler, BusFault_Handler, UsageFault_Handler, 0, 0, 0, 0,
     SVC_Handler, DebugMon_Handler, 0, PendSV_Handler, SysTick_Handler},
    {
        D10, D5, D, D, D,                           /* 0 .. 17 */
        ADC1_2_IRQHandler,                          /* 18 */
        D5,                                         /* 19 .. 23 */
        TIM1_BRK_TIM15_IRQHandler,                  /* 24 */
        D10, D10, D10, D10, D10, D10, D10, D5, D, D /* 25 .. 101 */
    },
};
#undef D
#undef D5
#undef D10
/* Every entry initialised: the last interrupt's handler is not null. */

void Default_Handler(void)
{
    for (;;) {
    }
}

/* NMI: a double ECC error of the flash raises it (RM0440 §3.3.2 "Error code correction (ECC)",
 * FLASH_ECCR.ECCD). One in the stored configuration's pages (a double word cut short by a power
 * loss) is the store's to report: the flash driver clears it and the read that met it returns an
 * error; the handler returns to that read. Any other cause (an ECC error in code or constants, the
 * clock security system, ...) stays fatal: the CPU stops here. */
void NMI_Handler(void)
{
    if (pmstep_stm32g4_flash_ecc_nmi()) {
        return;
    }
    for (;;) {
    }
}

void Reset_Handler(void)
{
    uint32_t *src = &_sidata;
    uint32_t *dst;
    for (dst = &_sdata; dst < &_edata; ++dst) {
        *dst = *src++;
    }
    for (dst = &_sbss; dst < &_ebss; ++dst) {
        *dst = 0u;
    }
    STM32G4_SCB->CPACR |= SCB_CPACR_CP10_CP11_FULL; /* FPU, before any floating-point instruction */
    STM32G4_SCB->VTOR = (uint32_t)(uintptr_t)&stm32g431_vector_table;
    __asm volatile("dsb\n\tisb" ::: "memory");
    (void)main();
    for (;;) {
    }
}
