# navigate with the shipped walkability model (now reading the footing) as the lattice's confident
# verdict on the five rough scenes of docs/results/2026-12-06-rough-scenes, 20 seeded starts each,
# as docs/results/2026-12-07-walkability-root-heights/navigate.sh ran the model before:
#   bash docs/results/2026-12-07-walkability-footing/navigate.sh
set -e
out=docs/results/2026-12-07-walkability-footing/navigate
for n in darpa rubbles_stairs_2 rubbles_stairs_3 rubbles_stairs_bridge_1 slalom_debris; do
  leas evaluate --terrain terrains/hpp/rough/$n.toml --methods navigate --checkpoint checkpoints/leas_talos \
    --n-starts 20 --workers 2 --no-progress --out /tmp/walk_navigate/footing/$n \
    --navigate-walkability checkpoints/walkability/walkability.npz
  mkdir -p $out/$n && cp /tmp/walk_navigate/footing/$n/table.md $out/$n/
done
