/**
 * @file stm32g4_regs.h
 * @brief The STM32G431 registers this port uses, written from the register maps of
 *        the reference manual (ST RM0440 Rev 8, "STM32G4 Series advanced Arm-based
 *        32-bit MCUs") and, for the core peripherals, the ARMv7-M Architecture
 *        Reference Manual (ARM DDI 0403E). No vendor header is used.
 *
 * Each peripheral is a struct of 32-bit registers at the offsets of its register
 * map (checked below with offsetof) and a base address from the memory map
 * (RM0440 §2.2.2, Table 4 "STM32G4 series memory map and peripheral register
 * boundary addresses"). Bit positions are given with the register they belong to.
 *
 * Host unit tests define STM32G4_FAKE_REGISTERS: every peripheral pointer then
 * points into one struct in RAM (stm32g4_fake), and the bounded wait loops call
 * stm32g4_fake_wait_hook() so a test can play the hardware (set ready flags).
 */
#ifndef STM32G4_REGS_H
#define STM32G4_REGS_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define STM32G4_STATIC_ASSERT(cond, name) typedef char stm32g4_static_assert_##name[(cond) ? 1 : -1]
#define STM32G4_BIT(n) (1u << (n))

/* ---------------------------------------------------------------------------
 * RCC, reset and clock control: RM0440 §7.4 "RCC registers", base 0x4002 1000
 * ------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t CR;         /* 0x00 clock control */
    volatile uint32_t ICSCR;      /* 0x04 internal clock sources calibration */
    volatile uint32_t CFGR;       /* 0x08 clock configuration */
    volatile uint32_t PLLCFGR;    /* 0x0C PLL configuration */
    uint32_t reserved0[2];        /* 0x10, 0x14 */
    volatile uint32_t CIER;       /* 0x18 */
    volatile uint32_t CIFR;       /* 0x1C */
    volatile uint32_t CICR;       /* 0x20 */
    uint32_t reserved1;           /* 0x24 */
    volatile uint32_t AHB1RSTR;   /* 0x28 */
    volatile uint32_t AHB2RSTR;   /* 0x2C */
    volatile uint32_t AHB3RSTR;   /* 0x30 */
    uint32_t reserved2;           /* 0x34 */
    volatile uint32_t APB1RSTR1;  /* 0x38 */
    volatile uint32_t APB1RSTR2;  /* 0x3C */
    volatile uint32_t APB2RSTR;   /* 0x40 */
    uint32_t reserved3;           /* 0x44 */
    volatile uint32_t AHB1ENR;    /* 0x48 */
    volatile uint32_t AHB2ENR;    /* 0x4C */
    volatile uint32_t AHB3ENR;    /* 0x50 */
    uint32_t reserved4;           /* 0x54 */
    volatile uint32_t APB1ENR1;   /* 0x58 */
    volatile uint32_t APB1ENR2;   /* 0x5C */
    volatile uint32_t APB2ENR;    /* 0x60 */
    uint32_t reserved5;           /* 0x64 */
    volatile uint32_t AHB1SMENR;  /* 0x68 */
    volatile uint32_t AHB2SMENR;  /* 0x6C */
    volatile uint32_t AHB3SMENR;  /* 0x70 */
    uint32_t reserved6;           /* 0x74 */
    volatile uint32_t APB1SMENR1; /* 0x78 */
    volatile uint32_t APB1SMENR2; /* 0x7C */
    volatile uint32_t APB2SMENR;  /* 0x80 */
    uint32_t reserved7;           /* 0x84 */
    volatile uint32_t CCIPR;      /* 0x88 peripherals independent clock configuration */
    uint32_t reserved8;           /* 0x8C */
    volatile uint32_t BDCR;       /* 0x90 */
    volatile uint32_t CSR;        /* 0x94 */
    volatile uint32_t CRRCR;      /* 0x98 */
    volatile uint32_t CCIPR2;     /* 0x9C */
} stm32g4_rcc_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_rcc_t, PLLCFGR) == 0x0C, rcc_pllcfgr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_rcc_t, AHB2ENR) == 0x4C, rcc_ahb2enr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_rcc_t, APB1ENR1) == 0x58, rcc_apb1enr1);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_rcc_t, APB2ENR) == 0x60, rcc_apb2enr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_rcc_t, CCIPR) == 0x88, rcc_ccipr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_rcc_t, CCIPR2) == 0x9C, rcc_ccipr2);

/* RCC_CR (§7.4.1) */
#define RCC_CR_HSION STM32G4_BIT(8)
#define RCC_CR_HSIRDY STM32G4_BIT(10)
#define RCC_CR_HSEON STM32G4_BIT(16)
#define RCC_CR_HSERDY STM32G4_BIT(17)
#define RCC_CR_PLLON STM32G4_BIT(24)
#define RCC_CR_PLLRDY STM32G4_BIT(25)
/* RCC_CFGR (§7.4.3): SW[1:0], SWS[3:2] (01 HSI16, 10 HSE, 11 PLL "R"), HPRE[7:4], PPRE1[10:8], PPRE2[13:11] */
#define RCC_CFGR_SW_POS 0u
#define RCC_CFGR_SW_MASK (3u << RCC_CFGR_SW_POS)
#define RCC_CFGR_SWS_POS 2u
#define RCC_CFGR_SWS_MASK (3u << RCC_CFGR_SWS_POS)
#define RCC_CFGR_SW_PLL 3u
#define RCC_CFGR_HPRE_POS 4u
#define RCC_CFGR_HPRE_MASK (0xFu << RCC_CFGR_HPRE_POS)
#define RCC_CFGR_HPRE_DIV1 0u
#define RCC_CFGR_HPRE_DIV2 8u
#define RCC_CFGR_PPRE1_POS 8u
#define RCC_CFGR_PPRE1_MASK (7u << RCC_CFGR_PPRE1_POS)
#define RCC_CFGR_PPRE2_POS 11u
#define RCC_CFGR_PPRE2_MASK (7u << RCC_CFGR_PPRE2_POS)
/* RCC_PLLCFGR (§7.4.4): PLLSRC[1:0] (10 HSI16, 11 HSE), PLLM[7:4] = M-1, PLLN[14:8] = N,
 * PLLPEN 16, PLLQEN 20, PLLREN 24, PLLR[26:25] (00 /2, 01 /4, 10 /6, 11 /8) */
