#!/usr/bin/env bash
# Regenerates every measured report in docs/reports/ with the settings the README documents, each
# written by the tool that measures it (command, commit and date at its top; tools/report.py):
#
#   cost                 tools/bench_target.py (builds qemu-pil, host-release, arm-m4f, stm32g431)
#                                                              -> docs/reports/cost.md, section "step"
#   position-cost        tools/bench_position_target.py --max-mean 615 --stepdir-max-mean 700 (the budgets of
#                        pil.position_cost and pil.stepdir_cost) -> docs/reports/cost.md, section "position"
#   benchmarks           tools/bench_sil.py --runs 9            -> docs/reports/benchmarks.md
#   envelope             tools/envelope.py, every preset, ideal and realistic chains, 20 s of ramps
#                                                              -> docs/reports/envelope.md (+ envelope.png)
#   envelope-weakened    tools/envelope.py --top weakened: the same at the field-weakened top speed
#                                                              -> docs/reports/envelope-weakened.md (+ .png)
#   position-acceptance  tools/position_acceptance.py, 50 moves, seed 1, 60 s hold, --write-scenarios
#                                                              -> docs/reports/position-acceptance.md
#   position-acceptance-weakened  the same with v_max half the field-weakened top speed (--top weakened)
#                                                              -> docs/reports/position-acceptance-weakened.md
#   mc-presets           tools/monte_carlo.py --preset P --cases 200 --seed 1, P = paper, 17hs4401,
#                        bj42d29, as1050 (realistic chain)     -> docs/reports/monte-carlo.md, section P
#   mc-weakened          tools/monte_carlo.py --preset P --weakened --cases 200 --seed 1: the same campaigns with
#                        the profile up to the field-weakened top speed -> docs/reports/monte-carlo.md, "P-weakened"
#   mc-robust            tools/monte_carlo.py --scenario sil/scenarios/robust.ini --cases 1000 --seed 1
#                                                              -> docs/reports/monte-carlo.md, section "robust"
#   mc-position          tools/monte_carlo.py --preset P --scenario (position-acceptance's P_realistic_run.ini)
#                        --cases 200 --seed 1 --speed-bound 1000 --angle-bound 0.5 --position-bound 0.5,
#                        P = 17hs4401, bj42d29, as1050          -> docs/reports/monte-carlo.md, "position-P"
#   fault-injection      tools/fault_injection.py, every fault on paper, 17hs4401, bj42d29, as1050
#                                                              -> docs/reports/fault-injection.md
#   motor-sweep          tools/sweep_motors.py, the 500 motors of tools/motor_population.py (seed 2026),
#                        paper, robust and self-commissioning modes, a speed Monte Carlo on 50 of its motors
#                                                              -> docs/reports/motor-sweep.md (+ .png)
#   self-commissioning   tools/self_commission.py, every preset on its chain and the realistic one
#                                                              -> docs/reports/self-commissioning.md
#   step-dir             tools/stepdir_compare.py, every preset, pmstep and open-loop microstepping on the
#                        same step streams                     -> docs/reports/step-dir.md (+ step-dir.png)
#   homing               tools/homing_sweep.py, every preset, ideal and realistic chains, homing speeds from
#                        0.1 % to 50 % of the top speed         -> docs/reports/homing.md
#   torque-speed         tools/torque_speed.py, every preset on 12, 24 and 48 V, pmstep and open-loop
#                        microstepping                          -> docs/reports/torque-speed.md (+ plots)
#
# The campaigns run on a thread pool of 2 (--engine threads --jobs 2; a case's result depends on its
# seed alone, not on the engine). Outputs of the runs (tables, cases, plots) go to OUT (out/reports);
# each campaign's folder is emptied first, so that nothing is resumed from another build.
#
# Usage: tools/write_reports.sh [STEP...]      (default: every step, in the order above)
#   NICE="nice -n 10" (default) runs each step but the 4 s benchmark at lower priority; NICE= runs
#   them as they are.
#   OUT=DIR for the runs' own outputs; PYTHON=... (default .venv/bin/python, else python3);
#   REPORTS=DIR writes the reports there instead of docs/reports (a trial run).
# Prints each step's command and time, and the total. A tool that wrote its report but exited non-zero
# (bench_position_target.py over its budget, bench_target.py's outputs not bit-identical) is listed at
# the end, its report shows why; a step that wrote no report failed: exit 1 (the others still run).
set -uo pipefail
cd "$(dirname "$0")/.."

