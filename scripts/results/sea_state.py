"""The realistic task under a JONSWAP sea (Hs 0.5 m, Tp 5 s, 2 m deep): metrics, force and
flow figures."""

from _common import SCRATCH, producer_cli, publish_figure
from _scenario_run import produce

if __name__ == "__main__":
    producer_cli(__doc__)
    produce(
        "sea_state",
        "scenarios/sea_state_force_tracking.toml",
        "The realistic task under a sea state (JONSWAP Hs 0.5 m, Tp 5 s, LBV150 at 2 m)",
        "sea_state_force.png",
    )
    publish_figure(SCRATCH / "sea_state" / "flow.png", "sea_state_flow.png")
