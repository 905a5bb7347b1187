#!/bin/sh
# The contact generator's step fallback (GeneratorConfig.fallback_lookahead), its
# single-support root bound (max_single_support_offset_xy) and its candidates screened over
# the foot's footprint (collision.foot_footprint): the policies' own arena guides,
# the pillar check, the scenarios and Table II, each against the generator without them
# (docs/results/2026-12-02-arms-in). Run from the repository root with the environment
# installed (`make venv`); 2 cores.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-02-step-fallback

# 1. Own arena guides, 256 starts, evaluation seed 0 (2 min each).
for PAIR in shipped:checkpoints/leas_talos pretrain:checkpoints/leas_talos/pretrain \
    learned:docs/results/2026-12-01-learned-paper/train_paper_learned \
    learned_arms_s0:docs/results/2026-12-02-arms-in/train_paper_learned_arms_s0 \
    learned_seeded:docs/results/2026-12-01-path-condition/train_paper_learned_seeded; do
  PYTHONPATH=$PWD python studies/guide_failures.py --policy ${PAIR#*:} --starts 256 --workers 2 \
    --spawns condition --out $D/guides/${PAIR%%:*}
done
# 1b. The shipped policy from generator-verified resets (the spawn verdicts are cached by
#     the generator's settings and code: 59 286 poses labelled again, about 10 min, once).
PYTHONPATH=$PWD python studies/guide_failures.py --policy checkpoints/leas_talos --starts 256 \
  --workers 2 --spawns generator --out $D/guides/shipped_verified_spawns

# 2. The pillar check (15 s per policy).
for P in checkpoints/leas_talos checkpoints/leas_talos/pretrain \
    docs/results/2026-12-01-learned-paper/train_paper_learned; do
  leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint $P --workers 2 \
    --no-progress --out $D/pillars/$(basename $P)
done

# 3. Every scenario and method with the shipped policy (6 min).
leas evaluate --checkpoint checkpoints/leas_talos --scenario all --workers 2 --no-progress \
  --out $D/evaluate_shipped

# 4. Table II's RBKino, 60 starts per cell (1 min).
PYTHONPATH=$PWD python studies/table2_baselines.py --out $D/table2 --n-starts 60 --workers 2 \
  --variants rblin,rbkino --sweep-steps ""
