#!/usr/bin/env bash
# Monte Carlo robustness study: installs what is missing, builds the optimised SIL, runs
# 200 randomised cases of sil/scenarios/robust.ini (plant, sensors, inverter, bus, initial
# angle, load; see DISTRIBUTIONS in tools/monte_carlo.py) on every core, and writes
# out/monte_carlo/report.md with its histograms, cases.csv and summary.json.
# Usage: tools/run_monte_carlo.sh [tools/monte_carlo.py options...]
#   e.g. tools/run_monte_carlo.sh --cases 1000 --seed 2     (later options win)
set -euo pipefail
cd "$(dirname "$0")/.."

tools/setup_host.sh

echo "== Monte Carlo: 200 cases of sil/scenarios/robust.ini"
.venv/bin/python tools/monte_carlo.py --sil build/host-release/sil/pmstep-sil \
  --scenario sil/scenarios/robust.ini --cases 200 --seed 1 --out out/monte_carlo "$@"
