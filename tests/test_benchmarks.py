"""benchmarks/env_throughput.py times programs that compute what they claim.

The checksum a timed program returns must equal the one of a plain Python loop
that steps a few envs one by one and sums each step's observation, reward and
done flag: a timed program that no longer computed the heightmap (XLA removes
work nothing reads) or that skipped a step would fail here.
"""

import dataclasses
import json
import sys
from pathlib import Path

import jax
import numpy as np
import pytest

from leas_jax.env import EnvConfig, LeasEnv, heightfield_from_terrain
from leas_jax.env.field import sample_bilinear
from leas_jax.env.heightmap import sample
from leas_jax.files import resolve_data_path
from leas_jax.terrain import load_terrain

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))

import common  # noqa: E402
import env_throughput as bench  # noqa: E402
from reference_env import ReferenceEnv, bilinear  # noqa: E402

ENVS, STEPS = 3, 12
# short episodes: the wrapper's fresh resets happen within the few steps
CONFIG = dataclasses.replace(EnvConfig(), episode_length=5)


@pytest.fixture(scope="module")
def field():
    return heightfield_from_terrain(load_terrain(resolve_data_path("terrains/training_arena.toml")), CONFIG)


def _timed(kind, field):
    compiled, _ = bench.compile_program(kind, field, CONFIG, ENVS, STEPS)
    return np.asarray(compiled(field, jax.random.PRNGKey(3)), np.float64)


def _loop(field, make_env, after_step=None):
    """Sums over steps and envs of (obs, reward, done, heightmap part of obs), one env at a time."""
    reset = jax.jit(lambda f, k: make_env(f).reset(k))
    step = jax.jit(lambda f, s, a: make_env(f).step(s, a))
    reset_keys, action_keys = bench.rollout_keys(jax.random.PRNGKey(3), ENVS, STEPS)
    actions = [bench.step_actions(k, ENVS) for k in action_keys]
    total = np.zeros(4)
    for i in range(ENVS):
        state = reset(field, reset_keys[i])
        for t in range(STEPS):
            state = step(field, state, actions[t][i])
            if after_step is not None:
                state = after_step(field, state)
            obs = np.asarray(state.obs, np.float64)
            total += [obs.sum(), float(state.reward), float(state.done), obs[4:].sum()]
    return total


@jax.jit
def _fresh_root(field, rng):
    env = LeasEnv(field, CONFIG)
    root = env.random_root(rng)
    return root, env.observe(root)


def _fresh_start(field, state):
    """FreshResetVmap's rule for one env: a finished episode continues from a fresh random start."""
    if float(state.done) == 0.0:
        return state
    root, obs = _fresh_root(field, state.pipeline_state.rng)
    return state.replace(pipeline_state=root, obs=obs)


def _assert_same(timed, loop):
    np.testing.assert_allclose(timed, loop[:3], rtol=1e-5, atol=1e-3)
    # the test can fail: without the heightmap, the observations' sum would be far off
    assert abs(timed[0] - (loop[0] - loop[3])) > 100 * (1e-5 * abs(loop[0]) + 1e-3)


def test_plain_vmap_checksum_is_the_python_loops(field):
    _assert_same(_timed("plain_vmap", field), _loop(field, lambda f: LeasEnv(f, CONFIG)))


def test_wrapper_checksum_is_the_python_loops(field):
    loop = _loop(field, lambda f: LeasEnv(f, CONFIG), after_step=_fresh_start)
    assert loop[2] > 0  # some episodes ended, so fresh starts were drawn and observed
    _assert_same(_timed("wrapper", field), loop)


def test_reference_checksum_is_the_python_loops(field):
    _assert_same(_timed("reference", field), _loop(field, lambda f: ReferenceEnv(f, CONFIG)))


def test_reference_heightmap_is_the_envs(field):
    """The reference samples the env's 77 heightmap points with the same heights."""
    key = jax.random.PRNGKey(0)
    lo, hi = field.origin - 0.5, field.origin + np.array(field.heights.shape) * field.resolution + 0.5
    xy = jax.random.uniform(key, (500, 2), minval=lo, maxval=hi)  # some points off the grid
    np.testing.assert_allclose(bilinear(field, xy), sample_bilinear(field, xy), atol=1e-5)
    ref = ReferenceEnv(field, CONFIG)
    state = ref.reset(key)
    pose = np.concatenate([np.asarray(state.pos), [float(state.yaw)]])
    assert state.obs.shape == (CONFIG.observation_size,)
    np.testing.assert_allclose(state.obs[4:], sample(field, pose, CONFIG.heightmap), atol=1e-5)


def test_save_records_machine_load_and_commit(tmp_path):
    path = common.save("probe", {"figure": 1.5}, common.load_average(), tmp_path / "out")
    record = json.loads(path.read_text())
    assert path == tmp_path / "out" / "probe.json" and record["figure"] == 1.5
    assert record["machine"]["cores"] >= 1 and record["machine"]["backend"] == jax.default_backend()
    for key in ("load_average_before", "load_average_after"):
        assert set(record[key]) == {"1min", "5min", "15min"}
    assert len(record["git"]["commit"]) == 40 and isinstance(record["git"]["dirty"], bool)
    assert not list(path.parent.glob("*.partial"))


ZEN3_CPUINFO = """processor\t: 0
vendor_id\t: AuthenticAMD
cpu family\t: 25
model\t\t: 1
model name\t: AMD EPYC
stepping\t: 1
flags\t\t: fpu sse sse2 avx fma avx2 bmi2 sha_ni

processor\t: 1
model name\t: another CPU
flags\t\t: avx512f
"""


