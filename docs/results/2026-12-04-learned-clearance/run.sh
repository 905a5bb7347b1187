#!/bin/sh
# The `quick` preset with the learned condition, its clearance term's six probe poses judged by
# the cylinders (EnvConfig.clearance_condition = "cylinders") instead of the network: 3 training
# seeds and the evaluation of ../2026-12-03-ablation's `learned` method (256 arena starts x 2
# evaluation seeds, eval_ground, every scenario with 20 starts), against which it is compared.
# Then the PPO throughput of `quick` and `paper` with each condition and probe judge, in one run.
# Run from the repository root with the environment installed (`make venv`); 2 cores; about
# 1 h. Resumable: finished runs and evaluations are reused.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-04-learned-clearance
PYTHONPATH=$PWD python studies/feasibility_study.py --out $D/study --preset quick --seeds 0,1,2 \
  --eval-seeds 0,1 --starts 256 --scenarios hole bridge stairs stairs_side circuit --scenario-starts 20 \
  --workers 2 --methods learned --clearance-condition cylinders
python benchmarks/train_throughput.py --presets quick,paper --conditions cylinders,learned \
  --clearance-conditions condition,cylinders --calls 5 --out $D
