#!/bin/sh
# Does `make run`'s planner phase lose anything at 100 k kept steps instead of 150 k?
# The phase is sized by wall time (no budget from 0 to 1.2 M kept steps changed coverage:
# ../2026-12-03-planner-phase-settings); 100 k would take about 45 s off `make run`.
# Each of the three 30 M `quick` geometric policies of ../2026-12-06-quick-budget (learned
# condition, seeds 0 1 2) is fine-tuned as `make run` fine-tunes it (`quick` planner preset, the
# geometric run's env, no condition refresh, the geometric seed) for 100 k and for 150 k kept
# steps; every policy, the geometric ones included, is judged on its own arena guides (128
# starts, evaluation seed 0) and on eval_bridge and eval_stairs (20 seeded starts each).
#   sh docs/results/2026-12-06-planner-budget/run.sh
# Run from the repository root with the environment installed (`make venv`); 2 cores, about an
# hour. Resumable: finished runs and judgements are kept (in $RUNS, default runs/planner-budget).
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-06-planner-budget
R=${RUNS:-runs/planner-budget}
G=${GEOMETRIC:-runs/quick-budget/study30/runs/learned}
judge() {  # judge POLICY OUT
  [ -f "$2/guide_failures.json" ] || PYTHONPATH=$PWD python studies/guide_failures.py --policy "$1" \
    --starts 128 --workers 2 --spawns condition --seed 0 --out "$2"
  [ -f "$2/scenarios/results.json" ] || leas evaluate --scenario bridge,stairs --methods leas \
    --checkpoint "$1" --n-starts 20 --workers 2 --no-progress --out "$2/scenarios"
}
for S in ${SEEDS:-0 1 2}; do
  judge "$G/seed$S/geometric" "$D/geometric/seed$S"
  for N in 100000 150000; do
    leas train --mode planner --preset quick --reachability learned --condition-refresh-every 0 \
      --init "$G/seed$S/geometric" --seed "$S" --timesteps "$N" --workers 2 --no-progress \
      --out "$R/planner$N/seed$S"
    mkdir -p "$D/planner$N/seed$S" && cp "$R/planner$N/seed$S/metrics.jsonl" "$R/planner$N/seed$S/config.json" "$D/planner$N/seed$S/"
    judge "$R/planner$N/seed$S" "$D/planner$N/seed$S"
  done
done
