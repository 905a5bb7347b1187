"""The env's learned termination condition on the training arena: data, fit and report
(`leas feasibility condition`). Host code around jitted pieces.

1. Data: the contact generator's walking truth (`walking_truth`: it covers the 0.36 m straight
   guide ahead of the pose) on `train_poses` fresh arena poses (`poses.sample_poses`, seed
   `train_seed`) and on `policy_train_poses` poses of a policy's own arena guides
   (`poses.policy_poses`, seed `policy_train_seed`; 0 leaves them out); for validation,
   `test_poses` other fresh poses (`test_seed`) and `policy_poses` poses of other guides of the
   policy (`policy_seed`). Labels are cached in `cache`/condition/<set>/ under the key of the
   terrain text, the generator's settings and code (`walkability.walking_labels`: rebuilt when
   any of them changes, resumable chunk by chunk).
2. Fit (`fit.fit`) on the training poses, the threshold set for 95 % sensitivity on a share of
   them kept aside. Weights to `weights` (.npz) with the data key, the terrain and the settings
   as metadata (`walking_truth.stale_weights` compares that key with the current generator's).
3. Report: sensitivity and specificity with 95 % Wilson intervals on both validation sets, of
   the learned condition, of other weights (`compare_weights`), of the calibrated cylinders
   (`ReachabilityConfig()`) and of the training presets' cylinders (`TRAINING_REACHABILITY`);
   the cost per env step of the learned condition against those cylinders, measured in the same
   run (interleaved repeats, `cost_envs` envs, random actions, fresh resets, compile time apart)
   with the load average before and after. Written as feasibility_condition.json (with the
   machine, load and commit) and feasibility_condition.md.
"""

from __future__ import annotations

import dataclasses
import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DEFAULT_WEIGHTS = "checkpoints/feasibility/walking.npz"  # the shipped weights (relative to the repository)


@dataclass(frozen=True)
class ConditionBuild:
    """Pose sets, fit and cost measurement of one build (the command's options)."""

    train_poses: int = 16000
    train_seed: int = 13
    policy_train_poses: int = 3000
    policy_train_seed: int = 14
    test_poses: int = 4000
    test_seed: int = 11
    policy_poses: int = 1000
    policy_seed: int = 12
    policy: str = "checkpoints/leas_talos"  # the policy whose guides give poses
    workers: int = 2  # generator processes (0 or 1: this process)
    steps: int | None = None  # Adam steps of the fit (None: `FitConfig`'s)
    mirror: bool = True  # add the mirrored poses to the fit
    weights: str = DEFAULT_WEIGHTS  # where the weights go
    compare_weights: tuple = ()  # other weights validated on the same poses
    cost_envs: int = 2048  # envs of the cost measurement (0: skip it)
    cost_steps: int = 100
    cost_repeats: int = 3
    cache: str = ".cache"  # label cache folder


def labelled_set(terrain, kind: str, count: int, seed: int, workers: int, cache: Path, policy=None):
    """(poses [N, 4], walking-truth labels [N] bool) of a fresh or policy pose set, the labels
    cached in `cache`/condition/<kind><count>_seed<seed>/."""
    from leas_jax.feasibility.poses import policy_poses, sample_poses
    from leas_jax.feasibility.walkability import walking_labels

    if count <= 0:
        return np.zeros((0, 4)), np.zeros(0, bool)
    if kind == "fresh":
        poses = sample_poses(terrain, count, seed)
    else:
        poses = policy_poses(policy, terrain, count, seed)
    return poses, walking_labels(
        terrain, poses, Path(cache) / "condition" / f"{kind}{count}_seed{seed}", workers
    )


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


def rates_cell(c: dict) -> str:
    """'sensitivity [95 % CI] | specificity [95 % CI] | feasible / infeasible' of `stats.rates`, in %."""
    (slo, shi), (plo, phi) = c["sensitivity_95ci"], c["specificity_95ci"]
    return (
        f"{100 * c['sensitivity']:.1f} % [{100 * slo:.1f}, {100 * shi:.1f}] | "
        f"{100 * c['specificity']:.1f} % [{100 * plo:.1f}, {100 * phi:.1f}] | "
        f"{c['tp'] + c['fn']} / {c['tn'] + c['fp']}"
    )


