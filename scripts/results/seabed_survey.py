"""The seabed survey: the BlueROV2 Heavy flies over a box and a rock with a multibeam
profiler, an imaging sonar, a camera and a DVL whose beams are cast at the world
(scenarios/seabed_survey.toml). The multibeam's soundings against the geometry, where the
DVL's bottom lock is lost and what the estimator does meanwhile; the figure of all four."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pinocchio as pin
from _common import DOCS, producer_cli, scratch, uvms_pin, write_result

from uvms_pin.results.estimate_metrics import estimate_errors
from uvms_pin.results.rollout import Rollout

SCENARIO = "scenarios/seabed_survey.toml"
SEABED_Z_M = -10.0
CRATE_TOP_Z_M = -7.8  # its centre at -8.9, 2.2 m high
CRATE_CENTRE_XY_M = (6.0, 0.0)
MOUNT = pin.rpy.rpyToMatrix(0.0, 1.5708, 0.0)  # the multibeam's frame in the body
CAMERA_TIME_S = 9.0


def soundings(rollout: Rollout) -> np.ndarray:
    """The multibeam's hits in the world (n, 3) [m]: each firing's beams from the vehicle's
    pose then (its origin; the fan's centre line, elevation 0)."""
    record = rollout.sonar("multibeam")
    rows = np.searchsorted(rollout.time_s, record.time_s - 1e-9)
    fan = np.column_stack(
        [np.cos(record.bearing_rad), np.sin(record.bearing_rad), np.zeros(len(record.bearing_rad))]
    )
    points = []
    for row, ranges in zip(rows, record.beam_range_m, strict=True):
        q = rollout.q[row]
        rotation = pin.Quaternion(q[3:7]).normalized().toRotationMatrix()
        heard = np.isfinite(ranges)
        directions = fan[heard] @ (rotation @ MOUNT).T
        points.append(q[:3] + ranges[heard, None] * directions)
    return np.vstack(points)


def lock_intervals(time_s: np.ndarray, lock: np.ndarray) -> list[tuple[float, float]]:
    """The intervals [first, last sample] the lock is lost over."""
    lost = np.flatnonzero(lock == 0.0)
    if len(lost) == 0:
        return []
    breaks = np.flatnonzero(np.diff(lost) > 1)
    starts = np.r_[lost[0], lost[breaks + 1]]
    stops = np.r_[lost[breaks], lost[-1]]
    return [(float(time_s[a]), float(time_s[b])) for a, b in zip(starts, stops, strict=True)]


def figure(rollout: Rollout, points: np.ndarray, errors: dict, path) -> None:
    fig, axes = plt.subplots(2, 2, figsize=(12, 8))
    ax = axes[0, 0]
    shown = ax.scatter(points[:, 0], points[:, 1], c=points[:, 2], s=3, cmap="viridis")
    fig.colorbar(shown, ax=ax, label="sounding height z [m]")
    ax.plot(rollout.q[:, 0], rollout.q[:, 1], "k-", lw=1, label="vehicle")
    ax.set(xlabel="x [m]", ylabel="y [m]", title="multibeam soundings (the crate, the rock)")
    ax.set_aspect("equal")
    ax.legend(loc="lower right")
    ax = axes[0, 1]
    dvl = rollout.signals["dvl"]
    ax.plot(rollout.time_s, dvl[:, 3], label="DVL altitude [m]")
    lost = dvl[:, 4] == 0.0
    ax.fill_between(rollout.time_s, 0, 1, where=lost, color="red", alpha=0.2,
                    transform=ax.get_xaxis_transform(), label="bottom lock lost")  # fmt: skip
    ax.set(xlabel="time [s]", ylabel="altitude [m]", title="the DVL's four beams cast at the world")
    ax.legend(loc="upper left")
    twin = ax.twinx()
    twin.plot(rollout.time_s, np.abs(errors["velocity"][:, 0]), "C1", lw=0.8,
              label="|estimate's x velocity error|")  # fmt: skip
    twin.plot(rollout.time_s, errors["velocity_sigma"][:, 0], "C1--", label="its sigma")
    twin.set(ylabel="velocity along the track [m/s]")
    twin.legend(loc="upper right")
    camera = rollout.camera("front")
    k = int(np.argmin(np.abs(camera.time_s - CAMERA_TIME_S)))
    axes[1, 0].imshow(camera.rgb[k])
    axes[1, 0].set(title=f"camera 'front' at {camera.time_s[k]:.1f} s")
    axes[1, 0].axis("off")
    fls = rollout.sonar("fls")
    j = int(np.argmin(np.abs(fls.time_s - CAMERA_TIME_S)))
    image = 10.0 * np.log10(np.maximum(fls.intensity[j], 1e-12))
    extent = [np.degrees(fls.bearing_rad[0]), np.degrees(fls.bearing_rad[-1]),
              fls.range_m[0], fls.range_m[-1]]  # fmt: skip
    axes[1, 1].imshow(image, origin="lower", aspect="auto", extent=extent, vmin=image.max() - 50,
                      cmap="copper")  # fmt: skip
    axes[1, 1].set(xlabel="bearing [deg] (port +)", ylabel="range [m]",
                   title=f"imaging sonar 'fls' at {fls.time_s[j]:.1f} s [dB]")  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main() -> None:
    producer_cli(__doc__)
    out = scratch("seabed_survey")
    result = uvms_pin("run", SCENARIO, "--out", str(out / "run"), "--quiet")
    rollout = Rollout.load(out / "run")
    points = soundings(rollout)
    flat = np.hypot(points[:, 0] - CRATE_CENTRE_XY_M[0], points[:, 1]) > 2.5
    flat &= np.abs(points[:, 2] - SEABED_Z_M) < 0.5  # off the crate, not on the rock
    on_crate = np.abs(points[:, 2] - CRATE_TOP_Z_M) < 0.5
    errors = estimate_errors(rollout)
    sigma_m_s = errors["velocity_sigma"][:, 0]  # along the track
    dvl = rollout.signals["dvl"]
    lost = lock_intervals(rollout.time_s, dvl[:, 4])
    figure(rollout, points, errors, DOCS / "seabed_survey.png")
    rows = [
        "| quantity | value |",
        "|---|---|",
        f"| multibeam soundings | {len(points)} |",
        f"| seabed soundings off the objects: mean height [m] (true {SEABED_Z_M}) | "
        f"{points[flat, 2].mean():.3f} |",
        f"| their standard deviation [m] (range noise 0.02 m) | {points[flat, 2].std():.3f} |",
        f"| soundings on the crate's top: mean height [m] (true {CRATE_TOP_Z_M}) | "
        f"{points[on_crate, 2].mean():.3f} ({on_crate.sum()} soundings) |",
        "| DVL bottom lock lost over [s] | "
        + ", ".join(f"{a:.2f} to {b:.2f}" for a, b in lost)
        + " |",
        f"| samples with bottom lock | {dvl[:, 4].mean():.3f} |",
    ]
    for a, b in lost:
        before = sigma_m_s[np.searchsorted(rollout.time_s, a) - 1]
        after = sigma_m_s[np.searchsorted(rollout.time_s, b)]
        rows.append(
            "| estimate's sigma of the velocity along the track before the lock is lost, "
            f"at its last lost sample [m/s] | {before:.4f}, {after:.4f} |"
        )
    body = (
        f"`uvms-pin run {SCENARIO}` (exit code {result.returncode}):\n\n"
        + "\n".join(rows)
        + "\n\n![the seabed survey](../seabed_survey.png)\n"
    )
    write_result(
        "seabed_survey", "A seabed survey: multibeam, sonar, camera and a beam-cast DVL",
        "python scripts/results/seabed_survey.py", body,
    )  # fmt: skip


if __name__ == "__main__":
    main()