def test_cpu_identity_tells_hosts_apart_by_family_model_and_vector_extension():
    zen3 = common.cpu_identity(ZEN3_CPUINFO)
    assert zen3 == {
        "cpu": "AMD EPYC",
        "cpu_family": 25,
        "cpu_model": 1,
        "cpu_stepping": 1,
        "vector_isa": "avx2",
    }
    zen4 = common.cpu_identity(
        ZEN3_CPUINFO.replace("model\t\t: 1", "model\t\t: 17").replace("avx2", "avx2 avx512f")
    )
    assert (zen4["cpu_model"], zen4["vector_isa"]) == (17, "avx512f")
    assert common.cpu_identity("model name\t: bare\nflags\t: fpu\n") == {
        "cpu": "bare",
        "cpu_family": None,
        "cpu_model": None,
        "cpu_stepping": None,
        "vector_isa": "none",
    }
    assert (
        common.cpu_summary({"cpu": "AMD EPYC", **zen3, "cores": 2})
        == "AMD EPYC, family 25 model 1, avx2, 2 cores"
    )
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():  # the record carries this host's identity
        assert common.machine()["vector_isa"] == common.cpu_identity(cpuinfo.read_text())["vector_isa"]


def test_cpu_busy_fraction_from_proc_stat():
    """/proc/stat's first line: user nice system idle iowait irq softirq steal guest guest_nice;
    busy is all but idle and iowait, over the first eight fields."""
    before = common.cpu_times("cpu  100 0 50 800 50 0 0 0 7 0\ncpu0 1 2 3 4\n")
    after = common.cpu_times("cpu  250 0 100 850 50 0 0 0 9 0\n")
    assert before == (150, 1000) and after == (350, 1250)
    assert common.busy_fraction(before, after) == 0.8
    assert common.busy_fraction(None, after) is None and common.busy_fraction(after, after) is None
    live = common.cpu_times()
    assert live is None or 0 <= live[0] <= live[1]


def test_contact_planner_speed_times_the_generator_with_the_settings_given(tmp_path):
    """`--set` reaches the timed generator: planning every 1 s instead of 0.5 s plans the
    flat path through other postures, and the JSON records the setting."""
    import contact_planner_speed as bench

    reports = {}
    for name, extra in (("default", []), ("coarse", ["--set", "planning_interval=1.0"])):
        bench.main(["--cases", "flat", "--runs", "1", "--out", str(tmp_path / name), *extra])
        reports[name] = json.loads((tmp_path / name / "contact_planner_speed.json").read_text())
    default, coarse = (reports[k]["cases"]["flat"] for k in ("default", "coarse"))
    assert reports["coarse"]["generator_settings"] == {"planning_interval": "1.0"}
    assert reports["default"]["generator_settings"] == {}
    assert default["coverage"] == coarse["coverage"] == 1.0 and default["postures"] != coarse["postures"]


def test_contact_worker_startup_times_each_stage_against_a_reference(tmp_path):
    """benchmarks/contact_worker_startup.py: every stage timed in fresh processes, and a
    reference checkout (here this one) measured alternately, with the ratio of the medians."""
    import contact_worker_startup as startup

    startup.main(["--runs", "1", "--reference", str(common.REPO), "--out", str(tmp_path)])
    saved = json.loads((tmp_path / "contact_worker_startup.json").read_text())
    assert {"machine", "git", "load_average_before"} <= set(saved)
    for name in ("this", "reference"):
        (start,) = saved["seconds"][name]
        assert set(start) == set(startup.STAGES) and all(t > 0 for t in start.values())
    assert set(saved["ratio_this_to_reference"]) == {*startup.STAGES, "total"}
    with pytest.raises(SystemExit):
        startup.main(["--reference", str(tmp_path)])  # not a checkout


def test_train_throughput_varies_the_clearance_probes_judge_where_probes_are_evaluated():
    """benchmarks/train_throughput.py's variants: the learned condition once per judge of the
    clearance probes where the preset has a clearance term (`quick`), once where it has none
    (`paper`); the cylinders once; each with its --epochs variants."""
    import train_throughput

    judges = ["condition", "cylinders"]
    quick = list(train_throughput.variants("quick", ["cylinders", "learned"], judges, [10]))
    assert [label for label, _ in quick] == [
        "cylinders",
        "learned (probes: condition)",
        "learned (probes: cylinders)",
    ]
    for (_, configs), judge in zip(quick[1:], judges, strict=True):
        assert [c.num_epochs for c in configs] == [3, 10]
        assert {(c.env.condition, c.env.clearance_condition) for c in configs} == {("learned", judge)}
    paper = list(train_throughput.variants("paper", ["cylinders", "learned"], judges, []))
    assert [label for label, _ in paper] == ["cylinders", "learned"]
    assert paper[0][1][0].env.condition == "cylinders" and paper[1][1][0].env.condition == "learned"


def test_newcombe_difference_matches_newcombes_worked_example():
    """Newcombe (1998), Table II example (a): 56/70 - 48/80 = 0.2000, method 10: 0.0524 to 0.3339."""
    diff, low, high = common.newcombe_difference((56, 70), (48, 80))
    assert diff == pytest.approx(0.2) and low == pytest.approx(0.0524, abs=5e-5)
    assert high == pytest.approx(0.3339, abs=5e-5)
