#!/bin/sh
# run.sh's `learned+planner` planner phase again, on run.sh's `learned` geometric runs of the
# same seeds (linked, not retrained), with the same evaluation; only the DAgger refits change:
#   frozen       --refresh-every 0: no refits, what the planner phase does alone -> study_frozen/
#   sensitivity  refits every 4 iterations whose threshold keeps 99.5 % of the feasible poses
#                held aside instead of FitConfig's 95 % -> study_sensitivity/
# Run after run.sh, from the repository root: sh docs/results/2026-12-03-ablation/run_refits.sh
# frozen|sensitivity; SEEDS (default 0,1,2) picks the seeds whose geometric runs exist.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-03-ablation
case "$1" in
  frozen) OUT=$D/study_frozen; REFITS="--refresh-every 0" ;;
  sensitivity) OUT=$D/study_sensitivity; REFITS="--refresh-every 4 --refresh-sensitivity 0.995" ;;
  *) echo "usage: sh $0 frozen|sensitivity" >&2; exit 2 ;;
esac
mkdir -p $OUT/runs
ln -sfn ../../study/runs/learned $OUT/runs/learned
PYTHONPATH=$PWD python studies/feasibility_study.py --out $OUT --methods learned+planner $REFITS \
  --preset quick --seeds ${SEEDS:-0,1,2} --eval-seeds 0,1 --starts 256 \
  --scenarios hole bridge stairs stairs_side circuit --scenario-starts 20 --workers 2
