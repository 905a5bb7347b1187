#!/usr/bin/env bash
# The paper's baselines and LeaS alone on the HPP rough scenes with the current contact generator
# (sole turns, wider step search): RBLin, RBKino+RRT and LeaS (the shipped policy) from the first
# 5 seeded starts of each scene (navigate's 20 are in ../2026-12-06-navigate-path-fallback).
#   bash docs/results/2026-12-06-rough-baselines/run.sh      (about 1 h of one core)
# Per-scene table.md files and summary.md are kept; results.json and guides stay under RUNS.
set -euo pipefail
cd "$(dirname "$0")/../../.."
HERE=docs/results/2026-12-06-rough-baselines
RUNS=${RUNS:-/tmp/rough_baselines}
for f in terrains/hpp/rough/*.toml terrains/hpp/rubble.toml; do
  name=$(basename "$f" .toml)
  [ -f "$RUNS/baselines/$name/results.json" ] && continue   # done: resume
  .venv/bin/leas evaluate --terrain "$f" --methods rblin,rbkino_rrt,leas --checkpoint checkpoints/leas_talos \
    --n-starts 5 --workers 1 --no-progress --out "$RUNS/baselines/$name"
  mkdir -p "$HERE/$name" && cp "$RUNS/baselines/$name/table.md" "$HERE/$name/"
done
.venv/bin/python docs/results/2026-12-06-rough-scenes/summarise.py "$RUNS" && cp "$RUNS/summary.md" "$HERE/"
