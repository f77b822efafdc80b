"""The controller comparison: the realistic task with the PPC, the three baselines and MPC,
nominal and over the robustness set."""

from _common import producer_cli, publish_figure, scratch, uvms_pin, write_result

CONTROLLERS = "ppc,pi_force,impedance,computed_torque,mpc"

if __name__ == "__main__":
    producer_cli(__doc__)
    out = scratch("compare_controllers")
    args = (
        "compare-controllers",
        "scenarios/realistic_force_tracking.toml",
        "--controllers",
        CONTROLLERS,
    )
    uvms_pin(*args, "--robustness", "--jobs", "2", "--out", str(out), "--quiet")
    publish_figure(out / "controllers_force.png", "controllers_force.png")
    body = (
        f"`uvms-pin {' '.join(args)}`:\n\n"
        + (out / "controllers.md").read_text()
        + "\n![force tracking per controller](../controllers_force.png)\n"
        + "\nWith `--robustness --jobs 2`: force error RMS after the transient per case, and "
        + "whether the task held (stopped: a funnel of the PPC broke):\n\n"
        + (out / "robustness.md").read_text()
    )
    write_result(
        "compare_controllers",
        "The PPC against baseline controllers",
        "python scripts/results/compare_controllers.py",
        body,
    )
