"""The arm comparison: the realistic task with every catalogue arm (table and figure)."""

from _common import producer_cli, publish_figure, scratch, uvms_pin, write_result

ARMS = "reference,so100,z1,kinova,ur3,ur5,ur10,panda,xarm7"

if __name__ == "__main__":
    producer_cli(__doc__)
    out = scratch("compare_arms")
    args = ("compare-arms", "scenarios/realistic_force_tracking.toml", "--arms", ARMS)
    uvms_pin(*args, "--out", str(out), "--jobs", "1")
    publish_figure(out / "comparison.png", "arm_comparison.png")
    body = (
        f"`uvms-pin {' '.join(args)}`:\n\n"
        + (out / "comparison.md").read_text()
        + "\n![arm comparison](../arm_comparison.png)\n"
    )
    write_result(
        "compare_arms",
        "Other arms on the same task",
        "python scripts/results/compare_arms.py",
        body,
    )
