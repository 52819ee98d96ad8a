/*
 * CMSDK APB UART0 of mps2-an386 (base 0x4000 4000; ARM DDI 0479C): DATA 0x00, STATE 0x04
 * (bit 0 TX buffer full, bit 1 RX buffer full), CTRL 0x08 (bit 0 TX enable, bit 1 RX enable),
 * BAUDDIV 0x10 (at least 16).
 */
#include "cmsdk_uart.h"

#define UART0_BASE 0x40004000u
#define UART_DATA (*(volatile uint32_t *)(UART0_BASE + 0x00u))
#define UART_STATE (*(volatile uint32_t *)(UART0_BASE + 0x04u))
#define UART_CTRL (*(volatile uint32_t *)(UART0_BASE + 0x08u))
#define UART_BAUDDIV (*(volatile uint32_t *)(UART0_BASE + 0x10u))
#define STATE_TX_FULL (1u << 0)
#define STATE_RX_FULL (1u << 1)
#define CTRL_TX_EN (1u << 0)
#define CTRL_RX_EN (1u << 1)

void cmsdk_uart_init(uint32_t bauddiv)
{
    UART_CTRL = 0u;
    UART_BAUDDIV = bauddiv < 16u ? 16u : bauddiv;
    UART_CTRL = CTRL_TX_EN | CTRL_RX_EN;
}

uint32_t cmsdk_uart_read(uint8_t *data, uint32_t max)
{
    uint32_t n = 0u;
    while (n < max && (UART_STATE & STATE_RX_FULL) != 0u) {
        data[n++] = (uint8_t)(UART_DATA & 0xFFu);
    }
    return n;
}

uint32_t cmsdk_uart_write(const uint8_t *data, uint32_t n)
{
    uint32_t k = 0u;
    while (k < n && (UART_STATE & STATE_TX_FULL) == 0u) {
        UART_DATA = data[k++];
    }
    return k;
}
