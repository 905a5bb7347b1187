#!/bin/sh
# `make run` from a fresh clone of this repository's HEAD, timed: the environment installed
# first (`make venv`, from pip's cache), then `/usr/bin/time -v make run`. Writes into the clone
# ($CLONE, default /tmp/make_run_clone): venv.log, run.log, run.err (time's record) and
# runs/quick/ (the run and its report.md).
#   sh docs/results/2026-12-06-make-run-planner-100k/run.sh
# Run on a quiet machine: the figure is wall time.
set -e
C=${CLONE:-/tmp/make_run_clone}
rm -rf "$C"
git clone -q "$PWD" "$C"
cd "$C"
make venv > venv.log 2>&1
uptime > load.log
/usr/bin/time -v make run > run.log 2> run.err
uptime >> load.log
