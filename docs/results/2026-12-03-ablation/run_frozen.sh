#!/bin/sh
# The planner phase on the learned condition with the condition frozen (no DAgger refits,
# --refresh-every 0): separates what the planner phase does from what the refits do. It
# continues run.sh's `learned` geometric runs of the same seeds (linked, not retrained), with
# the same planner phase and evaluation as run.sh's `learned+planner`. Run after run.sh, from
# the repository root; SEEDS (default 0,1,2) picks the seeds whose geometric runs exist.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-03-ablation
mkdir -p $D/study_frozen/runs
ln -sfn ../../study/runs/learned $D/study_frozen/runs/learned
PYTHONPATH=$PWD python benchmarks/feasibility_study.py --out $D/study_frozen --methods learned+planner \
  --refresh-every 0 --preset quick --seeds ${SEEDS:-0,1,2} \
  --eval-seeds 0,1 --starts 256 --scenarios hole bridge stairs stairs_side circuit --scenario-starts 20 \
  --workers 2
