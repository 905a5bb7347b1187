#!/usr/bin/env bash
# After execute.sh: the friction solver. `solver.sh hpp` simulates the HPP scenes' motions kept by
# execute.sh (runs/motions_checked) again on columns with elliptic friction cones and
# impratio 10 (variant columns_elliptic); `solver.sh evals` makes and executes the evaluation
# scenarios' plans (box terrains, where `mesh_contact` changes nothing) with MuJoCo's default
# solver (variant raster, as before) and with elliptic cones and impratio 10 (columns_elliptic);
# `solver.sh combine` merges every part into raster, columns and columns_elliptic.
set -euo pipefail
OUT=docs/results/2026-12-07-motion-mesh-contact
ELLIPTIC='{"mesh_contact": "columns", "cone": "elliptic", "impratio": 10.0}'
BEFORE='{"mesh_contact": "raster", "cone": "pyramidal", "impratio": 1.0}'
EVAL_A=ground,bridge
EVAL_B=stairs,hole,stairs_side,circuit
run() {  # variant, scenarios, SimulationConfig overrides, more arguments
    python studies/motion_execution.py --out "$OUT" --transitions --plans runs/motion_plans_checked \
        --motions runs/motions_checked --starts 2 --ground-starts 1 --max-plans 0 --max-postures 1000 \
        --variant "$1" --scenarios "$2" --simulation-config "$3" "${@:4}"
}
case "$1" in
    hpp) bash "$OUT/execute.sh" again columns_elliptic "$ELLIPTIC" ;;
    evals) run raster_evals_a "$EVAL_A" "$BEFORE" --also "columns_elliptic_evals_a=$ELLIPTIC" &
           run raster_evals_b "$EVAL_B" "$BEFORE" --also "columns_elliptic_evals_b=$ELLIPTIC"; wait ;;
    combine)
        for v in raster columns_elliptic; do
            python studies/motion_execution.py --out "$OUT" --combine "${v},${v}_evals_a,${v}_evals_b" --variant "${v}_all"
        done ;;
esac
