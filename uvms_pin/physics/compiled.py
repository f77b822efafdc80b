"""The compiled core (C++ on Pinocchio's C++ API): loading it and building it from a UVMS.

The Python implementation (`uvms_pin.physics.dynamics`, `uvms_pin.hydro`, `uvms_pin.sim.plant`) is the
readable reference; the core computes the same M, h, forward dynamics and plant right-hand
side (tests hold it to the reference at 1e-12) and advances the plant over a control period in
one call. Select with ``backend="core"`` (default) or ``backend="python"``.

The extension ``uvms_pin._core`` is built at ``pip install`` (scikit-build-core). If it is
missing or was built from other sources or against another Pinocchio, `core_module` raises
`CoreUnavailableError` with the command that rebuilds it.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from types import ModuleType

import numpy as np
import pinocchio as pin  # loads libpinocchio_default before the extension needs it

from uvms_pin.errors import ParameterError, UvmsPinError
from uvms_pin.flow import FlowField, SumFlow, UniformCurrent
from uvms_pin.flow.components import WaveField
from uvms_pin.model.uvms import UVMS

BACKENDS = ("core", "python")
API_VERSION = 1
REBUILD = "rebuild it with `pip install -e .` (or `make clean test`) in the uvms-pin checkout"
_SOURCE_DIR = Path(__file__).resolve().parents[2] / "src" / "uvms_core"


class CoreFallbackWarning(UserWarning):
    """Something the compiled core cannot represent runs on the (slower) Python reference."""


class CoreUnavailableError(UvmsPinError, ImportError):
    """The compiled core is missing, stale or built against another Pinocchio."""


def check_backend(backend: str) -> str:
    """``backend`` if it is one of `BACKENDS`, else ParameterError."""
    if backend not in BACKENDS:
        raise ParameterError(f"backend must be one of {BACKENDS}, got {backend!r}")
    return backend


def source_hash(source_dir: Path = _SOURCE_DIR) -> str | None:
    """The fingerprint CMakeLists.txt bakes into the extension (None without sources)."""
    files = sorted(p for p in source_dir.glob("*") if p.suffix in (".cpp", ".hpp"))
    if not files:
        return None
    lines = "".join(f"{p.name}:{hashlib.sha256(p.read_bytes()).hexdigest()}\n" for p in files)
    return hashlib.sha256(lines.encode()).hexdigest()


def _load() -> ModuleType:
    try:
        from uvms_pin import _core
    except ImportError as exc:
        raise CoreUnavailableError(f"the compiled core is not built ({exc}): {REBUILD}") from exc
    if _core.API_VERSION != API_VERSION:
        raise CoreUnavailableError(
            f"the compiled core has API {_core.API_VERSION}, this uvms_pin needs {API_VERSION}: "
            f"{REBUILD}"
        )
    if _core.PINOCCHIO_VERSION != pin.__version__:
        raise CoreUnavailableError(
            f"the compiled core was built against Pinocchio {_core.PINOCCHIO_VERSION} but "
            f"pinocchio {pin.__version__} is installed: {REBUILD}"
        )
    expected = source_hash()
    if expected is not None and expected != _core.SOURCE_HASH:
        raise CoreUnavailableError(
            f"the compiled core is stale (built from other sources than {_SOURCE_DIR}): {REBUILD}"
        )
    return _core


_MODULE: list[ModuleType] = []  # loaded once per process


def core_module() -> ModuleType:
    """The extension module, checked once per process (CoreUnavailableError otherwise)."""
    if not _MODULE:
        _MODULE.append(_load())
    return _MODULE[0]


def core_available() -> bool:
    try:
        core_module()
    except CoreUnavailableError:
        return False
    return True


def build_dynamics(uvms: UVMS):
    """A fresh compiled ``Dynamics`` of ``uvms`` (its model and stacked hydro arrays)."""
    core = core_module()
    damped = uvms.hydro_bodies_with_damping
    positions = np.array([b.placement_in_joint.translation for b in damped]).reshape(-1, 3)
    return core.Dynamics(
        uvms.model.saveToString(),
        uvms.water_density_kg_m3,
        np.ascontiguousarray(uvms.added_mass_per_joint, dtype=float),
        np.ascontiguousarray(uvms.volume_per_joint_m3, dtype=float),
        np.ascontiguousarray(uvms.center_of_buoyancy_per_joint_m, dtype=float),
        [int(j) for j in uvms.damping_joint_ids],
        np.ascontiguousarray(uvms.damping_action, dtype=float),
        np.ascontiguousarray(uvms.damping_rotation_in_joint, dtype=float),
        np.ascontiguousarray(positions, dtype=float),
        np.ascontiguousarray(uvms.damping_linear, dtype=float),
        np.ascontiguousarray(uvms.damping_quadratic, dtype=float),
    )


def dynamics_of(uvms: UVMS):
    """The compiled ``Dynamics`` of ``uvms``, built on first use and kept with it.

    Like ``uvms.data`` it reads the model when built: a UVMS changed in place afterwards
    needs ``uvms.copy()`` (or `with_model` / `with_hydro`), which builds a new one.
    """
    cached = uvms.__dict__.get("_core_dynamics")
    if cached is None:
        cached = build_dynamics(uvms)
        uvms.__dict__["_core_dynamics"] = cached
    return cached


def compiled_flow(flow: FlowField | None) -> tuple[np.ndarray, np.ndarray, float] | None:
    """The core's form of a flow: (uniform current (3,), wave components (m, 5), depth), or
    None when the core cannot represent it (a varying or sheared current, waves in
    different depths). Rows: amplitude, angular frequency, wavenumber, heading, phase, as in
    `uvms_pin.flow.components.WaveComponents`."""
    current = np.zeros(3)
    tables, depths = [], set()
    for field in flow.fields if isinstance(flow, SumFlow) else (() if flow is None else (flow,)):
        if isinstance(field, UniformCurrent):
            current = current + field.velocity_world_m_s
        elif isinstance(field, WaveField):
            c = field.components
            tables.append(
                np.column_stack(
                    [
                        c.amplitude_m,
                        c.angular_frequency_rad_s,
                        c.wavenumber_rad_m,
                        c.heading_rad,
                        c.phase_rad,
                    ]
                )
            )
            depths.add(c.water_depth_m)
        else:
            return None
    if len(depths) > 1:
        return None
    waves = np.vstack(tables) if tables else np.zeros((0, 5))
    return current, waves, depths.pop() if depths else math.inf
