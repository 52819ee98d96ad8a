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

tools/setup_host.sh

echo "== theorem check and empirical domain of attraction (about a minute)"
build/host-release/sil/gain_check/pmstep-gain-check --doa --doa-csv "$out/doa_runs.csv" --out "$out/doa.json" "$@" \
  | tee "$out/doa.txt"

echo "== figure"
.venv/bin/python tools/plot_doa.py "$out/doa_runs.csv" "$out/doa.json" "$out/doa.png"
