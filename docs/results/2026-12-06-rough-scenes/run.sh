#!/usr/bin/env bash
# The HPP group's rough scenes (terrains/hpp/rough, terrains/hpp/rubble.toml): 20 seeded starts
# each, every steering method the contact generator judges, then the summary table.
#   bash docs/results/2026-12-06-rough-scenes/run.sh [METHODS] [EXTRA NAVIGATE ARGS]
# Writes one `leas evaluate` folder per scene under eval/ (guides.npz left out of the tree) and
# summary.json / summary.md beside this script.
set -euo pipefail
cd "$(dirname "$0")/../../.."
HERE=docs/results/2026-12-06-rough-scenes
METHODS=${1:-rblin,rbkino_rrt,leas,navigate}
for f in terrains/hpp/rough/*.toml terrains/hpp/rubble.toml; do
  name=$(basename "$f" .toml)
  .venv/bin/leas evaluate --terrain "$f" --methods "$METHODS" --checkpoint checkpoints/leas_talos \
    --n-starts 20 --workers 2 --no-progress --out "$HERE/eval/$name"
  rm -f "$HERE/eval/$name/guides.npz"
done
.venv/bin/python "$HERE/summarise.py" "$HERE"
