#!/usr/bin/env bash
# The project's test command: installs what is missing, builds the host tree
# (ASan + UBSan) and the Cortex-M4F core, and runs every test with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."

tools/install_deps.sh

echo "== host build (preset host: ASan + UBSan)"
cmake --preset host >/dev/null
cmake --build --preset host

echo "== Cortex-M4F core (preset arm-m4f)"
cmake --preset arm-m4f >/dev/null
cmake --build --preset arm-m4f

echo "== tests"
ctest --preset host
