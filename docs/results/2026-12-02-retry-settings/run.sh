#!/bin/sh
# The contact generator's wider step search (candidates within 0.30 m of a step target, 24
# tried, comfort region 0.32 m, single-support root bound 0.25 m) and its retries of a stuck
# stretch with other step settings (GeneratorConfig.retry_settings, 4 planning poses back):
# the policies' own arena guides on two evaluation seeds, each paired with the generator
# before (its settings given back with --set), the scenarios, the pillar check, Table II's
# baselines and the learned condition relabelled. Run from the repository root with the
# environment installed (`make venv`); 2 cores.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=docs/results/2026-12-02-retry-settings
B=docs/results/2026-12-02-refined-planning-poses
BEFORE="--set max_foot_offset=0.25 --set max_single_support_offset_xy=0.20 --set candidate_radius=0.15 --set max_candidates=12 --set retry_settings=()"
g() { PYTHONPATH=$PWD python studies/guide_failures.py --starts 256 --workers 2 --spawns condition "$@"; }
c() { PYTHONPATH=$PWD python studies/guide_failures.py --compare "$@"; }

# 1. Own arena guides, 256 starts (2-3 min each on the idle machine). Evaluation seed 0 pairs
#    with the report of the generator before ($B); seed 1 runs both generators here.
for PAIR in shipped:checkpoints/leas_talos learned_arms_s0:docs/results/2026-12-02-arms-in/train_paper_learned_arms_s0 \
    pretrain:checkpoints/leas_talos/pretrain; do
  P=${PAIR%%:*}; POLICY=${PAIR#*:}
  g --policy $POLICY --seed 0 --out $D/guides/$P/seed0
  c $B/guides/$P/guide_failures.json $D/guides/$P/seed0/guide_failures.json --out $D/guides/$P/seed0
  if [ $P != pretrain ]; then
    g --policy $POLICY --seed 1 $BEFORE --out $D/guides/$P/seed1_before
    g --policy $POLICY --seed 1 --out $D/guides/$P/seed1
    c $D/guides/$P/seed1_before/guide_failures.json $D/guides/$P/seed1/guide_failures.json --out $D/guides/$P/seed1
  fi
done

# 2. The wider search alone, without retries (shipped policy, seed 0).
g --policy checkpoints/leas_talos --seed 0 --set "retry_settings=()" --out $D/guides/shipped/seed0_no_retries
c $B/guides/shipped/guide_failures.json $D/guides/shipped/seed0_no_retries/guide_failures.json \
  --out $D/guides/shipped/seed0_no_retries

# 3. The pillar check (15 s), every scenario and method with the shipped policy (6 min),
#    Table II's RBKino and RBLin, 60 starts per cell (1 min).
leas evaluate --terrain terrains/checks/pillars.toml --methods leas --checkpoint checkpoints/leas_talos \
  --workers 2 --no-progress --out $D/pillars
leas evaluate --checkpoint checkpoints/leas_talos --scenario all --workers 2 --no-progress \
  --out $D/evaluate_shipped
PYTHONPATH=$PWD python studies/table2_baselines.py --out $D/table2 --n-starts 60 --workers 2 \
  --variants rblin,rbkino --sweep-steps ""

#    The shipped policy's eval_ground speed and arena safety (10 s).
leas arena-check --checkpoint checkpoints/leas_talos --out $D/arena_check_shipped

# 4. The learned condition relabelled on this generator's walking truth (labels cached in
#    .cache/, 24 000 poses), fitted and validated; writes checkpoints/feasibility/walking.npz.
leas feasibility condition --workers 2 --out $D/feasibility

# 5. `make run` from a fresh clone of this commit (outside the repository, here /tmp/mr), then
#    its planner-phase policy's own arena guides on two evaluation seeds:
#      git clone . /tmp/mr && (cd /tmp/mr && time make run)
#      for S in 0 1; do PYTHONPATH=$PWD python studies/guide_failures.py --policy /tmp/mr/runs/quick/planner \
#        --starts 256 --workers 2 --spawns condition --seed $S --out $D/make_run/guides_seed$S; done
#    and runs/quick/report.md with its figures copied into $D/make_run/.

# 6. The ablation's geometric policies (docs/results/2026-12-02-ablation, 3 seeds each of
#    cylinders and the learned condition) judged by this generator, 2 evaluation seeds: the
#    finished runs are copied and reused, not retrained (10 min). The learned runs terminate
#    their episodes with the weights at their stored path, i.e. step 4's relabelled ones.
rm -rf /tmp/study && mkdir -p /tmp/study/runs
cp -r docs/results/2026-12-02-ablation/study/runs/cylinders docs/results/2026-12-02-ablation/study/runs/learned /tmp/study/runs/
PYTHONPATH=$PWD python studies/feasibility_study.py --out /tmp/study --methods cylinders,learned \
  --seeds 0,1,2 --eval-seeds 0,1 --starts 256 --workers 2
mkdir -p $D/study && cp /tmp/study/feasibility_study.json /tmp/study/feasibility_study.md /tmp/study/feasibility_study.png $D/study/

# 7. Planner-in-the-loop throughput on the idle machine, 12 iterations of 64 episodes from the
#    shipped pretrain, 2 contact workers (3 min).
PYTHONPATH=$PWD python benchmarks/planner_training_throughput.py --init checkpoints/leas_talos/pretrain \
  --workers 2 --iterations 12 --out $D/planner_throughput
