# The learned condition before (d49401f) and after (2f8b5f6) its ground points were sampled on
# their own: features at 20 000 poses compared, then geometric training throughput, the two trees
# alternated twice. Run from the repository root with the environment installed (`make venv`).
set -e
D=docs/results/2026-12-05-condition-ground-gather
R="$PWD"
PY="$R/.venv/bin/python"
git worktree remove --force /tmp/before 2>/dev/null || true
git worktree remove --force /tmp/after 2>/dev/null || true
git worktree add -f /tmp/before d49401f
git worktree add -f /tmp/after 2f8b5f6
for tree in before after; do
  (cd /tmp/$tree && PYTHONPATH=/tmp/$tree "$PY" "$R/$D/features.py" dump /tmp/features_$tree.npz)
done
"$PY" $D/features.py compare /tmp/features_before.npz /tmp/features_after.npz | tee $D/features.txt
for round in 1 2; do
  for tree in before after; do
    (cd /tmp/$tree && PYTHONPATH=/tmp/$tree "$PY" benchmarks/train_throughput.py --presets quick,paper \
      --conditions cylinders,learned --calls 20 --out "$R/$D/$tree$round")
  done
done
"$PY" $D/summarise.py > $D/summary.md
