#!/bin/sh
# Generalisation of the paper preset between two training arenas: every command
# of docs/results/2026-12-01-second-arena, in order. Run from the repository root.
set -e
D=docs/results/2026-12-01-second-arena
# the paper preset (geometric, 80 M steps, seed 0) on the HPP 10 x 10 scene
# leas train --preset paper --terrain terrains/hpp/random_10x10.toml --out runs/paper_10x10 --no-progress
TEN=$D/train_paper_random_10x10     # that run's policy.ckpt and config.json
OURS=checkpoints/leas_talos/pretrain  # the paper preset on terrains/training_arena.toml, seed 0
for label in ours ten; do
  if [ $label = ours ]; then P=$OURS; else P=$TEN; fi
  leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods leas --checkpoint $P \
    --workers 2 --no-progress --out $D/evaluate/$label/ours
  for s in bridge hole rubble stairs random_10x10; do
    leas evaluate --terrain terrains/hpp/$s.toml --methods leas --checkpoint $P \
      --workers 2 --no-progress --out $D/evaluate/$label/hpp_$s
  done
  for arena in terrains/training_arena.toml terrains/hpp/random_10x10.toml; do
    leas arena-check --checkpoint $P --terrain $arena --episodes 1024 \
      --out $D/arena_check/$label/$(basename $arena .toml)
  done
done
python docs/results/2026-12-01-mesh-terrains/summarise.py $D/evaluate/*/* > $D/evaluate.md
