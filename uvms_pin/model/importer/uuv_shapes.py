"""uuv_simulator's ``<hydrodynamic_model type="sphere">`` and ``type="cylinder"``: the added
mass and quadratic drag its plugin computes from a shape, in the plugin's SNAME frame.

Both models are the Fossen model (`uvms_pin.model.importer.fossen`) whose matrices, read
from the file as for ``type="fossen"`` (zero when absent), get some diagonal entries
overwritten from the shape (uuv_gazebo_plugins, HydrodynamicModel.cc, HMSphere and
HMCylinder), with rho the plugin's ``<fluid_density>``:

- **sphere** of radius r: A_ii = 2/3 rho pi r^3 (half the displaced water of the sphere) and
  Q_ii = -1/2 rho C_d pi r^2 with C_d = 0.5, for the three translations.
- **cylinder** of radius r and length L along ``<axis>`` i, j or k (x, y or z of the link):
  along the axis A = rho pi r^2 and Q = -1/2 rho C_circ pi r^2; across it
  A = rho pi r^2 L and Q = -1/2 rho C_len r L; about the two transverse axes
  A = rho pi r^2 L^3 / 12. C_circ and C_len are the plugin's table of L / (2 r).

What the plugin does that a reader may not expect, reproduced so that a run here is the
run in Gazebo, and said in the import's notes:

- without ``<radius>`` it takes the smallest side of the block's ``<box>`` (not half of
  it), without ``<length>`` the largest, without ``<axis>`` the box's longest direction;
- the cylinder's added mass along its axis, rho pi r^2, has no length factor (kg/m written
  as kg), and its transverse drag area is r L, not 2 r L;
- beyond L / (2 r) = 7 the plugin leaves C_circ unset; 0.99, its value up to 7, is taken.

``type="spheroid"`` and ``type="box"`` are refused: the plugin itself logs them as still in
development (its spheroid's added mass is a function of the link's mass).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from uvms_pin.errors import ModelError
from uvms_pin.model.importer.xml import child_numbers, child_text

__all__ = ["IN_DEVELOPMENT", "SHAPES", "SHAPE_TAGS", "shape_coefficients"]

#: the shape models the plugin logs as "still in development", refused
IN_DEVELOPMENT = ("spheroid", "box")
#: the <hydrodynamic_model> children a shape model reads
SHAPE_TAGS = {"radius", "length", "axis"}

_SPHERE_DRAG = 0.5  # the plugin's C_d of a sphere in subcritical flow
_AXES = ("i", "j", "k")
# the plugin's drag coefficients by L / (2 r): (upper bound of the ratio, C), first that holds
_CIRCULAR_DRAG = ((1.0, 0.91), (2.0, 0.85), (4.0, 0.87), (math.inf, 0.99))
_LENGTHWISE_DRAG = ((1.0, 0.63), (2.0, 0.68), (5.0, 0.74), (10.0, 0.82), (math.inf, 0.98))


def shape_coefficients(
    kind: str,
    model: ET.Element,
    block: ET.Element,
    rho_kg_m3: float,
    added_sname: np.ndarray,
    quadratic_sname: np.ndarray,
    where: str,
    link: str,
    notes: list[str],
) -> tuple[np.ndarray, np.ndarray]:
    """The added mass (6, 6) and quadratic damping diagonal (6,) of the shape model ``kind``
    (a key of `SHAPES`), the plugin's SNAME frame and signs: the file's ``added_sname`` and
    ``quadratic_sname`` with the shape's entries written over them."""
    added, quadratic = added_sname.copy(), quadratic_sname.copy()
    SHAPES[kind](model, _box(block, where, link), rho_kg_m3, added, quadratic, where, link, notes)
    return added, quadratic


def _sphere(model, box, rho, added, quadratic, where, link, notes) -> None:
    radius, said = _size(model, "radius", box, min, where, link)
    for i in range(3):
        added[i, i] = 2.0 / 3.0 * rho * math.pi * radius**3
        quadratic[i] = -0.5 * rho * _SPHERE_DRAG * math.pi * radius**2
    if said:
        notes.append(f"link '{link}': sphere of r = {radius:.6g} m ({said})")


