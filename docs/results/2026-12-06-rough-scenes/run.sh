#!/usr/bin/env bash
# The HPP group's rough scenes (terrains/hpp/rough, terrains/hpp/rubble.toml): navigate from the 20
# seeded starts of each scene's [scenario], the straight-line, RRT and LeaS baselines from the first
# 5 (RBKino+RRT's searches take about 40 s a start here), then the summary table.
#   bash docs/results/2026-12-06-rough-scenes/run.sh
# Writes one `leas evaluate` folder per scene under eval/ (navigate) and baselines/ (guides.npz,
# results.json and figures left out of the tree: rerun to get them) and summary.json / summary.md.
set -euo pipefail
cd "$(dirname "$0")/../../.."
HERE=docs/results/2026-12-06-rough-scenes
for f in terrains/hpp/rough/*.toml terrains/hpp/rubble.toml; do
  name=$(basename "$f" .toml)
  .venv/bin/leas evaluate --terrain "$f" --methods navigate --checkpoint checkpoints/leas_talos \
    --n-starts 20 --workers 2 --no-progress --out "$HERE/eval/$name"
  .venv/bin/leas evaluate --terrain "$f" --methods rblin,rbkino_rrt,leas --checkpoint checkpoints/leas_talos \
    --n-starts 5 --workers 1 --no-progress --out "$HERE/baselines/$name"
done
.venv/bin/python "$HERE/summarise.py" "$HERE"
