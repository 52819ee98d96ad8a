#!/usr/bin/env bash
# The main job: installs what is missing, builds the optimised SIL, runs the paper's
# Section III scenario through the real firmware and the plant model, writes
# out/paper/run.csv, out/paper/summary.json and the figures out/paper/fig*.png,
# and prints the summary. Extra arguments go to pmstep-sil (e.g. --set run.delay_periods=1).
set -euo pipefail
cd "$(dirname "$0")/.."

tools/setup_host.sh

echo "== paper scenario"
out=out/paper
build/host-release/sil/pmstep-sil --scenario paper --out "$out" "$@"

echo "== figures"
.venv/bin/python tools/plot_run.py "$out"
