"""Build, train and validate the learned feasibility condition.

1. Data (benchmarks/feasibility_data.py, cached in .cache/ and rebuilt when the terrain,
   the generator's settings or its sources change): the contact generator's walking
   truth on `--train-poses` fresh arena poses (seed `--train-seed`) and on
   `--policy-train-poses` poses of the policy's own arena guides (`--policy`, seed
   `--policy-train-seed`; 0 leaves them out); for validation, `--test-poses` other
   fresh poses (`--test-seed`) and `--policy-poses` poses of other guides of the policy
   (`--policy-seed`).
2. Fit (`leas_jax.feasibility.fit`) on the training poses; the threshold is set for 95 %
   sensitivity on a share of them kept aside. Weights to `--weights` (.npz), with the
   data key and the settings as metadata.
3. Report: sensitivity and specificity with 95 % Wilson intervals on both validation sets,
   of the learned condition, the calibrated cylinders (`ReachabilityConfig()`) and the
   training presets' cylinders (`TRAINING_REACHABILITY`); the cost per env step of the
   learned condition against those cylinders, measured in the same run (interleaved
   repeats, `--envs` envs, random actions, fresh resets, compile time apart), with the
   load average before and after.

    python benchmarks/feasibility_condition.py [--train-poses 16000] [--workers 2]
        [--weights checkpoints/feasibility/walking.npz] [--out docs/results/...]

Writes <out>/feasibility_condition.json (with the machine, load and commit) and
feasibility_condition.md (default out: benchmarks/results).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # the generator's workers are the parallelism

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

import feasibility_data as fd  # noqa: E402
import reachability_calibration as rc  # noqa: E402
import reachability_validation as rv  # noqa: E402

from leas_jax.feasibility.walking_truth import dataset_key  # noqa: E402

DEFAULT_WEIGHTS = "checkpoints/feasibility/walking.npz"


def labelled_set(terrain, kind: str, count: int, seed: int, workers: int, policy=None):
    """(poses [N, 4], walking-truth labels [N]) of a fresh or policy pose set (cached)."""
    if count <= 0:
        return np.zeros((0, 4)), np.zeros(0, bool)
    if kind == "fresh":
        poses = fd.fresh_poses(terrain, count, seed)
    else:
        poses = fd.policy_poses(policy, terrain, count, seed)
    return poses, fd.walking_labels(terrain, poses, f"{kind}{count}_seed{seed}", workers)


def env_step_cost(terrain, envs: int, steps: int, repeats: int, weights: str) -> dict:
    """Env steps per second with the training cylinders and with the learned condition (same run).

    Random actions, fresh resets (FreshResetVmap), `envs` envs for `steps` steps per call;
    the two conditions' calls alternate, best of `repeats` each. Returns the two rates, the
    learned condition's cost ratio (cylinders' rate / learned rate), compile times and the
    load average before and after.
    """
    import jax

    from leas_jax.env import FreshResetVmap, LeasEnv, ReachabilityConfig, heightfield_from_terrain
    from leas_jax.training.config import TRAINING_ENV

    configs = {
        "cylinders": TRAINING_ENV,
        # the learned condition reads the calibrated cylinders' margins: its field has their rasters
        "learned": dataclasses.replace(
            TRAINING_ENV, condition="learned", learned_weights=weights, reachability=ReachabilityConfig()
        ),
    }

    def compiled(config):
        field = heightfield_from_terrain(terrain, config)

        @jax.jit
        def run(field, key):
            wrapped = FreshResetVmap(LeasEnv(field, config))
            state = wrapped.reset(jax.random.split(key, envs))

            def body(state, k):
                state = wrapped.step(state, jax.random.uniform(k, (envs, 4), minval=-1.0, maxval=1.0))
                return state, state.done.sum()

            _, dones = jax.lax.scan(body, state, jax.random.split(key, steps))
            return dones.sum()  # read: XLA keeps every step

        return field, run

    load_before = os.getloadavg()
    runs, out = {}, {}
    for name, config in configs.items():
        field, run = compiled(config)
        t0 = time.perf_counter()
        run(field, jax.random.PRNGKey(0)).block_until_ready()
        runs[name] = (field, run)
        out[name] = {"compile_s": round(time.perf_counter() - t0, 2), "times": []}
    for r in range(repeats):
        for name, (field, run) in runs.items():
            t0 = time.perf_counter()
            run(field, jax.random.PRNGKey(r + 1)).block_until_ready()
            out[name]["times"].append(time.perf_counter() - t0)
    for row in out.values():
        row["steps_per_s"] = round(envs * steps / min(row["times"]))
        row["us_per_env_step"] = round(1e6 * min(row["times"]) / (envs * steps), 3)
    return {
        "envs": envs,
        "steps": steps,
        "repeats": repeats,
        **out,
        "cost_ratio_learned_over_cylinders": round(
            out["learned"]["us_per_env_step"] / out["cylinders"]["us_per_env_step"], 3
        ),
        "load_average_before": load_before,
        "load_average_after": os.getloadavg(),
    }


def _fmt(c: dict) -> str:
    (slo, shi), (plo, phi) = c["sensitivity_95ci"], c["specificity_95ci"]
    return (
        f"{100 * c['sensitivity']:.1f} % [{100 * slo:.1f}, {100 * shi:.1f}] | "
        f"{100 * c['specificity']:.1f} % [{100 * plo:.1f}, {100 * phi:.1f}] | "
        f"{c['tp'] + c['fn']} / {c['tn'] + c['fp']}"
    )


def markdown(report: dict) -> str:
    """The report's tables."""
    lines = [
        "# Learned feasibility condition: validation against the generator's walking truth",
        "",
        f"Training: {report['data']['train']} (threshold set for "
        f"{100 * report['fit']['target_sensitivity']:.0f} % sensitivity on {report['fit_info']['aside']} "
        "poses kept aside).",
        "",
        "| pose set | condition | sensitivity [95 % CI] | specificity [95 % CI] | feasible / infeasible |",
        "|---|---|---|---|---|",
    ]
    for set_name, rows in report["validation"].items():
        for name, c in rows.items():
            lines.append(f"| {set_name} | {name} | {_fmt(c)} |")
    cost = report.get("env_step_cost")
    if cost:
        lines += [
            "",
            f"Cost per env step ({cost['envs']} envs, {cost['steps']} steps, best of {cost['repeats']}, "
            f"load {cost['load_average_before'][0]:.1f} -> {cost['load_average_after'][0]:.1f}): "
            f"cylinders {cost['cylinders']['us_per_env_step']} us ({cost['cylinders']['steps_per_s']:,} steps/s), "
            f"learned {cost['learned']['us_per_env_step']} us ({cost['learned']['steps_per_s']:,} steps/s): "
            f"x {cost['cost_ratio_learned_over_cylinders']}.",
        ]
    return "\n".join(lines) + "\n"


