#!/usr/bin/env bash
# The project's test command: installs what is missing, builds the host tree
# (ASan + UBSan), the Cortex-M4F core and the STM32G431 image, and runs every test with
# ctest (which also cross-builds and runs the processor-in-the-loop images on QEMU).
set -euo pipefail
cd "$(dirname "$0")/.."

tools/install_deps.sh
# Python packages of the tools and their tests (the console's pyserial, the Monte Carlo
# campaigns on Dask, plots) into .venv.
tools/setup_venv.sh

echo "== host build (preset host: ASan + UBSan)"
cmake --preset host >/dev/null
cmake --build --preset host

echo "== Cortex-M4F core (preset arm-m4f)"
cmake --preset arm-m4f >/dev/null
cmake --build --preset arm-m4f

echo "== STM32G431 firmware image (preset stm32g431: .elf, .bin, .map)"
cmake --preset stm32g431 >/dev/null
cmake --build --preset stm32g431

echo "== tests"
ctest --preset host
