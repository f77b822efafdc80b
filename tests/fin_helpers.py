"""An LRAUV with fins, as gz-sim's underwater tutorial writes it: the importer's LRAUV test
file with the tutorial world's two LiftDrag systems (their numbers: gz-sim
tutorials/files/underwater_vehicles/buoyant_lrauv.sdf, commit 93bbf3e) put back."""

from __future__ import annotations

from pathlib import Path

import uvms_pin as up
from uvms_pin.model.importer.result import ImportResult

ROOT = Path(__file__).resolve().parent.parent
LRAUV = ROOT / "tests" / "model" / "importer" / "data" / "lrauv_hydrodynamics.sdf"


def lift_drag_plugin(link: str, forward: str, upward: str, extra: str = "") -> str:
    """A LiftDrag system of the tutorial's fins on ``link``."""
    return (
        '<plugin filename="gz-sim-lift-drag-system" name="gz::sim::systems::LiftDrag">'
        "<air_density>1000</air_density><cla>4.13</cla><cla_stall>-1.1</cla_stall>"
        "<cda>0.2</cda><cda_stall>0.03</cda_stall><alpha_stall>0.17</alpha_stall><a0>0</a0>"
        f"<area>0.0244</area><upward>{upward}</upward><forward>{forward}</forward>"
        f"<link_name>{link}</link_name><cp>0 0 0</cp>{extra}</plugin>"
    )


TUTORIAL_FINS = lift_drag_plugin("vertical_fins", "-1 0 0", "0 1 0") + lift_drag_plugin(
    "horizontal_fins", "1 0 0", "0 0 1"
)


def lrauv_sdf(plugins: str = TUTORIAL_FINS) -> str:
    """The LRAUV test file with ``plugins`` in its model (before its thruster)."""
    text = LRAUV.read_text()
    at = text.index('<plugin filename="gz-sim-thruster-system"')
    return text[:at] + plugins + text[at:]


def import_lrauv(folder: Path, plugins: str = TUTORIAL_FINS) -> ImportResult:
    """Import the LRAUV with ``plugins`` into ``folder``/lrauv.urdf (and its thrusters)."""
    source = folder / "lrauv_fins.sdf"
    source.write_text(lrauv_sdf(plugins))
    return up.import_model(source, folder / "lrauv.urdf")