def main(argv=None) -> None:
    from common import RESULTS, load_average, save

    from leas_jax.env import EnvConfig, ReachabilityConfig, heightfield_from_terrain
    from leas_jax.env import learned_feasibility as lf
    from leas_jax.feasibility import FitConfig, features_of, fit, predict
    from leas_jax.files import resolve_data_path
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import TRAINING_REACHABILITY
    from leas_jax.training.policy import load_policy

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--train-poses", type=int, default=16000)
    parser.add_argument("--train-seed", type=int, default=13)
    parser.add_argument("--policy-train-poses", type=int, default=3000)
    parser.add_argument("--policy-train-seed", type=int, default=14)
    parser.add_argument("--test-poses", type=int, default=4000)
    parser.add_argument("--test-seed", type=int, default=11)
    parser.add_argument("--policy-poses", type=int, default=1000)
    parser.add_argument("--policy-seed", type=int, default=12)
    parser.add_argument(
        "--policy", default="checkpoints/leas_talos", help="the policy whose guides give poses"
    )
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--steps", type=int, default=FitConfig.steps, help="Adam steps of the fit")
    parser.add_argument("--no-mirror", action="store_true", help="do not add the mirrored poses")
    parser.add_argument("--weights", default=DEFAULT_WEIGHTS, help="where to write the weights (.npz)")
    parser.add_argument(
        "--compare-weights",
        action="append",
        default=[],
        metavar="FILE",
        help="other learned-condition weights to validate on the same poses (a row each; repeatable), "
        "e.g. the weights a policy was trained with (its run's condition.npz)",
    )
    parser.add_argument("--cost-envs", type=int, default=2048, help="envs of the cost measurement (0: skip)")
    parser.add_argument("--cost-steps", type=int, default=100)
    parser.add_argument("--cost-repeats", type=int, default=3)
    parser.add_argument("--out", default=None, help="directory for the JSON and markdown report")
    args = parser.parse_args(argv)
    for other in args.compare_weights:
        if not resolve_data_path(other).is_file():
            parser.error(f"--compare-weights {other}: no such file")
    for name in ("train_poses", "test_poses"):
        if getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be >= 1")
    if len({args.train_seed, args.test_seed}) < 2 or len({args.policy_train_seed, args.policy_seed}) < 2:
        parser.error("the training and validation seeds must differ (the validation poses must be fresh)")

    load_before = load_average()
    began = time.perf_counter()
    terrain = load_terrain(rc.ARENA)
    policy = load_policy(args.policy) if args.policy_poses or args.policy_train_poses else None
    sets = {
        "train": labelled_set(terrain, "fresh", args.train_poses, args.train_seed, args.workers),
        "policy_train": labelled_set(
            terrain, "policy", args.policy_train_poses, args.policy_train_seed, args.workers, policy
        ),
        "fresh": labelled_set(terrain, "fresh", args.test_poses, args.test_seed, args.workers),
        "policy": labelled_set(terrain, "policy", args.policy_poses, args.policy_seed, args.workers, policy),
    }
    config = FitConfig(steps=args.steps, mirror=not args.no_mirror)
    plain = heightfield_from_terrain(terrain, EnvConfig())
    template = lf.init_params(__import__("jax").random.PRNGKey(0), config.hidden)
    xs = {name: features_of(template, plain, poses) for name, (poses, _) in sets.items()}
    train_x = np.concatenate([xs["train"], xs["policy_train"]])
    train_y = np.concatenate([sets["train"][1], sets["policy_train"][1]])
    t0 = time.perf_counter()
    params, info = fit(train_x, train_y, config)
    info["fit_seconds"] = round(time.perf_counter() - t0, 1)
    from leas_jax.contacts.planner.generator import GeneratorConfig

    key = dataset_key(terrain.text, GeneratorConfig())
    weights = resolve_data_path(args.weights)
    lf.save_params(
        weights,
        params,
        data_key=key,
        terrain=f"terrains/{rc.ARENA.name}",
        train=f"{args.train_poses} fresh (seed {args.train_seed}) + {args.policy_train_poses} policy "
        f"(seed {args.policy_train_seed}) poses",
        fit=json.dumps(dataclasses.asdict(config)),
        reachability=json.dumps(dataclasses.asdict(ReachabilityConfig())),  # whose margins it reads
    )
    print(f"wrote {weights} (fit {info['fit_seconds']} s, threshold {info['threshold']:.3f})")

    compared = {name: lf.load_params(resolve_data_path(name))[0] for name in args.compare_weights}
    validation = {}
    for set_name in ("fresh", "policy"):
        poses, truth = sets[set_name]
        if not len(poses):
            continue
        rows = {"learned": rv.rates(predict(params, xs[set_name]), truth)}
        for name, other in compared.items():
            rows[f"learned ({name})"] = rv.rates(predict(other, features_of(other, plain, poses)), truth)
        for name, cyl in (
            ("cylinders (ReachabilityConfig)", ReachabilityConfig()),
            ("cylinders (training)", TRAINING_REACHABILITY),
        ):
            rows[name] = rv.rates(rc.condition(terrain, poses, cyl), truth)
        validation[set_name] = rows
        for name, c in rows.items():
            print(f"  {set_name:7s} {name:32s} {_fmt(c)}")
    train_rates = rv.rates(predict(params, train_x), train_y)
    report = {
        "format": "leas-feasibility-condition-v1",
        "terrain": f"terrains/{rc.ARENA.name}",
        "policy": args.policy,
        "data_key": key,
        "data": {
            "train": f"{args.train_poses} fresh poses (seed {args.train_seed}) + {args.policy_train_poses} "
            f"poses of {args.policy}'s arena guides (seed {args.policy_train_seed})",
            "fresh": f"{args.test_poses} fresh poses (seed {args.test_seed})",
            "policy": f"{args.policy_poses} poses of {args.policy}'s arena guides (seed {args.policy_seed})",
            "feasible_fraction": {n: float(y.mean()) if len(y) else None for n, (_, y) in sets.items()},
        },
        "fit": dataclasses.asdict(config),
        "fit_info": info,
        "weights": str(args.weights),
        "training_rates": train_rates,
        "validation": validation,
    }
    if args.cost_envs > 0:
        report["env_step_cost"] = env_step_cost(
            terrain, args.cost_envs, args.cost_steps, args.cost_repeats, str(weights)
        )
        print(markdown({**report, "validation": {}}).splitlines()[-1])
    report["seconds"] = round(time.perf_counter() - began, 1)
    out = Path(args.out) if args.out else RESULTS
    save("feasibility_condition", report, load_before, out)
    (out / "feasibility_condition.md").write_text(markdown(report))
    print(f"wrote {out}/feasibility_condition.json and .md")


if __name__ == "__main__":
    main()
