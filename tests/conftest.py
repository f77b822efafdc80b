"""Shared fixtures: the reference model and tiny URDFs written on the fly."""

from __future__ import annotations

import contextlib
import io
import os
import re
import shutil
import subprocess
import sys
import traceback
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from slow_tests import SLOW_MODULES, SLOW_TESTS, longest_first

import uvms_pin as up

ROOT = Path(__file__).resolve().parents[1]
# the tests check full-length runs: a cap on durations in the developer's shell (docs/getting_started.md:
# UVMS_PIN_MAX_DURATION_S) does not apply to them (the doc test sets its own per snippet)
os.environ.pop("UVMS_PIN_MAX_DURATION_S", None)
REFERENCE_URDF = ROOT / "models" / "uvms_lbv150.urdf"
RHO = 1025.0
G = 9.81
#: relative agreement of the compiled core with the Python reference
REL = 1e-12
#: the shipped BlueROV2 Heavy + Reach Alpha 5 (its joints' drives as armature)
ALPHA5_URDF = ROOT / "models" / "uvms_bluerov2_alpha5.urdf"


def without_drives(urdf: Path, tmp_dir: Path) -> Path:
    """``urdf`` written to ``tmp_dir`` without its joints' ``<armature>`` (their drives'
    reflected rotor inertia): the light links a URDF without drive data gives (the Alpha 5's
    wrist link alone: ~8e-5 kg m^2 about its axis, against 0.0117 with its drive)."""
    text = urdf.read_text()
    stripped = re.sub(r"\s*<armature [^>]*/>", "", text)
    assert stripped != text, f"{urdf.name} has no <armature> to take out"
    path = tmp_dir / f"{urdf.stem}_without_drives.urdf"
    path.write_text(stripped)
    return path


def pytest_collection_modifyitems(config, items) -> None:
    """Mark ``slow`` the tests tests/slow_tests.py lists (`make check` leaves them out), then
    put the longest files first (`longest_first`)."""
    slow_in_file: Counter[str] = Counter()
    for item in items:
        path, _, _ = item.nodeid.partition("::")
        if path.startswith(SLOW_MODULES) or item.nodeid.partition("[")[0] in SLOW_TESTS:
            item.add_marker(pytest.mark.slow)
        if item.get_closest_marker("slow") is not None:  # listed here or marked in its file
            slow_in_file[path] += 1
    items.sort(key=lambda item: longest_first(item.nodeid.partition("::")[0], slow_in_file))


def mount_on_reference_vehicle(arm: str, tmp_dir: Path) -> up.UVMS:
    """A catalog arm (e.g. ``"panda"``) on the reference vehicle, at the reference arm's
    mount turned upside down, as compare-arms mounts it (its dry links allowed)."""
    from uvms_pin.model.mount.catalog import CATALOG
    from uvms_pin.model.mount.split import split_urdf

    split = split_urdf(REFERENCE_URDF, tmp_dir)
    entry = CATALOG[arm]
    return up.mount_arm(
        split.vehicle_urdf,
        entry.urdf,
        (split.mount_pose.translation, (np.pi, 0.0, 0.0)),
        ee_link=entry.ee_link,
        allow_dry_links=True,
    )


def continuous_joint_urdf(
    tmp_path: Path, joints=("arm_joint1", "arm_joint2", "arm_joint3", "arm_joint4")
) -> Path:
    """The reference URDF with ``joints`` made ``continuous`` (q then holds their cos and
    sin, nq != nv; their <limit> stays, urdfdom reads only effort and velocity of it)."""
    text = REFERENCE_URDF.read_text()
    for name in joints:
        old = f'<joint name="{name}" type="revolute">'
        assert old in text, name
        text = text.replace(old, f'<joint name="{name}" type="continuous">')
    path = tmp_path / "continuous.urdf"
    path.write_text(text)
    return path


#: the importer tests' vehicles (uuv_simulator's RexROV, gz-sim's LRAUV)
IMPORTER_DATA = ROOT / "tests" / "model" / "importer" / "data"