#define RCC_PLLCFGR_PLLSRC_HSI16 2u
#define RCC_PLLCFGR_PLLM_POS 4u
#define RCC_PLLCFGR_PLLN_POS 8u
#define RCC_PLLCFGR_PLLREN STM32G4_BIT(24)
#define RCC_PLLCFGR_PLLR_POS 25u
/* RCC_AHB2ENR (§7.4.15): GPIOxEN bits 0..6, ADC12EN 13 */
#define RCC_AHB2ENR_GPIOAEN_POS 0u
#define RCC_AHB2ENR_ADC12EN STM32G4_BIT(13)
/* RCC_APB1ENR1 (§7.4.17): TIM4EN 2, PWREN 28 */
#define RCC_APB1ENR1_TIM4EN STM32G4_BIT(2)
#define RCC_APB1ENR1_PWREN STM32G4_BIT(28)
/* RCC_APB2ENR (§7.4.19): SYSCFGEN 0, TIM1EN 11 */
#define RCC_APB2ENR_SYSCFGEN STM32G4_BIT(0)
#define RCC_APB2ENR_TIM1EN STM32G4_BIT(11)

/* ---------------------------------------------------------------------------
 * PWR, power control: RM0440 §6.4 "PWR registers", base 0x4000 7000
 * ------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t CR1;             /* 0x00 */
    volatile uint32_t CR2;             /* 0x04 */
    volatile uint32_t CR3;             /* 0x08 */
    volatile uint32_t CR4;             /* 0x0C */
    volatile uint32_t SR1;             /* 0x10 */
    volatile uint32_t SR2;             /* 0x14 */
    volatile uint32_t SCR;             /* 0x18 */
    uint32_t reserved0;                /* 0x1C */
    volatile uint32_t PUCRA_PDCRG[14]; /* 0x20 .. 0x54: pull-up/down control A..G */
    uint32_t reserved1[10];            /* 0x58 .. 0x7C */
    volatile uint32_t CR5;             /* 0x80 */
} stm32g4_pwr_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_pwr_t, SR2) == 0x14, pwr_sr2);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_pwr_t, CR5) == 0x80, pwr_cr5);
/* PWR_CR1 VOS[10:9] = 01: range 1; PWR_SR2 VOSF bit 10; PWR_CR5 R1MODE bit 8 (0: range 1 boost mode,
 * needed above 150 MHz, §6.1.5 "Dynamic voltage scaling management") */
#define PWR_CR1_VOS_POS 9u
#define PWR_CR1_VOS_MASK (3u << PWR_CR1_VOS_POS)
#define PWR_CR1_VOS_RANGE1 (1u << PWR_CR1_VOS_POS)
#define PWR_SR2_VOSF STM32G4_BIT(10)
#define PWR_CR5_R1MODE STM32G4_BIT(8)

/* ---------------------------------------------------------------------------
 * FLASH interface: RM0440 §3.7 "FLASH registers", base 0x4002 2000
 * ------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t ACR;      /* 0x00 access control */
    volatile uint32_t PDKEYR;   /* 0x04 power-down key */
    volatile uint32_t KEYR;     /* 0x08 key: unlocks FLASH_CR (write-only) */
    volatile uint32_t OPTKEYR;  /* 0x0C option key */
    volatile uint32_t SR;       /* 0x10 status */
    volatile uint32_t CR;       /* 0x14 control */
    volatile uint32_t ECCR;     /* 0x18 ECC */
    uint32_t reserved0;         /* 0x1C */
    volatile uint32_t OPTR;     /* 0x20 option */
    volatile uint32_t PCROP1SR; /* 0x24 PCROP area start */
    volatile uint32_t PCROP1ER; /* 0x28 PCROP area end */
    volatile uint32_t WRP1AR;   /* 0x2C write protection area A */
    volatile uint32_t WRP1BR;   /* 0x30 write protection area B */
} stm32g4_flash_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_flash_t, KEYR) == 0x08, flash_keyr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_flash_t, SR) == 0x10, flash_sr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_flash_t, CR) == 0x14, flash_cr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_flash_t, ECCR) == 0x18, flash_eccr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_flash_t, OPTR) == 0x20, flash_optr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_flash_t, WRP1BR) == 0x30, flash_wrp1br);
/* FLASH_ACR (§3.7.1): LATENCY[3:0], PRFTEN 8, ICEN 9, DCEN 10, ICRST 11, DCRST 12 (a cache reset
 * bit can be written only while that cache is disabled). Wait states (§3.3.3, Table 9
 * "Number of wait states according to CPU clock (HCLK) frequency"): range 1 boost mode one per
 * 34 MHz of HCLK (4 WS up to 170 MHz), range 1 normal mode one per 30 MHz (up to 150 MHz). */
#define FLASH_ACR_LATENCY_MASK 0xFu
#define FLASH_ACR_PRFTEN STM32G4_BIT(8)
#define FLASH_ACR_ICEN STM32G4_BIT(9)
#define FLASH_ACR_DCEN STM32G4_BIT(10)
#define FLASH_ACR_ICRST STM32G4_BIT(11)
#define FLASH_ACR_DCRST STM32G4_BIT(12)
/* FLASH_KEYR (§3.7.3): KEY1 then KEY2 clears FLASH_CR.LOCK; any other sequence locks FLASH_CR
 * until the next reset (§3.3.5 "Flash program and erase operations", unlocking). */
