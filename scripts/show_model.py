"""Load the reference UVMS and show it in meshcat.

    python scripts/show_model.py                      # live: a meshcat server on 127.0.0.1
    python scripts/show_model.py --html model.html    # headless: one self-contained page

The live view serves until Ctrl-C (or ``--seconds``). The page needs no server and no
network: open it in any browser.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import uvms_pin as up
from uvms_pin.apps.viz.live import LiveView
from uvms_pin.apps.viz.meshcat_scene import Frame, UvmsScene
from uvms_pin.apps.viz.replay import scene_html, write_page

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--urdf", default=str(ROOT / "models" / "uvms_lbv150.urdf"))
    parser.add_argument("--html", help="write a static page here instead of serving it")
    parser.add_argument("--port", type=int, default=7000, help="live view port (0: any free)")
    parser.add_argument("--seconds", type=float, help="serve this long, then stop")
    args = parser.parse_args(argv)

    uvms = up.load_uvms(args.urdf)
    q = uvms.neutral_configuration()
    q[:3] = [0.0, 0.0, -2.0]  # 2 m deep
    q[8:10] = [0.5, -0.5]  # elbow bent, so that the arm reads as an arm
    scene = UvmsScene(uvms, extent_world_m=q[None, :3])
    frame = Frame(0.0, q)
    print(f"{Path(args.urdf).name}: nq = {uvms.nq}, nv = {uvms.nv}, mass {uvms.mass_kg:.2f} kg")

    if args.html:
        path = write_page(
            scene_html(scene, frame, title=f"uvms-pin: {Path(args.urdf).name}"), args.html
        )
        print(f"wrote {path}")
        return 0
    try:
        with LiveView(scene, port=args.port, out=sys.stdout) as live:
            live.push(frame)  # shown now, and to every browser that connects
            print("serving; Ctrl-C to stop")
            deadline = np.inf if args.seconds is None else time.monotonic() + args.seconds
            while time.monotonic() < deadline:
                time.sleep(0.2)
    except KeyboardInterrupt:
        print("stopped")
    except up.UvmsPinError as exc:
        print(f"show_model: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
