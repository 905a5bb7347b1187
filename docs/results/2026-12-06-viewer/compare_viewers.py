"""One motion page three ways: this package's viewer, meshcat's static HTML and viser's embedded HTML.

    python compare_viewers.py export OUT_DIR     # the project's venv: motion, rollout, leas.html, scene.npz
    python compare_viewers.py meshcat OUT_DIR    # a venv with meshcat: meshcat.html from scene.npz
    python compare_viewers.py viser OUT_DIR      # a venv with viser: viser.html from scene.npz

The motion is the straight 0.6 m walk of tests/motion_helpers.py on eval_ground, simulated
in MuJoCo; the scene is the terrain, the planned and the simulated Talos (52 meshes each,
the viewer's decimated meshes) and their placements at 25 frames/s. Prints each page's
size and the time to build it.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

GHOST = (0.35, 0.6, 1.0, 0.35)


def export(out: Path) -> None:
    """Plan, motion and rollout; the package's page (leas.html) and the scene for the others."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests"))
    from motion_helpers import straight_plan

    from leas_jax.contacts import viewer
    from leas_jax.motion.motion import make_motion
    from leas_jax.motion.simulate import simulate
    from leas_jax.terrain.export import terrain_to_mesh

    motion = make_motion(straight_plan(0.6))
    rollout = simulate(motion)
    viewer._talos_visuals(viewer.DEFAULT_MESH_CELL)  # Talos and its meshes loaded once per process
    started = time.perf_counter()
    viewer.write_motion_html(
        out / "leas.html",
        motion.terrain,
        motion.plan_feet,
        [("planned (ghost)", motion.q, GHOST), ("simulated", rollout.q, None)],
        motion.dt,
        line=rollout.q[:, :3],
    )
    print(f"leas: build {time.perf_counter() - started:.2f} s, {(out / 'leas.html').stat().st_size} bytes")
    _, _, meshes, geom_mesh, _, geom_color = viewer._talos_visuals(viewer.DEFAULT_MESH_CELL)
    drawn = [g for g, m in enumerate(geom_mesh) if m >= 0]
    n = max(len(motion.q), len(rollout.q))
    frames = np.arange(0, n, int(round(1 / (viewer.DEFAULT_FRAME_RATE * motion.dt))))
    placements = [
        viewer.robot_placements(q[np.minimum(frames, len(q) - 1)])[0] for q in (motion.q, rollout.q)
    ]
    terrain = terrain_to_mesh(viewer._terrain_of(motion))
    arrays = {f"mesh{i}_{part}": a for i, (v, f) in enumerate(meshes) for part, a in (("v", v), ("f", f))}
    np.savez(
        out / "scene.npz",
        n_meshes=len(meshes),
        placements=np.stack(placements),  # [2, F, G, 3, 4], mesh scale folded in
        geom_mesh=np.array([geom_mesh[g] for g in drawn]),
        geom_color=np.array([geom_color[g] for g in drawn]),
        terrain_v=terrain.vertices,
        terrain_f=terrain.faces,
        **arrays,
    )


def build(which: str, out: Path) -> None:
    """meshcat.html or viser.html from scene.npz: the same meshes, colours and placements."""
    scene = np.load(out / "scene.npz")
    meshes = [(scene[f"mesh{i}_v"], scene[f"mesh{i}_f"]) for i in range(int(scene["n_meshes"]))]
    placements, geom_mesh, geom_color = scene["placements"], scene["geom_mesh"], scene["geom_color"]
    n_frames, n_geoms = placements.shape[1], len(geom_mesh)
    started = time.perf_counter()
    if which == "meshcat":
        import meshcat
        import meshcat.geometry as g
        from meshcat.animation import Animation

        vis = meshcat.Visualizer()
        terrain = g.TriangularMeshGeometry(scene["terrain_v"], scene["terrain_f"])
        vis["terrain"].set_object(terrain, g.MeshLambertMaterial(color=0xA89F8A))
        for r in range(2):
            for k in range(n_geoms):
                rgb = (np.asarray(geom_color[k]) * 255).astype(int)
                material = g.MeshLambertMaterial(
                    color=int(rgb[0]) << 16 | int(rgb[1]) << 8 | int(rgb[2]),
                    opacity=GHOST[3] if r == 0 else 1.0,
                    transparent=r == 0,
                )
                vis[f"robot{r}/g{k}"].set_object(g.TriangularMeshGeometry(*meshes[geom_mesh[k]]), material)
        animation = Animation(default_framerate=25)
        for i in range(n_frames):
            with animation.at_frame(vis, i) as frame:
                for r in range(2):
                    for k in range(n_geoms):
                        frame[f"robot{r}/g{k}"].set_transform(np.vstack([placements[r, i, k], [0, 0, 0, 1]]))
        vis.set_animation(animation, play=False)
        page = vis.static_html()
    else:
        import viser
        import viser.transforms as tf

        server = viser.ViserServer(port=8765, verbose=False)
        terrain_v, terrain_f = scene["terrain_v"].astype(np.float32), scene["terrain_f"].astype(np.uint32)
        server.scene.add_mesh_simple("/terrain", terrain_v, terrain_f, color=(168, 159, 138))
        serializer = server.get_scene_serializer()
        handles = []
        for r in range(2):
            for k in range(n_geoms):
                v, f = meshes[geom_mesh[k]]
                handles.append(
                    server.scene.add_mesh_simple(
                        f"/robot{r}/g{k}",
                        v.astype(np.float32),
                        f.astype(np.uint32),
                        color=tuple(int(c * 255) for c in geom_color[k]),
                        opacity=GHOST[3] if r == 0 else None,
                    )
                )
        for i in range(n_frames):
            for r in range(2):
                for k in range(n_geoms):
                    m = placements[r, i, k]
                    # viser poses take no scale: the mirrored meshes are shown unmirrored (pose only)
                    rotation = m[:, :3] / np.linalg.norm(m[:, :3], axis=0)
                    if np.linalg.det(rotation) < 0:
                        rotation[:, 1] *= -1
                    handles[r * n_geoms + k].position = m[:, 3]
                    handles[r * n_geoms + k].wxyz = tf.SO3.from_matrix(rotation).wxyz
            serializer.insert_sleep(1 / 25)
        page = serializer.as_html()
        server.stop()
    (out / f"{which}.html").write_text(page)
    print(f"{which}: build {time.perf_counter() - started:.1f} s, {len(page.encode())} bytes")


if __name__ == "__main__":
    command, folder = sys.argv[1], Path(sys.argv[2])
    folder.mkdir(parents=True, exist_ok=True)
    export(folder) if command == "export" else build(command, folder)