#define FLASH_KEY1 0x45670123u
#define FLASH_KEY2 0xCDEF89ABu
/* FLASH_SR (§3.7.5): EOP 0 (only with EOPIE), OPERR 1 (only with ERRIE), PROGERR 3, WRPERR 4,
 * PGAERR 5, SIZERR 6, PGSERR 7, MISERR 8, FASTERR 9, RDERR 14 (only with RDERRIE), OPTVERR 15,
 * each cleared by writing 1; BSY 16 (read-only: an operation runs). */
#define FLASH_SR_EOP STM32G4_BIT(0)
#define FLASH_SR_OPERR STM32G4_BIT(1)
#define FLASH_SR_PROGERR STM32G4_BIT(3)
#define FLASH_SR_WRPERR STM32G4_BIT(4)
#define FLASH_SR_PGAERR STM32G4_BIT(5)
#define FLASH_SR_SIZERR STM32G4_BIT(6)
#define FLASH_SR_PGSERR STM32G4_BIT(7)
#define FLASH_SR_MISERR STM32G4_BIT(8)
#define FLASH_SR_FASTERR STM32G4_BIT(9)
#define FLASH_SR_RDERR STM32G4_BIT(14)
#define FLASH_SR_OPTVERR STM32G4_BIT(15)
#define FLASH_SR_BSY STM32G4_BIT(16)
#define FLASH_SR_ERRORS                                                                                        \
    (FLASH_SR_OPERR | FLASH_SR_PROGERR | FLASH_SR_WRPERR | FLASH_SR_PGAERR | FLASH_SR_SIZERR | FLASH_SR_PGSERR \
     | FLASH_SR_MISERR | FLASH_SR_FASTERR | FLASH_SR_RDERR | FLASH_SR_OPTVERR)
/* The flags of a programming error: while one is set, the next program or erase start is refused
 * with PGSERR (§3.7.5 PGSERR; §3.3.6, §3.3.7 step "check and clear all error programming flags"). */
#define FLASH_SR_PROGRAMMING_ERRORS                                                                             \
    (FLASH_SR_PROGERR | FLASH_SR_WRPERR | FLASH_SR_PGAERR | FLASH_SR_SIZERR | FLASH_SR_PGSERR | FLASH_SR_MISERR \
     | FLASH_SR_FASTERR)
/* FLASH_CR (§3.7.6, reset value 0xC000 0000): PG 0, PER 1, MER1 2, PNB[8:3] (the page of a page
 * erase; 6 bits on the category 2 devices, 64 pages), STRT 16 (starts an erase; cleared by
 * hardware when BSY clears), OPTSTRT 17, FSTPG 18, EOPIE 24, ERRIE 25, RDERRIE 26, OBL_LAUNCH 27,
 * SEC_PROT1 28, OPTLOCK 30, LOCK 31 (set by software, cleared only by the key sequence). */
#define FLASH_CR_PG STM32G4_BIT(0)
#define FLASH_CR_PER STM32G4_BIT(1)
#define FLASH_CR_MER1 STM32G4_BIT(2)
#define FLASH_CR_PNB_POS 3u
#define FLASH_CR_PNB_MASK (0x3Fu << FLASH_CR_PNB_POS)
#define FLASH_CR_STRT STM32G4_BIT(16)
#define FLASH_CR_OPTSTRT STM32G4_BIT(17)
#define FLASH_CR_FSTPG STM32G4_BIT(18)
#define FLASH_CR_EOPIE STM32G4_BIT(24)
#define FLASH_CR_ERRIE STM32G4_BIT(25)
#define FLASH_CR_RDERRIE STM32G4_BIT(26)
#define FLASH_CR_OPTLOCK STM32G4_BIT(30)
#define FLASH_CR_LOCK STM32G4_BIT(31)
/* FLASH_ECCR (§3.7.7): ADDR_ECC[17:0] (byte offset from the start of the flash of the double
 * word that failed), SYSF_ECC 22 (the failure is in the system flash), ECCIE 24, ECCC 30 (a
 * single error corrected), ECCD 31 (a double error detected: raises the NMI); ECCC and ECCD are
 * cleared by writing 1, and a new failure is recorded only while both are clear (§3.3.2 "Error
 * code correction (ECC)"). */
#define FLASH_ECCR_ADDR_ECC_MASK 0x3FFFFu
#define FLASH_ECCR_SYSF_ECC STM32G4_BIT(22)
#define FLASH_ECCR_ECCIE STM32G4_BIT(24)
#define FLASH_ECCR_ECCC STM32G4_BIT(30)
#define FLASH_ECCR_ECCD STM32G4_BIT(31)
/* The main flash of the STM32G431xB (§3.3.1 "Flash memory organization", category 2 devices): one
 * bank of 128 KiB at 0x0800 0000, 64 pages of 2 KiB, rows of 64-bit double words (each with 8
 * ECC bits), programmed one double word at a time (§3.3.7 "Flash main memory programming
 * sequences", standard programming). */
#define STM32G4_FLASH_MEM_BASE 0x08000000u
#define STM32G4_FLASH_MEM_BYTES 0x20000u
#define STM32G4_FLASH_PAGE_BYTES 2048u
#define STM32G4_FLASH_PAGES 64u
#define STM32G4_FLASH_DOUBLE_WORD_BYTES 8u

/* ---------------------------------------------------------------------------
 * GPIO: RM0440 §9.4 "GPIO registers", GPIOA 0x4800 0000, one port per 0x400 (A..G)
 * ------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t MODER;   /* 0x00 00 input, 01 output, 10 alternate function, 11 analog */
    volatile uint32_t OTYPER;  /* 0x04 */
    volatile uint32_t OSPEEDR; /* 0x08 */
    volatile uint32_t PUPDR;   /* 0x0C 01 pull-up, 10 pull-down */
    volatile uint32_t IDR;     /* 0x10 */
    volatile uint32_t ODR;     /* 0x14 */
    volatile uint32_t BSRR;    /* 0x18 bits 0..15 set, 16..31 reset */
    volatile uint32_t LCKR;    /* 0x1C */
    volatile uint32_t AFR[2];  /* 0x20 AFRL (pins 0..7), 0x24 AFRH (pins 8..15), 4 bits per pin */
    volatile uint32_t BRR;     /* 0x28 */
} stm32g4_gpio_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_gpio_t, BSRR) == 0x18, gpio_bsrr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_gpio_t, AFR) == 0x20, gpio_afr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_gpio_t, BRR) == 0x28, gpio_brr);
/* GPIOx_OTYPER (§9.4.2): 1 = open drain (the output drives low or lets the line go) */
#define GPIO_MODE_INPUT 0u
#define GPIO_MODE_OUTPUT 1u
#define GPIO_MODE_AF 2u
#define GPIO_MODE_ANALOG 3u
#define GPIO_PULL_UP 1u
#define GPIO_PULL_DOWN 2u
#define GPIO_SPEED_VERY_HIGH 3u
#define STM32G4_GPIO_PORTS 7u