def model_beyond_the_reference(name: str, tmp_dir: Path) -> up.UVMS:
    """A model the derivative campaigns try besides the reference one: "bluerov2_heavy"
    (the bare vehicle), "rexrov" and "lrauv" (imported), "continuous" (the reference arm's
    joints continuous) or a catalog arm on the reference vehicle (e.g. "kinova")."""
    import warnings

    from uvms_pin.model.resources import shipped_path

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", up.ModelWarning)
        if name == "bluerov2_heavy":
            return up.load_uvms(shipped_path("models/bluerov2_heavy.urdf"))
        if name in ("rexrov", "lrauv"):
            source = {"rexrov": "rexrov_expanded.urdf", "lrauv": "lrauv_hydrodynamics.sdf"}
            up.import_model(IMPORTER_DATA / source[name], tmp_dir / f"{name}.urdf")
            return up.load_uvms(tmp_dir / f"{name}.urdf")
        if name == "continuous":
            return up.load_uvms(continuous_joint_urdf(tmp_dir))
        return mount_on_reference_vehicle(name, tmp_dir)


def body_urdf(
    *,
    mass: float = 10.0,
    inertia: tuple[float, float, float] = (0.1, 0.2, 0.3),
    com: tuple[float, float, float] = (0.0, 0.0, 0.0),
    hydro: str | None = None,
    collision: str | None = None,
) -> str:
    """A one-link robot named 'body' (also used as its own end-effector frame)."""
    parts = [
        '<robot name="one">',
        '  <link name="body">',
        f'    <inertial><origin xyz="{com[0]} {com[1]} {com[2]}"/><mass value="{mass}"/>'
        f'<inertia ixx="{inertia[0]}" iyy="{inertia[1]}" izz="{inertia[2]}" ixy="0" ixz="0" iyz="0"/></inertial>',
    ]
    if collision:
        parts.append(f"    <collision><geometry>{collision}</geometry></collision>")
    if hydro:
        parts.append(f"    <hydrodynamics>{hydro}</hydrodynamics>")
    parts += ["  </link>", "</robot>"]
    return "\n".join(parts)


def hydro_xml(volume: float, cob=(0, 0, 0), added=(0,) * 6, lin=(0,) * 6, quad=(0,) * 6) -> str:
    def s(x):
        return " ".join(str(v) for v in x)

    return (
        f'<volume value="{volume}"/><center_of_buoyancy xyz="{s(cob)}"/>'
        f'<added_mass diagonal="{s(added)}"/><linear_damping diagonal="{s(lin)}"/>'
        f'<quadratic_damping diagonal="{s(quad)}"/>'
    )


@pytest.fixture
def write_urdf(tmp_path: Path):
    """Write URDF text to a file and return its path."""

    def _write(text: str, name: str = "robot.urdf") -> Path:
        path = tmp_path / name
        path.write_text(text)
        return path

    return _write


@pytest.fixture
def load_body(write_urdf):
    """Load a one-link URDF as a UVMS whose end-effector and sensor frames are the body."""

    def _load(text: str, **kw) -> up.UVMS:
        return up.load_uvms(write_urdf(text), ee_frame="body", sensor_frame="body", **kw)

    return _load


@pytest.fixture(scope="session")
def reference_uvms() -> up.UVMS:
    return up.load_uvms(REFERENCE_URDF)


@dataclass(frozen=True)
class EndEffectorMove:
    """A start configuration q0 (nq,), its state at rest x0 (nq + nv,) and an end-effector
    target (pin.SE3)."""

    q0: np.ndarray
    x0: np.ndarray
    target: pin.SE3


@pytest.fixture
def ten_cm_move(reference_uvms) -> EndEffectorMove:
    """The reference UVMS 3 m down with the realistic scenario's arm, at rest, and a target
    10 cm forward and 5 cm down from its end-effector, in the same orientation (the
    optimal-control tests' point-to-point move)."""
    uvms = reference_uvms
    q0 = uvms.neutral_configuration()
    q0[2] = -3.0
    q0[7:] = [-0.2, 1.0, -0.8, 0.2]
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, q0)
    start = data.oMf[uvms.ee_frame_id]
    target = pin.SE3(start.rotation, start.translation + np.array([0.1, 0.0, -0.05]))
    return EndEffectorMove(q0, np.r_[q0, np.zeros(uvms.nv)], target)


