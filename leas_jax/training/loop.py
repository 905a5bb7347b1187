"""Host side of training: progress bar, JSONL/TensorBoard logs, checkpoints, resume.

Two modes share everything but the iteration: geometric PPO (`ppo.py`) and
planner-in-the-loop PPO (`planner.py`), where the contact generator's workers
validate batch k while JAX rolls out batch k+1.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import jax
import numpy as np

from leas_jax.env.config import NETWORK_CONDITIONS
from leas_jax.errors import LeasError, UsageError
from leas_jax.files import resolve_data_path
from leas_jax.training import checkpoint, records
from leas_jax.training.config import TrainConfig, pretraining_config
from leas_jax.training.ppo import TrainState, init_state, make_train_call


@dataclass(frozen=True)
class TrainResult:
    """Outcome of `train`: where things are and the last logged metrics."""

    run_dir: Path
    policy_path: Path
    env_steps: int
    wall_s: float
    metrics: dict


# TrainConfig keys that say how a run is recorded, not what it learns: a resumed run may change them.
RECORDING_KEYS = ("checkpoint_every_s", "keep_checkpoints")


def _config_differences(saved: dict, config: TrainConfig) -> list[str]:
    """Top-level TrainConfig keys (outside RECORDING_KEYS) whose values differ from `saved`."""
    current = json.loads(config.to_json())
    try:  # a run saved before a field existed has its default (e.g. EnvConfig.condition)
        saved = json.loads(TrainConfig.from_dict(saved).to_json())
    except (UsageError, TypeError):  # keys this version does not know: compare as saved
        saved = json.loads(json.dumps(saved))  # tuples -> lists, as in config.json
    keys = (set(saved) | set(current)) - set(RECORDING_KEYS)
    return sorted(k for k in keys if saved.get(k) != current.get(k))


def _saved_config(run_dir: Path, from_checkpoint: dict | None) -> dict:
    """The config a run directory's checkpoint trains: the one stored in the checkpoint, else config.json."""
    if from_checkpoint is not None:
        return from_checkpoint
    path = run_dir / "config.json"
    try:
        saved = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise LeasError(
            f"{path}: cannot read the config of the run to resume ({exc}); "
            "its checkpoint is of an earlier version that does not store it"
        ) from None
    if not isinstance(saved, dict):
        raise LeasError(f"{path}: not a TrainConfig object")
    return saved


def _check_config(run_dir: Path, config: TrainConfig, saved: dict | None) -> None:
    """Refuse to resume a run trained with another config; (re)write config.json.

    Args:
        saved: the resumed run's config, None when nothing is resumed (a run that
            never checkpointed leaves nothing to protect, so its config.json is replaced).
    """
    path = run_dir / "config.json"
    if saved is not None:
        diff = _config_differences(saved, config)
        if diff:
            raise UsageError(
                f"{path}: run directory holds a run with a different config "
                f"(differs in {', '.join(diff)}); use another --out or the same settings"
            )
    checkpoint.atomic_write_text(path, config.to_json())


def resume_point(run_dir: Path, allow_pickle: bool = False):
    """(TrainState, config dict or None, path) of the newest intact checkpoint of a run, or None.

    Newer checkpoints that are damaged (truncated, checksum mismatch, malformed)
    are renamed `<name>.corrupt` with a `CheckpointWarning`, so nothing is lost and
    the next resume does not meet them again. A refused legacy pickle is an error,
    not damage; so is a run whose every checkpoint is damaged (nothing is renamed then).
    """
    import os
    import warnings

    found = checkpoint.list_checkpoints(run_dir)
    damaged = []
    for _, path in reversed(found):
        try:
            state, config = checkpoint.read_state(path, allow_pickle)
        except checkpoint.PickleRefused:
            raise
        except checkpoint.CheckpointError as exc:
            damaged.append((path, exc))
            continue
        for bad, exc in damaged:
            aside = bad.with_name(bad.name + ".corrupt")
            os.replace(bad, aside)
            warnings.warn(
                f"{exc}; moved it to {aside.name} and resumed from the older {path.name}",
                checkpoint.CheckpointWarning,
                stacklevel=2,
            )
        return state, config, path
    if damaged:
        raise LeasError(f"{run_dir}: no intact checkpoint to resume from; {damaged[0][1]}")
    return None


