#!/bin/sh
# Lists the C sources the formatter checks (ctest static.clang_format): every tracked .c and .h
# but the sources whose layout tools/gen_reference.py reads to write the reference pages (its
# TYPES_H ... SCENARIO_KEYS_H): their enums, tables and comments are that generator's input, line
# by line, and stay as it parses them.
cd "$(dirname "$0")/.." || exit 2
git ls-files '*.c' '*.h' | grep -v -x -F \
    -e firmware/include/pmstep/pmstep_types.h \
    -e firmware/src/pmstep_config.c \
    -e firmware/src/pmstep_text.c \
    -e firmware/console/include/pmstep_console.h \
    -e firmware/console/src/pmstep_console_config.c \
    -e firmware/console/src/pmstep_console_request.c \
    -e firmware/console/include/pmstep_store.h \
    -e firmware/design/include/pmstep/pmstep_calibrate.h \
    -e hal/stm32g4/include/pmstep_hal_stm32g4.h \
    -e hal/stm32g4/src/stm32g4_convert.c \
    -e hal/stm32g4/src/stm32g4_board.c \
    -e sil/src/scenario_keys.c \
    -e sil/src/scenario_keys.h
