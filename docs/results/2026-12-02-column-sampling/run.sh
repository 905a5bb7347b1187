#!/bin/sh
# Env and training throughput before and after the samplers took separate x and y arrays
# (kinematics.world_xy, field.sample_nearest_xy / sample_bilinear_xy), measured in the same
# run, alternating, two rounds: the `paper` and `quick` presets with the cylinders and the
# learned condition. The benchmark scripts are this commit's; PYTHONPATH picks the package
# measured (each JSON's "leas_jax" records its checkout and commit). Run from the repository
# root with the environment installed (`make venv`); 2 cores, nothing else running (25 min).
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-02-column-sampling
BEFORE=f09e9c1
AFTER=${AFTER:-HEAD}
rm -rf /tmp/cs_before /tmp/cs_after
git worktree add --detach /tmp/cs_before $BEFORE
git worktree add --detach /tmp/cs_after $AFTER
for ROUND in 1 2; do
  for SIDE in before after; do
    P=/tmp/cs_$SIDE
    O=$D/$SIDE/round$ROUND
    for C in cylinders learned; do
      PYTHONPATH=$P python benchmarks/env_throughput.py --preset paper --envs 2048 --repeats 3 \
        --condition $C --out $O/env_$C
    done
    PYTHONPATH=$P python benchmarks/train_throughput.py --presets paper,quick --conditions cylinders,learned \
      --calls 3 --out $O
  done
done
git worktree remove --force /tmp/cs_before
git worktree remove --force /tmp/cs_after
python $D/summarise.py $D > $D/summary.md
cat $D/summary.md

# Where the `paper` preset's time goes after the change: the same training with 1 epoch per
# batch instead of 10 (the rest of an iteration, the unroll with its env steps, is the same).
PYTHONPATH=$PWD python benchmarks/train_throughput.py --presets paper --conditions cylinders,learned \
  --epochs 1 --calls 3 --out $D/epochs

# The shipped policy's own arena guides (evaluation seed 0) after the change, paired with the
# same run before it (docs/results/2026-12-02-retry-settings), 3 min.
PYTHONPATH=$PWD python studies/guide_failures.py --policy checkpoints/leas_talos --starts 256 --workers 2 \
  --spawns condition --seed 0 --out $D/guides_shipped_seed0
PYTHONPATH=$PWD python studies/guide_failures.py --compare \
  docs/results/2026-12-02-retry-settings/guides/shipped/seed0/guide_failures.json \
  $D/guides_shipped_seed0/guide_failures.json --out $D/guides_shipped_seed0
