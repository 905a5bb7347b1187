#!/bin/sh
# RBKino+RRT and LeaS on its waypoints on the stairs scenarios (not in the committed
# evaluation there), and navigate on every hole-sweep width.
# Usage: sh docs/results/2026-12-01-navigate/run_baselines.sh N
set -e
N=${1:-20}
OUT=docs/results/2026-12-01-navigate
for s in stairs stairs_side; do
  uptime
  nice -n 10 python -m leas_jax.cli evaluate --scenario "$s" --methods rbkino_rrt,leas_rrt --n-starts "$N" \
    --checkpoint checkpoints/leas_talos --workers 1 --no-progress --out "$OUT/rrt_$s"
done
uptime
nice -n 10 python -m leas_jax.cli hole-sweep --methods navigate --n-starts "$N" \
  --checkpoint checkpoints/leas_talos --workers 1 --no-progress --out "$OUT/hole_sweep"
uptime