/* ---------------------------------------------------------------------------
 * TIM1, advanced-control timer: RM0440 §28.6 "TIM1/TIM8/TIM20 registers", base 0x4001 2C00
 * ------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t CR1;   /* 0x00 */
    volatile uint32_t CR2;   /* 0x04 */
    volatile uint32_t SMCR;  /* 0x08 */
    volatile uint32_t DIER;  /* 0x0C */
    volatile uint32_t SR;    /* 0x10 flags, cleared by writing 0 */
    volatile uint32_t EGR;   /* 0x14 */
    volatile uint32_t CCMR1; /* 0x18 */
    volatile uint32_t CCMR2; /* 0x1C */
    volatile uint32_t CCER;  /* 0x20 */
    volatile uint32_t CNT;   /* 0x24 */
    volatile uint32_t PSC;   /* 0x28 */
    volatile uint32_t ARR;   /* 0x2C */
    volatile uint32_t RCR;   /* 0x30 */
    volatile uint32_t CCR1;  /* 0x34 */
    volatile uint32_t CCR2;  /* 0x38 */
    volatile uint32_t CCR3;  /* 0x3C */
    volatile uint32_t CCR4;  /* 0x40 */
    volatile uint32_t BDTR;  /* 0x44 */
    volatile uint32_t CCR5;  /* 0x48 */
    volatile uint32_t CCR6;  /* 0x4C */
    volatile uint32_t CCMR3; /* 0x50 channels 5 and 6 */
    volatile uint32_t DTR2;  /* 0x54 */
    volatile uint32_t ECR;   /* 0x58 */
    volatile uint32_t TISEL; /* 0x5C */
    volatile uint32_t AF1;   /* 0x60 */
    volatile uint32_t AF2;   /* 0x64 */
    uint32_t reserved0[221]; /* 0x68 .. 0x3D8 */
    volatile uint32_t DCR;   /* 0x3DC */
    volatile uint32_t DMAR;  /* 0x3E0 */
} stm32g4_tim_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_tim_t, CCER) == 0x20, tim_ccer);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_tim_t, RCR) == 0x30, tim_rcr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_tim_t, BDTR) == 0x44, tim_bdtr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_tim_t, CCMR3) == 0x50, tim_ccmr3);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_tim_t, AF1) == 0x60, tim_af1);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_tim_t, DCR) == 0x3DC, tim_dcr);
/* TIMx_CR1 (§28.6.1): CEN 0, UDIS 1, URS 2, CMS[6:5] (01: centre-aligned mode 1), ARPE 7 */
#define TIM_CR1_CEN STM32G4_BIT(0)
#define TIM_CR1_URS STM32G4_BIT(2)
#define TIM_CR1_CMS_POS 5u
#define TIM_CR1_CMS_CENTER1 (1u << TIM_CR1_CMS_POS)
#define TIM_CR1_ARPE STM32G4_BIT(7)
/* TIMx_CR2 (§28.6.2): OISx (idle output levels) bits 8..15, MMS2[23:20] (TRGO2 source:
 * 1000 = OC5REFC, the ADC trigger here) */
#define TIM_CR2_MMS2_POS 20u
#define TIM_CR2_MMS2_MASK (0xFu << TIM_CR2_MMS2_POS)
#define TIM_CR2_MMS2_OC5REFC 8u
/* TIMx_DIER (§28.6.4): BIE 7 */
#define TIM_DIER_BIE STM32G4_BIT(7)
/* TIMx_SR (§28.6.5): UIF 0, BIF 7, B2IF 8 */
#define TIM_SR_UIF STM32G4_BIT(0)
#define TIM_SR_BIF STM32G4_BIT(7)
#define TIM_SR_B2IF STM32G4_BIT(8)
/* TIMx_EGR (§28.6.6): UG 0 */
#define TIM_EGR_UG STM32G4_BIT(0)
/* TIMx_CCMRx output compare (§28.6.7, §28.6.9, §28.6.23): per channel pair, OCxPE bit 3 (+8),
 * OCxM[6:4] (+8) with OCxM[3] at bit 16 (+8); 0110 PWM mode 1, 0111 PWM mode 2 */
#define TIM_CCMR_OC_LOW_POS 0u
#define TIM_CCMR_OC_HIGH_POS 8u
#define TIM_CCMR_OCPE STM32G4_BIT(3)
#define TIM_CCMR_OCM_POS 4u
#define TIM_OCM_PWM1 6u
#define TIM_OCM_PWM2 7u
/* TIMx_CCER (§28.6.11): channel n (1..4) at 4(n-1): CCxE, CCxP, CCxNE, CCxNP; CC5E 16, CC5P 17 */
#define TIM_CCER_CCE(n) STM32G4_BIT(4u * ((n)-1u))
#define TIM_CCER_CCNE(n) STM32G4_BIT(4u * ((n)-1u) + 2u)
#define TIM_CCER_CC5E STM32G4_BIT(16)
/* TIMx_BDTR (§28.6.20): DTG[7:0], OSSI 10, OSSR 11, BKE 12, BKP 13 (1: break active high),
 * AOE 14, MOE 15, BKF[19:16] */
