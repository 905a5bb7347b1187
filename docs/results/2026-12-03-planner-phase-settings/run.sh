#!/bin/sh
# Can the planner-in-the-loop phase teach the policy what the contact generator rejects if it
# learns more from the generator's verdicts? Two settings of the phase against
# ../2026-12-02-planner-phase (150 k kept steps, 4 mini-batches: no difference):
#   length       1.2 M kept steps (8 x as many samples, 56 iterations), 4 mini-batches;
#   minibatches  150 k kept steps, 64 mini-batches of one episode (16 x the gradient steps per
#                batch, closer to the paper's 256 mini-batches of 48 steps; the learner waits on
#                the generator 92 % of the time, so they cost no wall time).
# Both: the shipped policy's geometric phase (checkpoints/leas_talos/pretrain, `paper` preset,
# cylinders) fine-tuned with `paper` planner settings otherwise (64 guides per iteration, 10
# epochs, the paper's pruning, learning rate 5e-4 decaying linearly to 0), seeds 0 1 2; each
# policy's own arena guides judged on the same 256 starts (evaluation seed 0) as
# ../2026-12-02-planner-phase, and the pretrain again on today's code.
#   sh docs/results/2026-12-03-planner-phase-settings/run.sh length|minibatches
# Run from the repository root with the environment installed (`make venv`); 2 cores; length
# about 2 h, minibatches about 30 min. Resumable: an interrupted run resumes, finished
# evaluations are kept.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-03-planner-phase-settings
R=${RUNS:-/tmp/planner_phase_settings}
case "$1" in
  length) SETTINGS="--timesteps 1200000 --num-minibatches 4" ;;
  minibatches) SETTINGS="--timesteps 150000 --num-minibatches 64" ;;
  *) echo "usage: sh $0 length|minibatches" >&2; exit 2 ;;
esac
judge() {  # judge POLICY OUT: the policy's own arena guides, evaluation seed 0, 256 starts
  [ -f "$2/guide_failures.json" ] || PYTHONPATH=$PWD python studies/guide_failures.py --policy "$1" \
    --starts 256 --workers 2 --spawns condition --seed 0 --out "$2"
}
for S in ${SEEDS:-0 1 2}; do
  # shellcheck disable=SC2086  # SETTINGS is several arguments
  leas train --mode planner --preset paper --init checkpoints/leas_talos/pretrain $SETTINGS \
    --seed "$S" --workers 2 --no-progress --out "$R/$1/seed$S"
  mkdir -p "$D/$1/seed$S" && cp "$R/$1/seed$S/metrics.jsonl" "$R/$1/seed$S/config.json" "$D/$1/seed$S/"
  judge "$R/$1/seed$S" "$D/$1/seed$S/guides"
done
judge checkpoints/leas_talos/pretrain "$D/pretrain"
python "$D/summarise.py" "$D" > "$D/summary.md"
