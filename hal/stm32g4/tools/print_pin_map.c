/*
 * Prints the wiring table of the default drive (pmstep_stm32g4_default_config(): a
 * NUCLEO-G431RB with a dual full-bridge stage) as Markdown, from its pin map, after checking
 * it. The README's bring-up table is this program's output.
 */
#include <stdio.h>

#include "pmstep_hal_stm32g4.h"

int main(void)
{
    const pmstep_stm32g4_config_t cfg = pmstep_stm32g4_default_config();
    pmstep_stm32g4_pin_use_t map[18];
    const pmstep_stm32g4_status_t st = pmstep_stm32g4_check_pins(&cfg);
    const uint32_t n = pmstep_stm32g4_pin_map(&cfg, map, 18u);
    uint32_t k;
    if (st != PMSTEP_STM32G4_OK) {
        fprintf(stderr, "pin map refused: %s\n", pmstep_stm32g4_status_str(st));
        return 1;
    }
    printf("| Pin  | MCU signal  | Mode   | Function |\n|------|-------------|--------|----------|\n");
    for (k = 0; k < n; ++k) {
        char signal[24];
        if (map[k].channel != 0u) {
            snprintf(signal, sizeof signal, "%s%u", map[k].signal, (unsigned)map[k].channel);
        } else {
            snprintf(signal, sizeof signal, "%s", map[k].signal);
        }
        char mode[12];
        if (map[k].channel != 0u) {
            snprintf(mode, sizeof mode, "analog");
        } else if (map[k].signal[0] == 'G') {
            snprintf(mode, sizeof mode, "%s", map[k].signal[5] == 'o' ? "output" : "input");
        } else {
            snprintf(mode, sizeof mode, "AF%u", (unsigned)map[k].pin.af);
        }
        printf("| P%c%-2u | %-11s | %-6s | %s |\n", 'A' + map[k].pin.port, (unsigned)map[k].pin.pin, signal, mode,
               map[k].function);
    }
    return 0;
}
