#!/usr/bin/env bash
# Execute every scene's verified plans made with the transition checks again with this code,
# on the plans cached by docs/results/2026-12-07-motion-transitions/plans.py
# (runs/motion_plans_checked), in two processes (one per core), merged; talos_maze's plan
# (2145 postures) alone with `execute.sh maze`.
# `execute.sh a|b|maze [SCENARIOS]` runs one part (or those of its scenarios);
# `execute.sh part VARIANT SCENARIOS` those scenarios as their own variant;
# `execute.sh combine [VARIANTS]` merges (default checked_a,checked_b) into `checked`.
set -euo pipefail
OUT=docs/results/2026-12-07-motion-arm-detours
A=ground,stairs,bridge,hpp_talos_stairs10,hpp_talos_navBauzil,hole,stairs_side,hpp_bridge,hpp_talos_flatGround,hpp_talos_stairs15,hpp_talos_navBauzil_obstacles,hpp_talos_navBauzil_hard,hpp_talos_plateformes,hpp_bridge_towr,circuit,hpp_slalom_debris
B=hpp_stairs,hpp_rubble,hpp_stairs_towr,hpp_cross_gap,hpp_rubbles_stairs_1,hpp_rubbles_stairs_2,hpp_rubbles_stairs_3,hpp_darpa,hpp_bauzil_ramp_simplified,hpp_rubbles_stairs_bridge_1,hpp_hole
run() {  # variant, scenarios, max postures
    python studies/motion_execution.py --out "$OUT" --transitions --plans runs/motion_plans_checked \
        --starts 2 --ground-starts 1 --max-plans 0 --max-postures "$3" --variant "$1" --scenarios "$2"
}
combine() {
    python studies/motion_execution.py --out "$OUT" --combine "$1" --variant "$2"
}
case "${1:-all}" in
    a) run checked_a "${2:-$A}" 1000 ;;
    b) run checked_b "${2:-$B}" 1000 ;;
    maze) run checked_maze hpp_talos_maze 0 ;;
    part) run "$2" "$3" 1000 ;;
    combine) combine "${2:-checked_a,checked_b}" checked ;;
    all) run checked_a "$A" 1000 & run checked_b "$B" 1000; wait
         combine checked_a,checked_b checked ;;
esac
