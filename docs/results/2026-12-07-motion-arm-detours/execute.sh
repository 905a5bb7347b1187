#!/usr/bin/env bash
# Execute every scene's verified plans again with this code, on the plans cached by
# docs/results/2026-12-07-motion-transitions/plans.py: those made with the transition checks
# (runs/motion_plans_checked) in two processes (one per core), merged; talos_maze's plan
# (2145 postures) alone; then the plans made without the checks (runs/motion_plans) of the
# HPP scenes that folder executed both ways.
# `execute.sh a|b|maze|unchecked [SCENARIOS]` runs one part (or those of its scenarios).
set -euo pipefail
OUT=docs/results/2026-12-07-motion-arm-detours
A=ground,stairs,bridge,hpp_talos_stairs10,hpp_talos_navBauzil,hole,stairs_side,hpp_bridge,hpp_talos_flatGround,hpp_talos_stairs15,hpp_talos_navBauzil_obstacles,hpp_talos_navBauzil_hard,hpp_talos_plateformes,hpp_bridge_towr,circuit,hpp_slalom_debris
B=hpp_stairs,hpp_rubble,hpp_stairs_towr,hpp_cross_gap,hpp_rubbles_stairs_1,hpp_rubbles_stairs_2,hpp_rubbles_stairs_3,hpp_darpa,hpp_bauzil_ramp_simplified,hpp_rubbles_stairs_bridge_1,hpp_hole
UB=hpp_stairs,hpp_bridge,hpp_bauzil_ramp_simplified,hpp_bridge_towr,hpp_cross_gap,hpp_darpa,hpp_rubbles_stairs_1,hpp_rubbles_stairs_2,hpp_rubble,hpp_slalom_debris,hpp_stairs_towr
run() {  # variant, scenarios, max postures
    python studies/motion_execution.py --out "$OUT" --transitions --plans runs/motion_plans_checked \
        --starts 2 --ground-starts 1 --max-plans 0 --max-postures "$3" --variant "$1" --scenarios "$2"
}
unchecked() {
    python studies/motion_execution.py --out "$OUT" --plans runs/motion_plans \
        --starts 2 --ground-starts 1 --max-plans 0 --max-postures 1000 --variant "$1" --scenarios "$2"
}
combine() {
    python studies/motion_execution.py --out "$OUT" --combine "$1" --variant "$2"
}
case "${1:-all}" in
    a) run checked_a "${2:-$A}" 1000 ;;
    b) run checked_b "${2:-$B}" 1000 ;;
    maze) run checked_maze hpp_talos_maze 0 ;;
    unchecked) unchecked unchecked "${2:-$UB}" ;;
    combine) combine checked_a,checked_b,checked_maze checked ;;
    all) run checked_a "$A" 1000 & run checked_b "$B" 1000; wait
         combine checked_a,checked_b checked ;;
esac
