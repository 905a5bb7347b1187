"""The command line prints no notice of mujoco.mjx's optional warp backend nor the equilibrium
LP's debug line (leas_jax.quiet)."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _python(*args: str) -> subprocess.CompletedProcess:
    """`python ARGS` in a fresh process from the repository root, its output captured."""
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=ROOT, timeout=300)


def _no_warp(done: subprocess.CompletedProcess) -> bool:
    """Neither stdout nor stderr mentions warp."""
    return "warp" not in (done.stdout + done.stderr).lower()


def test_help_prints_no_warp_notice():
    done = _python("-m", "leas_jax.cli", "--help")
    assert done.returncode == 0 and "usage: leas" in done.stdout
    assert _no_warp(done), done.stdout


def test_a_command_that_starts_brax_prints_no_warp_notice(tmp_path):
    """`leas run` imports training and evaluation (brax, hence mujoco.mjx) before it checks its
    arguments: its one-line error is then all it prints."""
    done = _python("-m", "leas_jax.cli", "run", "--mode", "planner", "--out", str(tmp_path / "run"))
    assert done.returncode == 2 and "drop --mode and --init" in done.stderr
    assert _no_warp(done), done.stdout + done.stderr


def test_brax_imports_the_backend_quietly():
    """The backend is imported (and finds no warp here) without a word on stdout."""
    code = (
        "import sys\n"
        "import leas_jax.training.ppo\n"
        "print(sorted(m for m in sys.modules if m.startswith('mujoco.mjx.warp'))[:1])\n"
    )
    done = _python("-c", code)
    assert done.returncode == 0, done.stderr
    assert done.stdout == "['mujoco.mjx.warp']\n"


@pytest.mark.parametrize(
    "before, expected",
    [
        # compiled code's writes on descriptor 1 inside the block (as hpp-centroidal-dynamics'
        # std::cout does) are gone; before and after it, and Python's own print, reach stdout
        ("os.write(1, b'before\\n')\n", "before\nafter\nprinted\n"),
        # a print before the block still sits in sys.stdout's buffer (stdout is a pipe here): the
        # block flushes it before discarding descriptor 1, so it reaches stdout, in order
        ("print('printed before')\n", "printed before\nafter\nprinted\n"),
    ],
    ids=["compiled-writes-discarded", "earlier-print-kept"],
)
def test_c_stdout_discarded_drops_what_is_written_inside_the_block_only(before, expected):
    block = (
        "with c_stdout_discarded():\n"
        "    os.write(1, b'[DEBUG] inside\\n')\n"
        "os.write(1, b'after\\n')\n"
        "print('printed', flush=True)\n"
    )
    code = "import os\nfrom leas_jax.quiet import c_stdout_discarded\n" + before + block
    done = _python("-c", code)
    assert done.returncode == 0, done.stderr
    assert done.stdout == expected
