"""The paper's scenario, literally: metrics table and force figure."""

from _scenario_run import produce

if __name__ == "__main__":
    produce(
        "paper",
        "scenarios/paper_force_tracking.toml",
        "The paper's scenario (continuous-time PPC, unlimited actuation)",
        "paper_force.png",
    )
