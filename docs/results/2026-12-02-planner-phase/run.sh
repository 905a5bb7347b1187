#!/bin/sh
# Does the planner-in-the-loop phase add anything on the current contact generator (wider step
# search and retries)? The shipped policy's geometric phase (checkpoints/leas_talos/pretrain,
# `paper` preset, cylinders) fine-tuned with the generator in the loop, `paper` planner
# settings (64 guides per iteration, 10 epochs of 4 mini-batches, the paper's pruning) for
# 150 k kept steps, 3 seeds; each policy's own arena guides judged like the pretrain's
# (docs/results/2026-12-02-column-sampling/guides_shipped_seed0 and
# ../2026-12-02-retry-settings/guides/pretrain/seed0: 256 starts, evaluation seed 0).
# Run from the repository root with the environment installed (`make venv`); 2 cores (30 min).
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-02-planner-phase
R=${RUNS:-/tmp/planner_phase}
for S in ${SEEDS:-0 1 2}; do
  leas train --mode planner --preset paper --init checkpoints/leas_talos/pretrain --timesteps 150000 \
    --seed $S --workers 2 --no-progress --out $R/seed$S
  mkdir -p $D/seed$S && cp $R/seed$S/metrics.jsonl $R/seed$S/config.json $D/seed$S/
  PYTHONPATH=$PWD python studies/guide_failures.py --policy $R/seed$S --starts 256 --workers 2 \
    --spawns condition --seed 0 --out $D/seed$S/guides
done
python $D/summarise.py $D > $D/summary.md
