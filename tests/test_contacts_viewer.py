"""Plan viewers: HTML structure and data, the inline renderer run under Node with a
recording WebGL stub, footprint geometry, mesh decimation and the footsteps PNG."""

from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
from types import SimpleNamespace

import numpy as np
import pytest

from leas_jax.contacts import viewer
from leas_jax.contacts.plan import ContactPlan

# Ground x in [-1, 1.5], a hole for x in [1.5, 2], a step x in [2, 3] 0.1 m high.
TERRAIN = """
name = "viewer_test"
bounds = [[-1.0, -1.0], [3.0, 1.0]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [0.25, 0.0, -0.1]
size = [2.5, 2.0, 0.2]

[[box]]
center = [2.5, 0.0, 0.0]
size = [1.0, 2.0, 0.2]
"""


@pytest.fixture(scope="module")
def plan() -> ContactPlan:
    """Seven postures of Talos at half-sitting: left step, right step, left step.

    Sole rows come from Pinocchio forward kinematics of half-sitting (soles at
    z = 0, the ground top), shifted along x; the stance foot keeps its row, the
    root sits between the feet.
    """
    import example_robot_data
    import pinocchio as pin

    robot = example_robot_data.load("talos")
    model, data = robot.model, robot.model.createData()
    frames = [model.getFrameId(name) for name in ("leg_left_sole_fix_joint", "leg_right_sole_fix_joint")]
    base = model.referenceConfigurations["half_sitting"].copy()
    pin.framesForwardKinematics(model, data, base)
    soles = np.array(
        [
            np.concatenate([data.oMf[f].translation, pin.Quaternion(data.oMf[f].rotation).coeffs()])
            for f in frames
        ]
    )
    foot_x = [0.0, 0.0]
    qs, feet = [], []
    for air, lands in ((None, None), (0, None), (None, 0), (1, None), (None, 1), (0, None), (None, 0)):
        if lands is not None:
            foot_x[lands] += 0.2
        rows = soles.copy()
        rows[:, 0] += foot_x
        if air is not None:
            rows[air] = np.nan
        q = base.copy()
        q[0] = float(np.mean(foot_x))
        qs.append(q)
        feet.append(rows)
    guide = np.stack([np.linspace(0.0, 2.4, 25), np.zeros(25), np.full(25, 1.02), np.zeros(25)], axis=1)
    return ContactPlan(
        q=np.array(qs),
        feet=np.array(feet),
        guide_index=np.arange(7) * 2,
        last_valid_index=12,
        coverage=0.5,
        terrain=TERRAIN,
        guide=guide,
    )


def _decode(b64: str, dtype) -> np.ndarray:
    return np.frombuffer(base64.b64decode(b64), dtype=dtype)


def _page_parts(text: str) -> tuple[dict, str]:
    data = re.search(r'<script id="plan-data" type="application/json">(.*?)</script>', text, re.S).group(1)
    code = re.search(r"<script>\n(.*?)</script>", text, re.S).group(1)
    return json.loads(data.replace("<\\/", "</")), code


def test_footprints_merge_held_placements_and_have_sole_size(plan):
    prints = viewer.footprints(plan)
    # Postures: both, L air, both (L moved), R air, both (R moved), L air, both (L moved):
    # initial L and R, then L at k=2, R at k=4, L at k=6.
    assert [(foot, k) for foot, k, _ in prints] == [(0, 0), (1, 0), (0, 2), (1, 4), (0, 6)]
    assert viewer.count_footsteps(plan) == 3
    corners = prints[0][2]
    assert np.linalg.norm(corners[0] - corners[1]) == pytest.approx(0.20)
    assert np.linalg.norm(corners[1] - corners[2]) == pytest.approx(0.13)
    assert np.allclose(corners.mean(axis=0), plan.feet[0, 0, :3])


def test_quaternion_matches_pinocchio():
    import pinocchio as pin

    rng = np.random.default_rng(0)
    quats = rng.normal(size=(20, 4))
    quats /= np.linalg.norm(quats, axis=1, keepdims=True)
    expected = [pin.Quaternion(q[3], q[0], q[1], q[2]).toRotationMatrix() for q in quats]
    assert np.allclose(viewer.quaternion_xyzw_to_matrix(quats), expected, atol=1e-12)