class RunLog:
    """metrics.jsonl + TensorBoard + tqdm bar + periodic atomic checkpoints of one run."""

    def __init__(
        self,
        run_dir: Path,
        config: TrainConfig,
        state: TrainState,
        resumed: bool,
        progress: bool,
        total_steps: int,
        on_log: Callable[[dict], None] | None,
    ):
        from tensorboardX import SummaryWriter
        from tqdm.auto import tqdm

        self.run_dir, self.config, self.on_log = run_dir, config, on_log
        self.path = run_dir / "metrics.jsonl"
        # back to the checkpoint: a resumed run's records equal an uninterrupted run's
        kept = records.truncate_metrics(self.path, int(state.iteration) if resumed else 0)
        records.truncate_events(run_dir / "tb", int(state.env_steps) if resumed else -1)
        self.wall_before = float(kept[-1].get("wall_s", 0.0)) if kept else 0.0
        self.writer = SummaryWriter(str(run_dir / "tb"))
        self.bar = tqdm(
            total=total_steps,
            initial=min(int(state.env_steps), total_steps),
            unit="step",
            unit_scale=True,
            disable=not progress,
            desc=f"train {config.mode} {config.preset}",
        )
        self.t_start = self.last_ckpt = time.perf_counter()
        self.record: dict = {}

    def log(self, record: dict, new_steps: int) -> None:
        record["wall_s"] = round(self.wall_before + time.perf_counter() - self.t_start, 3)
        self.record = record
        with open(self.path, "a") as f:
            f.write(json.dumps(record) + "\n")
        for k, v in record.items():
            if k not in ("iteration", "env_steps"):
                self.writer.add_scalar(k, v, record["env_steps"])
        self.writer.flush()  # the event file holds what metrics.jsonl holds, for truncation on resume
        if self.on_log:
            self.on_log(record)
        self.bar.update(new_steps)
        shown = {"ret": "episode_return", "invalid": "invalid_fraction", "cov": "mean_coverage"}
        self.bar.set_postfix({k: f"{record[v]:.2f}" for k, v in shown.items() if v in record})

    def maybe_checkpoint(self, state: TrainState) -> None:
        if time.perf_counter() - self.last_ckpt > self.config.checkpoint_every_s:
            self.checkpoint(state)

    def checkpoint(self, state: TrainState) -> None:
        steps = int(state.env_steps)
        checkpoint.save_state(self.run_dir, state, steps, self.config.keep_checkpoints, self.config.to_dict())
        checkpoint.save_policy(
            self.run_dir, state.normalizer, state.params.policy, self.config.to_dict(), steps
        )
        self.last_ckpt = time.perf_counter()

    def close(self) -> None:
        self.bar.close()
        self.writer.close()


def _summarise(raw: dict, env_steps: int, iteration: int, sps: float) -> dict:
    """Per-call geometric metrics -> JSON-friendly log record."""
    raw = {k: float(v) for k, v in raw.items()}
    episodes = raw.pop("episodes")
    ret, length, invalid = (
        raw.pop(k) for k in ("episode_return_sum", "episode_length_sum", "invalid_episodes")
    )
    record = {"iteration": iteration, "env_steps": env_steps, "sps": round(sps, 1), "episodes": int(episodes)}
    if episodes > 0:
        record.update(
            episode_return=ret / episodes,
            episode_length=length / episodes,
            invalid_fraction=invalid / episodes,
        )
    record.update(raw)
    return record


def initial_params_from(run_dir: str | Path, allow_pickle: bool = False):
    """(params, normalizer) of the newest intact full checkpoint of a run directory (for `init_from`)."""
    found = resume_point(resolve_data_path(run_dir), allow_pickle)
    if found is None:
        raise LeasError(f"{run_dir}: no checkpoints/step_*.ckpt to initialise from")
    state = found[0]
    return state.params, state.normalizer


