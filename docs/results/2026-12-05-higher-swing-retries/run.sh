# Two more generator retries (a 0.15 m swing lift, a 1.1 s lookahead): the shipped policy's own
# arena guides, 256 starts per evaluation seed 0-3, paired with the same episodes under the
# generator before (../2026-12-04-ship-learned/guides/planner). Seeds 0 and 1 chose the
# settings (re-planning only their failed guides with candidate retries); 2 and 3 are held out.
# Run from the repository root with the environment installed (`make venv`); about 10 min.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-05-higher-swing-retries
# The 6 default retries, then the two tried here (not the default: see README.md).
RETRIES='((("lookahead", 0.9),), (("candidate_radius", 0.40), ("max_candidates", 48)), (("max_foot_offset", 0.40),), (("lookahead", 0.5),), (("step_trigger", 0.05),), (("swing_lift", 0.03),), (("swing_lift", 0.15),), (("lookahead", 1.1),))'
for S in 0 1 2 3; do
  PYTHONPATH=$PWD python studies/guide_failures.py --policy checkpoints/leas_talos --starts 256 \
    --workers 2 --spawns condition --seed $S --out $D/guides/seed$S --set "retry_settings=$RETRIES"
done
# The same policy's guides before were judged as runs/shipped-learned, its training folder, so
# `--compare` refuses the pair (the policy paths differ); summarise.py pairs them by start.
python $D/summarise.py > $D/summary.md