def test_decimate_collapses_small_triangles():
    # Vertices 0 and 1 are 1 mm apart: one 1 cm cell, merged at their mean
    # (0.0005, 0, 0). Face [0, 1, 2] collapses; [0, 2, 3] survives; [1, 2, 3]
    # becomes a duplicate of it and is dropped.
    vertices = np.array([[0.0, 0, 0], [0.001, 0, 0], [1.0, 0, 0], [0, 1.0, 0]])
    faces = np.array([[0, 1, 2], [0, 2, 3], [1, 2, 3]])
    new_vertices, new_faces = viewer.decimate(vertices, faces, 0.01)
    assert new_faces.shape == (1, 3)
    assert np.allclose(new_vertices[new_faces[0]], [[0.0005, 0, 0], [1.0, 0, 0], [0, 1.0, 0]])


def test_write_html_is_self_contained_with_consistent_data(plan, tmp_path):
    path = tmp_path / "view.html"
    viewer.write_html(plan, path, max_postures=4)
    text = path.read_text()
    assert text.startswith("<!DOCTYPE html>") and text.rstrip().endswith("</html>")
    assert path.stat().st_size < 3e6
    assert re.search(r"<script[^>]+src=|<link|https?://|@import", text) is None  # nothing fetched
    data, code = _page_parts(text)
    assert "webgl2" in code and "mousemove" in code and "wheel" in code
    # Terrain: 2 boxes, 8 vertices and 12 triangles each.
    assert _decode(data["terrain"]["positions"], "<f4").size == 2 * 8 * 3
    assert _decode(data["terrain"]["indices"], "<u4").size == 2 * 12 * 3
    assert np.allclose(_decode(data["guide"], "<f4").reshape(-1, 3), plan.guide[:, :3], atol=1e-6)
    assert _decode(data["footprints"]["left"], "<f4").size == 3 * 4 * 3
    assert _decode(data["footprints"]["right"], "<f4").size == 2 * 4 * 3
    # Robot: 4 postures spread over 7, first and last kept, as configurations.
    robot = data["robot"]
    assert robot["postures"] == [0, 2, 4, 6] and robot["guide_index"] == [0, 4, 8, 12]
    assert robot["overlay"] and [t["name"] for t in robot["tracks"]] == ["robot"]
    q = _decode(robot["tracks"][0]["q"], "<f4").reshape(4, 39)
    assert np.allclose(q, plan.q[[0, 2, 4, 6]], atol=1e-6)
    assert np.allclose(_decode(robot["times"], "<f4"), np.arange(4) * viewer.PLAN_FRAME_PERIOD)
    model = robot["model"]
    assert model["kind"][:2] == ["universe", "free"] and set(model["kind"][2:]) == {"rx", "ry", "rz"}
    assert all(model["parent"][j] < j for j in range(1, 34)) and model["nq"] == 39
    assert (
        len(model["geom_joint"]) == len(robot["geoms"]) == _decode(model["geom_placements"], "<f4").size // 12
    )
    for mesh in data["meshes"]:
        vertices = _decode(mesh["positions"], "<f4").reshape(-1, 3)
        indices = _decode(mesh["indices"], "<u2" if mesh["index_type"] == "u16" else "<u4")
        assert indices.size % 3 == 0 and indices.max() < len(vertices)
    assert all(0 <= g["mesh"] < len(data["meshes"]) for g in robot["geoms"])
    # Terrain colours span the heights of its upward faces: the ground top (0) to the step top (0.1).
    assert data["terrain"]["heights"] == pytest.approx([0.0, 0.1], abs=1e-6)