def train(
    config: TrainConfig,
    out: str | Path,
    progress: bool = True,
    on_log: Callable[[dict], None] | None = None,
    stop_after_iterations: int | None = None,
    field=None,
    workers: int | None = None,
    address: str | None = None,
    pool_options: dict | None = None,
    allow_pickle: bool = False,
) -> TrainResult:
    """Train a LeaS policy; resume if `out` holds a checkpoint.

    Args:
        config: training configuration (see `leas_jax.training.config.preset`);
            `config.mode` picks geometric or planner-in-the-loop PPO.
        out: run directory (created); an existing one with checkpoints resumes.
            Planner mode with `config.pretrain` and no `init_from` first trains
            (or resumes) that geometric preset in `out/pretrain`.
        progress: show a tqdm progress bar.
        on_log: called with every log record (also written to metrics.jsonl).
        stop_after_iterations: stop (with a checkpoint) after this many
            iterations of this call, to split a run; None trains to the end.
        field: a prebuilt `Heightfield`; default: built from `config.terrain`.
        workers: planner mode: contact-generator worker processes (None: one
            per CPU; 0: in this process).
        address: planner mode: a validation backend address (e.g. a Ray
            cluster, see `leas_jax.contacts.validation.pool.register_backend`).
        pool_options: planner mode: more `ValidationPool` keyword arguments
            (task_timeout, max_attempts, plan_fn for fault-injection tests).
        allow_pickle: also read legacy pickle checkpoints (resume, `init_from`);
            unpickling can run code, so only for files you trust (warns).

    Returns:
        TrainResult with the run directory and `policy.ckpt` path.

    Host function: runs jitted iterations, writes files; not jittable.
    """
    from leas_jax.feasibility.spawns import arena_field
    from leas_jax.terrain import load_terrain

    config.validate()
    run_dir = Path(out)
    # everything that can fail on bad input is checked before anything is written
    terrain = load_terrain(config.terrain_path())
    if field is None:
        field = arena_field(
            terrain, _run_condition_env(run_dir, config.env), workers=workers, progress=progress
        )
    if run_dir.exists() and not run_dir.is_dir():
        raise UsageError(f"--out {run_dir}: exists and is not a directory")
    resumed = resume_point(run_dir, allow_pickle)
    _check_config(run_dir, config, None if resumed is None else _saved_config(run_dir, resumed[1]))
    _pin_condition(run_dir, config.env)
    init_from = config.init_from
    if config.mode == "planner" and not init_from and config.pretrain and resumed is None:
        init_from = run_dir / "pretrain"
        pretrain = pretraining_config(config)
        saved = checkpoint.list_checkpoints(init_from)
        if not saved or saved[-1][0] < pretrain.num_iterations * pretrain.batch_size:  # else: finished
            train(pretrain, init_from, progress=progress, field=field, allow_pickle=allow_pickle)
    initial = initial_params_from(init_from, allow_pickle) if resumed is None and init_from else None
    state: TrainState = init_state(config, field)
    if resumed is not None:
        state = checkpoint.like(state, resumed[0])
    elif initial is not None:
        params, normalizer = initial
        state = state.replace(
            params=checkpoint.like(state.params, params),
            normalizer=checkpoint.like(state.normalizer, normalizer),
        )
    total = config.num_timesteps if config.mode == "planner" else config.num_iterations * config.batch_size
    log = RunLog(run_dir, config, state, resumed is not None, progress, total, on_log)
    run = _planner_iterations if config.mode == "planner" else _geometric_iterations
    t_start = time.perf_counter()
    try:
        state = run(
            config,
            state,
            field,
            terrain,
            log,
            stop_after_iterations,
            dict(workers=workers, address=address, **(pool_options or {})),
        )
    except KeyboardInterrupt:
        log.checkpoint(state)
        log.close()
        raise
    log.checkpoint(state)
    log.close()
    return TrainResult(
        run_dir=run_dir,
        policy_path=run_dir / checkpoint.POLICY_NAME,
        env_steps=int(state.env_steps),
        wall_s=time.perf_counter() - t_start,
        metrics=log.record,
    )


RUN_CONDITION = "condition.npz"  # a run's own learned condition, beside its policy.ckpt (`load_policy`)


def _run_condition_env(run_dir: Path, env):
    """`env` with the learned condition of the run in `run_dir` where it holds one.

    A run trains with the condition it started with (its copy, `_pin_condition`) or the one its
    planner phase last refreshed, not whatever `env.learned_weights` names today: a relabelled
    default (`leas feasibility condition`) neither changes a resumed run nor the
    environment its policy is evaluated in.
    """
    pinned = run_dir / RUN_CONDITION
    if env.condition not in NETWORK_CONDITIONS or not pinned.is_file():
        return env
    return dataclasses.replace(env, learned_weights=str(pinned))


def _pin_condition(run_dir: Path, env) -> None:
    """Copy the learned condition's weights into `run_dir` (atomically) unless it holds them already.

    Warns (`walking_truth.StaleConditionWarning`) where the weights were fitted on the verdicts
    of another contact generator than the current one: the run would learn to satisfy a
    condition the generator no longer agrees with.
    """
    if env.condition not in NETWORK_CONDITIONS or (run_dir / RUN_CONDITION).is_file():
        return
    from leas_jax.env.learned_weights import load_params
    from leas_jax.feasibility.walking_truth import warn_if_stale
    from leas_jax.files import atomic_write_bytes

    weights = resolve_data_path(env.learned_weights)
    warn_if_stale(weights, load_params(weights)[1])
    run_dir.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(run_dir / RUN_CONDITION, weights.read_bytes())


def _geometric_iterations(config, state, field, terrain, log: RunLog, stop_after, pool_options) -> TrainState:
    call = make_train_call(config)
    start_iteration = int(state.iteration)
    per_call = config.iterations_per_call * config.batch_size
    while int(state.iteration) < config.num_iterations:
        if stop_after is not None and int(state.iteration) - start_iteration >= stop_after:
            break
        t0 = time.perf_counter()
        state, raw = call(state, field)
        raw = jax.device_get(raw)
        log.log(
            _summarise(
                raw, int(state.env_steps), int(state.iteration), per_call / (time.perf_counter() - t0)
            ),
            per_call,
        )
        log.maybe_checkpoint(state)
    return state


