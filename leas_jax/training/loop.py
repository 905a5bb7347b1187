"""Host side of training: progress bar, JSONL/TensorBoard logs, checkpoints, resume."""

from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

import jax
import numpy as np

from leas_jax.errors import UsageError
from leas_jax.training import checkpoint
from leas_jax.training.config import TrainConfig
from leas_jax.training.ppo import TrainState, init_state, make_train_call


@dataclass(frozen=True)
class TrainResult:
    """Outcome of `train`: where things are and the last logged metrics."""

    run_dir: Path
    policy_path: Path
    env_steps: int
    wall_s: float
    metrics: dict


def _check_config(run_dir: Path, config: TrainConfig) -> None:
    """Write config.json, or check that a resumed run uses the same config."""
    path = run_dir / "config.json"
    if not path.exists():
        checkpoint.atomic_write_text(path, config.to_json())
        return
    saved = json.loads(path.read_text())
    current = json.loads(config.to_json())
    diff = sorted(k for k in set(saved) | set(current) if saved.get(k) != current.get(k))
    if diff:
        raise UsageError(f"{path}: run directory holds a run with a different config "
                         f"(differs in {', '.join(diff)}); use another --out or the same settings")


def _summarise(raw: dict, env_steps: int, iteration: int, wall_s: float, sps: float) -> dict:
    """Per-call metrics dict -> JSON-friendly log record."""
    raw = {k: float(v) for k, v in raw.items()}
    episodes = raw.pop("episodes")
    ret, length, invalid = (raw.pop(k) for k in ("episode_return_sum", "episode_length_sum", "invalid_episodes"))
    record = {"iteration": iteration, "env_steps": env_steps, "wall_s": round(wall_s, 3), "sps": round(sps, 1),
              "episodes": int(episodes)}
    if episodes > 0:
        record.update(episode_return=ret / episodes, episode_length=length / episodes,
                      invalid_fraction=invalid / episodes)
    record.update(raw)
    return record


def _open_tensorboard(run_dir: Path):
    from tensorboardX import SummaryWriter
    return SummaryWriter(str(run_dir / "tb"))


def train(config: TrainConfig, out: str | Path, progress: bool = True,
          on_log: Optional[Callable[[dict], None]] = None, stop_after_iterations: Optional[int] = None,
          field=None) -> TrainResult:
    """Train a LeaS policy with geometric PPO; resume if `out` holds a checkpoint.

    Args:
        config: training configuration (see `leas_jax.training.config.preset`).
        out: run directory (created); an existing one with checkpoints resumes.
        progress: show a tqdm progress bar.
        on_log: called with every log record (also written to metrics.jsonl).
        stop_after_iterations: stop (with a checkpoint) after this many
            iterations of this call, to split a run; None trains to the end.
        field: a prebuilt `Heightfield`; default: built from `config.terrain`.

    Returns:
        TrainResult with the run directory and `policy.pkl` path.

    Host function: runs jitted iterations, writes files; not jittable.
    """
    from leas_jax.env import heightfield_from_terrain
    from leas_jax.terrain import load_terrain
    from tqdm.auto import tqdm

    config.validate()
    run_dir = Path(out)
    run_dir.mkdir(parents=True, exist_ok=True)
    _check_config(run_dir, config)
    if field is None:
        field = heightfield_from_terrain(load_terrain(config.terrain_path()), config.env)

    found = checkpoint.list_checkpoints(run_dir)
    state: TrainState = init_state(config, field)
    if found:
        state = jax.tree.map(jax.numpy.asarray, checkpoint.load_state(found[-1][1]))
    call = make_train_call(config)
    total_iterations = config.num_iterations
    start_iteration = int(state.iteration)
    log_path = run_dir / "metrics.jsonl"
    writer = _open_tensorboard(run_dir)
    bar = tqdm(total=total_iterations * config.batch_size, initial=int(state.env_steps), unit="step",
               unit_scale=True, disable=not progress, desc=f"train {config.preset}")
    t_start = time.perf_counter()
    last_ckpt = t_start
    record: dict = {}
    wall_before = float(json.loads(log_path.read_text().splitlines()[-1])["wall_s"]) if (
        found and log_path.exists() and log_path.read_text().strip()) else 0.0
    try:
        while int(state.iteration) < total_iterations:
            if stop_after_iterations is not None and int(state.iteration) - start_iteration >= stop_after_iterations:
                break
            t0 = time.perf_counter()
            state, raw = call(state, field)
            raw = jax.device_get(raw)
            dt = time.perf_counter() - t0
            steps = int(state.env_steps)
            record = _summarise(raw, steps, int(state.iteration), wall_before + time.perf_counter() - t_start,
                                config.iterations_per_call * config.batch_size / dt)
            with open(log_path, "a") as f:
                f.write(json.dumps(record) + "\n")
            for k, v in record.items():
                if k not in ("iteration", "env_steps"):
                    writer.add_scalar(k, v, steps)
            if on_log:
                on_log(record)
            bar.update(config.iterations_per_call * config.batch_size)
            bar.set_postfix(ret=f"{record.get('episode_return', float('nan')):.1f}",
                            invalid=f"{record.get('invalid_fraction', float('nan')):.2f}")
            if time.perf_counter() - last_ckpt > config.checkpoint_every_s:
                _save(run_dir, state, config)
                last_ckpt = time.perf_counter()
    except KeyboardInterrupt:
        _save(run_dir, state, config)
        bar.close()
        writer.close()
        raise
    _save(run_dir, state, config)
    bar.close()
    writer.close()
    return TrainResult(run_dir=run_dir, policy_path=run_dir / "policy.pkl", env_steps=int(state.env_steps),
                       wall_s=time.perf_counter() - t_start, metrics=record)


def _save(run_dir: Path, state: TrainState, config: TrainConfig) -> None:
    steps = int(state.env_steps)
    checkpoint.save_state(run_dir, state, steps, config.keep_checkpoints)
    checkpoint.save_policy(run_dir, state.normalizer, state.params.policy, config.to_dict(), steps)
