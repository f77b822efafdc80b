"""The comparison's files: ``comparison.csv``, ``comparison.md`` (and the figure).

Numbers are written with 4 significant digits; a number an arm never got (NaN) is an
empty cell. The Markdown table leaves out the long columns (why, dry links): they follow
as notes per arm; and the columns of a kind of task no arm has a value of (a tracking
task's table has no force column, `TASK_COLUMNS`).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

from uvms_pin.apps.arms.figure import comparison_figure
from uvms_pin.apps.arms.row import COLUMNS, TASK_COLUMNS, has_values
from uvms_pin.apps.arms.settings import CompareSettings
from uvms_pin.model.mount.catalog import UPSIDE_DOWN
from uvms_pin.results.atomic import write_text_atomic
from uvms_pin.results.format import cell_text


def write_comparison(
    rows: list[dict], out_dir: Path, *, scenario: str = "", settings: CompareSettings | None = None
) -> list[Path]:
    """``comparison.csv``, ``comparison.md`` and ``comparison.png`` (atomically)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_text_atomic(out / "comparison.csv", _csv_text(rows))
    write_text_atomic(out / "comparison.md", _markdown(rows, scenario, settings))
    return [out / "comparison.csv", out / "comparison.md", comparison_figure(rows, out)]


def _csv_text(rows: list[dict]) -> str:
    """Every column of `COLUMNS`, headed by its key."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([key for key, _ in COLUMNS])
    for row in rows:
        writer.writerow([cell_text(row.get(key, "")) for key, _ in COLUMNS])
    return buffer.getvalue()


def _markdown(rows: list[dict], scenario: str, settings: CompareSettings | None) -> str:
    """The title, the settings, the table and the notes per arm."""
    unused = {key for keys in TASK_COLUMNS.values() for key in keys if not has_values(rows, key)}
    table_cols = [c for c in COLUMNS if c[0] not in ("reason", "dry_links", *unused)]
    lines = [
        f"# Arm comparison: {scenario}",
        "",
        "Same vehicle, same task, same vehicle controller; the arm part of the controller is "
        "adapted to each arm's joint count (see `uvms_pin.apps.arms.compare`).",
    ]
    if settings is not None:
        lines.append(_settings_line(settings, rows))
    lines += [
        "",
        "| " + " | ".join(label for _, label in table_cols) + " |",
        "|" + "---|" * len(table_cols),
    ]
    for row in rows:
        lines.append("| " + " | ".join(cell_text(row.get(k, "")) for k, _ in table_cols) + " |")
    lines += ["", "## Notes per arm", ""]
    lines += _notes(rows)
    return "\n".join(lines) + "\n"


def _mount_text(settings: CompareSettings, rows: list[dict]) -> str:
    """The arms' mount orientation: the comparison's, the one they share, or each one's."""
    if settings.mount_rpy is not None:
        return f"mount rpy {_rpy_text(settings.mount_rpy)} rad"
    mounted = {row["arm"]: row["mount_rpy"] for row in rows if row.get("mount_rpy") is not None}
    if len(set(mounted.values())) <= 1:
        shared = next(iter(mounted.values()), UPSIDE_DOWN)
        return f"mount rpy {_rpy_text(shared)} rad"
    each = ", ".join(f"{arm} {_rpy_text(rpy)}" for arm, rpy in mounted.items())
    return f"mount rpy each arm's own [rad]: {each}"


def _rpy_text(rpy) -> str:
    return str(tuple(round(float(x), 4) for x in rpy))


def _settings_line(settings: CompareSettings, rows: list[dict]) -> str:
    """Duration, mount orientation and trim of the comparison, in one sentence."""
    trim = (
        "none"
        if settings.trim is None
        else (
            f"foam {settings.trim.foam_density_kg_m3:g} kg/m^3 on top, lead ballast below, "
            f"target BG {settings.trim.bg_m * 100:g} cm"
        )
    )
    return (
        f"Duration: {f'{settings.duration_s:g} s' if settings.duration_s else 'as in the scenario'}; "
        f"{_mount_text(settings, rows)}; trim: {trim}."
    )


def _notes(rows: list[dict]) -> list[str]:
    """Per arm: why it ended as it did ("completed" if nothing to say), and its dry links."""
    lines = []
    for row in rows:
        note = row.get("reason") or "completed"
        dry = row.get("dry_links")
        if dry:
            note += f" (links with mass but no geometry, no buoyancy: {dry})"
        lines.append(f"- **{row['arm']}** ({row['status']}): {note}")
    return lines