def test_the_renderer_is_the_packaged_viewer_js_inlined(plan, tmp_path):
    from importlib import resources
    from pathlib import Path

    script = resources.files("leas_jax.contacts").joinpath("viewer.js").read_text(encoding="utf-8")
    assert viewer.viewer_script() == script and len(script) > 5000
    viewer.write_html(plan, tmp_path / "view.html", robot=False)
    _, code = _page_parts((tmp_path / "view.html").read_text())
    assert code == script  # verbatim: nothing of the file lost, nothing else in the element
    # A wheel (non-editable install) holds only the package data pyproject.toml names.
    pyproject = (Path(__file__).parents[1] / "pyproject.toml").read_text()
    table = re.search(r"^\[tool\.setuptools\.package-data\]\n(.*?)(?:^\[|\Z)", pyproject, re.M | re.S)
    assert table and re.search(r'^"leas_jax\.contacts" = \[[^]]*"viewer\.js"', table.group(1), re.M)


def test_a_placeholder_in_the_data_is_not_substituted(plan, tmp_path):
    named = ContactPlan(
        q=plan.q,
        feet=plan.feet,
        guide_index=plan.guide_index,
        last_valid_index=plan.last_valid_index,
        coverage=plan.coverage,
        terrain=TERRAIN.replace('name = "viewer_test"', 'name = "__SCRIPT__ __DATA__"'),
        guide=plan.guide,
    )
    viewer.write_html(named, tmp_path / "view.html", robot=False)
    text = (tmp_path / "view.html").read_text()
    data, code = _page_parts(text)
    assert data["name"] == "__SCRIPT__ __DATA__" and code == viewer.viewer_script()
    assert text.count("__SCRIPT__") == 2  # the title and the data, nothing substituted into them


def test_write_html_without_robot_is_small(plan, tmp_path):
    path = tmp_path / "view.html"
    viewer.write_html(plan, path, robot=False)
    data, _ = _page_parts(path.read_text())
    assert data["robot"] is None and data["meshes"] == []
    assert path.stat().st_size < 50_000


# Minimal DOM + WebGL2 stand-ins: every gl call is recorded, constants are their
# names. Enough to execute the page's script end to end and count draw calls.
_HARNESS = r"""
const calls = [];
const glStub = new Proxy({}, {get(target, name) {
  if (typeof name !== "string") return undefined;
  if (/^[A-Z0-9_]+$/.test(name)) return name;
  return (...args) => {
    calls.push([name, args.map(a => (typeof a === "string" || typeof a === "number") ? a : null)]);
    if (name === "getShaderParameter" || name === "getProgramParameter") return true;
    if (name === "getAttribLocation") return 0;
    return {};
  };
}});
const elements = {};
const htmlWrites = [];  // every assignment that would parse HTML (innerHTML, outerHTML)
function node(props) {
  const made = {style: {}, dataset: {}, children: [], textContent: "", ...props,
    appendChild(child) { this.children.push(child); return child; }, addEventListener() {}};
  for (const name of ["innerHTML", "outerHTML"])
    Object.defineProperty(made, name, {set(value) { htmlWrites.push([made.id || made.tag, name, value]); }});
  return made;
}
function element(id) {
  if (!elements[id]) elements[id] = node({id, value: "0", max: "0", checked: id === "show-robot",
    clientWidth: 800, clientHeight: 600, width: 0, height: 0,
    getContext: kind => (kind === "webgl2" ? glStub : null)});
  return elements[id];
}
element("plan-data").textContent = PLAN_JSON;
global.document = {getElementById: element, body: element("body"),
  createElement: tag => node({tag}), createTextNode: text => node({tag: "#text", textContent: text}),
  write() { htmlWrites.push(["document", "write"]); }};
global.window = {addEventListener() {}, devicePixelRatio: 1};
global.location = {hash: typeof PAGE_HASH === "string" ? PAGE_HASH : ""};
global.atob = s => Buffer.from(s, "base64").toString("binary");
// animation frames run only when the script calls step(ms): a test drives the clock
let clockNow = 0, frameCallbacks = [];
global.performance = {now: () => clockNow};
global.requestAnimationFrame = cb => { frameCallbacks.push(cb); return frameCallbacks.length; };
function step(ms) {
  clockNow += ms;
  const due = frameCallbacks; frameCallbacks = [];
  due.forEach(cb => cb(clockNow));
}
function drawsOf(from) {
  const out = {};
  for (const [name, args] of calls.slice(from)) if (name.startsWith("draw")) {
    const key = name + ":" + args[0]; out[key] = (out[key] || 0) + 1; }
  return out;
}
"""


