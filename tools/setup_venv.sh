#!/usr/bin/env bash
# The tools' Python environment: .venv with the pinned packages of tools/requirements.txt
# (plots, the host console's pyserial). Used by tools/setup_host.sh and tools/test_all.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv/bin/python ]; then
  if ! python3 -m venv .venv 2>/dev/null; then
    rm -rf .venv
    tools/install_deps.sh python3-venv
    python3 -m venv .venv
  fi
fi
.venv/bin/python -m pip install --quiet --disable-pip-version-check -r tools/requirements.txt
