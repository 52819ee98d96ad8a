#!/usr/bin/env bash
# The project's Python environment: .venv at the repository root with the pinned packages of
# tools/requirements.txt (plots: numpy, matplotlib; the host console: pyserial; Monte Carlo
# campaigns: dask.distributed). Used by tools/setup_host.sh (people) and tools/test_all.sh (CI);
# safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== Python environment (.venv, tools/requirements.txt)"
if [ ! -x .venv/bin/python ]; then
  if ! python3 -m venv .venv 2>/dev/null; then
    rm -rf .venv
    tools/install_deps.sh python3-venv
    python3 -m venv .venv
  fi
fi
.venv/bin/python -m pip install --quiet --disable-pip-version-check -r tools/requirements.txt
