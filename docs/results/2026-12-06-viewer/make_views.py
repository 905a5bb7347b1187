"""Screenshots of the HTML viewer on a mesh scene and a box scene (before/after figures).

    python docs/results/2026-12-06-viewer/make_views.py OUT.png [--viewer VIEWER.py]

Writes terrain-only pages (no robot) of terrains/hpp/demos/talos_stairs10.toml (one mesh)
and terrains/eval_stairs.toml (boxes) with the viewer module `VIEWER.py` (default: the
installed leas_jax.contacts.viewer), draws each in headless Chromium (software WebGL2,
SwiftShader) at its default camera, 900x600, and saves both side by side, halved, as a
palette PNG.
"""

from __future__ import annotations

import argparse
import importlib.util
import shutil
import subprocess
import tempfile
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from PIL import Image

REPO = Path(__file__).resolve().parents[3]
SCENES = ("terrains/hpp/demos/talos_stairs10.toml", "terrains/eval_stairs.toml")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out")
    parser.add_argument("--viewer", default=None, help="a viewer.py to load instead of the installed one")
    args = parser.parse_args()
    if args.viewer:
        spec = importlib.util.spec_from_file_location("viewer_under_test", args.viewer)
        viewer = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(viewer)
    else:
        from leas_jax.contacts import viewer
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    panels = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, scene in enumerate(SCENES):
            plan = SimpleNamespace(
                q=np.zeros((0, 39)),
                feet=np.zeros((0, 2, 7)),
                guide_index=np.zeros(0, int),
                last_valid_index=-1,
                coverage=0.0,
                terrain=(REPO / scene).read_text(),
                guide=np.zeros((1, 4)),
            )
            page, shot = Path(tmp) / f"{k}.html", Path(tmp) / f"{k}.png"
            viewer.write_html(plan, page)
            subprocess.run(
                [chromium, "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                 "--force-device-scale-factor=1", "--hide-scrollbars", "--window-size=900,600",
                 "--virtual-time-budget=5000", f"--screenshot={shot}", f"file://{page}"],
                capture_output=True, check=True, timeout=300,
            )  # fmt: skip
            panels.append(Image.open(shot).convert("RGB").resize((450, 300), Image.LANCZOS))
    figure = Image.new("RGB", (900, 300))
    for k, panel in enumerate(panels):
        figure.paste(panel, (450 * k, 0))
    figure.quantize(colors=128, method=Image.Quantize.MEDIANCUT).save(args.out, optimize=True)


if __name__ == "__main__":
    main()
