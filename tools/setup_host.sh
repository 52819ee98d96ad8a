#!/usr/bin/env bash
# Shared set-up of the scripts for people (run_paper.sh, run_doa.sh, run_monte_carlo.sh):
# installs the Debian packages that are missing, builds the optimised host tree (preset
# host-release: pmstep-sil, pmstep-gain-check) and makes the Python environment .venv with
# the pinned packages of tools/requirements.txt (tools/setup_venv.sh). Run from the repository root.
set -euo pipefail
cd "$(dirname "$0")/.."

tools/install_deps.sh

echo "== build (preset host-release)"
cmake --preset host-release >/dev/null
cmake --build --preset host-release

tools/setup_venv.sh
