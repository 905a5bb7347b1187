"""Features and verdicts of the learned condition (`checkpoints/feasibility/walking.npz`) at 20 000
random poses over the training arena and past its edges (z -1.5 to 2.5 m), written to an .npz,
or two such files compared: run once with each tree on PYTHONPATH, then compare.

    PYTHONPATH=<tree> python features.py dump OUT.npz
    python features.py compare A.npz B.npz
"""

import sys

import numpy as np


def dump(out: str) -> None:
    import jax
    import jax.numpy as jnp

    from leas_jax.env import learned_feasibility as lf
    from leas_jax.env.field import heightfield_from_terrain
    from leas_jax.terrain import load_terrain
    from leas_jax.training.config import TRAINING_ENV, learned_condition_env

    env = learned_condition_env(TRAINING_ENV)
    field = heightfield_from_terrain(load_terrain("terrains/training_arena.toml"), env)
    rng = np.random.default_rng(1)
    n = 20_000
    poses = np.column_stack(
        [rng.uniform(-2, 30, n), rng.uniform(-2, 30, n), rng.uniform(-1.5, 2.5, n), rng.uniform(-4, 4, n)]
    )

    def one(f, q):
        return (
            lf.features(f.condition, f, q, env.reachability),
            lf.valid(f.condition, f, q, env.reachability),
        )

    features, valid = jax.jit(lambda f, p: jax.vmap(lambda q: one(f, q))(p))(
        field, jnp.asarray(poses, jnp.float32)
    )
    np.savez(out, poses=poses, features=np.asarray(features), valid=np.asarray(valid))


def compare(a: str, b: str) -> None:
    with np.load(a) as x, np.load(b) as y:
        assert np.array_equal(x["poses"], y["poses"])
        differ = np.abs(x["features"] - y["features"]).max(axis=1) > 0
        print(
            f"{len(differ)} poses: features differ at {int(differ.sum())} (largest difference "
            f"{float(np.abs(x['features'] - y['features']).max())}), verdicts differ at "
            f"{int((x['valid'] != y['valid']).sum())}; {int(y['valid'].sum())} poses accepted"
        )


if __name__ == "__main__":
    {"dump": dump, "compare": compare}[sys.argv[1]](*sys.argv[2:])