#define TIM_BDTR_DTG_MASK 0xFFu
#define TIM_BDTR_OSSI STM32G4_BIT(10)
#define TIM_BDTR_OSSR STM32G4_BIT(11)
#define TIM_BDTR_BKE STM32G4_BIT(12)
#define TIM_BDTR_BKP STM32G4_BIT(13)
#define TIM_BDTR_AOE STM32G4_BIT(14)
#define TIM_BDTR_MOE STM32G4_BIT(15)
#define TIM_BDTR_BKF_POS 16u
/* TIMx_AF1 (§28.6.25): BKINE 0 (BKIN pin input enable, 1 at reset), BKINP 9 (BKIN polarity) */
#define TIM_AF1_BKINE STM32G4_BIT(0)
#define TIM_AF1_BKINP STM32G4_BIT(9)

/* ---------------------------------------------------------------------------
 * TIM4, general-purpose 16-bit timer: RM0440 chapter 29 "General-purpose timers
 * (TIM2/TIM3/TIM4/TIM5)", registers §29.5, base 0x4000 0800 (APB1). Same register layout as
 * TIM1 (stm32g4_tim_t; RCR, BDTR, CCR5, CCR6, CCMR3 and DTR2 are reserved on it). The STEP/DIR
 * input counts with it.
 * ------------------------------------------------------------------------- */
/* TIMx_CR1 (§29.5.1): DIR 4 (read-only in encoder mode: the last count's direction), CKD[9:8]
 * (t_DTS = t_CK_INT << CKD; 00 here) */
#define TIM_CR1_DIR STM32G4_BIT(4)
#define TIM_CR1_CKD_POS 8u
#define TIM_CR1_CKD_MASK (3u << TIM_CR1_CKD_POS)
/* TIMx_SMCR (§29.5.3): SMS[3:0] at bits 16, 2, 1, 0. 1010: encoder mode, clock plus direction, x2
 * (both edges of tim_ti2fp2 counted); 1011: clock plus direction, x1 (one edge of tim_ti2fp2, the
 * one CC2P selects); the direction from the level of tim_ti1fp1 (CC1P = 0: up while tim_ti1 is
 * high). §29.4 "Encoder interface mode", "Clock plus direction encoder mode". */
#define TIM_SMCR_SMS_LOW_MASK 7u
#define TIM_SMCR_SMS_BIT3 STM32G4_BIT(16)
#define TIM_SMCR_SMS_MASK (TIM_SMCR_SMS_LOW_MASK | TIM_SMCR_SMS_BIT3)
#define TIM_SMCR_SMS_CLOCK_DIR_X2 (TIM_SMCR_SMS_BIT3 | 2u)
#define TIM_SMCR_SMS_CLOCK_DIR_X1 (TIM_SMCR_SMS_BIT3 | 3u)
/* TIMx_CCMR1 input capture mode (§29.5.7): CC1S[1:0] (01: IC1 on tim_ti1), IC1PSC[3:2], IC1F[7:4];
 * CC2S[9:8] (01: IC2 on tim_ti2), IC2PSC[11:10], IC2F[15:12]. ICxF: the digital filter, an edge
 * passes after N consecutive samples at the new level, sampled at f_SAMPLING:
 * 0000 none (f_DTS, N = 1); 0001..0011 f_CK_INT, N = 2, 4, 8; 0100/0101 f_DTS/2, N = 6/8;
 * 0110/0111 f_DTS/4, N = 6/8; 1000/1001 f_DTS/8, N = 6/8; 1010..1100 f_DTS/16, N = 5, 6, 8;
 * 1101..1111 f_DTS/32, N = 5, 6, 8. */
#define TIM_CCMR1_CC1S_POS 0u
#define TIM_CCMR1_IC1F_POS 4u
#define TIM_CCMR1_CC2S_POS 8u
#define TIM_CCMR1_IC2F_POS 12u
#define TIM_CCMR_CCS_MASK 3u
#define TIM_CCMR_CCS_INPUT_TI 1u
#define TIM_CCMR_ICF_MASK 0xFu
/* TIMx_CCER (§29.5.11): CC1E 0, CC1P 1, CC1NP 3, CC2E 4, CC2P 5, CC2NP 7 */
#define TIM_CCER_CC1P STM32G4_BIT(1)
#define TIM_CCER_CC1NP STM32G4_BIT(3)
#define TIM_CCER_CC2P STM32G4_BIT(5)
#define TIM_CCER_CC2NP STM32G4_BIT(7)
/* TIMx_TISEL (§29.5.25): TI1SEL[3:0], TI2SEL[11:8]; 0000 = the TIMx_CHx pin */
#define TIM_TISEL_TI1SEL_MASK 0xFu
#define TIM_TISEL_TI2SEL_MASK (0xFu << 8)

