#!/bin/sh
# The contact generator with the arms held in where a half-sitting arm meets the terrain
# (GeneratorConfig.upper_bodies): the policies' own arena guides, the pillar check and the
# scenarios, each against the rigid upper body where it was measured before. Run from the
# repository root with the environment installed (`make venv`); 2 cores.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-02-arms-in

# 1. The shipped policy's own arena guides, rigid upper body then arms held in (4 min).
for UB in half_sitting half_sitting,arms_in; do
  python studies/guide_failures.py --policy checkpoints/leas_talos --starts 256 --workers 2 \
    --spawns condition --upper-bodies $UB --out $D/shipped/$UB
done

# 2. Earlier policies of the paper preset (seed 0), arms held in (2 min each); their
#    rigid-upper-body figures are in docs/results/2026-12-01-learned-paper and -path-condition.
for PAIR in pretrain:checkpoints/leas_talos/pretrain \
    learned:docs/results/2026-12-01-learned-paper/train_paper_learned \
    learned_seeded:docs/results/2026-12-01-path-condition/train_paper_learned_seeded \
    seeded_geometric:docs/results/2026-12-01-path-condition/train_paper_seeded_geometric; do
  python studies/guide_failures.py --policy ${PAIR#*:} --starts 256 --workers 2 \
    --spawns condition --out $D/${PAIR%%:*}
done

# 3. The pillar check (15 s per policy).
leas evaluate --terrain terrains/checks/pillars.toml --methods rblin --workers 2 --no-progress \
  --out $D/pillars/rblin
for P in checkpoints/leas_talos checkpoints/leas_talos/pretrain \
    docs/results/2026-12-01-learned-paper/train_paper_learned \
    docs/results/2026-12-01-path-condition/train_paper_learned_seeded; do
  leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint $P --workers 2 \
    --no-progress --out $D/pillars/$(basename $P)
done

# 4. Every scenario and method with the shipped policy (5 min).
leas evaluate --checkpoint checkpoints/leas_talos --scenario all --workers 2 --no-progress \
  --out $D/evaluate_shipped

# 5. The learned condition relabelled and refitted on the new generator's walking truth
#    (the label cache's key holds the generator's settings, so every pose is labelled again:
#    24 000 poses, 3 min with 2 workers on the idle machine).
leas feasibility condition --workers 2 \
  --weights $D/walking_arms_in.npz --out $D/feasibility

# 6. The paper preset trained with the relabelled condition, seeds 0-2 (21 min each), and
#    evaluated like the policies above (own arena guides, scenarios, pillars, arena check).
for S in 0 1 2; do
  leas train --preset paper --seed $S --reachability learned --condition-weights $D/walking_arms_in.npz \
    --out runs/paper_learned_arms_s$S --no-progress
  T=$D/train_paper_learned_arms_s$S
  mkdir -p $T && cp runs/paper_learned_arms_s$S/config.json runs/paper_learned_arms_s$S/policy.ckpt $T/
  python studies/guide_failures.py --policy $T --starts 256 --workers 2 --spawns condition \
    --out $D/learned_arms_s$S
  leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods leas --checkpoint $T \
    --workers 2 --no-progress --out $D/evaluate_learned_arms_s$S
  leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint $T --workers 2 \
    --no-progress --out $D/pillars/train_paper_learned_arms_s$S
  leas arena-check --checkpoint $T --episodes 1024 --out $D/arena_check_learned_arms_s$S
done

# 7. The shipped policy's failed guides re-planned with other generator settings (3 min).
python studies/guide_failures.py --policy checkpoints/leas_talos --starts 256 --workers 2 \
  --spawns condition --what-if --out $D/shipped/what_if

# 7b. The same with resets at generator-verified poses (the spawns' verdicts rebuilt once, 2.5 min).
python studies/guide_failures.py --policy checkpoints/leas_talos --starts 256 --workers 2 \
  --spawns generator --out $D/shipped/verified_spawns

# 8. `make run` from a fresh clone (8 min with the environment installed), then its
#    fine-tuned policy's own arena guides (run from the clone's root, where runs/quick is).
#   time make run
#   python studies/guide_failures.py --policy runs/quick/planner --starts 256 --workers 2 \
#     --spawns condition --out $D/make_run/own_guides
