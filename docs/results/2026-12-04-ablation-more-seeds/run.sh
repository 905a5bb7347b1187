#!/bin/sh
# Training seeds 3, 4 and 5 of ../2026-12-03-ablation's geometric methods (cylinders, learned;
# `quick` preset, the same evaluation: 256 arena starts x 2 evaluation seeds, eval_ground, every
# scenario with 20 starts). With 3 seeds the cylinders' stairs and circuit success spanned
# 0-100 % against the learned condition's 100 % on every seed: do more seeds tell them apart?
# Run from the repository root with the environment installed (`make venv`); 2 cores; about
# 1.5 h. Resumable: finished runs and evaluations are reused; the report is rewritten after
# every run (seeds outer, methods inner).
set -e
export PATH="$PWD/.venv/bin:$PATH"
PYTHONPATH=$PWD python studies/feasibility_study.py --out docs/results/2026-12-04-ablation-more-seeds/study \
  --preset quick --seeds 3,4,5 --methods cylinders,learned --eval-seeds 0,1 --starts 256 \
  --scenarios hole bridge stairs stairs_side circuit --scenario-starts 20 --workers 2