/* ---------------------------------------------------------------------------
 * ADC1/ADC2: RM0440 §21.7 "ADC registers (for each ADC)", ADC1 0x5000 0000, ADC2 0x5000 0100;
 * common registers of ADC1/ADC2 §21.8, at 0x5000 0300
 * ------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t ISR;     /* 0x00 flags, cleared by writing 1 */
    volatile uint32_t IER;     /* 0x04 */
    volatile uint32_t CR;      /* 0x08 */
    volatile uint32_t CFGR;    /* 0x0C */
    volatile uint32_t CFGR2;   /* 0x10 */
    volatile uint32_t SMPR1;   /* 0x14 sample time, channels 0..9 (3 bits each) */
    volatile uint32_t SMPR2;   /* 0x18 channels 10..18 */
    uint32_t reserved0;        /* 0x1C */
    volatile uint32_t TR1;     /* 0x20 */
    volatile uint32_t TR2;     /* 0x24 */
    volatile uint32_t TR3;     /* 0x28 */
    uint32_t reserved1;        /* 0x2C */
    volatile uint32_t SQR1;    /* 0x30 */
    volatile uint32_t SQR2;    /* 0x34 */
    volatile uint32_t SQR3;    /* 0x38 */
    volatile uint32_t SQR4;    /* 0x3C */
    volatile uint32_t DR;      /* 0x40 */
    uint32_t reserved2[2];     /* 0x44, 0x48 */
    volatile uint32_t JSQR;    /* 0x4C injected sequence */
    uint32_t reserved3[4];     /* 0x50 .. 0x5C */
    volatile uint32_t OFR[4];  /* 0x60 .. 0x6C */
    uint32_t reserved4[4];     /* 0x70 .. 0x7C */
    volatile uint32_t JDR[4];  /* 0x80 .. 0x8C injected data */
    uint32_t reserved5[4];     /* 0x90 .. 0x9C */
    volatile uint32_t AWD2CR;  /* 0xA0 */
    volatile uint32_t AWD3CR;  /* 0xA4 */
    uint32_t reserved6[2];     /* 0xA8, 0xAC */
    volatile uint32_t DIFSEL;  /* 0xB0 */
    volatile uint32_t CALFACT; /* 0xB4 */
    uint32_t reserved7[2];     /* 0xB8, 0xBC */
    volatile uint32_t GCOMP;   /* 0xC0 */
} stm32g4_adc_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_adc_t, SMPR1) == 0x14, adc_smpr1);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_adc_t, DR) == 0x40, adc_dr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_adc_t, JSQR) == 0x4C, adc_jsqr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_adc_t, JDR) == 0x80, adc_jdr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_adc_t, DIFSEL) == 0xB0, adc_difsel);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_adc_t, GCOMP) == 0xC0, adc_gcomp);

typedef struct {
    volatile uint32_t CSR; /* 0x00 (0x300 from ADC1) */
    uint32_t reserved0;    /* 0x04 */
    volatile uint32_t CCR; /* 0x08 */
    volatile uint32_t CDR; /* 0x0C */
} stm32g4_adc_common_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_adc_common_t, CCR) == 0x08, adc_ccr);

/* ADC_ISR / ADC_IER (§21.7.1, §21.7.2): ADRDY 0, EOC 2, EOS 3, OVR 4, JEOC 5, JEOS 6, JQOVF 10 */
#define ADC_ISR_ADRDY STM32G4_BIT(0)
#define ADC_ISR_JEOC STM32G4_BIT(5)
#define ADC_ISR_JEOS STM32G4_BIT(6)
#define ADC_IER_JEOSIE STM32G4_BIT(6)
/* ADC_CR (§21.7.3): ADEN 0, ADDIS 1, ADSTART 2, JADSTART 3, ADSTP 4, JADSTP 5, ADVREGEN 28,
 * DEEPPWD 29, ADCALDIF 30, ADCAL 31. The bits written by setting ("rs") must be masked out of
 * read-modify-writes, or a write could start what it reads as running. */
#define ADC_CR_ADEN STM32G4_BIT(0)
#define ADC_CR_ADDIS STM32G4_BIT(1)
#define ADC_CR_ADSTART STM32G4_BIT(2)
#define ADC_CR_JADSTART STM32G4_BIT(3)
#define ADC_CR_ADSTP STM32G4_BIT(4)
#define ADC_CR_JADSTP STM32G4_BIT(5)
#define ADC_CR_ADVREGEN STM32G4_BIT(28)
#define ADC_CR_DEEPPWD STM32G4_BIT(29)
#define ADC_CR_ADCALDIF STM32G4_BIT(30)
#define ADC_CR_ADCAL STM32G4_BIT(31)
#define ADC_CR_RS_BITS \
    (ADC_CR_ADCAL | ADC_CR_JADSTP | ADC_CR_ADSTP | ADC_CR_JADSTART | ADC_CR_ADSTART | ADC_CR_ADDIS | ADC_CR_ADEN)
/* ADC_CFGR (§21.7.4): JQDIS 31 (1 at reset: no injected queue, JSQR written directly) */
#define ADC_CFGR_JQDIS STM32G4_BIT(31)
/* ADC_JSQR (§21.7.16): JL[1:0] = conversions - 1, JEXTSEL[6:2], JEXTEN[8:7] (01 rising edge),
 * JSQ1[13:9], JSQ2[19:15], JSQ3[25:21], JSQ4[31:27] */
#define ADC_JSQR_JL_POS 0u
#define ADC_JSQR_JEXTSEL_POS 2u
#define ADC_JSQR_JEXTEN_POS 7u
#define ADC_JSQR_JEXTEN_RISING 1u
#define ADC_JSQR_JSQ1_POS 9u
#define ADC_JSQR_JSQ2_POS 15u
/* Injected trigger of ADC1/ADC2: jext8 = TIM1_TRGO2 (§21.4.18, Table 164 "ADC1/ADC2 - External
 * triggers for injected channels") */
#define ADC12_JEXTSEL_TIM1_TRGO2 8u
/* ADC_CCR (§21.8.2): CKMODE[17:16] = 11: synchronous clock HCLK/4 (42.5 MHz at 170 MHz, below the
 * 60 MHz limit); a synchronous clock keeps the trigger-to-sample latency fixed */
#define ADC_CCR_CKMODE_POS 16u
#define ADC_CCR_CKMODE_MASK (3u << ADC_CCR_CKMODE_POS)
#define ADC_CCR_CKMODE_HCLK_DIV4 (3u << ADC_CCR_CKMODE_POS)
#define ADC_CHANNEL_MAX 18u

