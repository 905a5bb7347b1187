#!/bin/sh
# Navigate on the five evaluation scenarios (N starts each, the scenarios' seeded draws).
# Usage: sh docs/results/2026-12-01-navigate/run_eval.sh N
set -e
N=${1:-20}
OUT=docs/results/2026-12-01-navigate
for s in hole bridge stairs stairs_side circuit; do
  uptime
  nice -n 10 python -m leas_jax.cli evaluate --scenario "$s" --methods navigate --n-starts "$N" \
    --checkpoint checkpoints/leas_talos --workers 2 --no-progress --out "$OUT/eval_$s"
  uptime
done
