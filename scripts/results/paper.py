"""The paper's scenario, literally: metrics table and force figure."""

from _common import producer_cli
from _scenario_run import produce

if __name__ == "__main__":
    producer_cli(__doc__)
    produce(
        "paper",
        "scenarios/paper_force_tracking.toml",
        "The paper's scenario (continuous-time PPC, unlimited actuation)",
        "paper_force.png",
    )
