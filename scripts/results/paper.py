"""The paper's scenario, literally: metrics table and force figure; and the same with noise
drawn every 10 ms (not rate-bounded), where the funnel breaks whatever the integrator."""

from _common import ROOT, producer_cli
from _scenario_run import produce

import uvms_pin as up

SCENARIO = "scenarios/paper_force_tracking.toml"


def fast_noise_exits() -> str:
    """When f_x leaves its funnel with a new noise draw every 10 ms, by integrator and
    tolerance (the same time: the closed loop, not the integrator)."""
    rows = ["| integrator | rtol | funnel left at t [s] | by |", "|---|---|---|---|"]
    for method in ("LSODA", "Radau"):
        for rtol in (1e-6, 1e-8):
            overrides = {
                "sensors.sample_period_s": 0.01,
                "integrator.method": method,
                "integrator.rtol": rtol,
            }
            try:
                up.simulate(up.load_scenario(ROOT / SCENARIO, overrides), progress=False)
                rows.append(f"| {method} | {rtol:g} | never | |")
            except up.FunnelViolation as exc:
                rows.append(f"| {method} | {rtol:g} | {exc.time_s:.4f} | {exc.component} |")
    return (
        "\nThe same scenario with a new noise draw every 10 ms "
        '(`"sensors.sample_period_s": 0.01`):\n\n' + "\n".join(rows) + "\n"
    )


if __name__ == "__main__":
    producer_cli(__doc__)
    produce(
        "paper",
        SCENARIO,
        "The paper's scenario (continuous-time PPC, unlimited actuation)",
        "paper_force.png",
        replay=True,
        extra=fast_noise_exits(),
    )
