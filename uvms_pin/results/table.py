"""A rollout as a pandas table: one row per logged sample, one named column per component.

Column names are ``<array>.<component>_<unit>``:

- ``<array>`` is a `RolloutData` array (``q``, ``v``, ``tau``, ``wrench_contact_world``, ...)
  or a logged signal (``tau_commanded``, the controller's ``e_x``, ``rho_zeta``, ...); a
  signal named like a base array gets the prefix ``signal.`` (the PPC's ``tau`` becomes
  ``signal.tau.*``). The frame is in the array's name (``_world``, ``_body``); vehicle
  velocities and generalized forces are in the vehicle body frame.
- ``<component>`` is ``vehicle.<axis>`` for the free-flyer part (``x y z qx qy qz qw`` of
  q; ``vx vy vz wx wy wz`` of v; ``fx fy fz mx my mz`` of a wrench or generalized force)
  and the joint's URDF name for the arm (a continuous joint's configuration is two
  columns, ``q.<joint>.cos`` and ``q.<joint>.sin``); a task-space (first-level) quantity uses
  ``fx fy fz roll pitch yaw``; the world's contacts (signal ``world_contact``) use
  ``<body>|<object>.fx fy fz`` (force on the body, N), ``.x y z`` (its point, m) and
  ``.mx my mz`` (moment about it, N m), and so do the free objects' (``free_object_contact``);
  a signal this module does not know uses its index.
- ``_<unit>`` is the SI unit (``m``, ``rad``, ``m_s``, ``rad_s``, ``N``, ``Nm``, ``J``);
  dimensionless columns (quaternion, normalized errors) have none.
- a signal a controller logged as a `uvms_pin.results.signal.Signal` has its own names and
  units: ``<signal>.<component>_<unit>`` (unit ``"m/s"`` -> suffix ``m_s``).

The time ``time_s`` is the index. ``DataFrame.attrs["units"]`` maps every column to its
unit as text ("m/s", "N m"; "" when dimensionless) and ``attrs["metadata"]`` holds the
rollout's metadata.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from uvms_pin.results.joint_positions import CONTINUOUS, KINDS, configuration_width
from uvms_pin.results.signal import unit_suffix

if TYPE_CHECKING:
    import pandas as pd

    from uvms_pin.results.rollout_data import RolloutData

# (component, unit) per layout; joints are appended from the rollout's metadata
_POSE = [("x", "m"), ("y", "m"), ("z", "m"), ("qx", ""), ("qy", ""), ("qz", ""), ("qw", "")]
_TWIST = [("vx", "m_s"), ("vy", "m_s"), ("vz", "m_s"), ("wx", "rad_s"), ("wy", "rad_s"), ("wz", "rad_s")]  # fmt: skip
_WRENCH = [("fx", "N"), ("fy", "N"), ("fz", "N"), ("mx", "Nm"), ("my", "Nm"), ("mz", "Nm")]
_TASK = [("fx", "N"), ("fy", "N"), ("fz", "N"), ("roll", "rad"), ("pitch", "rad"), ("yaw", "rad")]
_TASK_RATE = [("vx", "m_s"), ("vy", "m_s"), ("vz", "m_s"), ("roll", "rad_s"), ("pitch", "rad_s"), ("yaw", "rad_s")]  # fmt: skip
_RPY = [("roll", "rad"), ("pitch", "rad"), ("yaw", "rad")]
_FORCE = [("fx", "N"), ("fy", "N"), ("fz", "N")]

# joint units per layout: revolute, prismatic
_JOINT_UNITS = {
    "configuration": ("rad", "m"),
    "velocity": ("rad_s", "m_s"),
    "effort": ("Nm", "N"),
    "ratio": ("", ""),
}

#: Known signals: name -> (column prefix, vehicle/task components, joint layout or None).
SIGNAL_LAYOUTS: dict[str, tuple[str, list[tuple[str, str]], str | None]] = {
    "tau_commanded": ("tau_commanded", _WRENCH, "effort"),
    "force_desired_world_N": ("force_desired_world", _FORCE, None),
    "rpy_desired": ("rpy_desired", _RPY, None),
    "rpy_ee": ("rpy_ee", _RPY, None),
    "e_x": ("e_x", _TASK, None),
    "rho_x": ("rho_x", _TASK, None),
    "xi_x": ("xi_x", [(c, "") for c, _ in _TASK], None),
    "eps_x": ("eps_x", [(c, "") for c, _ in _TASK], None),
    "xdot_r": ("xdot_r", _TASK_RATE, None),
    "zeta_r": ("zeta_r", _TWIST, "velocity"),
    "e_zeta": ("e_zeta", _TWIST, "velocity"),
    "rho_zeta": ("rho_zeta", _TWIST, "velocity"),
    "xi_zeta": ("xi_zeta", [(c, "") for c, _ in _TWIST], "ratio"),
    "eps_zeta": ("eps_zeta", [(c, "") for c, _ in _TWIST], "ratio"),
    "tau": ("tau", _WRENCH, "effort"),
}

_BASE_ARRAYS = ("q", "v", "tau", "wrench_contact_world", "wrench_measured_world",
                "wrench_disturbance_body", "kinetic_energy", "potential_energy")  # fmt: skip


def _joints(rollout: RolloutData, width: int) -> list[tuple[str, str]]:
    """(name, kind) of the arm joints; ``joint<k>`` / revolute when the metadata has none."""
    names = list(rollout.metadata.get("arm_joint_names") or [])
    kinds = list(rollout.metadata.get("arm_joint_kinds") or [])
    if len(names) != width:
        names = [f"joint{k + 1}" for k in range(width)]
    if len(kinds) != width:
        kinds = ["revolute"] * width
    return list(zip(names, kinds, strict=True))


def _configuration_joints(rollout: RolloutData, width: int) -> list[tuple[str, str]] | None:
    """(name, kind) of the arm joints whose configuration takes ``width`` entries of q (a
    continuous joint two), from the metadata; None when it does not say."""
    names = list(rollout.metadata.get("arm_joint_names") or [])
    kinds = list(rollout.metadata.get("arm_joint_kinds") or [])
    if len(names) == len(kinds) and set(kinds) <= set(KINDS):
        if configuration_width(kinds) == width:
            return list(zip(names, kinds, strict=True))
    return None


def _labels(
    rollout: RolloutData, prefix: str, vehicle: list, joint_layout: str | None, width: int
) -> list[tuple[str, str]]:
    """(column, unit) for an array of ``width`` columns laid out as vehicle + joints."""
    n_joint = width - len(vehicle) if joint_layout else 0
    if width != len(vehicle) + n_joint or n_joint < 0:
        return [(f"{prefix}.{k}", "") for k in range(width)]
    out = [(f"{prefix}.vehicle.{c}" if joint_layout else f"{prefix}.{c}", u) for c, u in vehicle]
    revolute_unit, prismatic_unit = _JOINT_UNITS[joint_layout] if joint_layout else ("", "")
    joints = _configuration_joints(rollout, n_joint) if joint_layout == "configuration" else None
    for name, kind in joints or _joints(rollout, n_joint):
        if kind == CONTINUOUS and joints is not None:  # (cos, sin) of the angle
            out += [(f"{prefix}.{name}.cos", ""), (f"{prefix}.{name}.sin", "")]
        else:
            unit = prismatic_unit if kind == "prismatic" else revolute_unit
            out.append((f"{prefix}.{name}", unit))
    return out


#: the 9 columns of each (body, object) pair of the ``world_contact`` signal
_CONTACT_PAIR = [
    *_FORCE,
    ("x", "m"),
    ("y", "m"),
    ("z", "m"),
    ("mx", "Nm"),
    ("my", "Nm"),
    ("mz", "Nm"),
]


#: a signal of pair wrenches -> the metadata key naming its pairs
_PAIR_SIGNALS = {
    "world_contact": "world_contact_pairs",
    "free_object_contact": "free_object_contact_pairs",
}


def _world_contact_labels(
    rollout: RolloutData, width: int, name: str = "world_contact"
) -> list[tuple[str, str]]:
    """``<name>.<body>|<object>.fx_N`` ...: force, point, moment of each pair."""
    pairs = list(rollout.metadata.get(_PAIR_SIGNALS[name]) or [])
    if len(pairs) * len(_CONTACT_PAIR) != width:
        return [(f"{name}.{k}", "") for k in range(width)]
    return [(f"{name}.{pair}.{c}", u) for pair in pairs for c, u in _CONTACT_PAIR]


#: unit suffix in a column name -> the unit as text in ``attrs["units"]``
UNIT_TEXT = {"m_s": "m/s", "rad_s": "rad/s", "Nm": "N m"}


def _named_labels(prefix: str, described, width: int) -> list[tuple[str, str]] | None:
    """(column, unit text) of a signal logged as a `Signal` (its component names and
    units, kept in the metadata's ``signal_units``); None when it was not, or the record
    does not fit its width."""
    if not isinstance(described, dict):
        return None
    components, units = described.get("components") or [], described.get("units") or []
    if len(components) != width or len(units) != width:
        return None
    return [(f"{prefix}.{c}", u) for c, u in zip(components, units, strict=True)]


def _column_name(label: str, unit: str) -> str:
    suffix = unit_suffix(unit)
    return f"{label}_{suffix}" if suffix else label


def column_layout(rollout: RolloutData) -> list[tuple[str, str, np.ndarray]]:
    """(column name, unit suffix, values) for every column of `to_dataframe`, in order."""
    blocks: list[tuple[list[tuple[str, str]], np.ndarray]] = [
        (_labels(rollout, "q", _POSE, "configuration", rollout.q.shape[1]), rollout.q),
        (_labels(rollout, "v", _TWIST, "velocity", rollout.v.shape[1]), rollout.v),
        (_labels(rollout, "tau", _WRENCH, "effort", rollout.tau.shape[1]), rollout.tau),
    ]
    for name in ("wrench_contact_world", "wrench_measured_world", "wrench_disturbance_body"):
        blocks.append((_labels(rollout, name, _WRENCH, None, 6), getattr(rollout, name)))
    blocks.append(([("kinetic_energy", "J")], rollout.kinetic_energy_J[:, None]))
    blocks.append(([("potential_energy", "J")], rollout.potential_energy_J[:, None]))
    described = rollout.metadata.get("signal_units") or {}
    for name, values in rollout.signals.items():
        values = values.reshape(len(values), -1)
        prefix, vehicle, joint_layout = SIGNAL_LAYOUTS.get(name, (name, [], None))
        if prefix in _BASE_ARRAYS:
            prefix = f"signal.{prefix}"
        if name in _PAIR_SIGNALS:
            labels = _world_contact_labels(rollout, values.shape[1], name)
        elif (named := _named_labels(prefix, described.get(name), values.shape[1])) is not None:
            labels = named
        elif not vehicle:
            labels = [(f"{prefix}.{k}", "") for k in range(values.shape[1])]
        else:
            labels = _labels(rollout, prefix, vehicle, joint_layout, values.shape[1])
        blocks.append((labels, values))
    return [
        (_column_name(label, unit), unit, values[:, k])
        for labels, values in blocks
        for k, (label, unit) in enumerate(labels)
    ]


def to_dataframe(rollout: RolloutData) -> pd.DataFrame:
    """The rollout as a `pandas.DataFrame` (see the module docstring for the columns)."""
    import pandas as pd

    layout = column_layout(rollout)
    frame = pd.DataFrame(
        {name: values for name, _, values in layout},
        index=pd.Index(rollout.time_s, name="time_s"),
    )
    frame.attrs["units"] = {name: UNIT_TEXT.get(unit, unit) for name, unit, _ in layout}
    frame.attrs["metadata"] = dict(rollout.metadata)
    return frame
