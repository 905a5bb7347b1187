#!/bin/sh
# The learned condition's ablation on the current generator (retries, wider step search, refined planning
# poses): cylinders / learned condition, each with and without the planner phase, 3 training
# seeds of the `quick` preset (80 M geometric env steps, 150 k kept planner steps), 256 arena
# starts x 2 evaluation seeds, every scenario. The learned condition is the shipped
# checkpoints/feasibility/walking.npz (relabelled on this generator in ../2026-12-02-retry-settings).
# Run from the repository root with the environment installed (`make venv`); 2 cores; about
# 5 h on a slow day. Resumable: run it again and finished runs and evaluations are reused.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-03-ablation
PYTHONPATH=$PWD python studies/feasibility_study.py --out $D/study --preset quick --seeds 0,1,2 \
  --eval-seeds 0,1 --starts 256 --scenarios hole bridge stairs stairs_side circuit --scenario-starts 20 \
  --workers 2