/* ---------------------------------------------------------------------------
 * LPUART1: RM0440 §38.7 "LPUART registers", base 0x4000 8000 (the NUCLEO's virtual COM port)
 * ------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t CR1;   /* 0x00 */
    volatile uint32_t CR2;   /* 0x04 */
    volatile uint32_t CR3;   /* 0x08 */
    volatile uint32_t BRR;   /* 0x0C 256 f_ck / baud, 0x300..0xFFFFF */
    uint32_t reserved0[2];   /* 0x10, 0x14 */
    volatile uint32_t RQR;   /* 0x18 */
    volatile uint32_t ISR;   /* 0x1C */
    volatile uint32_t ICR;   /* 0x20 flags cleared by writing 1 */
    volatile uint32_t RDR;   /* 0x24 */
    volatile uint32_t TDR;   /* 0x28 */
    volatile uint32_t PRESC; /* 0x2C */
} stm32g4_lpuart_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_lpuart_t, ISR) == 0x1C, lpuart_isr);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_lpuart_t, PRESC) == 0x2C, lpuart_presc);
/* LPUART_CR1 (§38.7.1): UE 0, RE 2, TE 3. LPUART_ISR (§38.7.8): PE 0, FE 1, NE 2, ORE 3, RXNE 5,
 * TXE 7. LPUART_ICR (§38.7.9): PECF 0, FECF 1, NECF 2, ORECF 3. RCC_APB1ENR2 (§7.4.18): LPUART1EN 0.
 * RCC_CCIPR (§7.4.26): LPUART1SEL[11:10], 00 = PCLK1. */
#define LPUART_CR1_UE STM32G4_BIT(0)
#define LPUART_CR1_RE STM32G4_BIT(2)
#define LPUART_CR1_TE STM32G4_BIT(3)
#define LPUART_ISR_ERRORS (STM32G4_BIT(0) | STM32G4_BIT(1) | STM32G4_BIT(2) | STM32G4_BIT(3))
#define LPUART_ISR_RXNE STM32G4_BIT(5)
#define LPUART_ISR_TXE STM32G4_BIT(7)
#define LPUART_BRR_MIN 0x300u
#define LPUART_BRR_MAX 0xFFFFFu
#define RCC_APB1ENR2_LPUART1EN STM32G4_BIT(0)
#define RCC_CCIPR_LPUART1SEL_MASK (3u << 10)

/* ---------------------------------------------------------------------------
 * Cortex-M4 core peripherals (ARMv7-M ARM, ARM DDI 0403E)
 * ------------------------------------------------------------------------- */
/* NVIC (B3.4.3): ISER 0xE000E100, ICER 0xE000E180, ISPR 0xE000E200, ICPR 0xE000E280,
 * IPR 0xE000E400 (one byte per interrupt; the STM32G4 implements the upper 4 bits) */
typedef struct {
    volatile uint32_t ISER[8]; /* 0x000 */
    uint32_t reserved0[24];
    volatile uint32_t ICER[8]; /* 0x080 */
    uint32_t reserved1[24];
    volatile uint32_t ISPR[8]; /* 0x100 */
    uint32_t reserved2[24];
    volatile uint32_t ICPR[8]; /* 0x180 */
    uint32_t reserved3[24];
    volatile uint32_t IABR[8]; /* 0x200 */
    uint32_t reserved4[56];
    volatile uint8_t IPR[240]; /* 0x300 */
} stm32g4_nvic_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_nvic_t, ICER) == 0x80, nvic_icer);
STM32G4_STATIC_ASSERT(offsetof(stm32g4_nvic_t, IPR) == 0x300, nvic_ipr);
/* SCB (B3.2.2): VTOR 0xE000ED08, CPACR 0xE000ED88 (CP10/CP11 at bits 20..23) */
typedef struct {
    volatile uint32_t VTOR;  /* 0xE000ED08 */
    uint32_t reserved0[31];  /* 0xE000ED0C .. 0xE000ED84 */
    volatile uint32_t CPACR; /* 0xE000ED88 */
} stm32g4_scb_t;
STM32G4_STATIC_ASSERT(offsetof(stm32g4_scb_t, CPACR) == 0x80, scb_cpacr);
#define SCB_CPACR_CP10_CP11_FULL (0xFu << 20)
/* Debug: DEMCR 0xE000EDFC, TRCENA bit 24 (C1.6.5); DWT_CTRL 0xE0001000 CYCCNTENA bit 0,
 * DWT_CYCCNT 0xE0001004 (C1.8.7, C1.8.8) */
typedef struct {
    volatile uint32_t CTRL;   /* 0xE0001000 */
    volatile uint32_t CYCCNT; /* 0xE0001004 */
} stm32g4_dwt_t;
#define DWT_CTRL_CYCCNTENA STM32G4_BIT(0)
#define DEMCR_TRCENA STM32G4_BIT(24)

/* Interrupt numbers (RM0440 §14.3, Table 97 "STM32G4 Series vector table") */
#define STM32G4_IRQ_ADC1_2 18u
#define STM32G4_IRQ_TIM1_BRK_TIM15 24u
#define STM32G4_IRQ_COUNT 102u

/* Base addresses (RM0440 Table 4) */
#define STM32G4_TIM4_BASE 0x40000800u
#define STM32G4_PWR_BASE 0x40007000u
#define STM32G4_LPUART1_BASE 0x40008000u
#define STM32G4_TIM1_BASE 0x40012C00u
#define STM32G4_RCC_BASE 0x40021000u
#define STM32G4_FLASH_R_BASE 0x40022000u
#define STM32G4_GPIOA_BASE 0x48000000u
#define STM32G4_GPIO_STRIDE 0x400u
#define STM32G4_ADC1_BASE 0x50000000u
#define STM32G4_ADC2_BASE 0x50000100u
#define STM32G4_ADC12_COMMON_BASE 0x50000300u
#define STM32G4_NVIC_BASE 0xE000E100u
#define STM32G4_SCB_VTOR_ADDR 0xE000ED08u
#define STM32G4_DEMCR_ADDR 0xE000EDFCu
#define STM32G4_DWT_BASE 0xE0001000u

