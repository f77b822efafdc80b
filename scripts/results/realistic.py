"""The realistic scenario (thrust-limited LBV150, 500 Hz): metrics table and force figure."""

from _common import producer_cli
from _scenario_run import produce

if __name__ == "__main__":
    producer_cli(__doc__)
    produce(
        "realistic",
        "scenarios/realistic_force_tracking.toml",
        "The realistic scenario (thrust-limited LBV150, 500 Hz sampled PPC)",
        "realistic_force.png",
    )
