"""gz-sim's ``Hydrodynamics`` system (``gz::sim::systems::Hydrodynamics``) as uvms-pin
coefficients.

Its parameters are SNAME stability derivatives named force-axis letter (x y z k m n) then
velocity letters (U V W P Q R): added mass ``<xDotU>``..., linear damping ``<xU>``...,
quadratic ``<xUabsU>``... What it applies (gz-sim src/systems/hydrodynamics), in the link
frame itself (no NED change; velocities at the link origin, the wrench at the link origin):

    tau = Ma nu_dot - C(Ma, nu) nu + (L + sum_k Q_k |nu_k|) nu

with Ma, L, Q_k negative by Fossen's sign convention. So M_A = -Ma, D_lin = -L and
D_quad_i = -Q[i, i, i] (``<xUabsU>``, ``<yVabsV>``, ...). Cross quadratic terms
(``<xUabsV>``, ``<xUV>``...) have no uvms-pin counterpart and are reported. gz-sim's Coriolis
uses only Ma's diagonal; uvms-pin's uses the whole M_A (the same when Ma is diagonal).
Buoyancy is another system (``Buoyancy``, from the collision volumes), read by the caller.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.hydro.params import HydroParams
from uvms_pin.model.importer.fossen import note_asymmetry
from uvms_pin.model.importer.xml import element_numbers

__all__ = ["FORCE_AXES", "VELOCITIES", "gz_hydrodynamics"]

FORCE_AXES = "xyzkmn"
VELOCITIES = "UVWPQR"
_FLAGS = {"link_name", "namespace", "default_current", "disable_coriolis", "disable_added_mass"}


def gz_hydrodynamics(
    plugin: ET.Element,
    volume_m3: float,
    center_of_buoyancy_m: np.ndarray,
    where: str,
    notes: list[str],
) -> HydroParams:
    """The plugin's coefficients with the link's buoyancy (volume, centre) as `HydroParams`
    in the link frame; what is not carried over is appended to ``notes``."""
    link = (plugin.findtext("link_name") or "?").strip()
    added = np.zeros((6, 6))
    linear = np.zeros((6, 6))
    quadratic = np.zeros(6)
    for child in plugin:
        tag = child.tag
        if tag in _FLAGS:
            _note_flag(child, link, notes)
            continue
        parsed = _parse_name(tag)
        if parsed is None:
            notes.append(f"link '{link}': Hydrodynamics <{tag}> not mapped (unknown parameter)")
            continue
        value = float(element_numbers(child, (1,), where, link)[0])
        kind, i, j, k = parsed
        if kind == "added":
            added[i, j] = -value
        elif kind == "linear":
            linear[i, j] = -value
        elif kind == "abs" and i == j == k:
            quadratic[i] = -value
        elif value != 0.0:
            notes.append(
                f"link '{link}': Hydrodynamics <{tag}> = {value:g} not mapped "
                "(uvms-pin has diagonal quadratic damping only)"
            )
    if np.any(added - np.diag(np.diag(added))):
        notes.append(
            f"link '{link}': off-diagonal added mass: gz-sim's Coriolis uses only the "
            "diagonal, uvms-pin's the whole matrix"
        )
    note_asymmetry(added, link, notes)
    try:
        return HydroParams(
            volume_m3,
            center_of_buoyancy_m,
            0.5 * (added + added.T),
            linear,
            quadratic,
            origin=f"gz-sim Hydrodynamics ({where})",
        )
    except ParameterError as exc:
        raise ModelError(str(exc), path=where, link=link) from exc


def _parse_name(tag: str) -> tuple[str, int, int, int] | None:
    """``xDotU`` -> ("added", 0, 0, -1); ``xU`` -> ("linear", ...); ``xUabsU`` -> ("abs",
    i, j, k); ``xUV`` -> ("quadratic", i, j, k); None for anything else."""
    if len(tag) < 2 or tag[0] not in FORCE_AXES:
        return None
    i, rest = FORCE_AXES.index(tag[0]), tag[1:]
    if rest.startswith("Dot") and len(rest) == 4 and rest[3] in VELOCITIES:
        return "added", i, VELOCITIES.index(rest[3]), -1
    if len(rest) == 1 and rest in VELOCITIES:
        return "linear", i, VELOCITIES.index(rest), -1
    if len(rest) == 5 and rest[1:4] == "abs" and rest[0] in VELOCITIES and rest[4] in VELOCITIES:
        return "abs", i, VELOCITIES.index(rest[0]), VELOCITIES.index(rest[4])
    if len(rest) == 2 and all(c in VELOCITIES for c in rest):
        return "quadratic", i, VELOCITIES.index(rest[0]), VELOCITIES.index(rest[1])
    return None


def _note_flag(child: ET.Element, link: str, notes: list[str]) -> None:
    text = (child.text or "").strip()
    if child.tag in ("disable_coriolis", "disable_added_mass") and text.lower() in ("1", "true"):
        notes.append(
            f"link '{link}': <{child.tag}> is true in the source; uvms-pin always has added "
            "mass and its Coriolis term"
        )
    elif child.tag == "default_current" and text and any(float(v) for v in text.split()):
        notes.append(
            f"link '{link}': <default_current> {text} m/s: set it as the scenario's [water] current"
        )
