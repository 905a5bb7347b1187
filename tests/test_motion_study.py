"""studies/motion_execution.py: scene names, rates and the merged report (no planning, no MuJoCo)."""

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "studies"))

import motion_execution as study  # noqa: E402

from leas_jax.stats import wilson  # noqa: E402


def test_every_named_hpp_scene_has_its_terrain_file():
    for name in study.TARGET + study.OTHERS:
        if name.startswith("hpp_"):
            assert (ROOT / study.HPP_FILES[name]).is_file(), name
    rough = {f"hpp_{p.stem}" for p in (ROOT / "terrains/hpp/rough").glob("*.toml")} | {"hpp_rubble"}
    demos = {f"hpp_{p.stem}" for p in (ROOT / "terrains/hpp/demos").glob("*.toml")}
    assert rough == set(study.ROUGH)
    assert demos <= set(study.TARGET + study.OTHERS)
    assert all(study.METHODS[name] == "navigate" for name in study.ROUGH + ("circuit",))


def test_rates_use_the_shared_wilson_and_survive_no_trials():
    assert study._rate(0, 0) == {"ok": 0, "n": 0, "rate": None, "wilson95": None}
    low, high = wilson(27, 29)
    assert study._rate(27, 29)["wilson95"] == [round(low, 3), round(high, 3)]


def _execution(plan, success, made=True, error=None):
    return {
        "plan": plan,
        "postures": 10,
        "made": made,
        "error": error,
        "success": success,
        "fallen": False if made else None,
        "message": None if success else "left sole lands 4.1 cm from its placement",
        "torque_ratio_by_group": {"legs": 0.5},
        "duration_s": 10.0 if made else None,
        "make_cpu_seconds": 1.0,
        "simulate_cpu_seconds": 2.0,
    }


def test_combine_merges_variants_and_reports_skipped_plans(tmp_path):
    def write(variant, scenarios):
        report = {
            "question": "q",
            "variant": variant,
            "motion_config": {},
            "simulation_config": {},
            "starts": 2,
            "ground_starts_per_cell": 1,
            "max_plans": 2,
            "scenarios": scenarios,
        }
        (tmp_path / f"motion_execution_{variant}.json").write_text(json.dumps(report))

    write(
        "a",
        {
            "ground": {
                "method": "rblin",
                "starts": 1,
                "verified_plans": 1,
                "executions": [_execution("g", True)],
            }
        },
    )
    write(
        "b",
        {
            "hpp_darpa": {
                "method": "navigate",
                "starts": 2,
                "verified_plans": 2,
                "executions": [_execution("d0", True), _execution("d1", False)],
            },
            "hpp_talos_maze": {
                "method": "navigate",
                "starts": 1,
                "verified_plans": 1,
                "executions": [],
                "skipped": [{"plan": "hpp_talos_maze_0.npz", "postures": 2145}],
            },
            "hpp_cross_gap": {"method": "navigate", "starts": 2, "verified_plans": 0, "executions": []},
        },
    )
    args = study.argparse.Namespace(out=str(tmp_path), combine="a,b", variant="all")
    report = study.combine(args)
    totals = report["summary"]["totals"]
    assert totals["all"]["ok"] == 2 and totals["all"]["n"] == 3
    assert totals["target"]["ok"] == 1 and totals["target"]["n"] == 1
    assert report["summary"]["causes"] == {"landing > 3 cm / 5 deg": 1}
    text = (tmp_path / "motion_execution_all.md").read_text()
    assert "hpp_talos_maze_0.npz (2145 postures)" in text
    assert "| hpp_cross_gap | navigate | 2 | 0 | - |" in text


def test_motions_refused_for_collisions_are_named_so():
    def refused(error):
        return study.cause(_execution("p.npz", False, made=False, error=error))

    lift = "postures 76 and 77: lift: at sample 0, leg_left_4_link_0 comes within 0.817 cm of terrain mesh tile 10"
    assert refused(lift + "; sample by sample: ...") == "no motion: terrain clearance"
    check = "shift between postures 24 and 25 (t = 18.9-20.4 s): collisions fails at t = 19.5 s: arm_right_5_link_0"
    assert (
        refused(check + " collides with terrain mesh tile 2 (40 failing samples)") == "no motion: collisions"
    )
    assert refused("postures 3 and 4: lift: at sample 21 the soles are out of the legs' reach") == (
        "no motion: soles out of reach"
    )
