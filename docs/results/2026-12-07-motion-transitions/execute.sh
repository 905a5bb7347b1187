#!/usr/bin/env bash
# Execute every scene's plans made with the transition checks (cached by plans.py in
# runs/motion_plans_checked), in two processes (one per core), then merge them.
# `execute.sh a|b [SCENARIOS]` runs one half (or those of its scenarios); a run of some
# scenarios replaces them in its half's JSON and keeps the others.
set -euo pipefail
OUT=docs/results/2026-12-07-motion-transitions
A=ground,stairs,bridge,hpp_talos_stairs10,hpp_talos_navBauzil,hole,stairs_side,hpp_bridge,hpp_talos_flatGround,hpp_talos_stairs15,hpp_talos_navBauzil_obstacles,hpp_talos_navBauzil_hard,hpp_talos_plateformes,hpp_bridge_towr,circuit,hpp_slalom_debris
B=hpp_stairs,hpp_rubble,hpp_stairs_towr,hpp_cross_gap,hpp_rubbles_stairs_1,hpp_rubbles_stairs_2,hpp_rubbles_stairs_3,hpp_darpa,hpp_bauzil_ramp_simplified,hpp_rubbles_stairs_bridge_1,hpp_talos_maze,hpp_hole
# The HPP stairs, bridges, rough scenes and rubble whose plans made with the checks differ
# from those made without (plans.json): their unchecked plans (runs/motion_plans) are executed
# too, a comparison on the same code and starts.
UB=hpp_stairs,hpp_bridge,hpp_bauzil_ramp_simplified,hpp_bridge_towr,hpp_cross_gap,hpp_darpa,hpp_rubbles_stairs_1,hpp_rubbles_stairs_2,hpp_rubbles_stairs_3,hpp_rubbles_stairs_bridge_1,hpp_slalom_debris,hpp_stairs_towr,hpp_rubble
unchecked() {
    python studies/motion_execution.py --out "$OUT" --plans runs/motion_plans \
        --starts 2 --ground-starts 1 --max-plans 0 --max-postures 1000 --variant "$1" --scenarios "$2"
}
run() {
    python studies/motion_execution.py --out "$OUT" --transitions --plans runs/motion_plans_checked \
        --starts 2 --ground-starts 1 --max-plans 0 --max-postures 1000 --variant "$1" --scenarios "$2"
}
case "${1:-all}" in
    a) run checked_a "${2:-$A}" ;;
    b) run checked_b "${2:-$B}" ;;
    combine) python studies/motion_execution.py --out "$OUT" --combine "${2:-checked_a,checked_b}" --variant checked ;;
    unchecked) unchecked unchecked "${2:-$UB}" ;;
    all) run checked_a "$A" & run checked_b "$B"; wait
         python studies/motion_execution.py --out "$OUT" --combine checked_a,checked_b --variant checked
         unchecked unchecked "$UB" ;;
esac
