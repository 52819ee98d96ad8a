#!/usr/bin/env bash
# What the paper's theorems guarantee for a configuration, and the measured domain of
# attraction of the firmware: builds the optimised tree, runs pmstep-gain-check --doa on a
# scenario (default: the paper's), and plots the result.
# Usage: tools/run_doa.sh [OUT_DIR] [pmstep-gain-check options...]   (default OUT_DIR: out/doa)
# Writes OUT_DIR/doa.txt (the report), doa.json, doa_runs.csv (every SIL run) and doa.png.
set -euo pipefail
cd "$(dirname "$0")/.."

out=out/doa
if [ $# -gt 0 ] && [ "${1#-}" = "$1" ]; then
  out=$1
  shift
fi
mkdir -p "$out"

tools/install_deps.sh

echo "== build (preset host-release)"
cmake --preset host-release >/dev/null
cmake --build --preset host-release

echo "== plotting environment (.venv)"
if [ ! -x .venv/bin/python ]; then
  if ! python3 -m venv .venv 2>/dev/null; then
    rm -rf .venv
    tools/install_deps.sh python3-venv
    python3 -m venv .venv
  fi
fi
if [ -f tools/requirements.txt ]; then
  .venv/bin/python -m pip install --quiet --disable-pip-version-check -r tools/requirements.txt
elif ! .venv/bin/python -c "import matplotlib" 2>/dev/null; then
  .venv/bin/python -m pip install --quiet --disable-pip-version-check matplotlib
fi

echo "== theorem check and empirical domain of attraction (about a minute)"
build/host-release/sil/gain_check/pmstep-gain-check --doa --doa-csv "$out/doa_runs.csv" --out "$out/doa.json" "$@" \
  | tee "$out/doa.txt"

echo "== figure"
.venv/bin/python tools/plot_doa.py "$out/doa_runs.csv" "$out/doa.json" "$out/doa.png"