STEPS_ALL=(cost position-cost benchmarks envelope envelope-weakened position-acceptance position-acceptance-weakened mc-presets mc-weakened mc-robust mc-position fault-injection
           motor-sweep self-commissioning step-dir homing torque-speed)
MC_PRESETS=(paper 17hs4401 bj42d29 as1050)
MC_POSITION=(17hs4401 bj42d29 as1050)
OUT=${OUT:-out/reports}
NICE=${NICE-nice -n 10}
if [ -z "${PYTHON:-}" ]; then
  if [ -x .venv/bin/python ]; then PYTHON=.venv/bin/python; else PYTHON=python3; fi
fi
SIL=build/host-release/sil/pmstep-sil
TUNE=build/host-release/sil/pmstep-tune
REPORTS=${REPORTS:-docs/reports}

if [ $# -gt 0 ]; then STEPS=("$@"); else STEPS=("${STEPS_ALL[@]}"); fi
for s in "${STEPS[@]}"; do
  case " ${STEPS_ALL[*]} " in
    *" $s "*) ;;
    *) echo "write_reports: unknown step '$s' (steps: ${STEPS_ALL[*]})" >&2; exit 2 ;;
  esac
done

failed=()
flagged=()
started=$SECONDS
marker=$(mktemp)
trap 'rm -f "$marker"' EXIT

# run NAME REPORT COMMAND...: one measurement, timed; it failed if REPORT was not written anew.
run() {
  local name=$1 page=$2
  shift 2
  local t0=$SECONDS status=0
  echo "== [$name] $*"
  touch "$marker"
  sleep 1  # file times in whole seconds on some file systems: a report written now is newer
  # shellcheck disable=SC2086  # NICE is a command and its options
  $NICE "$@" || status=$?
  if [ ! "$page" -nt "$marker" ]; then
    echo "== [$name] FAILED (exit $status, $page not written) after $((SECONDS - t0)) s"
    failed+=("$name")
  elif [ "$status" -ne 0 ]; then
    echo "== [$name] wrote $page in $((SECONDS - t0)) s; the tool exited $status (see the report)"
    flagged+=("$name (exit $status)")
  else
    echo "== [$name] wrote $page in $((SECONDS - t0)) s"
  fi
}

need_sil() {
  if [ ! -x "$SIL" ] || [ ! -x "$TUNE" ]; then
    echo "== building host-release (pmstep-sil, pmstep-tune)"
    $NICE cmake --preset host-release >/dev/null && $NICE cmake --build --preset host-release >/dev/null
  fi
}

campaign() {  # campaign SECTION OUTDIR ARGS...: one Monte Carlo campaign into its section of the page
  local section=$1 dir=$2
  shift 2
  rm -rf "$dir"
  run "mc $section" "$REPORTS/monte-carlo.md" "$PYTHON" tools/monte_carlo.py --sil "$SIL" "$@" --out "$dir" --engine threads --jobs 2 \
    --no-plots --report "$REPORTS/monte-carlo.md" --report-section "$section"
}

