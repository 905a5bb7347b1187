"""`leas train`, and the training arguments `leas run` shares (leas_jax.pipeline)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from leas_jax.arguments import (
    add_allow_pickle_argument,
    add_ray_address_argument,
    non_negative_int,
    non_negative_seconds,
    positive_int,
)
from leas_jax.env.config import CLEARANCE_CONDITIONS
from leas_jax.errors import UsageError
from leas_jax.training.config import LEARNED_REFRESH_EVERY, PRESETS, learned_condition_env, preset


def add_training_arguments(parser) -> None:
    """The arguments of `leas train`, which `leas run` takes too."""
    parser.add_argument(
        "--preset",
        default="quick",
        choices=sorted(PRESETS),
        help="geometric: smoke (< 1 min), quick (30 M steps, 3 epochs, clearance reward term, "
        "~3 min on 2 cores with the cylinders, ~6 with the learned condition), paper (80 M steps, 10 epochs, the paper's reward, ~25 min); "
        "planner: smoke (20 k kept steps from scratch), quick and paper (the geometric preset of the same name in "
        "<out>/pretrain, then 100 k / 600 k kept steps with the planner)",
    )
    parser.add_argument(
        "--mode",
        default="geometric",
        choices=["geometric", "planner"],
        help="geometric: reachability condition only; planner: every episode validated by the "
        "Talos contact generator (the paper's method)",
    )
    parser.add_argument(
        "--init",
        metavar="RUN_DIR",
        default=None,
        help="planner mode: fine-tune from this geometric run's latest checkpoint "
        "(instead of the preset's own pretraining)",
    )
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="planner mode: contact-generator worker processes (default: one per CPU; "
        "0 plans in this process)",
    )
    add_ray_address_argument(parser, "planner mode: validate the guides")
    parser.add_argument(
        "--out", required=True, metavar="DIR", help="run directory (resumes if it holds a checkpoint)"
    )
    parser.add_argument("--seed", type=int, default=None, help="PRNG seed (default: the preset's, 0)")
    parser.add_argument(
        "--terrain",
        metavar="FILE",
        default=None,
        help="training terrain (default terrains/training_arena.toml)",
    )
    parser.add_argument(
        "--timesteps", type=positive_int, default=None, help="override the preset's env steps"
    )
    parser.add_argument(
        "--num-envs", type=positive_int, default=None, help="override the number of parallel envs"
    )
    parser.add_argument(
        "--num-minibatches",
        type=positive_int,
        metavar="N",
        default=None,
        help="override the preset's gradient steps per epoch: each PPO epoch splits the batch's "
        "envs (planner mode: episodes) into N parts; must divide the number of envs",
    )
    parser.add_argument(
        "--reachability",
        choices=["presets", "calibrated", "learned"],
        default="presets",
        help="condition the policy trains with (both phases): presets (the default: "
        "TRAINING_REACHABILITY, the cylinders alone) or calibrated (ReachabilityConfig(): "
        "lookahead legs, foothold and gripper disks, 95.5 / 90.2 %% sensitivity / specificity "
        "against the walking generator on fresh poses; docs/results/INDEX.md gives the trade) or "
        "learned (the network of checkpoints/feasibility/walking.npz, trained on the generator's "
        "walking verdicts; in planner mode refreshed on the generator's verdicts on the policy's "
        "guides: docs/results/2026-12-01-feasibility)",
    )
    parser.add_argument(
        "--condition-weights",
        metavar="FILE",
        default=None,
        help="with --reachability learned: the learned condition's weights (default "
        "checkpoints/feasibility/walking.npz; studies/condition_from_paths.py refits them on the "
        "generator's whole-path verdicts)",
    )
    parser.add_argument(
        "--clearance-condition",
        choices=CLEARANCE_CONDITIONS,
        default=None,
        help="with --reachability learned and a preset with the clearance term (quick): what judges "
        "the term's six probe poses, the network itself (condition, the default) or the calibrated "
        "cylinders (cylinders: training 1.5 x cheaper, but its policies crossed no bridge; "
        "docs/results/2026-12-04-learned-clearance)",
    )
    parser.add_argument(
        "--condition-seed-data",
        metavar="FILE",
        default=None,
        help="with --mode planner --reachability learned: labelled poses (.npz of poses [K, 4] and "
        "labels [K]) that every refresh of the condition also fits, e.g. the path_verdicts.npz of "
        "studies/condition_from_paths.py or an earlier run's condition_data.npz",
    )
    parser.add_argument(
        "--condition-refresh-every",
        type=non_negative_int,
        metavar="N",
        default=None,
        help="with --mode planner --reachability learned: refit the condition on the generator's "
        f"verdicts on the policy's guides every N iterations (DAgger; default {LEARNED_REFRESH_EVERY}); "
        "0 keeps it as loaded. With the refits the `quick` policies covered 98.6 %% of their "
        "guides by stopping (1.39 m per episode), with 0 90.0 %% at 3.41 m "
        "(docs/results/2026-12-03-ablation)",
    )
    parser.add_argument(
        "--spawns",
        choices=["condition", "generator"],
        default="condition",
        help="where random resets start: condition (the default: near grid points where the "
        "condition's cylinders hold for every yaw) or generator (at poses where the Talos contact "
        "generator stands in double support, verified once per terrain and cached; a few minutes "
        "on the training arena)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument(
        "--checkpoint-every",
        type=non_negative_seconds,
        default=None,
        metavar="SECONDS",
        help="wall-clock seconds between checkpoints (default 60; 0: after every logged iteration); "
        "a checkpoint is also written at the end and on Ctrl-C",
    )
    add_allow_pickle_argument(parser, "checkpoints (resume, --init)")


def config_from_args(args):
    """TrainConfig of the parsed `leas train` / `leas run` arguments."""
    overrides = {}
    if args.init is not None:
        if args.mode != "planner":
            raise UsageError("--init is for --mode planner (fine-tuning a geometric policy)")
        if not (Path(args.init) / "checkpoints").is_dir():
            raise UsageError(f"--init: {args.init} holds no checkpoints/ (give a `leas train` run directory)")
        overrides["init_from"] = str(args.init)
    if args.workers is not None and args.workers < 0:
        raise UsageError(f"--workers must be >= 0, got {args.workers}")
    if args.seed is not None:
        overrides["seed"] = args.seed
    if args.terrain is not None:
        if not Path(args.terrain).is_file():
            raise UsageError(f"--terrain: no such file: {args.terrain}")
        overrides["terrain"] = args.terrain
    if args.timesteps is not None:
        overrides["num_timesteps"] = args.timesteps
    if args.num_envs is not None:
        overrides["num_envs"] = args.num_envs
    if args.num_minibatches is not None:
        overrides["num_minibatches"] = args.num_minibatches
    if args.checkpoint_every is not None:
        overrides["checkpoint_every_s"] = args.checkpoint_every
    config = preset(args.preset, mode=args.mode, **overrides)
    if args.reachability == "calibrated":
        from leas_jax.env import ReachabilityConfig

        config = dataclasses.replace(
            config, env=dataclasses.replace(config.env, reachability=ReachabilityConfig())
        )
    weights = args.condition_weights
    if weights is not None and args.reachability != "learned":
        raise UsageError("--condition-weights is for --reachability learned")
    if args.reachability == "learned":
        from leas_jax.env.config import EnvConfig
        from leas_jax.files import resolve_data_path

        if weights is None:
            weights = EnvConfig.learned_weights
        elif not resolve_data_path(weights).is_file():
            raise UsageError(f"--condition-weights: no such file: {weights}")
        refresh = 0
        if config.mode == "planner":
            refresh = (
                LEARNED_REFRESH_EVERY
                if args.condition_refresh_every is None
                else args.condition_refresh_every
            )
        config = dataclasses.replace(
            config, env=learned_condition_env(config.env, weights), condition_refresh_every=refresh
        )
    if args.clearance_condition is not None:
        if args.reachability != "learned":
            raise UsageError("--clearance-condition is for --reachability learned")
        if config.env.rewards.clearance == 0.0:
            raise UsageError(f"--clearance-condition: preset {args.preset!r} has no clearance term")
        config = dataclasses.replace(
            config, env=dataclasses.replace(config.env, clearance_condition=args.clearance_condition)
        )
    if args.condition_refresh_every is not None and (
        args.reachability != "learned" or config.mode != "planner"
    ):
        raise UsageError("--condition-refresh-every is for --mode planner --reachability learned")
    if args.condition_seed_data is not None:
        if args.reachability != "learned" or config.mode != "planner":
            raise UsageError("--condition-seed-data is for --mode planner --reachability learned")
        from leas_jax.training.planner import seed_data

        seed_data(
            args.condition_seed_data
        )  # refused here, naming the file, rather than after the first batch
        config = dataclasses.replace(config, condition_seed_data=args.condition_seed_data)
    if args.spawns != config.env.spawns:
        config = dataclasses.replace(config, env=dataclasses.replace(config.env, spawns=args.spawns))
    return config


def cmd_train(args) -> int:
    from leas_jax.training.loop import train

    config = config_from_args(args)
    result = train(
        config,
        args.out,
        progress=not args.no_progress,
        workers=args.workers,
        address=args.ray_address,
        allow_pickle=args.allow_pickle,
    )
    print(training_summary(result))
    return 0


def training_summary(result) -> str:
    """The line `leas train` ends with; a resumed run that had nothing left to train says so
    (its call logged no iteration, so there is no speed to report)."""
    if "sps" not in result.metrics:
        return f"already trained: {result.env_steps:,} env steps; policy: {result.policy_path}"
    return (
        f"trained {result.env_steps:,} env steps in {result.wall_s:.0f} s "
        f"({result.metrics['sps']:,.0f} steps/s); policy: {result.policy_path}"
    )


def cmd_convert(args) -> int:
    """`leas convert`: rewrite a run directory's pickle policy and checkpoints in the checkpoint format."""
    from leas_jax.training.checkpoint import convert_run

    if not args.allow_pickle:
        raise UsageError(
            "convert reads pickle files, which can run code: pass --allow-pickle to confirm you trust them"
        )
    for run in args.run_dir:
        if not Path(run).is_dir():
            raise UsageError(f"RUN_DIR: {run}: not a directory")
    for run in args.run_dir:
        for old, new in convert_run(Path(run)):
            print(f"{old} -> {new}")
    return 0


def register(subparsers) -> None:
    train = subparsers.add_parser(
        "train",
        help="train a LeaS policy (geometric PPO)",
        description="Train a LeaS policy with Brax PPO on the training arena. "
        "Writes config.json, checkpoints/, policy.ckpt, metrics.jsonl "
        "and tb/ into --out; an interrupted run resumes from its last "
        "checkpoint when started again with the same --out.",
    )
    add_training_arguments(train)
    train.set_defaults(func=cmd_train)

    convert = subparsers.add_parser(
        "convert",
        help="rewrite pickle policies and checkpoints of earlier versions in the checkpoint format",
        description="Read RUN_DIR/policy.pkl and RUN_DIR/checkpoints/step_*.pkl (pickles of earlier "
        "versions, which can run code when loaded) and write policy.ckpt and step_*.ckpt beside them "
        "(data only, with a checksum); the pickles are kept. Same parameters, bit for bit.",
    )
    convert.add_argument("run_dir", nargs="+", metavar="RUN_DIR")
    add_allow_pickle_argument(convert, "the pickles to convert (required)")
    convert.set_defaults(func=cmd_convert)