def random_configuration(uvms: up.UVMS, rng: np.random.Generator) -> np.ndarray:
    """A random q: position in a 2 m box, uniform random orientation, joints within limits
    (a continuous joint anywhere in [-pi, pi])."""
    model, arm = uvms.model, uvms.arm_joints
    q = np.empty(model.nq)
    q[:3] = rng.uniform(-1.0, 1.0, 3)
    quat = rng.normal(size=4)
    q[3:7] = quat / np.linalg.norm(quat)
    lo = np.maximum(arm.lower, -np.pi)
    hi = np.minimum(arm.upper, np.pi)
    q[7:] = arm.configuration(rng.uniform(lo, hi))
    return q


def random_state(
    uvms: up.UVMS, rng: np.random.Generator, *, speed: float = 0.5, depth_m: float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A random (q, v, tau): q on the manifold with every joint within its limits (any joint
    type: ball, continuous; at most +-pi), the vehicle at ``depth_m`` (None: 2.5 to 3.5 m
    deep, where wave kinematics still matter), v of scale ``speed`` [m/s, rad/s], tau of
    scale 5 [N, N m]."""
    model = uvms.model
    lower = np.maximum(model.lowerPositionLimit, -np.pi)
    upper = np.minimum(model.upperPositionLimit, np.pi)
    pin.seed(int(rng.integers(2**31)))  # pin.randomConfiguration draws from its own generator
    q = pin.randomConfiguration(model, lower, upper)
    q[2] = -3.0 + rng.uniform(-0.5, 0.5) if depth_m is None else depth_m
    return q, rng.normal(scale=speed, size=uvms.nv), rng.normal(scale=5.0, size=uvms.nv)


def with_spherical_joint(uvms: up.UVMS, joint_id: int) -> up.UVMS:
    """The same bodies and frames, joint ``joint_id`` (a revolute) made a ball joint."""
    old = uvms.model
    new = pin.Model()
    new.name, new.gravity = old.name, old.gravity
    for j in range(1, old.njoints):
        joint = pin.JointModelSpherical() if j == joint_id else old.joints[j]
        added = new.addJoint(old.parents[j], joint, old.jointPlacements[j], old.names[j])
        new.appendBodyToJoint(added, old.inertias[j], pin.SE3.Identity())
        new.armature[new.joints[added].idx_v : new.joints[added].idx_v + joint.nv] = (
            old.armature[old.joints[j].idx_v] if joint.nv == 1 else 1e-3
        )
    for f in list(old.frames)[1:]:
        new.addFrame(
            pin.Frame(f.name, f.parentJoint, f.parentFrame, f.placement, f.type, f.inertia),
            False,
        )
    return uvms.with_model(new)


def central_difference(function, x: np.ndarray, n: int, step: float, plus=None) -> np.ndarray:
    """d function / dx along n tangent directions, by the 4-point central difference (error
    O(step^4)): (8 (f(h) - f(-h)) - (f(2h) - f(-2h))) / (12 h) per column. ``plus(x, dx)``
    moves x (default x + dx; ``pin.integrate`` for a configuration: the tangent convention)."""
    plus = (lambda x0, dx: x0 + dx) if plus is None else plus
    columns = []
    for k in range(n):
        e = np.zeros(n)
        e[k] = step
        near = np.asarray(function(plus(x, e))) - np.asarray(function(plus(x, -e)))
        far = np.asarray(function(plus(x, 2 * e))) - np.asarray(function(plus(x, -2 * e)))
        columns.append((8.0 * near - far) / (12.0 * step))
    return np.stack(columns, axis=-1)


def free_body_state(uvms: up.UVMS) -> np.ndarray:
    return pin.neutral(uvms.model)


# ---- the documentation's snippets (tests/test_docs_run.py): what ran, what was skipped
DOCS_RUN_SUMMARY = pytest.StashKey[list]()


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    lines = config.stash.get(DOCS_RUN_SUMMARY, None)
    if lines:
        terminalreporter.section("documentation snippets")
        for line in lines:
            terminalreporter.write_line(line)


def heavy_packages_loaded_by(code: str, heavy: set[str]) -> list[str]:
    """The packages of ``heavy`` (top-level names) that running ``code`` in a fresh
    interpreter loads: what a start-up that does only this pays for."""
    top_level = "{m.split('.')[0] for m in sys.modules}"
    report = f"\nimport sys\nprint(','.join(sorted({top_level} & set({sorted(heavy)!r}))))\n"
    result = subprocess.run([sys.executable, "-c", code + report], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return [name for name in result.stdout.strip().split(",") if name]


# ---- the command line as a user runs it, and relative comparisons (used across folders)
def uvms_pin_command() -> list[str]:
    exe = Path(sys.executable).with_name("uvms-pin")
    if exe.exists():
        return [str(exe)]
    found = shutil.which("uvms-pin")
    if found is None:
        pytest.fail("the uvms-pin console script is not installed (pip install -e .)")
    return [found]


def run(*args: str, cwd: Path = ROOT, process: bool = False) -> subprocess.CompletedProcess:
    """``uvms-pin ARGS`` in ``cwd``: in this process (`run_cli_in_process`, a second of
    imports spared a call), or with ``process`` the installed console script in a process of
    its own (what the entry point's wiring or the interpreter's exit must show).
    tests/apps/cli/test_bad_inputs.py holds the two to the same answers."""
    if not process:
        return run_cli_in_process(list(args), cwd)
    return subprocess.run(
        [*uvms_pin_command(), *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )


def run_cli_in_process(args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """``uvms-pin ARGS`` in ``cwd`` run in this process as the console script runs it:
    ``sys.exit(main(ARGS))``, an uncaught exception printed as the interpreter prints it (exit
    status 1), Python's default warning filters; stdout and stderr captured as text. The
    modules the run imported from ``cwd`` (a user's controller) are forgotten after it, as a
    new process would not have them. A second of import time spared per call; what only a
    process shows (Ctrl-C, a closed stdout, the interpreter's own exit) needs `run_cli`."""
    from uvms_pin.apps.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    modules_before = set(sys.modules)
    previous_cwd = Path.cwd()
    os.chdir(cwd)
    try:
        with (
            contextlib.redirect_stdout(out),
            contextlib.redirect_stderr(err),
            warnings.catch_warnings(),
        ):
            _python_default_warning_filters()
            try:
                status = main(list(args))
            except SystemExit as exc:  # argparse's errors, --version
                status = _exit_status(exc.code)
            except Exception:
                traceback.print_exc()
                status = 1
    finally:
        os.chdir(previous_cwd)
        _forget_modules_under(Path(cwd).resolve(), set(sys.modules) - modules_before)
    return subprocess.CompletedProcess(["uvms-pin", *args], status, out.getvalue(), err.getvalue())


def _python_default_warning_filters() -> None:
    """The filters of a fresh ``python`` (no -W, no PYTHONWARNINGS): what pytest added removed;
    changing them also voids the once-per-location records of earlier runs."""
    warnings.resetwarnings()
    for category in (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning):
        warnings.simplefilter("ignore", category)
    warnings.filterwarnings("default", category=DeprecationWarning, module="__main__")


def _exit_status(code: object) -> int:
    """The process's exit status for ``sys.exit(code)``: None 0, an int itself, else the
    code printed on stderr and 1."""
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)
    return 1


def _forget_modules_under(directory: Path, names: set[str]) -> None:
    for name in names:
        file = getattr(sys.modules.get(name), "__file__", None)
        if file and Path(file).resolve().is_relative_to(directory):
            del sys.modules[name]


def assert_rel(actual: np.ndarray, expected: np.ndarray, rel: float = REL) -> None:
    """max |a - e| <= rel * max |e| (relative to the size of the whole quantity)."""
    scale = max(float(np.max(np.abs(expected))), 1e-300)
    err = float(np.max(np.abs(actual - expected)))
    assert err <= rel * scale, f"relative error {err / scale:.3g} > {rel:g}"
