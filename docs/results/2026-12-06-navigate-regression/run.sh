#!/usr/bin/env bash
# Navigate with the lattice that offers doubtful ground: the HPP Talos demo queries (cold, each in
# its own Navigator; plans verified), the evaluation scenarios and every hole-sweep width.
#   bash docs/results/2026-12-06-navigate-regression/run.sh
set -euo pipefail
cd "$(dirname "$0")/../../.."
HERE=docs/results/2026-12-06-navigate-regression
.venv/bin/python studies/navigate_demos.py --workers 1 --out "$HERE/demos" | tee "$HERE/demos.txt"
.venv/bin/leas evaluate --scenario hole,bridge,stairs,stairs_side,circuit --methods navigate \
  --checkpoint checkpoints/leas_talos --n-starts 20 --workers 2 --no-progress --out "$HERE/scenarios"
.venv/bin/leas hole-sweep --methods navigate --checkpoint checkpoints/leas_talos --n-starts 10 \
  --workers 2 --no-progress --out "$HERE/hole_sweep"
rm -f "$HERE"/scenarios/guides.npz "$HERE"/hole_sweep/*/guides.npz "$HERE"/hole_sweep/guides.npz
