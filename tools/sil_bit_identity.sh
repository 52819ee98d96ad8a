#!/usr/bin/env bash
# Checks that this tree's pmstep-sil gives bit-identical results to an earlier commit's:
# builds pmstep-sil of BASE (git archive into a temporary folder, host-release, -j2), runs the
# same scenario with both, and compares the records (--record: every period's firmware inputs
# and outputs) and run.csv with cmp. Used to show that a new plant term that is off (e.g.
# motor.detent_torque_Nm = 0) changes nothing.
#   tools/sil_bit_identity.sh BASE [pmstep-sil arguments...]
#   tools/sil_bit_identity.sh 403c8ab --set run.integrator=rk4 --set run.substeps=4
# Needs build/host-release/sil/pmstep-sil of this tree. Exit 0 when identical, 1 when not.
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:?usage: tools/sil_bit_identity.sh BASE [pmstep-sil arguments...]}
shift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git archive "$base" | tar -x -C "$work"
(cd "$work" && cmake --preset host-release >/dev/null 2>&1 && cmake --build build/host-release -j2 --target pmstep-sil >/dev/null)
status=0
"$work/build/host-release/sil/pmstep-sil" --quiet --out "$work/out-base" --record "$work/base.rec" "$@" || status=$?
build/host-release/sil/pmstep-sil --quiet --out "$work/out-new" --record "$work/new.rec" "$@" || [ $? -eq "$status" ]
cmp "$work/base.rec" "$work/new.rec"
cmp "$work/out-base/run.csv" "$work/out-new/run.csv"
echo "bit-identical to $base: record ($(stat -c %s "$work/new.rec") bytes) and run.csv"
