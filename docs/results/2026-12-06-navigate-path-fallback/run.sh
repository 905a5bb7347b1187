#!/usr/bin/env bash
# Navigate with the searched path walked where the generator stops on the policy's guide
# (NavigateConfig.path_fallback, on by default) against the policy walking every search
# (--navigate-policy-only).
#   bash docs/results/2026-12-06-navigate-path-fallback/run.sh [bridge|rough|regression]...
# bridge: eval_bridge, 10 seeded starts, the `quick` preset's 30 M geometric policies of
#   ../2026-12-06-quick-budget (runs/quick-budget/study30/runs/learned/seed{0,1,2}/geometric, made
#   by its README's commands), with and without the fallback.
# rough: the shipped policy on the HPP rough scenes (../2026-12-06-sole-turns: 20 seeded starts
#   each, the same seeds), those where navigate replanned first.
# regression: the shipped policy on the HPP Talos demo queries and the evaluation scenarios.
# Per-run table.md files are kept; results.json and guides are left out of the tree.
set -euo pipefail
cd "$(dirname "$0")/../../.."
HERE=docs/results/2026-12-06-navigate-path-fallback
STAGES=${*:-bridge rough regression}
QUICK=runs/quick-budget/study30/runs/learned
keep() { mkdir -p "$HERE/$2"; cp "$1/table.md" "$HERE/$2/"; }
for stage in $STAGES; do
  case $stage in
    bridge)
      for s in 0 1 2; do
        for mode in fallback policy_only; do
          flag=""; [ $mode = policy_only ] && flag=--navigate-policy-only
          .venv/bin/leas evaluate --scenario bridge --methods navigate --checkpoint $QUICK/seed$s/geometric \
            --n-starts 10 --workers 1 --no-progress $flag --out /tmp/path_fallback/bridge/seed$s/$mode
          keep /tmp/path_fallback/bridge/seed$s/$mode bridge/quick30M_seed$s/$mode
        done
      done ;;
    rough)
      # the scenes where navigate replanned first, then the others
      for name in cross_gap rubbles_stairs_1 rubble rubbles_stairs_3 rubbles_stairs_bridge_1 darpa \
          rubbles_stairs_2 bauzil_ramp_simplified bridge_towr slalom_debris stairs_towr; do
        f=terrains/hpp/rough/$name.toml; [ -f "$f" ] || f=terrains/hpp/$name.toml
        [ -f /tmp/path_fallback/rough/$name/results.json ] && continue   # done: resume
        .venv/bin/leas evaluate --terrain "$f" --methods navigate --checkpoint checkpoints/leas_talos \
          --n-starts 20 --workers 1 --no-progress --out /tmp/path_fallback/rough/$name
        keep /tmp/path_fallback/rough/$name rough/$name
      done ;;
    regression)
      .venv/bin/python studies/navigate_demos.py --workers 1 --out /tmp/path_fallback/demos | tee "$HERE/demos.txt"
      .venv/bin/leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods navigate \
        --checkpoint checkpoints/leas_talos --n-starts 20 --workers 1 --no-progress --out /tmp/path_fallback/scenarios
      keep /tmp/path_fallback/scenarios scenarios
      .venv/bin/leas hole-sweep --methods navigate --checkpoint checkpoints/leas_talos --n-starts 10 \
        --workers 1 --no-progress --out /tmp/path_fallback/hole_sweep
      mkdir -p "$HERE/hole_sweep" && cp /tmp/path_fallback/hole_sweep/hole_sweep.md "$HERE/hole_sweep/" ;;
  esac
done
