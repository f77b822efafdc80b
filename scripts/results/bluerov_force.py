"""The force task on the BlueROV2 Heavy + Reach Alpha 5: metrics table and force figure."""

from _common import producer_cli
from _scenario_run import produce

if __name__ == "__main__":
    producer_cli(__doc__)
    produce(
        "bluerov_force",
        "scenarios/bluerov_alpha5_force_tracking.toml",
        "The force task on a BlueROV2 Heavy + Reach Alpha 5 (T200 thrust, Alpha 5 torques)",
        "bluerov_alpha5_force.png",
    )
