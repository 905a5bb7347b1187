# The generator's retries with the swing lift held high only over a rise
# (`GeneratorConfig.swing_lift_on_rise` retry, then the 1.1 s lookahead): the shipped policy's
# own arena guides, 256 starts per evaluation seed 0-3, paired by start with the same episodes
# under the 6 retries before (../2026-12-04-ship-learned/guides/planner) and with the 0.15 m
# lift everywhere (../2026-12-05-higher-swing-retries/guides).
# Run from the repository root with the environment installed (`make venv`); about 8 min.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-05-swing-lift-on-rise
for S in 0 1 2 3; do
  PYTHONPATH=$PWD python benchmarks/guide_failures.py --policy checkpoints/leas_talos --starts 256 \
    --workers 2 --spawns condition --seed $S --out $D/guides/seed$S
done
python $D/summarise.py > $D/summary.md
