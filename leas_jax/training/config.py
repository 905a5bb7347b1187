"""Training configuration and presets.

Mapping of the paper's Table I (Stable Baselines PPO, 6 actors x 2048 steps
per batch, 10 epochs, 256 mini-batches) to vectorised training:

* one iteration collects `num_envs x unroll_length` transitions (the paper's
  "batch size"), then runs `num_epochs` passes of `num_minibatches` gradient
  steps over them (Brax's `num_updates_per_batch` and `num_minibatches`);
* the paper's 12 288 transitions per batch become 2048 envs x 16 steps =
  32 768: thousands of envs are what make JAX fast, and a longer batch keeps
  the gradient noise no larger than the paper's;
* 256 mini-batches of 48 transitions would cost thousands of tiny XLA calls
  per iteration on a CPU; the presets cut each batch into 8 mini-batches of
  4096 transitions. The `paper` preset keeps the paper's sample reuse (10
  epochs); `quick` makes 3 passes over 30 M steps, where its learning
  curves plateau (`num_epochs` and `num_timesteps` are configurable);
* gamma 0.97, clip 0.2, learning rate 5e-4, 2 x 64 tanh networks: Table I.
  GAE lambda 0.95, value loss 0.5 and gradient norm 0.5 are Stable
  Baselines' PPO2 defaults, which the paper used.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path

from leas_jax.env.config import (
    CLEARANCE_CONDITIONS,
    CurriculumConfig,
    EnvConfig,
    HeightmapConfig,
    ReachabilityConfig,
    RewardWeights,
)
from leas_jax.errors import UsageError
from leas_jax.files import resolve_data_path

# The reachability condition every preset trains with (TrainConfig's default env): the
# cylinders alone, trunk r 0.30 m with the root 0.825 m above everything under it, legs
# r 0.05 m reaching 0.55-1.175 m below the root; no lookahead, foothold or hands term.
# It is looser than ReachabilityConfig's calibrated default (sensitivity / specificity
# 78.6 / 89.7 % against the walking generator on 48 000 arena poses, where the default
# gives 95.7 / 90.0 %). Geometric policies trained with a calibrated condition climb
# eval_stairs and follow eval_circuit more reliably, but barely step onto eval_bridge's beam
# (its lookahead legs must be on the 0.30 m beam 0.30 m before the root is), and their arena
# episodes end 2-3 times as often, mostly on the hands term, whose disks lie beyond the
# heightmap's +-0.45 m (so `make run`'s >= 90 % arena target would fail). Figures:
# docs/results/2026-11-22-benchmarks-h100/condition_comparison.json and docs/results/INDEX.md,
# "Reachability calibration". The planner-in-the-loop phase catches what this looser
# condition lets through.
REACHABILITY_TERMS_OFF = dict(leg_forward=0.0, foothold_spread=None, hand_radius=None)
TRAINING_REACHABILITY = ReachabilityConfig(trunk_bottom=-0.825, leg_top=-0.55, **REACHABILITY_TERMS_OFF)
TRAINING_ENV = EnvConfig(reachability=TRAINING_REACHABILITY)


def learned_condition_env(env: EnvConfig, weights: str = EnvConfig.learned_weights) -> EnvConfig:
    """`env` terminating on the learned feasibility condition (`leas_jax.env.learned_feasibility`,
    weights `weights`) instead of its cylinders. Its reachability becomes the calibrated
    ReachabilityConfig(): the shipped weights read those cylinders' margins (the field needs
    their rasters; `leas feasibility condition` fits them so)."""
    return dataclasses.replace(
        env, condition="learned", learned_weights=weights, reachability=ReachabilityConfig()
    )


# Planner mode with the learned condition: refit it on the generator's verdicts every this many
# iterations (`TrainConfig.condition_refresh_every`, see there).
LEARNED_REFRESH_EVERY = 4


@dataclass(frozen=True)
class TrainConfig:
    """PPO training configuration. Field defaults: Table I and the paper's MDP; `preset(name)` gives the presets."""

    preset: str = "quick"
    # "geometric": PPO on the reachability condition alone; "planner": the paper's
    # method, every episode validated by the Talos contact generator (planner.py).
    mode: str = "geometric"
    # planner mode: start from this geometric run's latest checkpoint ("" = see `pretrain`)
    init_from: str = ""
    # planner mode without init_from: first train this geometric preset into
    # <out>/pretrain and start from it ("" = from scratch). Not the paper's
    # recipe (it validated every episode from the first); see PLANNER_PRESETS.
    pretrain: str = ""
    terrain: str = "terrains/training_arena.toml"  # training terrain file
    num_timesteps: int = 60_000_000  # env steps in total
    num_envs: int = 2048
    unroll_length: int = 16  # steps per env per iteration
    num_minibatches: int = 16  # per epoch (paper: 256 of a smaller batch, see module doc)
    num_epochs: int = 10  # passes over each batch, paper Table I (noptepochs)
    learning_rate: float = 5e-4  # paper Table I (initial value)
    # Stable Baselines' PPO1, which the paper modified, anneals the learning rate
    # linearly to zero by default (schedule='linear'); "constant" keeps it.
    learning_rate_schedule: str = "linear"
    discounting: float = 0.97  # paper Table I
    gae_lambda: float = 0.95  # Stable Baselines PPO2 default
    clipping_epsilon: float = 0.2  # paper Table I
    entropy_cost: float = 1e-3  # small exploration bonus; Table I gives none
    vf_coefficient: float = 0.5  # Stable Baselines PPO2 default
    max_grad_norm: float = 0.5  # Stable Baselines PPO2 default
    reward_scaling: float = 1.0
    normalize_observations: bool = True
    hidden_sizes: tuple = (64, 64)  # paper §IV: 2 x 64 tanh
    seed: int = 0
    iterations_per_call: int = 4  # iterations fused into one compiled call (fewer host round trips)
    # Planner mode with the learned condition (env.condition "learned"): every this many
    # iterations, refit the condition on the generator's verdicts on the policy's guides so far
    # (training/planner.py, `VerdictData`: DAgger); 0 never. An iteration of the planner
    # presets validates 64 guides, which give ~100-250 labelled poses (a failure and up to four
    # covered poses each); refitting every 4 iterations on at least 400 poses keeps each refit
    # (200 Adam steps, a few seconds on 2 cores) small against the validation's minute.
    condition_refresh_every: int = 0
    condition_refresh_min_poses: int = 400
    # The share of the feasible poses held aside that a refit keeps feasible when it sets its
    # threshold (`FitConfig.target_sensitivity`); None: FitConfig's, 0.95. The poses held aside
    # are the policy's own guide poses, so 0.95 rejects about 1 in 20 of the poses the policy
    # visits: refitted so, the condition ended 59-86 % of the training episodes and the policy
    # stopped (docs/results/2026-12-03-ablation).
    condition_refresh_sensitivity: float | None = None
    # Poses drawn as resets are and labelled by the condition the run starts with, fitted with
    # the verdicts at every refit (`VerdictData`); 0: the verdicts alone. Refitted on the
    # verdicts alone, the condition forgot the stairs the policy's guides avoid: it rejected
    # 15.6 % of the poses of the stairs climbs the generator walks, against 0.1 % before; 4000
    # anchors kept that to 1.8 %, still enough to end 55 of 60 climbs, and the policy still
    # stopped (docs/results/2026-12-01-learned-paper): so off by default.
    condition_anchor_poses: int = 0
    # An .npz of labelled poses (`poses` [K, 4] (x, y, z, yaw), world; `labels` [K] bool) that
    # every refit also fits, the DAgger loop's aggregated data carried from elsewhere: the
    # generator's verdicts on another policy's whole guides (studies/condition_from_paths.py's
    # path_verdicts.npz) or an earlier run's condition_data.npz. "": none. Seeded with the
    # cylinders policy's verdicts, the paper preset's DAgger phase kept eval_stairs and
    # eval_stairs_side at 36.7 and 46.7 % success (0 and 0 % without); its policy still stops
    # (1.05 m of progress per arena episode; docs/results/2026-12-01-path-condition).
    condition_seed_data: str = ""
    checkpoint_every_s: float = 60.0  # wall-clock seconds between checkpoints
    keep_checkpoints: int = 3
    env: EnvConfig = field(
        default_factory=lambda: TRAINING_ENV
    )  # the presets' condition, see TRAINING_REACHABILITY

    def terrain_path(self) -> Path:
        """The training terrain file: as given, else relative to the repository root."""
        return resolve_data_path(self.terrain)

    @property
    def batch_size(self) -> int:
        """Transitions per iteration."""
        return self.num_envs * self.unroll_length

    @property
    def num_iterations(self) -> int:
        """Geometric mode: iterations of the run (planner mode stops on env steps instead)."""
        per_call = self.batch_size * self.iterations_per_call
        return max(1, -(-self.num_timesteps // per_call)) * self.iterations_per_call

    def validate(self) -> TrainConfig:
        """Raise UsageError naming the first bad field."""
        positive = [
            "num_timesteps",
            "num_envs",
            "unroll_length",
            "num_minibatches",
            "num_epochs",
            "learning_rate",
            "iterations_per_call",
            "keep_checkpoints",
        ]
        if self.condition_anchor_poses < 0:
            raise UsageError(
                f"TrainConfig.condition_anchor_poses must be >= 0, got {self.condition_anchor_poses!r}"
            )
        if self.condition_refresh_sensitivity is not None and not 0 < self.condition_refresh_sensitivity <= 1:
            raise UsageError(
                "TrainConfig.condition_refresh_sensitivity must be in (0, 1] or None, "
                f"got {self.condition_refresh_sensitivity!r}"
            )
        if self.condition_refresh_every < 0:
            raise UsageError(
                f"TrainConfig.condition_refresh_every must be >= 0, got {self.condition_refresh_every!r}"
            )
        for name in positive:
            if not getattr(self, name) > 0:
                raise UsageError(f"TrainConfig.{name} must be > 0, got {getattr(self, name)!r}")
        if not 0 < self.discounting <= 1:
            raise UsageError(f"TrainConfig.discounting must be in (0, 1], got {self.discounting!r}")
        if self.mode not in ("geometric", "planner"):
            raise UsageError(f"TrainConfig.mode must be 'geometric' or 'planner', got {self.mode!r}")
        if self.learning_rate_schedule not in ("linear", "constant"):
            raise UsageError(
                f"TrainConfig.learning_rate_schedule must be 'linear' or 'constant', "
                f"got {self.learning_rate_schedule!r}"
            )
        if self.pretrain and self.pretrain not in PRESETS:
            raise UsageError(
                f"TrainConfig.pretrain must be '' or a geometric preset ({', '.join(PRESETS)}), "
                f"got {self.pretrain!r}"
            )
        if self.env.clearance_condition not in CLEARANCE_CONDITIONS:
            raise UsageError(
                f"TrainConfig.env.clearance_condition must be one of {', '.join(CLEARANCE_CONDITIONS)}, "
                f"got {self.env.clearance_condition!r}"
            )
        if self.num_envs % self.num_minibatches:
            raise UsageError(
                f"TrainConfig.num_envs ({self.num_envs}) must be a multiple of "
                f"num_minibatches ({self.num_minibatches})"
            )
        return self

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2, sort_keys=True)

    @staticmethod
    def from_dict(data: dict) -> TrainConfig:
        """Inverse of `to_dict`; unknown keys raise UsageError naming them."""
        data = dict(data)
        env = dict(data.pop("env", {}))
        if "reachability" in env:
            # A run saved before an optional term's field existed trained without that term,
            # and the calibrated defaults turn some on: a missing key means the term is off.
            env["reachability"] = {**REACHABILITY_TERMS_OFF, **env["reachability"]}
        sub = {
            "reachability": ReachabilityConfig,
            "heightmap": HeightmapConfig,
            "rewards": RewardWeights,
            "curriculum": CurriculumConfig,
        }
        env_kwargs = {k: sub[k](**v) if k in sub else v for k, v in env.items()}
        if "hidden_sizes" in data:
            data["hidden_sizes"] = tuple(data["hidden_sizes"])
        names = {f.name for f in dataclasses.fields(TrainConfig)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise UsageError(f"unknown TrainConfig keys: {', '.join(unknown)}")
        return TrainConfig(env=EnvConfig(**env_kwargs), **data)


# The `quick` presets add the clearance reward term (not in the paper, whose five terms
# `paper` keeps): minus the fraction of the six root poses shifted by 0.10 m along the root
# frame's axes that fail the reachability condition. Without it, `quick` policies end 11-17 %
# of training-arena episodes on an invalid pose, mostly near-misses while creeping beside
# walls, pillars and stairs (`leas arena-check`); with it, 92-94 % stay valid at 0.10 m
# (docs/results/INDEX.md, "The clearance term"). It stays out of `paper`: on a 0.30 m beam
# its sideways probes fail 1.5 cm off the axis, and a paper run with it crossed eval_bridge
# 3.3 % of the time against 68.3 % without (same section).
QUICK_ENV = dataclasses.replace(TRAINING_ENV, rewards=RewardWeights(clearance=1.0), clearance_margin=0.10)

# The `generalist` preset: 80 M steps, `quick`'s reward terms and clearance term on a curriculum
# arena (`terrains/curriculum_arena.toml`, `leas terrain curriculum`: 8 rows of difficulty x 10
# terrain families, each family's rows stopping where this termination still lets a walk across,
# `curriculum.CURRICULUM_CEILINGS`; envs moved between rows as legged_gym's terrain levels move
# them, `EnvConfig.curriculum`), terminating on the walkability model of rough ground (fitted on the
# same families: `leas feasibility walkability`) instead of the arena-fitted condition. The
# reward terms are `quick`'s. Measured (docs/results/2026-12-07-generalist-recipe, one to three
# seeds each): without the clearance term, or with the `paper` preset's 10 epochs as well, a policy
# walks at most 0.5 m further per episode and still stops at stairs; what stops it is the
# walkability model, which ends an episode on every stair flight the generator climbs, at poses
# its own walking truth walks (the model's errors, 4.3 % of walkable poses on unseen terrains,
# are too many for a check that each of 400 poses must pass). Those policies trained on the
# model fitted on 4 terrains per family; the one fitted on 120 small terrains per family and
# 40 more at jittered root heights still ends every one of those stair guides, with runs of 3-53
# rejected poses (docs/results/2026-12-07-walkability-root-heights). With the arena-fitted condition
# instead a policy climbs eval_stairs but walks less than the paper-arena policy on every arena,
# so neither change is made here. For that model the termination's threshold was a logit of -5
# instead of its own (0.24): on unseen terrains of the families it keeps 98.9 % of the walkable poses
# at root heights within 0.1 m of the nominal one and refuses 42.5 % of the others (94.2 / 67.9 %
# at 0.24), and it ends none of the evaluation stair and circuit guides, whose lowest logits are
# -4.6 to -1.8. Trained with it, two seeds walk 0.3-0.9 m further per episode on every arena
# than the same seeds did (2.3-2.6 m on the paper and fresh arenas against 1.8-2.1 m), still
# short of the paper-arena policy, and still reach no stairs target
# (docs/results/2026-12-07-walkability-root-heights). The model now shipped also reads the
# footing and rejects more of those guides' poses (their lowest logits -6.9 to -3.2): the
# threshold is -7 by the same rule, ending none of them, where the model keeps 99.6 % of the
# walkable test poses at jittered heights and refuses 36.1 % of the others
# (docs/results/2026-12-07-walkability-footing).
GENERALIST_ENV = dataclasses.replace(
    QUICK_ENV,
    condition="walkability",
    learned_weights="checkpoints/walkability/walkability.npz",
    condition_threshold=-7.0,
    reachability=ReachabilityConfig(),
)
CURRICULUM_ARENA = "terrains/curriculum_arena.toml"

PRESETS = {
    # under a minute on 2 cores, compile included: checks that everything runs
    "smoke": dict(
        num_timesteps=400_000,
        num_envs=512,
        unroll_length=16,
        num_minibatches=4,
        num_epochs=4,
        iterations_per_call=4,
    ),
    # 3 epochs of 8 mini-batches and 30 M steps, sized by the learning curves so that `make run`
    # stays within 10 minutes on 2 cores (80 M took 13-17 of its minutes with the learned
    # condition). Return and invalid episodes plateau by 25-30 M (80 M: 342 -> 346 return after
    # 30 M); trained to 30 M (the learning rate decaying to 0 there), 3 seeds cover their own
    # guides and climb stairs and circuit as an 80 M policy does, but progress 0.3 m less per
    # episode and cross eval_bridge less often (10 % against 55 %):
    # docs/results/2026-12-06-quick-budget. `paper` keeps the paper's 80 M.
    "quick": dict(num_timesteps=30_000_000, num_epochs=3, num_minibatches=8, env=QUICK_ENV),
    # the paper's budget and sample reuse: 80 M steps, 10 epochs (Table I), ~25 minutes here
    "paper": dict(num_timesteps=80_000_000, num_epochs=10, num_minibatches=8),
    # the paper's 80 M steps with quick's PPO settings on the curriculum arena, with the
    # walkability model (GENERALIST_ENV)
    "generalist": dict(
        num_timesteps=80_000_000,
        num_epochs=3,
        num_minibatches=8,
        env=GENERALIST_ENV,
        terrain=CURRICULUM_ARENA,
    ),
}

# Planner mode: an iteration is `num_envs` whole episodes (up to 400 steps),
# every guide validated by the contact generator; `num_timesteps` counts the
# steps kept after pruning. The budget is sized by the generator's speed
# (benchmarks/planner_training_throughput.py: a few thousand kept steps/s on
# 2 cores at best, 700-4 000 in practice), so the paper's 80 M planner-validated
# steps (53 h on 12 cores) would take days here. `quick` and `paper` therefore
# start from a geometric policy (`pretrain`, the geometric preset of the same
# name: the reachability condition alone) and fine-tune with the planner in the loop;
# `smoke` trains from scratch. The learning rate decays linearly to 0 over the
# kept steps (Stable Baselines' PPO1 default, as in the geometric presets); a
# constant 5e-4 made a 500 k-step fine-tuning worse than a 150 k-step one
# (docs/results/2026-11-22-make-run-planner-500k). Neither more samples nor more gradient
# steps made the phase help on the current generator (docs/results/2026-12-03-planner-phase-
# settings, 3 seeds): 1.2 M kept steps covered 88.7 % of the policy's own arena guides against
# 88.8 % after 150 k; 64 mini-batches per epoch (the paper's count is 256 of 48 steps) covered
# 88.9 % but slowed the policy from 3.3 to 2.2-2.8 m per episode. Hence 4 mini-batches, and
# budgets sized by wall time rather than by a measured gain. `quick` (`make run`'s phase) keeps
# 100 k: from the three 30 M learned-condition pretrains, 100 k and 150 k kept steps cover
# 96.1 % and 93.8 % of their own arena guides (difference +2.3 points [-0.8, +5.6]), cross
# eval_bridge and eval_stairs equally, and the pretrains 94.3 %
# (docs/results/2026-12-06-planner-budget); 100 k is 5 iterations instead of 7.
PLANNER_PRESETS = {
    "smoke": dict(num_timesteps=20_000, num_envs=16, num_minibatches=2, num_epochs=4),
    "quick": dict(
        num_timesteps=100_000, num_envs=64, num_minibatches=4, num_epochs=4, pretrain="quick", env=QUICK_ENV
    ),
    "paper": dict(num_timesteps=600_000, num_envs=64, num_minibatches=4, num_epochs=10, pretrain="paper"),
    # `quick`'s fine-tuning settings (and its earlier 150 k kept steps) on the generalist
    # pretrain; its episodes start on rows 0 to CurriculumConfig.initial_max_level of the
    # curriculum (the rows move with geometric episodes)
    "generalist": dict(
        num_timesteps=150_000,
        num_envs=64,
        num_minibatches=4,
        num_epochs=4,
        pretrain="generalist",
        env=GENERALIST_ENV,
        terrain=CURRICULUM_ARENA,
    ),
}


def pretraining_config(config: TrainConfig) -> TrainConfig:
    """The geometric run a planner-mode `config` with `pretrain` starts from (same terrain, seed, env)."""
    return preset(config.pretrain, mode="geometric", terrain=config.terrain, seed=config.seed, env=config.env)


def preset(name: str, mode: str = "geometric", **overrides) -> TrainConfig:
    """A preset's config for `mode` with keyword overrides; unknown names raise UsageError.
    An `env` override replaces the preset's whole EnvConfig (`quick`'s is QUICK_ENV)."""
    table = PLANNER_PRESETS if mode == "planner" else PRESETS
    if name not in table:
        raise UsageError(f"unknown preset {name!r}; choose one of {', '.join(table)}")
    return TrainConfig(preset=name, mode=mode, **{**table[name], **overrides}).validate()