@pytest.mark.skipif(shutil.which("node") is None, reason="Node.js not installed")
def test_html_renderer_runs_under_node(plan, tmp_path):
    path = tmp_path / "view.html"
    viewer.write_html(plan, path, max_postures=4)
    data, code = _page_parts(path.read_text())
    n_geoms = len(data["robot"]["geoms"])
    script = (
        f"const PLAN_JSON = {json.dumps(json.dumps(data))};\n"
        + _HARNESS
        + code
        + r"""
const first = drawsOf(0);
const mark = calls.length;
element("show-all").checked = true;
element("posture").value = "3";
element("show-all").onchange();
const all = drawsOf(mark);
console.log(JSON.stringify({first, all, rendered: element("body").dataset.rendered,
                            label: element("posture-label").textContent, max: element("posture").max}));
"""
    )
    (tmp_path / "run.js").write_text(script)
    done = subprocess.run(["node", str(tmp_path / "run.js")], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout.strip().splitlines()[-1])
    # First frame: terrain + the robot at one posture (indexed), guide lines,
    # footprint fills and outlines (arrays).
    assert out["first"]["drawElements:TRIANGLES"] == 1 + n_geoms
    assert out["first"]["drawArrays:LINE_STRIP"] == 2  # covered part and failed tail
    assert out["first"]["drawArrays:TRIANGLES"] == 2 and out["first"]["drawArrays:LINES"] == 2
    # "All stored postures": 4 robots.
    assert out["all"]["drawElements:TRIANGLES"] == 1 + 4 * n_geoms
    assert out["rendered"] == "2" and out["max"] == 3
    assert out["label"] == "#0 (guide index 0)"


