#!/bin/sh
# The paper preset trained with the learned feasibility condition against the same preset with
# the cylinders: every command of docs/results/2026-12-01-learned-paper, in order.
# Run from the repository root with the package's environment on PATH.
set -e
D=docs/results/2026-12-01-learned-paper
# training (80 M geometric steps, seed 0): runs/paper_learned, its policy kept in $D/train_paper_learned
# leas train --preset paper --reachability learned --out runs/paper_learned --no-progress
LEARNED=$D/train_paper_learned
CYLINDERS=checkpoints/leas_talos/pretrain   # the same preset with the presets' cylinders, seed 0
# cost per env step of the two conditions in one run (the machine otherwise idle)
PYTHONPATH=$PWD python benchmarks/train_throughput.py --presets paper --conditions cylinders,learned --calls 3 --out $D
for label in learned cylinders; do
  if [ $label = learned ]; then P=$LEARNED; else P=$CYLINDERS; fi
  for spawns in condition generator; do
    PYTHONPATH=$PWD python studies/guide_failures.py --policy $P --starts 256 --workers 2 \
      --spawns $spawns --out $D/guides/$label/$spawns
  done
done
leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods leas --checkpoint $LEARNED \
  --workers 2 --no-progress --out $D/evaluate
leas arena-check --checkpoint $LEARNED --episodes 1024 --out $D/arena_check
# planner-in-the-loop fine-tuning of the learned policy, the condition refreshed on the generator's
# verdicts (DAgger); its policy, config and refreshed condition kept in $D/train_paper_learned_planner
# leas train --mode planner --preset paper --init runs/paper_learned --reachability learned --workers 2 \
#   --out runs/paper_learned_planner --no-progress
PLANNER=$D/train_paper_learned_planner
for spawns in condition generator; do
  PYTHONPATH=$PWD python studies/guide_failures.py --policy $PLANNER --starts 256 --workers 2 \
    --spawns $spawns --out $D/guides/learned_planner/$spawns
done
leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods leas --checkpoint $PLANNER \
  --workers 2 --no-progress --out $D/evaluate_planner
leas arena-check --checkpoint $PLANNER --episodes 1024 --out $D/arena_check_planner
# which of the cylinders policy's successful scenario guides would each learned condition end?
leas evaluate --scenario bridge,stairs,stairs_side --methods leas --checkpoint $CYLINDERS \
  --workers 2 --no-progress --out /tmp/cylinders_eval
PYTHONPATH=$PWD python studies/condition_on_guides.py --evaluation /tmp/cylinders_eval \
  --policy $LEARNED --out $D/condition_on_guides
PYTHONPATH=$PWD python studies/condition_on_guides.py --evaluation /tmp/cylinders_eval \
  --policy $PLANNER --out $D/condition_on_guides_planner
# the same planner phase with every refit anchored on 4000 reset-like poses labelled by the
# starting condition (TrainConfig.condition_anchor_poses); kept in $D/train_paper_learned_anchored
# PYTHONPATH=$PWD python $D/train_anchored.py runs/paper_learned runs/paper_learned_anchored
ANCHORED=$D/train_paper_learned_anchored
PYTHONPATH=$PWD python studies/guide_failures.py --policy $ANCHORED --starts 256 --workers 2 \
  --spawns condition --out $D/guides/learned_anchored/condition
leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods leas --checkpoint $ANCHORED \
  --workers 2 --no-progress --out $D/evaluate_anchored
PYTHONPATH=$PWD python studies/condition_on_guides.py --evaluation /tmp/cylinders_eval \
  --policy $ANCHORED --out $D/condition_on_guides_anchored
