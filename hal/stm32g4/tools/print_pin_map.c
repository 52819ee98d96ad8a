/*
 * Prints the wiring table of the default drive (pmstep_stm32g4_default_config(): a
 * NUCLEO-G431RB with a dual full-bridge stage) as Markdown, from its pin map, after checking
 * it, with the STEP/DIR input enabled (its four pins last; a build without the STEP/DIR mode
 * leaves them free). The wiring table of docs/getting-started/nucleo-g431rb.md is this
 * program's output.
 */
#include <stdio.h>

#include "pmstep_hal_stm32g4.h"

int main(void)
{
    pmstep_stm32g4_config_t cfg = pmstep_stm32g4_default_config();
    pmstep_stm32g4_pin_use_t map[PMSTEP_STM32G4_PIN_USES_MAX];
    pmstep_stm32g4_status_t st;
    uint32_t n;
    uint32_t k;
    cfg.step_input.enabled = true;
    st = pmstep_stm32g4_check_pins(&cfg);
    n = pmstep_stm32g4_pin_map(&cfg, map, PMSTEP_STM32G4_PIN_USES_MAX);
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
            /* "GPIO input", "GPIO output", "GPIO open drain" */
            snprintf(mode, sizeof mode, "%s",
                     map[k].signal[5] == 'i'   ? "input"
                     : map[k].signal[6] == 'u' ? "output"
                                               : "open drain");
        } else {
            snprintf(mode, sizeof mode, "AF%u", (unsigned)map[k].pin.af);
        }
        printf("| P%c%-2u | %-11s | %-6s | %s |\n", 'A' + map[k].pin.port, (unsigned)map[k].pin.pin, signal, mode,
               map[k].function);
    }
    return 0;
}