def _run_page_under_node(data: dict, tail: str, tmp_path, page_hash: str = "") -> dict:
    """Run the page's script on `data` in the Node harness, then `tail`; the last stdout line as JSON."""
    script = (
        f"const PLAN_JSON = {json.dumps(json.dumps(data))};\nconst PAGE_HASH = {json.dumps(page_hash)};\n"
        + _HARNESS
        + viewer.viewer_script()
        + tail
    )
    (tmp_path / "run.js").write_text(script)
    done = subprocess.run(["node", str(tmp_path / "run.js")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.skipif(shutil.which("node") is None, reason="Node.js not installed")
def test_page_kinematics_match_pinocchio(plan, tmp_path):
    """The page's forward kinematics (JavaScript, float32) place every mesh where Pinocchio does."""
    import example_robot_data
    import pinocchio as pin

    model = example_robot_data.load("talos").model
    rng = np.random.default_rng(3)
    qs = [plan.q[3]]
    for _ in range(3):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        q[:3] = rng.uniform(-3, 3, 3)
        qs.append(q)
    qs = np.array(qs)
    expected, _ = viewer.robot_placements(qs)
    data = viewer.html_payload(plan, max_postures=2)
    out = _run_page_under_node(
        data,
        f"const QS = {json.dumps(qs.tolist())};\n"
        + r"""
const got = QS.map(q => window.leasViewer.geomPlacements(Float32Array.from(q), 0).map(m => Array.from(m)));
console.log(JSON.stringify(got));
""",
        tmp_path,
    )
    got = np.array(out)  # [N, G, 16] column-major 4x4
    assert got.shape == (len(qs), expected.shape[1], 16)
    top = got.reshape(len(qs), -1, 4, 4).transpose(0, 1, 3, 2)[:, :, :3, :]  # rows of [R | p]
    assert np.abs(top - expected).max() < 2e-4
    assert np.allclose(got[..., [3, 7, 11]], 0) and np.allclose(got[..., 15], 1)


def _rollout_view(tmp_path, fall_at=None):
    """A planned motion (100 Hz, 3 s of Talos at half-sitting moving 0.3 m along x) and its
    simulated rollout, which ends at `fall_at` samples; the page write_rollout_html makes of them."""
    import example_robot_data

    from leas_jax.motion.commands import write_rollout_html

    talos = example_robot_data.load("talos")
    base = talos.model.referenceConfigurations["half_sitting"].copy()  # not a view into the model
    n = 301
    q = np.tile(base, (n, 1))
    q[:, 0] = np.linspace(0.0, 0.3, n)
    simulated = q[: fall_at or n].copy()
    simulated[:, 1] += 0.01  # off the plan by 1 cm
    motion = SimpleNamespace(
        q=q, dt=0.01, duration=3.0, terrain=TERRAIN, plan_feet=np.full((1, 2, 7), np.nan)
    )
    rollout = SimpleNamespace(
        q=simulated,
        success=fall_at is None,
        fallen=fall_at is not None,
        summary=lambda: {"phases_reached": 2 if fall_at else 3, "phases": 3},
    )
    path = tmp_path / "rollout.html"
    write_rollout_html(motion, rollout, path)
    return path, q, simulated


def test_rollout_page_holds_the_plan_and_the_simulation_at_25_hz(tmp_path):
    path, q, simulated = _rollout_view(tmp_path, fall_at=150)
    data, code = _page_parts(path.read_text())
    robot = data["robot"]
    assert [t["name"] for t in robot["tracks"]] == ["planned (ghost)", "simulated"]
    assert [t["style"] for t in robot["tracks"]] == ["ghost", "solid"]
    times = _decode(robot["times"], "<f4")
    assert np.allclose(times, np.arange(0, 301, 4) * 0.01, atol=1e-6)  # 25 frames/s, 0 to 3 s
    planned = _decode(robot["tracks"][0]["q"], "<f4").reshape(-1, 39)
    assert np.allclose(planned, q[::4], atol=1e-6)
    # The simulation ends at sample 149 (fell): its frames stop there, the last sample kept.
    sim = _decode(robot["tracks"][1]["q"], "<f4").reshape(-1, 39)
    assert np.allclose(sim, simulated[list(range(0, 150, 4)) + [149]], atol=1e-6)
    assert "postures" not in robot and not robot["overlay"]
    assert "fell" in data["subtitle"] and "2/3 phases" in data["subtitle"]
    assert np.allclose(_decode(data["guide"], "<f4").reshape(-1, 3), simulated[:, :3], atol=1e-6)
    # Size: meshes (~0.5 MB) and 0.2 kB per frame and track.
    assert path.stat().st_size < 900_000


@pytest.mark.skipif(shutil.which("node") is None, reason="Node.js not installed")
def test_rollout_page_plays_both_robots_in_time(tmp_path):
    path, _, _ = _rollout_view(tmp_path, fall_at=150)
    data, _ = _page_parts(path.read_text())
    n_geoms = len(data["robot"]["geoms"])
    out = _run_page_under_node(
        data,
        r"""
const first = drawsOf(0), label0 = element("posture-label").textContent;
element("speed").value = "2";
element("play").onclick();
step(0);
step(500);  // 0.5 s at 2x: 1 s of motion, frame 25
const f1 = element("posture").value, label1 = element("posture-label").textContent;
step(2500);  // past the end (3 s): loops to the start
const f2 = element("posture").value;
element("play").onclick();  // pause
const text = element("play").textContent;
step(1000);
const f3 = element("posture").value;
// the simulated robot holds its last posture (sample 149) at t = 2 s
element("posture").value = "50"; element("posture").oninput();
const held = window.leasViewer.trackPlacements(DATA.robot.tracks[1], 50)[0][12];
const last = window.leasViewer.trackPlacements(DATA.robot.tracks[1], 38)[0][12];
const ghost = window.leasViewer.trackPlacements(DATA.robot.tracks[0], 50)[0][12];
console.log(JSON.stringify({first, label0, f1, label1, f2, text, f3, held, last, ghost,
  tracks: element("tracks").children.length}));
""",
        tmp_path,
    )
    # Two robots in the first frame: the terrain, then both tracks' geometries.
    assert out["first"]["drawElements:TRIANGLES"] == 1 + 2 * n_geoms
    assert out["label0"] == "t = 0.00 s / 3.00 s"
    assert out["f1"] == "25" and out["label1"] == "t = 1.00 s / 3.00 s"
    assert int(out["f2"]) < 10 and out["text"] == "play" and out["f3"] == out["f2"]
    assert out["held"] == out["last"] and out["ghost"] > out["held"]  # the ghost walks on
    assert out["tracks"] == 2  # a checkbox per track


HOSTILE_NAME = '<img src=x onerror="require(`fs`).writeFileSync(`pwned`, `x`)"></script><!--'


@pytest.mark.skipif(shutil.which("node") is None, reason="Node.js not installed")
def test_a_hostile_terrain_name_is_shown_as_text_only(plan, tmp_path):
    """The terrain name reaches the page only as text: the title is escaped, the embedded JSON holds
    no "<", and the script puts the name in a text node (no innerHTML or document.write anywhere)."""
    hostile = ContactPlan(
        q=plan.q,
        feet=plan.feet,
        guide_index=plan.guide_index,
        last_valid_index=plan.last_valid_index,
        coverage=plan.coverage,
        terrain=TERRAIN.replace('name = "viewer_test"', "name = " + json.dumps(HOSTILE_NAME)),
        guide=plan.guide,
    )
    path = tmp_path / "view.html"
    viewer.write_html(hostile, path, robot=False)
    text = path.read_text()
    assert "<img" not in text and 'onerror="' not in text
    assert text.count("</script>") == 2  # the JSON element's and the code's: the name closed none
    data, code = _page_parts(text)
    assert data["name"] == HOSTILE_NAME
    assert re.search(r"innerHTML|outerHTML|insertAdjacentHTML|document\.write", code) is None
    script = (
        f"const PLAN_JSON = {json.dumps(json.dumps(data))};\n"
        + _HARNESS
        + code
        + r"""
console.log(JSON.stringify({htmlWrites, info: element("info").children.map(c => [c.tag, c.textContent])}));
"""
    )
    (tmp_path / "run.js").write_text(script)
    done = subprocess.run(
        ["node", str(tmp_path / "run.js")], capture_output=True, text=True, timeout=60, cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["htmlWrites"] == []
    assert out["info"][0] == ["b", HOSTILE_NAME]
    assert out["info"][1][0] == "#text" and out["info"][1][1].startswith(": coverage ")
    assert not (tmp_path / "pwned").exists()


def test_footsteps_png_shows_feet_guide_and_failed_tail(plan, tmp_path):
    import matplotlib.image

    path = tmp_path / "steps.png"
    viewer.write_footsteps_png(plan, path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rgb = matplotlib.image.imread(str(path))[..., :3]

    def has(color, tol=0.08):
        return bool((np.abs(rgb - np.asarray(color)).max(axis=-1) < tol).any())

    assert has((1.0, 0.0, 0.0))  # failed guide tail (red)
    assert has((0.196, 0.804, 0.196))  # covered guide (limegreen)
    assert has((0.043, 0.102, 0.2))  # the hole (#0b1a33)
    # Footprint fills: foot colour at alpha 0.55 over the light-grey ground.
    ground = rgb[rgb.shape[0] // 2, rgb.shape[1] // 4]
    for color in viewer.FOOT_COLORS:
        assert has(0.55 * np.asarray(color) + 0.45 * ground, tol=0.06)


def test_empty_plan_still_renders(plan, tmp_path):
    # A generator that fails at the first pose returns no posture at all.
    empty = ContactPlan(
        q=np.zeros((0, 39)),
        feet=np.zeros((0, 2, 7)),
        guide_index=np.zeros(0, int),
        last_valid_index=-1,
        coverage=0.0,
        terrain=TERRAIN,
        guide=plan.guide,
    )
    assert viewer.footprints(empty) == [] and viewer.count_footsteps(empty) == 0
    viewer.write_html(empty, tmp_path / "v.html")
    data, _ = _page_parts((tmp_path / "v.html").read_text())
    assert data["robot"] is None and data["last_valid_index"] == -1
    viewer.write_footsteps_png(empty, tmp_path / "v.png")
    assert (tmp_path / "v.png").stat().st_size > 1000
