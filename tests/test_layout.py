"""The package's layout: no import cycles, neither training nor navigate depends on evaluation;
the test tiers."""

import subprocess
import sys
from pathlib import Path

import import_graph
from conftest import SLOW_TIER


def _evaluation(modules: set[str]) -> list[str]:
    """The modules of `leas_jax.eval` among `modules`, sorted."""
    return sorted(m for m in modules if m == "leas_jax.eval" or m.startswith("leas_jax.eval."))


def test_no_import_cycles():
    """No cycle anywhere in the package, annotation-only imports included."""
    assert import_graph.cycles(import_graph.graph()) == []


def test_training_imports_no_evaluation_code():
    reached = import_graph.reached(import_graph.graph(), "leas_jax.training")
    assert _evaluation(reached) == []
    assert "leas_jax.contacts.validation.pool" in reached  # the walk follows lazy imports


def test_navigate_imports_no_evaluation_code():
    """Navigate sits below the evaluation (which runs it as a method): what both use, the
    metrics of a guide, the LeaS horizon and the scenario files, lies below both."""
    reached = import_graph.reached(import_graph.graph(), "leas_jax.navigate")
    assert _evaluation(reached) == []
    assert {"leas_jax.contacts.metrics", "leas_jax.steering.horizon", "leas_jax.terrain.generate"} <= reached


def test_a_cycle_is_found(tmp_path):
    """The checker on a small package: a cycle through a lazy import and a `from . import`,
    one through a TYPE_CHECKING import, none through a package's own submodule."""
    package = tmp_path / "leas_jax"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("from leas_jax import a\n")
    (package / "a.py").write_text("def f():\n    from leas_jax.sub import b\n")
    (package / "sub" / "__init__.py").write_text("")
    (package / "sub" / "b.py").write_text("from .. import c\n")
    (package / "c.py").write_text("import leas_jax.a\n")
    (package / "d.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from leas_jax import e\n"
    )
    (package / "e.py").write_text("from leas_jax import d\n")
    edges = import_graph.graph(tmp_path)
    assert edges["leas_jax.sub.b"] == {"leas_jax.c"}
    assert edges["leas_jax.d"] == {"leas_jax.e"}
    assert import_graph.cycles(edges) == [
        ["leas_jax.a", "leas_jax.c", "leas_jax.sub.b"],
        ["leas_jax.d", "leas_jax.e"],
    ]
    assert import_graph.reached(edges, "leas_jax.sub") == {
        "leas_jax.sub",
        "leas_jax.sub.b",
        "leas_jax.c",
        "leas_jax.a",
    }
    assert import_graph.reached(edges, "leas_jax.su") == set()  # a prefix is a whole module name


def test_the_slow_tier_names_existing_tests():
    """Every id of conftest.SLOW_TIER is collected (a renamed test must not leave the list silently)."""
    root = Path(__file__).resolve().parents[1]
    files = sorted({nodeid.split("::")[0] for nodeid in SLOW_TIER})
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "--collect-only",
            "-q",
            "-m",
            "slow",
            "-p",
            "no:cacheprovider",
            *files,
        ],
        capture_output=True,
        text=True,
        cwd=root,
        timeout=300,
    )
    collected = set(done.stdout.split())
    assert sorted(set(SLOW_TIER) - collected) == [], done.stdout[-2000:] + done.stderr[-2000:]