def cost_line(cost: dict) -> str:
    """One sentence of `env_step_cost`'s figures."""
    return (
        f"Cost per env step ({cost['envs']} envs, {cost['steps']} steps, best of {cost['repeats']}, "
        f"load {cost['load_average_before'][0]:.1f} -> {cost['load_average_after'][0]:.1f}): "
        f"cylinders {cost['cylinders']['us_per_env_step']} us ({cost['cylinders']['steps_per_s']:,} steps/s), "
        f"learned {cost['learned']['us_per_env_step']} us ({cost['learned']['steps_per_s']:,} steps/s): "
        f"x {cost['cost_ratio_learned_over_cylinders']}."
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
            lines.append(f"| {set_name} | {name} | {rates_cell(c)} |")
    if report.get("env_step_cost"):
        lines += ["", cost_line(report["env_step_cost"])]
    return "\n".join(lines) + "\n"


def validation_rows(terrain, field, params, compared: dict, poses: np.ndarray, x: np.ndarray, truth):
    """{condition: `stats.rates`} against `truth` [N] bool at poses [N, 4]: of the fitted weights
    (`x`, the poses' features), of each other weights of `compared` ({name: params}, features
    read on `field`, the terrain's default heightfield) and of both cylinders."""
    from leas_jax.env import ReachabilityConfig
    from leas_jax.feasibility.fit import features_of, predict
    from leas_jax.feasibility.poses import cylinder_verdicts
    from leas_jax.stats import rates
    from leas_jax.training.config import TRAINING_REACHABILITY

    rows = {"learned": rates(predict(params, x), truth)}
    for name, other in compared.items():
        rows[f"learned ({name})"] = rates(predict(other, features_of(other, field, poses)), truth)
    for name, cylinders in (
        ("cylinders (ReachabilityConfig)", ReachabilityConfig()),
        ("cylinders (training)", TRAINING_REACHABILITY),
    ):
        rows[name] = rates(cylinder_verdicts(terrain, poses, cylinders), truth)
    return rows


def labelled_sets(options: ConditionBuild, terrain, say=print) -> dict:
    """{set: (poses [N, 4], labels [N] bool)} of the four pose sets of a build: train,
    policy_train (the fit), fresh and policy (the validation); a set of 0 poses is empty."""
    from leas_jax.training.policy import load_policy

    o = options
    policy = load_policy(o.policy) if o.policy_poses or o.policy_train_poses else None
    plan = {
        "train": ("fresh", o.train_poses, o.train_seed),
        "policy_train": ("policy", o.policy_train_poses, o.policy_train_seed),
        "fresh": ("fresh", o.test_poses, o.test_seed),
        "policy": ("policy", o.policy_poses, o.policy_seed),
    }
    sets = {}
    for name, (kind, count, seed) in plan.items():
        say(f"labelling {name}: {count} {kind} poses (seed {seed})")
        sets[name] = labelled_set(terrain, kind, count, seed, o.workers, Path(o.cache), policy)
    return sets


def save_weights(path: Path, params, key: str, options: ConditionBuild, config) -> None:
    """Write the fitted weights with their data key, terrain and settings (`stale_weights` reads
    the key and the terrain)."""
    from leas_jax.env import ReachabilityConfig
    from leas_jax.env import learned_feasibility as lf
    from leas_jax.feasibility.poses import ARENA

    o = options
    lf.save_params(
        path,
        params,
        data_key=key,
        terrain=f"terrains/{ARENA.name}",
        train=f"{o.train_poses} fresh (seed {o.train_seed}) + {o.policy_train_poses} policy "
        f"(seed {o.policy_train_seed}) poses",
        fit=json.dumps(dataclasses.asdict(config)),
        reachability=json.dumps(dataclasses.asdict(ReachabilityConfig())),  # whose margins it reads
    )


def data_description(options: ConditionBuild, sets: dict) -> dict:
    """The report's description of the pose sets, with each one's feasible fraction."""
    o = options
    return {
        "train": f"{o.train_poses} fresh poses (seed {o.train_seed}) + {o.policy_train_poses} "
        f"poses of {o.policy}'s arena guides (seed {o.policy_train_seed})",
        "fresh": f"{o.test_poses} fresh poses (seed {o.test_seed})",
        "policy": f"{o.policy_poses} poses of {o.policy}'s arena guides (seed {o.policy_seed})",
        "feasible_fraction": {n: float(y.mean()) if len(y) else None for n, (_, y) in sets.items()},
    }


def build(options: ConditionBuild, out: Path, say=print) -> dict:
    """Data, fit and report of the learned condition on the training arena (host).

    Labels the four pose sets (`labelled_sets`), fits the network on the training ones, writes
    the weights to `options.weights` (a path as given or relative to the repository), validates
    on the other two and returns the report, also written to `out` as feasibility_condition.json
    (with the machine, load and commit) and feasibility_condition.md.
    """
    import jax

    from leas_jax.contacts.planner.generator import GeneratorConfig
    from leas_jax.env import EnvConfig, heightfield_from_terrain
    from leas_jax.env import learned_feasibility as lf
    from leas_jax.feasibility.fit import FitConfig, features_of, fit, predict
    from leas_jax.feasibility.poses import ARENA
    from leas_jax.feasibility.walking_truth import dataset_key
    from leas_jax.files import atomic_write_text, resolve_data_path
    from leas_jax.provenance import git_state, load_average, provenance
    from leas_jax.stats import rates
    from leas_jax.terrain import load_terrain

    o = options
    load_before, git = load_average(), git_state()
    began = time.perf_counter()
    terrain = load_terrain(ARENA)
    sets = labelled_sets(o, terrain, say)
    config = FitConfig(mirror=o.mirror)
    if o.steps is not None:
        config = dataclasses.replace(config, steps=o.steps)
    plain = heightfield_from_terrain(terrain, EnvConfig())
    template = lf.init_params(jax.random.PRNGKey(0), config.hidden)
    xs = {name: features_of(template, plain, poses) for name, (poses, _) in sets.items()}
    train_x = np.concatenate([xs["train"], xs["policy_train"]])
    train_y = np.concatenate([sets["train"][1], sets["policy_train"][1]])
    t0 = time.perf_counter()
    params, info = fit(train_x, train_y, config)
    info["fit_seconds"] = round(time.perf_counter() - t0, 1)
    key = dataset_key(terrain.text, GeneratorConfig())
    weights = resolve_data_path(o.weights)
    save_weights(weights, params, key, o, config)
    say(f"wrote {weights} (fit {info['fit_seconds']} s, threshold {info['threshold']:.3f})")

    compared = {name: lf.load_params(resolve_data_path(name))[0] for name in o.compare_weights}
    validation = {}
    for set_name in ("fresh", "policy"):
        poses, truth = sets[set_name]
        if len(poses):
            validation[set_name] = validation_rows(
                terrain, plain, params, compared, poses, xs[set_name], truth
            )
            for name, c in validation[set_name].items():
                say(f"  {set_name:7s} {name:32s} {rates_cell(c)}")
    report = {
        "format": "leas-feasibility-condition-v1",
        "terrain": f"terrains/{ARENA.name}",
        "policy": o.policy,
        "data_key": key,
        "data": data_description(o, sets),
        "fit": dataclasses.asdict(config),
        "fit_info": info,
        "weights": str(o.weights),
        "training_rates": rates(predict(params, train_x), train_y),
        "validation": validation,
    }
    if o.cost_envs > 0:
        report["env_step_cost"] = env_step_cost(
            terrain, o.cost_envs, o.cost_steps, o.cost_repeats, str(weights)
        )
        say(cost_line(report["env_step_cost"]))
    report["seconds"] = round(time.perf_counter() - began, 1)
    record = {"command": "leas feasibility condition", **provenance(load_before, git), **report}
    out = Path(out)
    atomic_write_text(out / "feasibility_condition.json", json.dumps(record, indent=2) + "\n")
    atomic_write_text(out / "feasibility_condition.md", markdown(report))
    return record
