#!/bin/sh
# The contact generator's shifted first stance (GeneratorConfig.stance_shifts) and its root
# stepping sideways where the arms still meet the terrain held in (arm_clearance_shifts):
# the policies' own arena guides (the same episodes as docs/results/2026-12-02-step-fallback,
# so each guide is paired with its earlier verdict), the pillar check, the scenarios and
# Table II. Run from the repository root with the environment installed (`make venv`); 2 cores.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-02-stance-arm-shifts

# 1. Own arena guides, 256 starts, evaluation seed 0 (2 min each on the idle machine).
for PAIR in shipped:checkpoints/leas_talos pretrain:checkpoints/leas_talos/pretrain \
    learned_arms_s0:docs/results/2026-12-02-arms-in/train_paper_learned_arms_s0; do
  PYTHONPATH=$PWD python studies/guide_failures.py --policy ${PAIR#*:} --starts 256 --workers 2 \
    --spawns condition --out $D/guides/${PAIR%%:*}
done

# 2. The pillar check (15 s).
leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint checkpoints/leas_talos \
  --workers 2 --no-progress --out $D/pillars

# 3. Every scenario and method with the shipped policy (6 min).
leas evaluate --checkpoint checkpoints/leas_talos --scenario all --workers 2 --no-progress \
  --out $D/evaluate_shipped

# 4. Table II's RBKino and RBLin, 60 starts per cell (1 min).
PYTHONPATH=$PWD python studies/table2_baselines.py --out $D/table2 --n-starts 60 --workers 2 \
  --variants rblin,rbkino --sweep-steps ""

# 5. Each policy's guides paired with the step-fallback generator's verdicts on the same episodes.
for P in shipped pretrain learned_arms_s0; do
  PYTHONPATH=$PWD python studies/guide_failures.py \
    --compare docs/results/2026-12-02-step-fallback/guides/$P/guide_failures.json \
    $D/guides/$P/guide_failures.json --out $D/guides/$P
done