def _cylinder(model, box, rho, added, quadratic, where, link, notes) -> None:
    radius, radius_said = _size(model, "radius", box, min, where, link)
    length, length_said = _size(model, "length", box, max, where, link)
    axis, axis_said = _axis(model, box, where, link)
    ratio = length / (2.0 * radius)
    circular = next(c for bound, c in _CIRCULAR_DRAG if ratio <= bound)
    lengthwise = next(c for bound, c in _LENGTHWISE_DRAG if ratio <= bound)
    across = [a for a in range(3) if a != axis]
    added[axis, axis] = rho * math.pi * radius**2
    quadratic[axis] = -0.5 * circular * math.pi * radius**2 * rho
    for a in across:
        added[a, a] = rho * math.pi * radius**2 * length
        added[3 + a, 3 + a] = rho * math.pi * radius**2 * length**3 / 12.0
        quadratic[a] = -0.5 * lengthwise * radius * length * rho
    taken = "; ".join(s for s in (radius_said, length_said, axis_said) if s)
    unset = (
        f"; L / (2 r) = {ratio:.3g} > 7, where the plugin leaves the axial drag coefficient "
        "unset: 0.99 taken (its value up to 7)"
        if ratio > 7.0
        else ""
    )
    notes.append(
        f"link '{link}': cylinder of r = {radius:.6g} m, L = {length:.6g} m along "
        f"{'xyz'[axis]}{f' ({taken})' if taken else ''}: added mass along the axis "
        f"rho pi r^2 = {added[axis, axis]:.6g} kg, without a length factor, and transverse "
        f"drag area r L, as uuv_simulator computes them{unset}"
    )


#: the shape models by their <type>
SHAPES = {"sphere": _sphere, "cylinder": _cylinder}


def _box(block: ET.Element, where: str, link: str) -> np.ndarray | None:
    """The block's ``<box>`` sides (x, y, z) = (width, length, height) [m], as the plugin
    builds its bounding box; None without a whole one."""
    box = block.find("box")
    if box is None:
        return None
    sides = [child_numbers(box, tag, (1,), where, link) for tag in ("width", "length", "height")]
    if any(side is None for side in sides):
        return None
    values = np.array([float(side[0]) for side in sides])
    if not np.all(values > 0.0):
        raise ModelError(f"<box> sides must be > 0, got {values.tolist()}", path=where, link=link)
    return values


def _size(model, tag, box, pick, where, link) -> tuple[float, str]:
    """``<tag>`` of the model [m], else the box's side ``pick`` (min or max) as the plugin
    takes it; and what the notes say of where it came from ("" when given)."""
    given = child_numbers(model, tag, (1,), where, link)
    said = ""
    if given is not None:
        value = float(given[0])
    elif box is not None:
        value = float(pick(box))
        said = f"{tag}: the <box>'s {'smallest' if pick is min else 'largest'} side"
    else:
        raise ModelError(
            f"<hydrodynamic_model> needs a <{tag}> or a <box> to take it from "
            "(uuv_simulator would use Gazebo's bounding box of the link, which a file does not "
            "hold)",
            path=where,
            link=link,
        )
    if not value > 0.0:
        raise ModelError(f"<{tag}> must be > 0, got {value}", path=where, link=link)
    return value, said


def _axis(model, box, where, link) -> tuple[int, str]:
    """The cylinder's axis index (0, 1, 2) from ``<axis>`` i, j or k, else the box's longest
    side (x first on a tie, as the plugin); and what the notes say of it."""
    text = child_text(model, "axis")
    if text is not None:
        if text not in _AXES:
            raise ModelError(f'<axis> must be "i", "j" or "k", got "{text}"', path=where, link=link)
        return _AXES.index(text), ""
    if box is None:
        raise ModelError(
            "a cylinder <hydrodynamic_model> needs an <axis> or a <box> to take it from",
            path=where,
            link=link,
        )
    return int(np.flatnonzero(box == box.max())[0]), "axis: the <box>'s longest side"
