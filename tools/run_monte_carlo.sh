#!/usr/bin/env bash
# Monte Carlo robustness study: installs what is missing, builds the optimised SIL, runs
# 200 randomised cases of sil/scenarios/robust.ini (plant, sensors, inverter, bus, initial
# angle, load; see DISTRIBUTIONS in tools/mc_distributions.py) on a local Dask cluster of
# one worker per core, and writes out/monte_carlo/report.md with its histograms, cases.csv
# and summary.json. Run again, it resumes the cases not finished; a rebuilt pmstep-sil is
# another campaign (pass another --out, or remove out/monte_carlo).
# Usage: tools/run_monte_carlo.sh [tools/monte_carlo.py options...]
#   e.g. tools/run_monte_carlo.sh --cases 1000 --seed 2 --out out/mc1000     (later options win)
#        tools/run_monte_carlo.sh --scheduler tcp://HOST:8786 --ship-sil      (an existing cluster)
set -euo pipefail
cd "$(dirname "$0")/.."

tools/setup_host.sh

echo "== Monte Carlo: 200 cases of sil/scenarios/robust.ini"
.venv/bin/python tools/monte_carlo.py --sil build/host-release/sil/pmstep-sil \
  --scenario sil/scenarios/robust.ini --cases 200 --seed 1 --out out/monte_carlo "$@"
