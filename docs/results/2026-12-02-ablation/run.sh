#!/bin/sh
# The learned condition's ablation at make run's scale: the learned condition relabelled on the current
# generator, then cylinders / learned condition, each with and without the planner phase,
# 3 training seeds of the `quick` preset (80 M geometric env steps, 150 k kept planner steps).
# Run from the repository root with the environment installed (`make venv`); 2 cores.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-02-ablation

# 1. The learned condition on the current generator's walking truth: labels cached in .cache/
#    (24 000 poses, about 3 min), fit, validation, cost per env step; writes the shipped weights.
leas feasibility condition --workers 2 --out $D/feasibility

# 2. The study (about 2 h: 6 geometric runs of 7-9 min, 6 planner phases, 12 evaluations).
PYTHONPATH=$PWD python studies/feasibility_study.py --out $D/study --preset quick --seeds 0,1,2 \
  --eval-seeds 0 --starts 256 --scenarios bridge stairs stairs_side circuit --scenario-starts 20 \
  --workers 2
