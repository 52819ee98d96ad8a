/**
 * @file cmsdk_uart.h
 * @brief UART0 of the mps2-an386 machine: the Cortex-M System Design Kit APB UART (ARM DDI
 *        0479C, "APB UART"), polled, never waiting. QEMU connects it to its first -serial
 *        backend (a TCP socket, a pty, a file).
 */
#ifndef CMSDK_UART_H
#define CMSDK_UART_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** UART0 with transmitter and receiver on, @p bauddiv (>= 16; QEMU ignores the rate). */
void cmsdk_uart_init(uint32_t bauddiv);

/** Takes up to @p max received bytes (the UART holds one at a time). */
uint32_t cmsdk_uart_read(uint8_t *data, uint32_t max);

/** Sends as many of @p n bytes as the transmitter takes now. @return that count. */
uint32_t cmsdk_uart_write(const uint8_t *data, uint32_t n);

#ifdef __cplusplus
}
#endif

#endif /* CMSDK_UART_H */
