# The learned condition relabelled on the generator of the swing lift over a rise, and `make run`
# trained with it. Run from the repository root with the environment installed (`make venv`).
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-05-relabelled-condition

# 1. Labels (24 000 poses, ~21 min with 2 workers; cached in .cache/), fit, validation of the
#    new weights and of those the shipped policy was trained with (its run's condition.npz),
#    the cost per env step; writes checkpoints/feasibility/walking.npz.
leas feasibility condition --workers 2 \
  --compare-weights checkpoints/leas_talos/condition.npz --out $D/feasibility

# 2. `make run` from a fresh clone of the commit holding the new weights (~22 min), then its
#    planner-phase policy's own arena guides, evaluation seeds 0-3 (~5 min):
#   git clone . /tmp/mr && (cd /tmp/mr && time make run)
#   for S in 0 1 2 3; do PYTHONPATH=$PWD python studies/guide_failures.py --policy /tmp/mr/runs/quick/planner \
#     --starts 256 --workers 2 --spawns condition --seed $S --out $D/make_run/guides_seed$S; done
# and runs/quick/report.md with its figures copied into $D/make_run/.
python $D/summarise.py > $D/summary.md
