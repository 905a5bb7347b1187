#!/bin/sh
# The DAgger planner phase with refits that set their threshold for 99.5 % sensitivity
# (--refresh-sensitivity 0.995) instead of FitConfig's 95 %: the refits at 95 % rejected about
# 1 in 20 of the policy's own poses and the policy stopped. Otherwise as run.sh's
# `learned+planner` (refit every 4 iterations), on run.sh's `learned` geometric runs of the same
# seeds (linked, not retrained). Run after run.sh, from the repository root; SEEDS (default
# 0,1,2) picks the seeds.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-03-ablation
mkdir -p $D/study_sensitivity/runs
ln -sfn ../../study/runs/learned $D/study_sensitivity/runs/learned
PYTHONPATH=$PWD python benchmarks/feasibility_study.py --out $D/study_sensitivity --methods learned+planner \
  --refresh-every 4 --refresh-sensitivity 0.995 --preset quick --seeds ${SEEDS:-0,1,2} \
  --eval-seeds 0,1 --starts 256 --scenarios hole bridge stairs stairs_side circuit --scenario-starts 20 \
  --workers 2