def _planner_iterations(config, state, field, terrain, log: RunLog, stop_after, pool_options) -> TrainState:
    """Planner-in-the-loop PPO: validation of batch k overlaps the rollout of batch k+1.

    A batch in flight when the run stops is dropped (it is re-drawn on
    resume from the saved PRNG key); only updated states are checkpointed.
    """
    from leas_jax.contacts.validation.pool import ValidationPool, available_cpus
    from leas_jax.env.learned_weights import load_params
    from leas_jax.training.planner import VerdictData, guides_of, make_planner_fns

    rollout, update = make_planner_fns(config)
    verdicts = VerdictData(config, seed=config.seed)
    if (
        verdicts.enabled and (log.run_dir / RUN_CONDITION).is_file()
    ):  # a given field; the run's refreshed condition
        field = field.replace(condition=load_params(log.run_dir / RUN_CONDITION)[0])
    timestep = config.env.timestep
    state = state.replace(env_state=None, episode_return=None, episode_length=None)
    start_iteration = int(state.iteration)

    def draw(state):
        key, k_roll, k_update = jax.random.split(state.key, 3)
        episodes = rollout(state, field, k_roll)
        return state.replace(key=key), episodes, k_update

    # the learner mostly waits on validation: give the workers every core (the default)
    if pool_options.get("workers") is None and pool_options.get("address") is None:
        pool_options = {**pool_options, "workers": available_cpus()}
    pool = ValidationPool(terrain, return_plans=False, **pool_options)
    try:
        state, episodes, k_update = draw(state)
        future = pool.submit(guides_of(episodes), timestep)
        while int(state.env_steps) < config.num_timesteps:
            if stop_after is not None and int(state.iteration) - start_iteration >= stop_after:
                break
            t0 = time.perf_counter()
            # batch k+1 is drawn with the parameters from before update k (one update stale)
            next_state, next_episodes, next_k_update = draw(state)
            next_future = pool.submit(guides_of(next_episodes), timestep)
            t_wait = time.perf_counter()
            results = future.result()
            wait_s = time.perf_counter() - t_wait
            state, record = _apply_validated_batch(state, episodes, results, k_update, update)
            if verdicts.enabled:
                record["condition_poses_added"] = verdicts.add(
                    guides_of(episodes), np.array([r.last_valid_index for r in results])
                )
                if verdicts.due():
                    field, fit_info = verdicts.refresh(field)  # the next draws terminate on it
                    verdicts.save(log.run_dir, field)
                    record.update(
                        condition_poses=fit_info["poses"], condition_threshold=fit_info["threshold"]
                    )
            state = state.replace(key=next_state.key)
            episodes, future, k_update = next_episodes, next_future, next_k_update
            elapsed = time.perf_counter() - t0
            record.update(
                iteration=int(state.iteration),
                env_steps=int(state.env_steps),
                sps=round(record["kept_steps"] / elapsed, 1),
                rolled_sps=round(record["rolled_steps"] / elapsed, 1),
                validation_wait_s=round(wait_s, 3),
                wait_fraction=round(wait_s / elapsed, 3),
            )
            log.log(record, int(record["kept_steps"]))
            log.maybe_checkpoint(state)
    finally:
        pool.close(cancel_pending=True)  # the batch in flight is not needed any more
        if verdicts.enabled:
            verdicts.save(log.run_dir, field)
    return state


def _apply_validated_batch(state, episodes, results, key, update):
    """Prune one validated batch, run the PPO update; (state, log record).

    Paths whose validation failed (a worker died twice, a timeout, a planner
    exception) count as not covered at all (last_valid_index -1, masked); a
    batch where every path failed means the generator is broken: stop.
    """
    from leas_jax.training.planner import training_batch

    errors = [r.error for r in results if r.error is not None]
    if errors and len(errors) == len(results):
        raise LeasError(f"contact generator failed on every path of a batch; first error: {errors[0]}")

    last_valid = np.array([r.last_valid_index for r in results])
    coverage = np.array([r.coverage for r in results])
    batch, stats = training_batch(episodes, last_valid)
    state, losses = update(state, batch, key)
    record = {
        **stats,
        "mean_coverage": float(coverage.mean()),
        "full_coverage_fraction": float((coverage >= 1.0).mean()),
        "generator_errors": len(errors),
        **{k: float(v) for k, v in jax.device_get(losses).items()},
    }
    return state, record
