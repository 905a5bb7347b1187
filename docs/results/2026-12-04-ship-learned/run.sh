#!/bin/sh
# Ship the ablation's better geometric method: the learned condition
# (../2026-12-04-ablation-more-seeds: stairs and circuit on 5 of 5 `quick` seeds against 1 of 5
# with the cylinders, further progress, equal coverage). The `paper` preset retrained with it,
# planner phase with the condition held fixed as in the ablation (--condition-refresh-every 0),
# judged as the shipped policy was (../2026-12-02-retry-settings): its own arena guides on two
# evaluation seeds, the pillar check, arena-check, every scenario; then `make run` with the
# learned condition from a fresh clone. Run from the repository root with the environment
# installed (`make venv`); 2 cores; about 1.5 h. Every step resumes or is rerun whole.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-04-ship-learned
R=runs/shipped-learned
g() { PYTHONPATH=$PWD python studies/guide_failures.py --starts 256 --workers 2 --spawns condition "$@"; }

# 1. The `paper` preset with the learned condition: 80 M geometric steps, then 600 k kept steps
#    of planner-in-the-loop fine-tuning (about 35 min).
leas train --mode planner --preset paper --reachability learned --condition-refresh-every 0 \
  --no-progress --out $R

# 2. Its own arena guides, 256 starts, evaluation seeds 0 and 1 (3 min each); its pretrain, seed 0.
for S in 0 1; do g --policy $R --seed $S --out $D/guides/planner/seed$S; done
g --policy $R/pretrain --seed 0 --out $D/guides/pretrain/seed0

# 2b. Evaluation seeds 2 and 3 of it and of the policy it replaces (the cylinders'
#     checkpoints/leas_talos of commit d9d19ad; its seeds 0 and 1 are in
#     ../2026-12-02-retry-settings/guides/shipped): 1024 starts each in all.
OLD=/tmp/leas_talos_cylinders
[ -d $OLD ] || { mkdir -p $OLD && git archive d9d19ad checkpoints/leas_talos | tar -x -C $OLD; }
for S in 2 3; do
  g --policy $R --seed $S --out $D/guides/planner/seed$S
  g --policy $OLD/checkpoints/leas_talos --seed $S --out $D/guides/cylinders_shipped/seed$S
done

# 3. eval_ground speed and arena safety (10 s), the pillar check (15 s), every scenario and
#    method (about 20 min).
leas arena-check --checkpoint $R --out $D/arena_check
leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint $R \
  --workers 2 --no-progress --out $D/pillars
leas evaluate --checkpoint $R --scenario all --workers 2 --no-progress --out $D/evaluate

# 4. `make run` (now `leas run --preset quick --reachability learned`) from a fresh clone of this
#    commit outside the repository, then its planner-phase policy's own arena guides:
#      git clone . /tmp/mr && (cd /tmp/mr && time make run)
#      for S in 0 1; do g --policy /tmp/mr/runs/quick/planner --seed $S --out $D/make_run/guides_seed$S; done
#    and runs/quick/report.md with its figures copied into $D/make_run/.
