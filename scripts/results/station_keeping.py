"""The own-controller example of docs/getting_started.md (scripts/station_keeping/): how far
its PD lets the arm-less LBV150 drift from its station in a 0.2 m/s current, and the static offset of a PD."""

import numpy as np
import pinocchio as pin
from _common import ROOT, producer_cli, scratch, uvms_pin, write_result

import uvms_pin as up

SCENARIO = "scripts/station_keeping/station_keeping.toml"


def main() -> None:
    out = scratch("station_keeping")
    result = uvms_pin("run", SCENARIO, "--out", str(out), "--quiet")
    rollout = up.Rollout.load(out)
    params = rollout.metadata["controller"]["params"]
    station = np.array(params["target_position_world_m"])
    distance_m = np.linalg.norm(rollout.q[:, :3] - station, axis=1)
    # a PD holds a constant load F with the offset F / K_p: here drag + net buoyancy, world
    # axes, at the final pose and at rest in the current
    uvms = up.load_uvms(ROOT / "models" / "lbv150.urdf")
    current = np.array(rollout.metadata["parameters"]["water"]["current_world_m_s"])
    q_end = rollout.q[-1]
    load_body = up.bias_forces(uvms, q_end, np.zeros(uvms.nv), current)[:3]
    rotation = pin.Quaternion(q_end[3:7]).toRotationMatrix()
    offset_m = np.linalg.norm(rotation @ load_body) / params["kp_position_N_m"]
    settled = rollout.time_s > rollout.time_s[-1] / 2
    rows = [
        ("status", rollout.metadata["status"]),
        ("simulated time [s]", f"{rollout.time_s[-1]:.3f}"),
        ("largest distance from the station [cm]", f"{100 * distance_m.max():.2f}"),
        ("mean distance over the second half [cm]", f"{100 * distance_m[settled].mean():.2f}"),
        ("a PD's static offset \\|drag + net buoyancy\\| / K_p [cm]", f"{100 * offset_m:.2f}"),
    ]
    body = (
        f"`uvms-pin run {SCENARIO}` (exit code {result.returncode}), seed "
        f"{rollout.metadata['seed']}, K_p = {params['kp_position_N_m']:g} N/m:\n\n"
        "| metric | value |\n|---|---|\n" + "\n".join(f"| {k} | {v} |" for k, v in rows) + "\n"
    )
    write_result(
        "station_keeping",
        "Station keeping with your own controller (a PD, LBV150 without arm, 0.2 m/s current)",
        "python scripts/results/station_keeping.py",
        body,
    )


if __name__ == "__main__":
    producer_cli(__doc__)
    main()
