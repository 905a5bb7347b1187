#!/bin/bash
# GPU quick-train + arena-check (2026-11-22). Run from the repo root on the device.
set -o pipefail
ROOT=$PWD
LOG=$OUT/gpu_quick_device.log
{ date -u +%FT%TZ; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader; } >"$LOG" 2>&1
cp .whl4/all.tar.xz.* /tmp/parts/ || exit 1
ls -la /tmp/parts >>"$LOG"
(cd /tmp/parts && sha256sum -c "$ROOT/.whl4/SHA256SUMS") >>"$LOG" 2>&1 || { echo "chunk check FAILED"; cat "$LOG"; exit 1; }
mkdir -p /tmp/site
s=$(date +%s); cat /tmp/parts/all.tar.xz.* | xz -dc -T0 | tar -C /tmp/site -xf - || { echo unpack FAILED; exit 1; }
echo "unpacked in $(( $(date +%s) - s )) s" >>"$LOG"
export PYTHONPATH=/tmp/site:$ROOT PYTHONUNBUFFERED=1
python3 -c "import jax, jaxlib, numpy, flax, brax; print('jax', jax.__version__, 'jaxlib', jaxlib.__version__, 'numpy', numpy.__version__, 'flax', flax.__version__, 'backend', jax.default_backend(), jax.devices())" >>"$LOG" 2>&1
cat "$LOG"
leas() { python3 -c "import sys; from leas_jax.cli import main; sys.argv[0] = 'leas'; sys.exit(main())" "$@"; }
echo "=== leas train --preset quick --mode geometric --out /tmp/r --no-progress $(date -u +%FT%TZ)" | tee $OUT/gpu_quick_train.log
{ time leas train --preset quick --mode geometric --out /tmp/r --no-progress; echo "rc $?"; } 2>&1 | tee -a $OUT/gpu_quick_train.log
tar -C /tmp -cf $OUT/gpu_quick_run.tar r && ls -la $OUT/gpu_quick_run.tar
echo "=== leas arena-check --checkpoint /tmp/r --out \$OUT/gpu_arena $(date -u +%FT%TZ)" | tee $OUT/gpu_quick_arena_check.log
{ time timeout 240 python3 -c "import sys; from leas_jax.cli import main; sys.argv[0] = 'leas'; sys.exit(main())" arena-check --checkpoint /tmp/r --out $OUT/gpu_arena; echo "rc $?"; } 2>&1 | tee -a $OUT/gpu_quick_arena_check.log
cat $OUT/gpu_arena/arena_check.md 2>/dev/null