#if defined(STM32G4_FAKE_REGISTERS)
/* Host tests: every register in RAM. */
typedef struct {
    stm32g4_rcc_t rcc;
    stm32g4_pwr_t pwr;
    stm32g4_flash_t flash;
    stm32g4_gpio_t gpio[STM32G4_GPIO_PORTS];
    stm32g4_tim_t tim1;
    stm32g4_tim_t tim4;
    stm32g4_adc_t adc1;
    stm32g4_adc_t adc2;
    stm32g4_adc_common_t adc12;
    stm32g4_lpuart_t lpuart1;
    stm32g4_nvic_t nvic;
    stm32g4_scb_t scb;
    volatile uint32_t demcr;
    stm32g4_dwt_t dwt;
} stm32g4_fake_t;
extern stm32g4_fake_t stm32g4_fake;
/** Called in every iteration of a bounded wait loop: the test plays the hardware here. */
void stm32g4_fake_wait_hook(void);
/** A GPIO port's block: every driver access to a port goes through it, so a test can play the
 *  clock gating of the port (writes to a port whose clock is off are lost on the hardware). */
stm32g4_gpio_t *stm32g4_fake_gpio(uint32_t port);
#define STM32G4_RCC (&stm32g4_fake.rcc)
#define STM32G4_PWR (&stm32g4_fake.pwr)
#define STM32G4_FLASH (&stm32g4_fake.flash)
#define STM32G4_GPIO(port) stm32g4_fake_gpio((uint32_t)(port))
#define STM32G4_TIM1 (&stm32g4_fake.tim1)
#define STM32G4_TIM4 (&stm32g4_fake.tim4)
#define STM32G4_ADC1 (&stm32g4_fake.adc1)
#define STM32G4_ADC2 (&stm32g4_fake.adc2)
#define STM32G4_ADC12 (&stm32g4_fake.adc12)
#define STM32G4_LPUART1 (&stm32g4_fake.lpuart1)
#define STM32G4_NVIC (&stm32g4_fake.nvic)
#define STM32G4_SCB (&stm32g4_fake.scb)
#define STM32G4_DEMCR (stm32g4_fake.demcr)
#define STM32G4_DWT (&stm32g4_fake.dwt)
#define STM32G4_WAIT_HOOK() stm32g4_fake_wait_hook()
/** LPUART data registers: a read of RDR takes the byte (and clears RXNE), a write of TDR sends
 *  one; plain RAM cannot show either, so the fake goes through these. */
uint32_t stm32g4_fake_lpuart_rdr(void);
void stm32g4_fake_lpuart_tdr(uint32_t byte);
#define STM32G4_LPUART_READ_RDR(u) ((void)(u), stm32g4_fake_lpuart_rdr())
#define STM32G4_LPUART_WRITE_TDR(u, b) ((void)(u), stm32g4_fake_lpuart_tdr(b))
/** FLASH: a write of a register with side effects (a key, a flag cleared by writing 1, a start
 *  bit) and the flash memory array. Plain RAM would not show two keys written in a row, would
 *  keep a flag "cleared" by writing 1, and has no flash behind the addresses; the model sees each
 *  access through these. @p offset: the register's offset in stm32g4_flash_t. */
void stm32g4_fake_flash_reg_write(uint32_t offset, uint32_t value);
uint32_t stm32g4_fake_flash_read32(uint32_t addr);
void stm32g4_fake_flash_write32(uint32_t addr, uint32_t value);
#define STM32G4_FLASH_REG_WRITE(reg, v) stm32g4_fake_flash_reg_write((uint32_t)offsetof(stm32g4_flash_t, reg), (v))
#define STM32G4_FLASH_MEM_READ32(addr) stm32g4_fake_flash_read32(addr)
#define STM32G4_FLASH_MEM_WRITE32(addr, v) stm32g4_fake_flash_write32((addr), (v))
#define STM32G4_INSTRUCTION_BARRIER() ((void)0)
#else
#define STM32G4_RCC ((stm32g4_rcc_t *)STM32G4_RCC_BASE)
#define STM32G4_PWR ((stm32g4_pwr_t *)STM32G4_PWR_BASE)
#define STM32G4_FLASH ((stm32g4_flash_t *)STM32G4_FLASH_R_BASE)
#define STM32G4_GPIO(port) ((stm32g4_gpio_t *)(STM32G4_GPIOA_BASE + STM32G4_GPIO_STRIDE * (uint32_t)(port)))
#define STM32G4_TIM1 ((stm32g4_tim_t *)STM32G4_TIM1_BASE)
#define STM32G4_TIM4 ((stm32g4_tim_t *)STM32G4_TIM4_BASE)
#define STM32G4_ADC1 ((stm32g4_adc_t *)STM32G4_ADC1_BASE)
#define STM32G4_ADC2 ((stm32g4_adc_t *)STM32G4_ADC2_BASE)
#define STM32G4_ADC12 ((stm32g4_adc_common_t *)STM32G4_ADC12_COMMON_BASE)
#define STM32G4_LPUART1 ((stm32g4_lpuart_t *)STM32G4_LPUART1_BASE)
#define STM32G4_NVIC ((stm32g4_nvic_t *)STM32G4_NVIC_BASE)
#define STM32G4_SCB ((stm32g4_scb_t *)STM32G4_SCB_VTOR_ADDR)
#define STM32G4_DEMCR (*(volatile uint32_t *)STM32G4_DEMCR_ADDR)
#define STM32G4_DWT ((stm32g4_dwt_t *)STM32G4_DWT_BASE)
#define STM32G4_WAIT_HOOK() ((void)0)
#define STM32G4_LPUART_READ_RDR(u) ((u)->RDR)
#define STM32G4_LPUART_WRITE_TDR(u, b) ((u)->TDR = (b))
#define STM32G4_FLASH_REG_WRITE(reg, v) (STM32G4_FLASH->reg = (v))
#define STM32G4_FLASH_MEM_READ32(addr) (*(volatile const uint32_t *)(uintptr_t)(addr))
#define STM32G4_FLASH_MEM_WRITE32(addr, v) (*(volatile uint32_t *)(uintptr_t)(addr) = (v))
/* ISB (ARMv7-M A7.7.37): the instructions before it complete before those after it start. */
#define STM32G4_INSTRUCTION_BARRIER() __asm volatile("isb" ::: "memory")
#endif

#ifdef __cplusplus
}
#endif

#endif /* STM32G4_REGS_H */
