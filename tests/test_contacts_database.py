"""Per-leg sample database: flat soles, limits, collision filter, disk cache."""

import os

import numpy as np
import pinocchio as pin
import pytest

from leas_jax.contacts.robot import database as D
from leas_jax.contacts.robot.model import load_talos

SMALL = D.DatabaseConfig(samples=300, seed=7)


@pytest.fixture()
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("LEAS_CACHE_DIR", str(tmp_path))
    D.leg_database.cache_clear()
    yield tmp_path
    D.leg_database.cache_clear()


def test_samples_flat_within_limits_and_collision_free(cache):
    talos = load_talos()
    for side in (0, 1):
        db = D.leg_database(side, SMALL)
        leg = talos.legs[side]
        assert 50 < len(db.q) <= SMALL.samples
        assert np.all((db.q >= leg.lower) & (db.q <= leg.upper))
        for k in range(0, len(db.q), 17):
            q = talos.q_ref.copy()
            q[leg.q_index] = db.q[k]
            pin.framesForwardKinematics(talos.model, talos.data, q)
            oMf = talos.data.oMf[talos.sole_frame_ids[side]]
            np.testing.assert_allclose(oMf.rotation[:, 2], [0, 0, 1], atol=1e-9)  # flat sole
            np.testing.assert_allclose(oMf.translation, db.positions[k], atol=1e-9)  # indexed position
        # KD-tree queries return exactly the samples within the radius.
        centre = talos.nominal_sole_in_root[side]
        idx = db.near(centre, 0.2)
        dist = np.linalg.norm(db.positions - centre, axis=1)
        assert set(idx.tolist()) == set(np.nonzero(dist <= 0.2)[0].tolist())
        col = db.near_column(centre, 0.15, 0.05)
        horizontal = np.linalg.norm(db.positions[:, :2] - centre[:2], axis=1)
        expected = np.nonzero((horizontal <= 0.15) & (np.abs(db.positions[:, 2] - centre[2]) <= 0.05))[0]
        assert set(col.tolist()) == set(expected.tolist())


def test_collision_filter_drops_samples(cache):
    """Some flat-sole draws put the thigh or foot into the pelvis/other body parts."""
    talos = load_talos()
    drawn = D.sample_flat_sole(talos, 0, 2000, 1)
    kept = D.build_leg_database(talos, 0, D.DatabaseConfig(samples=2000, seed=1))
    assert 0 < len(kept) < len(drawn)


def test_cache_written_atomically_reused_and_keyed(cache):
    talos = load_talos()
    first = D.leg_database(0, SMALL)
    files = sorted(p.name for p in cache.iterdir())
    assert len(files) == 1 and files[0].endswith(".npz") and not any(f.endswith(".tmp") for f in files)
    # Reused: a fresh process-level cache reads the file (the same samples).
    D.leg_database.cache_clear()
    path = cache / files[0]
    mtime = os.stat(path).st_mtime_ns
    again = D.leg_database(0, SMALL)
    np.testing.assert_array_equal(first.q, again.q)
    assert os.stat(path).st_mtime_ns == mtime
    # Another setting is another key, another file; the seed changes the samples.
    other = D.DatabaseConfig(samples=300, seed=8)
    assert D.cache_key(talos, 0, other) != D.cache_key(talos, 0, SMALL)
    assert D.cache_key(talos, 1, SMALL) != D.cache_key(talos, 0, SMALL)
    D.leg_database(0, other)
    assert len(list(cache.iterdir())) == 2
    # A corrupt cache file is rebuilt.
    path.write_bytes(b"not an npz")
    D.leg_database.cache_clear()
    rebuilt = D.leg_database(0, SMALL)
    np.testing.assert_array_equal(rebuilt.q, first.q)
