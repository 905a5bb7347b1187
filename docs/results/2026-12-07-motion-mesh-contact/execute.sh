#!/usr/bin/env bash
# Execute the verified plans of every HPP scene (mesh terrains) made with the transition checks
# (runs/motion_plans_checked, made by docs/results/2026-12-07-motion-transitions/plans.py) with
# this code, in two processes (one per core): each motion is made once and simulated on both
# collision surfaces of a mesh terrain (`SimulationConfig.mesh_contact`): variants `raster` and
# `columns`. The made motions are kept in runs/motions_checked, so that
# `execute.sh again VARIANT JSON` simulates the same motions with other SimulationConfig settings.
# talos_maze (2145 postures) is left out (--max-postures 1000), as in the earlier runs.
# `execute.sh a|b` runs one half; `execute.sh combine` merges the halves.
set -euo pipefail
OUT=docs/results/2026-12-07-motion-mesh-contact
A=hpp_rubbles_stairs_1,hpp_rubbles_stairs_3,hpp_rubble,hpp_talos_stairs10,hpp_talos_flatGround,hpp_talos_stairs15,hpp_hole
B=hpp_rubbles_stairs_bridge_1,hpp_rubbles_stairs_2,hpp_slalom_debris,hpp_bauzil_ramp_simplified,hpp_darpa,hpp_stairs,hpp_bridge_towr,hpp_stairs_towr,hpp_cross_gap,hpp_talos_navBauzil,hpp_talos_navBauzil_obstacles,hpp_talos_navBauzil_hard,hpp_talos_plateformes,hpp_bridge
run() {  # variant, scenarios, SimulationConfig overrides, more arguments
    python studies/motion_execution.py --out "$OUT" --transitions --plans runs/motion_plans_checked \
        --motions runs/motions_checked --starts 2 --ground-starts 1 --max-plans 0 --max-postures 1000 \
        --variant "$1" --scenarios "$2" --simulation-config "$3" "${@:4}"
}
both() {  # half (a or b), scenarios
    run "raster_$1" "$2" '{"mesh_contact": "raster"}' --also "columns_$1={\"mesh_contact\": \"columns\"}"
}
combine() {  # variant
    python studies/motion_execution.py --out "$OUT" --combine "$1_a,$1_b" --variant "$1"
}
case "${1:-all}" in
    a) both a "$A" ;;
    b) both b "$B" ;;
    again) run "$2_a" "$A" "$3" & run "$2_b" "$B" "$3"; wait; combine "$2" ;;
    combine) combine raster; combine columns ;;
    all) both a "$A" & both b "$B"; wait; combine raster; combine columns ;;
esac
