"""The bad-input corpus's vocabulary: a `Case`, how its directory is prepared, and how its
output is judged (`check_case`). The cases are in ``test_bad_inputs.py`` (the first round)
and ``bad_inputs_round2.py``; one test runs them all."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from cli_support import ROOT, URDF, passive_scenario

BAD_URDF = """<robot name="bad">
  <link name="a"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"/>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>
</robot>
"""

GOOD_BUT = passive_scenario  # the valid scenario with a replacement (what is wrong)


def write(name: str, content: str | bytes) -> Callable[[Path], None]:
    def setup(case_dir: Path) -> None:
        path = case_dir / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)

    return setup


def mkdir(name: str) -> Callable[[Path], None]:
    return lambda case_dir: (case_dir / name).mkdir()


def steps(*setups: Callable[[Path], None]) -> Callable[[Path], None]:
    def setup(case_dir: Path) -> None:
        for s in setups:
            s(case_dir)

    return setup


def copy_study_inputs(case_dir: Path) -> None:
    for name in ("base.toml", "study.toml"):
        shutil.copy(case_dir.parent.parent / "study" / name, case_dir / name)


def urdf_with(**replace: str) -> str:
    """The reference URDF's text with replacements (``old=new``, as keyword pairs given as
    a dict: ``urdf_with(**{'old': 'new'})``)."""
    text = URDF.read_text()
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    return text


def scenario_with(model: str, duration_s: float = 0.1, extra: str = "", **replace: str) -> str:
    """The passive scenario on ``model`` (a path relative to the case directory), with
    ``extra`` TOML appended."""
    text = passive_scenario(duration_s, **replace).replace(f'"{URDF}"', f'"{model}"')
    return text + extra


REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


def realistic_with(duration_s: float = 0.1, **replace: str) -> str:
    """The realistic force-tracking scenario, ``duration_s`` long, model by absolute path."""
    text = (
        REALISTIC.read_text()
        .replace('"uvms_lbv150"', f'"{URDF}"')
        .replace("duration_s = 10.0", f"duration_s = {duration_s}")
    )
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    return text


@dataclass(frozen=True)
class Case:
    """``uvms-pin ARGS`` in a directory holding ``prior`` (a run's outputs) and
    ``study_out`` (a study's results); ``{good}``, ``{study}``, ``{urdf}``, ``{ro}`` in
    ARGS are a valid scenario, a valid study, the reference URDF and a directory that
    cannot be written.

    Attributes:
        needles: what the message line (the last line of stderr starting with
            ``uvms-pin``) must say.
        watch: results that must not change, or an --out that must not appear.
        code: the exit status.
        traceback_of: the user's file whose traceback must be shown (as such: after a
            line saying so, the frames, the exception); None: no traceback at all.
        after: further checks of the case directory (what was kept, and how).
        script: run ``python SCRIPT ARGS`` (a file the setup wrote) instead of
            ``uvms-pin ARGS``: a failing system simulated in the process.
        interrupts: Ctrl-C after the first line of stderr, then after each delay [s].
    """

    name: str
    args: tuple[str, ...]
    needles: tuple[str, ...]
    setup: Callable[[Path], None] | None = None
    watch: str = "prior"
    code: int = 2
    traceback_of: str | None = None
    after: Callable[[Path], None] | None = None
    script: str | None = None
    interrupts: tuple[float, ...] = ()


def rollout_kept(out: str, status: str, **metadata) -> Callable[[Path], None]:
    """``out`` holds a whole rollout with ``status`` (and these metadata entries)."""

    def check(case_dir: Path) -> None:
        from uvms_pin.results.rollout import Rollout

        rollout = Rollout.load(case_dir / out)
        assert rollout.metadata["status"] == status, rollout.metadata["status"]
        metrics = json.loads((case_dir / out / "metrics.json").read_text())
        assert metrics["status"] == status
        for key, value in metadata.items():
            assert value in str(rollout.metadata[key]), (key, rollout.metadata[key])

    return check


def check_case(case: Case, stderr: str) -> str:
    """The message line, after checking that stderr holds only the project's lines
    (argparse's usage, indented continuations, ``uvms-pin:`` lines) and, for a case with
    ``traceback_of``, the user's traceback shown as such; returns the message line."""
    lines = stderr.strip().splitlines()
    if case.code == 0 and not case.needles:  # a run that is right: not a word on stderr
        assert not lines, stderr
        return ""
    if case.traceback_of is None:
        assert "Traceback" not in stderr, stderr
    else:
        start = next(k for k, line in enumerate(lines) if line.startswith("Traceback"))
        assert lines[start - 1].startswith("uvms-pin:") and "traceback" in lines[start - 1]
        end = next(k for k in range(start + 1, len(lines)) if not lines[k].startswith(" "))
        frames = "\n".join(lines[start:end])
        assert case.traceback_of in frames and "uvms_pin/" not in frames, frames
        lines = lines[:start] + lines[end + 1 :]  # the exception line too
    assert lines and lines[-1].startswith("uvms-pin"), stderr
    for line in lines:
        assert line.startswith(("usage:", " ", "uvms-pin")), stderr
    return lines[-1]
