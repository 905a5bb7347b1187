"""`leas simulate --video`: offscreen frames of Talos in MuJoCo written as a GIF; bad options
and a machine without OpenGL are one-line usage errors."""

import numpy as np
import pytest
from motion_helpers import straight_plan

from leas_jax.cli import main
from leas_jax.motion.video import VideoError, frame_indices


def test_frame_indices_follow_speed_fps_and_window():
    # 10 s of 100 Hz samples at 10x speed and 10 fps: one frame per motion second
    np.testing.assert_array_equal(frame_indices(1001, 0.01, 10.0, 10.0), np.arange(0, 1001, 100))
    np.testing.assert_array_equal(frame_indices(1001, 0.01, 10.0, 10.0, (2.0, 4.5)), [200, 300, 400])
    assert frame_indices(1001, 0.01, 1.0, 10.0, (9.5, 50.0))[-1] == 1000


@pytest.fixture(scope="module")
def motion_file(tmp_path_factory):
    from leas_jax.motion.motion import make_motion

    path = tmp_path_factory.mktemp("video") / "motion.npz"
    make_motion(straight_plan(0.3)).save(path)
    return path


def test_bad_video_options_are_usage_errors(motion_file, tmp_path, capsys):
    cases = [
        (["--video", str(tmp_path / "a.mp4")], "--video"),
        (["--video-speed", "4"], "--video-speed: give --video too"),
        (["--video", str(tmp_path / "a.gif"), "--video-size", "big"], "--video-size"),
        (["--video", str(tmp_path / "a.gif"), "--video-speed", "0"], "--video-speed"),
        (["--video", str(tmp_path / "a.gif"), "--video-window", "5,2"], "--video-window"),
    ]
    for extra, expected in cases:
        assert main(["simulate", str(motion_file), *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert expected in err and "\n" not in err, err


def test_simulate_writes_a_gif(motion_file, tmp_path, capsys):
    from PIL import Image

    from leas_jax.motion.video import ensure_gl

    try:
        ensure_gl()
    except VideoError as exc:  # no GL on this machine: the command says so and exits 2
        assert main(["simulate", str(motion_file), "--video", str(tmp_path / "t.gif")]) == 2
        assert "no OpenGL backend" in capsys.readouterr().err
        pytest.skip(str(exc))
    out = tmp_path / "t.gif"
    args = ["simulate", str(motion_file), "--video", str(out), "--video-speed", "5", "--video-size", "96x72"]
    assert main(args) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    gif = Image.open(out)
    assert gif.size == (96, 72) and gif.n_frames >= 10
    frames = []
    for index in (0, gif.n_frames - 1):
        gif.seek(index)
        frames.append(np.asarray(gif.convert("RGB")))
    # Talos walks: the frames differ, and each shows more than a background
    assert not np.array_equal(frames[0], frames[1])
    assert all(f.std() > 5.0 for f in frames)


def test_no_gl_is_one_line_exit_2(motion_file, tmp_path, capsys, monkeypatch):
    import leas_jax.motion.video as video

    def no_gl():
        raise VideoError("no OpenGL backend renders offscreen (test)")

    monkeypatch.setattr(video, "ensure_gl", no_gl)
    assert main(["simulate", str(motion_file), "--video", str(tmp_path / "t.gif")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "no OpenGL backend" in err
    assert not (tmp_path / "t.gif").exists()
