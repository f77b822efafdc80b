"""perception.png: what a run's cameras and sonars saw, one band of the figure per sensor.

- a camera: its colour image and its z-depth at four firings evenly spread over the run (the
  first and the last included), the depth on one colour scale for all four, from the nearest
  to the 98th percentile (white: nothing met);
- an imaging sonar: its intensity [dB] at the same four instants, range up, bearing across
  (port to the left, as a sonar display), on one dB scale (50 dB below the brightest echo);
- a multibeam: its swath over the run, each beam's detected range (white: heard nothing)
  against time and bearing;
- an altimeter (any sonar of one beam): its echogram, the echo at each range over time [dB],
  its reading drawn on it (an altimeter's, a multibeam's), the range axis up to twice the
  farthest reading; titled with its type.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from uvms_pin.results.figures.standard import mark_stop, save_figure
from uvms_pin.results.perception import camera_record, sonar_record
from uvms_pin.results.rollout_data import RolloutData

PERCEPTION_FIGURE = "perception.png"
#: firings shown of a camera or an imaging sonar
SNAPSHOTS = 4
#: the dB range shown below a sonar's brightest echo
SONAR_DB_RANGE = 50.0


def snapshot_rows(count: int, shown: int = SNAPSHOTS) -> np.ndarray:
    """The firings shown of ``count``: ``shown`` evenly spread, the first and the last
    included (every firing when there are fewer)."""
    return np.unique(np.round(np.linspace(0, count - 1, min(shown, count))).astype(int))


def decibels(intensity: np.ndarray) -> tuple[np.ndarray, float, float]:
    """10 log10 of ``intensity`` (zero at 1e-30) and the scale shown: from `SONAR_DB_RANGE`
    below the brightest echo to it."""
    db = 10.0 * np.log10(np.maximum(intensity, 1e-30))
    top = float(db.max()) if np.any(intensity > 0.0) else 0.0
    return db, top - SONAR_DB_RANGE, top


def edges(centres: np.ndarray, spacing: float) -> tuple[float, float]:
    """The outer edges of cells centred on the sorted ``centres``, ``spacing`` apart when
    there is a single one (an image's extent: each cell drawn about its own value)."""
    step = float(centres[1] - centres[0]) if len(centres) > 1 else spacing
    return float(centres[0]) - 0.5 * step, float(centres[-1]) + 0.5 * step


def _bands(rollout: RolloutData) -> list[tuple[str, str, int]]:
    """(name, kind, rows of the figure) of each sensor, in the scenario's order."""
    out = []
    for name, about in (rollout.metadata.get("perception") or {}).items():
        if name not in rollout.perception:
            continue
        kind = about.get("kind")
        if kind == "camera":
            out.append((name, "camera", 2))
        else:
            out.append((name, "sonar", 1))
    return out


def plot_perception(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """What each camera and sonar of ``rollout`` saw (see the module)."""
    bands = _bands(rollout)
    rows = sum(r for _, _, r in bands)
    fig = Figure(figsize=(3.2 * SNAPSHOTS + 1.2, 2.7 * rows + 0.6))
    grid = fig.add_gridspec(rows, SNAPSHOTS + 1, width_ratios=[1.0] * SNAPSHOTS + [0.06])
    row, over_time = 0, []  # the axes with time along x (a stopped run's stop drawn there)
    for name, kind, height in bands:
        if kind == "camera":
            _camera(fig, grid, row, rollout, name)
        else:
            over_time += _sonar(fig, grid, row, rollout, name)
        row += height
    mark_stop(
        fig, over_time, rollout, f"{rollout.metadata.get('scenario', '')}: cameras and sonars"
    )
    return save_figure(fig, path)


def _camera(fig: Figure, grid, row: int, rollout: RolloutData, name: str) -> None:
    record = camera_record(rollout.perception, rollout.metadata, name)
    shown = snapshot_rows(len(record.time_s))
    depth = record.depth_m[shown]
    finite = depth[np.isfinite(depth)]
    # up to the 98th percentile: a few grazing rays meeting the surface hundreds of metres
    # away would otherwise leave everything near in one colour
    low, high = (float(finite.min()), float(np.percentile(finite, 98))) if finite.size else (0, 1)
    image = None
    for column, k in enumerate(shown):
        ax = fig.add_subplot(grid[row, column])
        ax.imshow(record.rgb[k])
        ax.set_title(f"camera '{name}', t = {record.time_s[k]:.2f} s", fontsize=8)
        ax.axis("off")
        ax = fig.add_subplot(grid[row + 1, column])
        image = ax.imshow(np.ma.masked_invalid(depth[column]), vmin=low, vmax=high, cmap="viridis")
        ax.set_title("z-depth", fontsize=8)
        ax.axis("off")
        if not np.any(np.isfinite(depth[column])):  # open water: not a blank to puzzle over
            ax.text(0.5, 0.5, "nothing in view", ha="center", va="center",
                    transform=ax.transAxes, fontsize=8, color="0.4")  # fmt: skip
    fig.colorbar(image, cax=fig.add_subplot(grid[row + 1, SNAPSHOTS]), label="z-depth [m]")


def _sonar(fig: Figure, grid, row: int, rollout: RolloutData, name: str) -> list:
    """The sonar's band; the axes drawn with time along x (none for an imaging sonar)."""
    record = sonar_record(rollout.perception, rollout.metadata, name)
    period_s = 1.0 / float(rollout.metadata["perception"][name]["rate_hz"])
    times = edges(record.time_s, period_s)
    bearings = edges(np.degrees(record.bearing_rad), 1.0)
    ranges = edges(record.range_m, 1.0)
    if record.intensity.shape[2] == 1:  # one beam (an altimeter's): its echogram over time
        kind = rollout.metadata["perception"][name]["spec"]["type"]
        return [_echogram(fig, grid, row, f"{kind} '{name}'", record, times, ranges)]
    if record.beam_range_m is not None:  # a multibeam: its swath over the run
        ax = fig.add_subplot(grid[row, :SNAPSHOTS])
        swath = np.ma.masked_invalid(record.beam_range_m.T)
        extent = [*times, *bearings]
        image = ax.imshow(swath, origin="lower", aspect="auto", extent=extent, cmap="viridis",
                          interpolation="nearest")  # fmt: skip
        ax.set(xlabel="time [s]", ylabel="bearing [deg]", title=f"multibeam '{name}': detections")
        fig.colorbar(image, cax=fig.add_subplot(grid[row, SNAPSHOTS]), label="range [m]")
        return [ax]
    db, low, high = decibels(record.intensity)
    # port (positive bearing) on the left, as a sonar display shows it
    extent = [bearings[1], bearings[0], *ranges]
    for column, k in enumerate(snapshot_rows(len(record.time_s))):
        ax = fig.add_subplot(grid[row, column])
        image = ax.imshow(db[k][:, ::-1], origin="lower", aspect="auto", extent=extent,
                          vmin=low, vmax=high, cmap="copper")  # fmt: skip
        ax.set(xlabel="bearing [deg] (port +)", ylabel="range [m]" if column == 0 else None)
        ax.set_title(f"sonar '{name}', t = {record.time_s[k]:.2f} s", fontsize=8)
    fig.colorbar(image, cax=fig.add_subplot(grid[row, SNAPSHOTS]), label="echo [dB]")
    return []


def _echogram(fig: Figure, grid, row: int, title: str, record, times, ranges):
    """A one-beam sonar's echogram (echo [dB] by range over time) with its reading (an
    altimeter's, a one-beam multibeam's), the range axis up to twice its farthest reading
    (the water column beyond is empty); ``title``: its type and name."""
    ax = fig.add_subplot(grid[row, :SNAPSHOTS])
    db, low, high = decibels(record.intensity)
    image = ax.imshow(db[:, :, 0].T, origin="lower", aspect="auto", extent=[*times, *ranges],
                      vmin=low, vmax=high, cmap="copper", interpolation="nearest")  # fmt: skip
    reading = None if record.beam_range_m is None else record.beam_range_m[:, 0]
    if reading is not None and np.any(np.isfinite(reading)):
        ax.plot(record.time_s, reading, color="tab:cyan", lw=1.0, label="reading")
        ax.legend(loc="upper right", fontsize=8)
        ax.set_ylim(ranges[0], min(ranges[1], 2.0 * float(np.nanmax(reading))))
    elif not np.any(record.intensity):  # nothing within its range: not a black puzzle
        ax.text(0.5, 0.5, f"no echo within {ranges[1]:.3g} m", ha="center", va="center",
                transform=ax.transAxes, fontsize=9, color="0.7")  # fmt: skip
    ax.set(xlabel="time [s]", ylabel="range [m]", title=f"{title}: echogram")
    fig.colorbar(image, cax=fig.add_subplot(grid[row, SNAPSHOTS]), label="echo [dB]")
    return ax


def perception_figures(rollout: RolloutData, directory: Path) -> list[Path]:
    """perception.png when the run had cameras or sonars that fired."""
    if not _bands(rollout):
        return []
    return [plot_perception(rollout, Path(directory) / PERCEPTION_FIGURE)]
