#!/usr/bin/env bash
# With execute.sh: the friction solver, and the parts run beside execute.sh's halves.
#   solver.sh c        A's scenarios after rubbles_stairs_1, last first, in a third process
#                      (raster_c, columns_c, columns_elliptic_c); execute.sh's `a` then finds
#                      their motions kept and simulates them again only
#   solver.sh elliptic HALF   the scenarios of execute.sh's half (a or b) simulated again on
#                      columns with elliptic friction cones and impratio 10 (columns_elliptic_HALF),
#                      from the motions kept in runs/motions_checked; darpa_0's motion is made
#                      again (this code centres its one-foot posture 54, the only one of these
#                      plans that it changes)
#   solver.sh evals    the evaluation scenarios' plans (box terrains, where `mesh_contact`
#                      changes nothing), made and executed with MuJoCo's default solver (raster)
#                      and with elliptic cones and impratio 10 (columns_elliptic)
#   solver.sh combine  every part merged into raster_all, columns (HPP scenes only) and
#                      columns_elliptic_all
set -euo pipefail
OUT=docs/results/2026-12-07-motion-mesh-contact
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
    elliptic)
        rm -f runs/motions_checked/hpp_darpa_0.*
        if [ "$2" = a ]; then run columns_elliptic_a "$A" "$ELLIPTIC"; else run columns_elliptic_b "$B" "$ELLIPTIC"; fi ;;
    evals) run raster_evals_a "$EVAL_A" "$BEFORE" --also "columns_elliptic_evals_a=$ELLIPTIC" &
           run raster_evals_b "$EVAL_B" "$BEFORE" --also "columns_elliptic_evals_b=$ELLIPTIC"; wait ;;
    combine)
        for v in raster columns_elliptic; do
            python studies/motion_execution.py --out "$OUT" --combine "${v}_a,${v}_b,${v}_c" --variant "$v"
            python studies/motion_execution.py --out "$OUT" --combine "${v},${v}_evals_a,${v}_evals_b" --variant "${v}_all"
        done
        python studies/motion_execution.py --out "$OUT" --combine columns_a,columns_b,columns_c --variant columns ;;
esac
