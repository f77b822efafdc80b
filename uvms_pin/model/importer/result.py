"""What an import gives: the URDF text, the thrusters and what could not be mapped."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from uvms_pin.hydro.params import HydroParams

__all__ = ["ImportResult", "ImportedThruster"]


@dataclass(frozen=True)
class ImportedThruster:
    """One thruster as the source file describes it, in the vehicle (root link) frame.

    Attributes:
        name: the thruster's link or joint name in the source.
        position_body_m: where it pushes (3,) in the root link frame [m].
        direction_body: unit direction of positive thrust (3,) in the root link frame.
        time_constant_s: first-order rotor time constant [s] (None: not given).
        thrust_law: ``"quadratic"`` (thrust = coefficient x |x| x) or what the source names.
        thrust_coefficient: the coefficient of the quadratic law [N per command^2] (gz-sim:
            K_T rho D^4 with omega in rad/s; uuv_simulator: rotorConstant).
        max_forward_N, max_reverse_N: thrust limits if the source gives them, else None.
    """

    name: str
    position_body_m: np.ndarray
    direction_body: np.ndarray
    time_constant_s: float | None
    thrust_law: str
    thrust_coefficient: float | None
    max_forward_N: float | None = None
    max_reverse_N: float | None = None


@dataclass
class ImportResult:
    """The outcome of `import_model`.

    Attributes:
        urdf_text: the uvms-pin URDF (``<hydrodynamics>`` tags, no Gazebo plugins).
        hydro: the hydrodynamic coefficients written, per link, in the link frame.
        thrusters: the thrusters found, in file order.
        fluid_density_kg_m3: the fluid density the source states (None: not stated).
        not_mapped: one sentence per thing the source says that uvms-pin did not carry over.
        source_format: ``"urdf"`` or ``"sdf"``.
    """

    urdf_text: str
    hydro: dict[str, HydroParams]
    thrusters: list[ImportedThruster]
    fluid_density_kg_m3: float | None
    not_mapped: list[str] = field(default_factory=list)
    source_format: str = "urdf"

    def grouped_notes(self) -> list[str]:
        """`not_mapped` with the notes that say the same of several links, joints or plugins
        said once, naming them all (``links 'a', 'b': no hydrodynamics in the source; ...``),
        in the order of their first; what a terminal shows (the URDF keeps every note)."""
        groups: dict[tuple[str, str], list[tuple[str, str]]] = {}
        for note in self.not_mapped:
            found = _NAMED.match(note)
            key = (found["kind"], found["rest"]) if found else ("", note)
            groups.setdefault(key, []).append((found["name"] if found else "", note))
        out = []
        for (kind, rest), members in groups.items():
            if len(members) == 1:
                out.append(members[0][1])
            else:
                names = ", ".join(repr(name) for name, _ in members)
                out.append(f"{kind}s {names}: {rest}")
        return out


# a note about one link, joint or plugin: "link 'name': what", "plugin 'name' not mapped"
_NAMED = re.compile(r"^(?P<kind>link|joint|plugin) '(?P<name>[^']+)':? (?P<rest>.*)$", re.S)
