#!/usr/bin/env bash
# Soles that turn to fit small faces (GeneratorConfig.sole_turns) and stalled rollouts cut and
# searched round (NavigateConfig.stall_time): navigate on the HPP group's rough
# scenes (20 seeded starts each), the HPP Talos demo queries (cold, verified), the evaluation
# scenarios and every hole-sweep width; then (stage "baselines") RBLin, RBKino+RRT and LeaS alone
# from the first 5 starts of each rough scene.
#   bash docs/results/2026-12-06-sole-turns/run.sh [navigate|regression|baselines]...  (default: all three)
# Per-scene table.md files are kept; results.json and guides are left out of the tree.
set -euo pipefail
cd "$(dirname "$0")/../../.."
HERE=docs/results/2026-12-06-sole-turns
STAGES=${*:-navigate regression baselines}
SCENES="terrains/hpp/rough/*.toml terrains/hpp/rubble.toml"
for stage in $STAGES; do
  case $stage in
    navigate)
      for f in $SCENES; do
        .venv/bin/leas evaluate --terrain "$f" --methods navigate --checkpoint checkpoints/leas_talos \
          --n-starts 20 --workers 1 --no-progress --out "$HERE/eval/$(basename "$f" .toml)"
      done ;;
    regression)
      .venv/bin/python studies/navigate_demos.py --workers 1 --out "$HERE/demos" | tee "$HERE/demos.txt"
      .venv/bin/leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods navigate \
        --checkpoint checkpoints/leas_talos --n-starts 20 --workers 1 --no-progress --out "$HERE/scenarios"
      .venv/bin/leas hole-sweep --methods navigate --checkpoint checkpoints/leas_talos --n-starts 10 \
        --workers 1 --no-progress --out "$HERE/hole_sweep" ;;
    baselines)
      for f in $SCENES; do
        .venv/bin/leas evaluate --terrain "$f" --methods rblin,rbkino_rrt,leas --checkpoint checkpoints/leas_talos \
          --n-starts 5 --workers 1 --no-progress --out "$HERE/baselines/$(basename "$f" .toml)"
      done ;;
  esac
done
.venv/bin/python docs/results/2026-12-06-rough-scenes/summarise.py "$HERE"
