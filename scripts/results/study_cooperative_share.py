"""The cooperative_share study (9 runs of the 24 s cooperative transport: the follower's
load share x the bar's density): its report's summary and every run's transport metrics."""

import math
import tomllib

import pandas as pd
from _common import ROOT, producer_cli
from _study import produce

from uvms_pin.model.uvms import DEFAULT_WATER_DENSITY_KG_M3

SHARE = "robots[1].controller.load_share"
DENSITY = "world.objects[0].density_kg_m3"
GRAVITY_M_S2 = 9.81  # Pinocchio's model.gravity


def _bar_and_water() -> tuple[float, float]:
    """(the bar's volume [m^3], the water's density [kg/m^3]) of the base scenario."""
    scenario = tomllib.loads((ROOT / "scenarios" / "cooperative_transport.toml").read_text())
    bar = scenario["world"]["objects"][0]
    volume = math.pi * bar["radius_m"] ** 2 * bar["length_m"]
    return volume, scenario["water"].get("density_kg_m3", DEFAULT_WATER_DENSITY_KG_M3)


COLUMNS = {
    "alpha/bar_delivered": "delivered (within 5 cm)",
    "alpha/bar_final_distance_m": "bar's final distance to the path's end [m]",
    "bar/final_z_m": "bar's final z [m]",
    "alpha/bar_tracking_error_rms_m": "bar's tracking error, rms [m]",
    "bravo/funnel_kept": "follower's estimate in its funnel",
    "bravo/estimate_xi_max": "follower's largest abs(xi)",
    "bar/max_speed_m_s": "bar's top speed [m/s]",
}


def runs(table: pd.DataFrame) -> str:
    """Every run: its share, its bar's net weight and what the transport did."""
    rows = table.sort_values([SHARE, DENSITY])
    volume_m3, water_kg_m3 = _bar_and_water()
    out = pd.DataFrame(
        {
            "follower's share c_f (c_l = 0.5)": rows[SHARE],
            "bar density [kg/m^3]": rows[DENSITY],
            "net weight [N] (believed 3.37)": (rows[DENSITY] - water_kg_m3)
            * volume_m3
            * GRAVITY_M_S2,
            **{label: rows[column] for column, label in COLUMNS.items()},
        }
    )
    formats = {"bar density [kg/m^3]": "{:.0f}", "delivered (within 5 cm)": "{:.0f}"}
    header = "| " + " | ".join(out.columns) + " |\n|" + "---|" * len(out.columns)
    lines = [
        "| "
        + " | ".join(
            formats.get(c, "{:.3g}").format(v) for c, v in zip(out.columns, row, strict=True)
        )
        + " |"
        for row in out.to_numpy()
    ]
    return "## Every run\n\n" + header + "\n" + "\n".join(lines) + "\n"


if __name__ == "__main__":
    producer_cli(__doc__)
    produce(
        "study_cooperative_share",
        "studies/cooperative_share.toml",
        "Study: the cooperative transport when the team's load share or the bar's weight is wrong",
        runs,
    )
