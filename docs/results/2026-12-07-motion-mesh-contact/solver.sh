#!/usr/bin/env bash
# With execute.sh: the friction solver, and the parts run beside execute.sh's halves.
#   solver.sh c        A's scenarios after rubbles_stairs_1, last first, in a third process
#                      (raster_c, columns_c, columns_elliptic_c: elliptic cones, impratio 10);
#                      execute.sh's `a` then finds their motions kept and simulates them only.
#                      It was stopped during rubbles_stairs_3 (`a` ran that one).
#   solver.sh final HALF   the scenarios of execute.sh's half (a or b) simulated again with the
#                      settings kept (columns, pyramidal cones, impratio 10: variant final_HALF)
#                      from the motions kept in runs/motions_checked; darpa_0's motion is made
#                      again (this code centres its one-foot posture 54, the only posture of these
#                      plans that it changes: one_foot_fallback.txt)
#   solver.sh evals    the evaluation scenarios' plans (box terrains, where `mesh_contact`
#                      changes nothing), made and executed with MuJoCo's default solver (raster)
#                      and with the settings kept (final)
#   solver.sh combine  every part merged: raster_all (before), final_all (now), and for the HPP
#                      scenes alone raster, columns, final
set -euo pipefail
OUT=docs/results/2026-12-07-motion-mesh-contact
FINAL='{"mesh_contact": "columns", "cone": "pyramidal", "impratio": 10.0}'
ELLIPTIC='{"mesh_contact": "columns", "cone": "elliptic", "impratio": 10.0}'
COLUMNS='{"mesh_contact": "columns", "cone": "pyramidal", "impratio": 1.0}'
BEFORE='{"mesh_contact": "raster", "cone": "pyramidal", "impratio": 1.0}'
A=hpp_rubbles_stairs_1,hpp_rubbles_stairs_3,hpp_rubble,hpp_talos_stairs10,hpp_talos_flatGround,hpp_talos_stairs15,hpp_hole
C=hpp_hole,hpp_talos_stairs15,hpp_talos_flatGround,hpp_talos_stairs10,hpp_rubble,hpp_rubbles_stairs_3
B=hpp_rubbles_stairs_bridge_1,hpp_rubbles_stairs_2,hpp_slalom_debris,hpp_bauzil_ramp_simplified,hpp_darpa,hpp_stairs,hpp_bridge_towr,hpp_stairs_towr,hpp_cross_gap,hpp_talos_navBauzil,hpp_talos_navBauzil_obstacles,hpp_talos_navBauzil_hard,hpp_talos_plateformes,hpp_bridge
EVAL_A=ground,bridge
EVAL_B=stairs,hole,stairs_side,circuit
run() {  # variant, scenarios, SimulationConfig overrides, more arguments
    python studies/motion_execution.py --out "$OUT" --transitions --plans runs/motion_plans_checked \
        --motions runs/motions_checked --starts 2 --ground-starts 1 --max-plans 0 --max-postures 1000 \
        --variant "$1" --scenarios "$2" --simulation-config "$3" "${@:4}"
}
case "$1" in
    c) run raster_c "$C" "$BEFORE" --also "columns_c=$COLUMNS" --also "columns_elliptic_c=$ELLIPTIC" ;;
    final)
        if [ "$2" = a ]; then run final_a "$A" "$FINAL"; else rm -f runs/motions_checked/hpp_darpa_0.*; run final_b "$B" "$FINAL"; fi ;;
    evals) run raster_evals_a "$EVAL_A" "$BEFORE" --also "final_evals_a=$FINAL" &
           run raster_evals_b "$EVAL_B" "$BEFORE" --also "final_evals_b=$FINAL"; wait ;;
    combine)
        python studies/motion_execution.py --out "$OUT" --combine raster_c,raster_a,raster_b --variant raster
        python studies/motion_execution.py --out "$OUT" --combine columns_c,columns_a,columns_b --variant columns
        python studies/motion_execution.py --out "$OUT" --combine final_a,final_b --variant final
        for v in raster final; do
            python studies/motion_execution.py --out "$OUT" --combine "${v},${v}_evals_a,${v}_evals_b" --variant "${v}_all"
        done ;;
esac
# talos_maze's plan (2145 postures), alone: `solver.sh maze` (variant final_maze)
if [ "$1" = maze ]; then
    python studies/motion_execution.py --out "$OUT" --transitions --plans runs/motion_plans_checked \
        --motions runs/motions_checked --starts 2 --ground-starts 1 --max-plans 0 --max-postures 0 \
        --variant final_maze --scenarios hpp_talos_maze --simulation-config "$FINAL"
fi
