#!/bin/sh
# The learned condition refitted on the contact generator's whole-path verdicts, and the paper
# preset trained with it: every command of docs/results/2026-12-01-path-condition,
# in order. Run from the repository root with the package's environment on PATH.
set -e
D=docs/results/2026-12-01-path-condition
CYLINDERS=checkpoints/leas_talos/pretrain   # the teacher: the paper preset with the presets' cylinders, seed 0
LEARNED=docs/results/2026-12-01-learned-paper/train_paper_learned   # the same preset with checkpoints/feasibility/walking.npz
# the refit, per-pose threshold (95 % sensitivity on the poses kept aside), with its trade-off table;
# the planned teacher guides (13 MB) are kept in $D/refit_per_pose/teacher_guides_0.npz and reused
PYTHONPATH=$PWD python studies/condition_from_paths.py --episodes 1024 --holdout 256 --workers 2 \
  --weights-out $D/train_paper_paths/condition.npz --out $D/refit_per_pose
# the same refit, threshold for 80 % of the fitted guides' surely feasible prefixes passing whole
mkdir -p $D/refit_path80 && cp $D/refit_per_pose/teacher_guides_0.npz $D/refit_path80/
PYTHONPATH=$PWD python studies/condition_from_paths.py --episodes 1024 --holdout 256 --workers 2 \
  --path-sensitivity 0.8 --weights-out $D/train_paper_paths80/condition.npz --out $D/refit_path80
cp $D/refit_per_pose/teacher_guides_0.npz /tmp/teacher_guides_0.npz   # reused by the second round below
rm $D/refit_per_pose/teacher_guides_0.npz $D/refit_path80/teacher_guides_0.npz
# training with each (80 M geometric steps, seed 0); policies and configs kept in $D/train_paper_paths*,
# whose condition.npz `load_policy` reads (the weights were given by their path at training time)
# leas train --preset paper --reachability learned --condition-weights $D/train_paper_paths80/condition.npz \
#   --out runs/paper_paths80 --no-progress
# leas train --preset paper --reachability learned --condition-weights $D/train_paper_paths/condition.npz \
#   --out runs/paper_paths --no-progress
# which of the cylinders policy's successful scenario guides would each refitted condition end?
leas evaluate --scenario bridge,stairs,stairs_side --methods leas --checkpoint $CYLINDERS \
  --workers 2 --no-progress --out /tmp/cylinders_eval
for run in paths paths80; do
  P=$D/train_paper_$run
  PYTHONPATH=$PWD python studies/condition_on_guides.py --evaluation /tmp/cylinders_eval \
    --policy $P --out $D/condition_on_guides_$run
  PYTHONPATH=$PWD python studies/guide_failures.py --policy $P --starts 256 --workers 2 \
    --spawns condition --out $D/guides/$run/condition
  leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods leas --checkpoint $P \
    --workers 2 --no-progress --out $D/evaluate_$run
done
PYTHONPATH=$PWD python studies/guide_failures.py --policy $D/train_paper_paths --starts 256 --workers 2 \
  --spawns generator --out $D/guides/paths/generator
leas arena-check --checkpoint $D/train_paper_paths --episodes 1024 --out $D/arena_check
# the pillar check terrain: the straight guide, then each policy
leas evaluate --terrain terrains/checks/pillars.toml --methods rblin --workers 2 --no-progress --out $D/pillars/rblin
for P in checkpoints/leas_talos $CYLINDERS $LEARNED $D/train_paper_paths80 $D/train_paper_paths; do
  leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint $P --workers 2 \
    --no-progress --out $D/pillars/$(basename $P)
done
# the DAgger planner phase of 2026-12-01-learned-paper again, every refresh also fitting the teacher's
# path verdicts ($D/refit_per_pose/path_verdicts.npz, written by the first refit above)
# leas train --mode planner --preset paper --init runs/paper_learned --reachability learned \
#   --condition-seed-data $D/refit_per_pose/path_verdicts.npz --workers 2 --out runs/paper_learned_seeded --no-progress
SEEDED=$D/train_paper_learned_seeded
PYTHONPATH=$PWD python studies/guide_failures.py --policy $SEEDED --starts 256 --workers 2 \
  --spawns condition --out $D/guides/learned_seeded/condition
leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods leas --checkpoint $SEEDED \
  --workers 2 --no-progress --out $D/evaluate_learned_seeded
PYTHONPATH=$PWD python studies/condition_on_guides.py --evaluation /tmp/cylinders_eval \
  --policy $SEEDED --out $D/condition_on_guides_learned_seeded
leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint $SEEDED --workers 2 \
  --no-progress --out $D/pillars/train_paper_learned_seeded
# the paper preset trained again, from scratch, against the seeded phase's final condition (fixed)
# leas train --preset paper --reachability learned --condition-weights $SEEDED/condition.npz \
#   --out runs/paper_seeded_geometric --no-progress
AGAIN=$D/train_paper_seeded_geometric
PYTHONPATH=$PWD python studies/guide_failures.py --policy $AGAIN --starts 256 --workers 2 \
  --spawns condition --out $D/guides/seeded_geometric/condition
leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods leas --checkpoint $AGAIN \
  --workers 2 --no-progress --out $D/evaluate_seeded_geometric
leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint $AGAIN --workers 2 \
  --no-progress --out $D/pillars/train_paper_seeded_geometric
leas arena-check --checkpoint $AGAIN --episodes 1024 --out $D/arena_check_seeded_geometric
# a second outer round, refit only: the retrained policy's verdicts with the teacher's
mkdir -p $D/refit_round2 && cp /tmp/teacher_guides_0.npz $D/refit_round2/teacher_guides_1.npz
PYTHONPATH=$PWD python studies/condition_from_paths.py --teacher $AGAIN $CYLINDERS \
  --weights $SEEDED/condition.npz --episodes 1024 --holdout 256 --workers 2 \
  --weights-out /tmp/round2_condition.npz --out $D/refit_round2
rm $D/refit_round2/teacher_guides_*.npz $D/refit_round2/path_verdicts.npz
find $D -name guides.npz -delete   # 0.3-2.8 MB each, remade above
