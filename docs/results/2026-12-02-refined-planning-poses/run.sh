#!/bin/sh
# The contact generator planning again at every guide pose between two planning poses where
# the second cannot be reached from the first (GeneratorConfig.refine_stride = 1): Table II's
# RBKino, the policies' own arena guides (paired with docs/results/2026-12-02-stance-arm-shifts,
# the same episodes), the scenarios and the pillar check. Run from the repository root with
# the environment installed (`make venv`); 2 cores.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-02-refined-planning-poses
B=docs/results/2026-12-02-stance-arm-shifts

# 1. Table II's RBKino and RBLin, 60 starts per cell (1 min).
PYTHONPATH=$PWD python studies/table2_baselines.py --out $D/table2 --n-starts 60 --workers 2 \
  --variants rblin,rbkino --sweep-steps ""

# 2. Own arena guides, 256 starts, evaluation seed 0 (2 min each on the idle machine), paired.
for PAIR in shipped:checkpoints/leas_talos pretrain:checkpoints/leas_talos/pretrain \
    learned_arms_s0:docs/results/2026-12-02-arms-in/train_paper_learned_arms_s0; do
  PYTHONPATH=$PWD python studies/guide_failures.py --policy ${PAIR#*:} --starts 256 --workers 2 \
    --spawns condition --out $D/guides/${PAIR%%:*}
  PYTHONPATH=$PWD python studies/guide_failures.py --compare $B/guides/${PAIR%%:*}/guide_failures.json \
    $D/guides/${PAIR%%:*}/guide_failures.json --out $D/guides/${PAIR%%:*}
done

# 3. The pillar check (15 s) and every scenario and method with the shipped policy (6 min).
leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint checkpoints/leas_talos \
  --workers 2 --no-progress --out $D/pillars
leas evaluate --checkpoint checkpoints/leas_talos --scenario all --workers 2 --no-progress \
  --out $D/evaluate_shipped

# 4. The day's three generator changes together: paired with docs/results/2026-12-02-step-fallback.
for P in shipped pretrain learned_arms_s0; do
  mkdir -p $D/guides/$P/since_step_fallback
  PYTHONPATH=$PWD python studies/guide_failures.py \
    --compare docs/results/2026-12-02-step-fallback/guides/$P/guide_failures.json \
    $D/guides/$P/guide_failures.json --out $D/guides/$P/since_step_fallback
done

# 5. The learned condition relabelled on this generator's walking truth (labels cached in
#    .cache/, 24 000 poses), fitted and validated; writes checkpoints/feasibility/walking.npz.
leas feasibility condition --workers 2 --out $D/feasibility
