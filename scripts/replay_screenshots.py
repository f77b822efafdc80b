"""Re-make the replay screenshots the docs and the README show, in headless Chromium.

    python scripts/replay_screenshots.py [--only NAME ...]

Each is a shipped scenario run with ``--html``, its replay opened in Debian's ``chromium``
(driven through the DevTools protocol by the tests' own `HeadlessPage`), paused at one time
and saved as a PNG under docs/. Needs chromium (``make test`` installs it when it can).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "apps" / "viz"))

from viz_support import HeadlessPage  # noqa: E402


@dataclass(frozen=True)
class Shot:
    scenario: str
    time_s: float
    png: str
    size: tuple[int, int] = (1200, 800)
    camera_js: str = ""  # run after seeking: a closer camera; the replay's own otherwise


# the BlueROV2 close up, behind the vehicle's left (as tests/apps/viz/test_robot_view.py sees it)
_CLOSE = (
    "viewer.set_transform(['meshcat', 'uvms_pin'], "
    "[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -0.25, 0.05, 2.0, 1]); "
    "viewer.camera.position.set(0.75, 0.35, -0.85); viewer.controls.update(); true"
)

# the hot stab's receptacle close up, from the side above (the stab at full depth)
_RECEPTACLE = (
    "viewer.set_transform(['meshcat', 'uvms_pin'], "
    "[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -0.72, 0.11, 2.25, 1]); "
    "viewer.camera.position.set(-0.15, 0.3, 0.5); viewer.controls.update(); true"
)

SHOTS = {
    "push_object": Shot("push_object", 10.0, "docs/push_object_replay.png"),
    "seabed_landing": Shot("seabed_landing", 11.0, "docs/seabed_landing_replay.png"),
    "bluerov_alpha5": Shot(
        "bluerov_alpha5_force_tracking", 5.0, "docs/replay_bluerov_alpha5.png", (1000, 640), _CLOSE
    ),
    "hot_stab": Shot("hot_stab", 12.0, "docs/hot_stab_replay.png", (1000, 640), _RECEPTACLE),
}


def shoot(shot: Shot, work: Path) -> Path:
    out = work / shot.scenario
    subprocess.run(
        [str(Path(sys.executable).with_name("uvms-pin")), "run", str(ROOT / "scenarios" / f"{shot.scenario}.toml"),
         "--out", str(out), "--html", "--quiet", "--overwrite"],
        check=True,
    )  # fmt: skip
    page = HeadlessPage(*shot.size)
    try:
        page.open((out / "replay.html").as_uri(), "viewer.animator.actions.length > 0")
        page.evaluate(f"animator.pause(); seek({shot.time_s}); true")
        if shot.camera_js:
            page.evaluate(shot.camera_js)
        page.next_frames(8)
        return page.screenshot(ROOT / shot.png)
    finally:
        page.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=sorted(SHOTS), help="some of the shots")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as work:
        for name in args.only or sorted(SHOTS):
            print(f"wrote {shoot(SHOTS[name], Path(work))}")


if __name__ == "__main__":
    main()
