# The generator's retries with the swing lift held high only over a rise
# (`GeneratorConfig.swing_lift_on_rise` retry, then the 1.1 s lookahead): the shipped policy's
# own arena guides, 256 starts per evaluation seed 0-3, paired by start with the same episodes
# under the 6 retries before (../2026-12-04-ship-learned/guides/planner) and with the 0.15 m
# lift everywhere (../2026-12-05-higher-swing-retries/guides).
# Run from the repository root with the environment installed (`make venv`); about 20 min, then
# `make run` (about 25 min).
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-05-swing-lift-on-rise
for S in 0 1 2 3; do
  PYTHONPATH=$PWD python studies/guide_failures.py --policy checkpoints/leas_talos --starts 256 \
    --workers 2 --spawns condition --seed $S --out $D/guides/seed$S
done
python $D/summarise.py > $D/summary.md

# The pillar check (15 s) and every scenario and method (about 10 min) with this generator.
leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint checkpoints/leas_talos \
  --workers 2 --no-progress --out $D/pillars
leas evaluate --checkpoint checkpoints/leas_talos --scenario all --workers 2 --no-progress --out $D/evaluate

# `make run` from a fresh clone of this commit outside the repository, then its planner-phase
# policy's own arena guides (evaluation seeds 0-3):
#   git clone . /tmp/mr && (cd /tmp/mr && time make run)
#   for S in 0 1 2 3; do PYTHONPATH=$PWD python studies/guide_failures.py --policy /tmp/mr/runs/quick/planner \
#     --starts 256 --workers 2 --spawns condition --seed $S --out $D/make_run/guides_seed$S; done
# and runs/quick/report.md with its figures copied into $D/make_run/.