k=0
for step in "${STEPS[@]}"; do
  k=$((k + 1))
  echo
  echo "=== step $k of ${#STEPS[@]}: $step ($((SECONDS - started)) s so far)"
  case $step in
    cost)
      run cost "$REPORTS/cost.md" "$PYTHON" tools/bench_target.py --report "$REPORTS/cost.md" ;;
    position-cost)
      run position-cost "$REPORTS/cost.md" "$PYTHON" tools/bench_position_target.py --max-mean 615 --stepdir-max-mean 700 \
        --report "$REPORTS/cost.md" ;;
    benchmarks)  # 4 s, at normal priority: at nice 10 on a busy machine the wall figures mean little
      need_sil
      NICE='' run benchmarks "$REPORTS/benchmarks.md" "$PYTHON" tools/bench_sil.py --runs 9 --sil "$SIL" --report "$REPORTS/benchmarks.md" ;;
    envelope)
      need_sil
      run envelope "$REPORTS/envelope.md" "$PYTHON" tools/envelope.py --sil "$SIL" --tune "$TUNE" --out "$OUT/envelope" \
        --report "$REPORTS/envelope.md" ;;
    envelope-weakened)
      need_sil
      run envelope-weakened "$REPORTS/envelope-weakened.md" "$PYTHON" tools/envelope.py --sil "$SIL" --tune "$TUNE" \
        --out "$OUT/envelope-weakened" --top weakened --report "$REPORTS/envelope-weakened.md" ;;
    position-acceptance)
      need_sil
      run position-acceptance "$REPORTS/position-acceptance.md" "$PYTHON" tools/position_acceptance.py --sil "$SIL" --tune "$TUNE" \
        --out "$OUT/position_acceptance" --write-scenarios --report "$REPORTS/position-acceptance.md" ;;
    position-acceptance-weakened)
      need_sil
      run position-acceptance-weakened "$REPORTS/position-acceptance-weakened.md" "$PYTHON" tools/position_acceptance.py \
        --sil "$SIL" --tune "$TUNE" --out "$OUT/position_acceptance_weakened" --top weakened \
        --report "$REPORTS/position-acceptance-weakened.md" ;;
    mc-presets)
      need_sil
      for p in "${MC_PRESETS[@]}"; do
        campaign "$p" "$OUT/mc_$p" --preset "sil/scenarios/motors/$p.ini" --cases 200 --seed 1
      done ;;
    mc-weakened)
      need_sil
      for p in "${MC_PRESETS[@]}"; do
        campaign "$p-weakened" "$OUT/mc_$p-weakened" --preset "sil/scenarios/motors/$p.ini" --weakened --cases 200 --seed 1
      done ;;
    mc-robust)
      need_sil
      campaign robust "$OUT/mc_robust" --scenario sil/scenarios/robust.ini --cases 1000 --seed 1 ;;
    mc-position)
      need_sil
      for p in "${MC_POSITION[@]}"; do
        scenario="$OUT/position_acceptance/${p}_realistic_run.ini"
        if [ ! -f "$scenario" ]; then
          echo "== [mc position-$p] FAILED: no $scenario (the step position-acceptance writes it)"
          failed+=("mc position-$p")
          continue
        fi
        campaign "position-$p" "$OUT/mc_position_$p" --preset "sil/scenarios/motors/$p.ini" --scenario "$scenario" \
          --cases 200 --seed 1 --speed-bound 1000 --angle-bound 0.5 --position-bound 0.5
      done ;;
    fault-injection)
      need_sil
      run fault-injection "$REPORTS/fault-injection.md" "$PYTHON" tools/fault_injection.py --sil "$SIL" --tune "$TUNE" \
        --report "$REPORTS/fault-injection.md" ;;
    motor-sweep)
      need_sil
      run motor-sweep "$REPORTS/motor-sweep.md" "$PYTHON" tools/sweep_motors.py --tune "$TUNE" --jobs 2 \
        --modes paper-ideal,robust-realistic,self-commission-realistic --mc-sample 50 \
        --report "$REPORTS/motor-sweep.md" --plot "$REPORTS/motor-sweep.png" ;;
    self-commissioning)
      need_sil
      run self-commissioning "$REPORTS/self-commissioning.md" "$PYTHON" tools/self_commission.py --tune "$TUNE" \
        --report "$REPORTS/self-commissioning.md" ;;
    step-dir)
      need_sil
      rm -rf "$OUT/stepdir_compare"
      run step-dir "$REPORTS/step-dir.md" "$PYTHON" tools/stepdir_compare.py --sil "$SIL" --tune "$TUNE" \
        --out "$OUT/stepdir_compare" --report "$REPORTS/step-dir.md" ;;
    homing)
      need_sil
      rm -rf "$OUT/homing_sweep"
      run homing "$REPORTS/homing.md" "$PYTHON" tools/homing_sweep.py --sil "$SIL" --tune "$TUNE" \
        --out "$OUT/homing_sweep" --report "$REPORTS/homing.md" ;;
    torque-speed)
      need_sil
      rm -rf "$OUT/torque_speed"
      run torque-speed "$REPORTS/torque-speed.md" "$PYTHON" tools/torque_speed.py --sil "$SIL" --tune "$TUNE" \
        --out "$OUT/torque_speed" --report "$REPORTS/torque-speed.md" ;;
  esac
done

total=$((SECONDS - started))
echo
echo "=== write_reports: ${#STEPS[@]} steps in ${total} s ($((total / 60)) min $((total % 60)) s)"
if [ ${#flagged[@]} -gt 0 ]; then
  echo "=== written, but the tool exited non-zero: ${flagged[*]}"
fi
if [ ${#failed[@]} -gt 0 ]; then
  echo "=== FAILED (no report): ${failed[*]}"
  exit 1
fi
echo "=== every report written"
