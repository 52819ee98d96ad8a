#!/usr/bin/env bash
# The main job: installs what is missing, builds the optimised SIL, runs the paper's
# Section III scenario through the real firmware and the plant model, writes
# out/paper/run.csv, out/paper/summary.json and the figures out/paper/fig*.png,
# and prints the summary. Extra arguments go to pmstep-sil (e.g. --set run.delay_periods=1).
set -euo pipefail
cd "$(dirname "$0")/.."

tools/install_deps.sh

echo "== build (preset host-release)"
cmake --preset host-release >/dev/null
cmake --build --preset host-release

echo "== plotting environment (.venv, tools/requirements.txt)"
if [ ! -x .venv/bin/python ]; then
  if ! python3 -m venv .venv 2>/dev/null; then
    rm -rf .venv
    tools/install_deps.sh python3-venv
    python3 -m venv .venv
  fi
fi
.venv/bin/python -m pip install --quiet --disable-pip-version-check -r tools/requirements.txt

echo "== paper scenario"
out=out/paper
build/host-release/sil/pmstep-sil --scenario paper --out "$out" "$@"

echo "== figures"
.venv/bin/python tools/plot_run.py "$out"
