"""The comparison table as CSV and Markdown."""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any

from uvms_pin.apps.compare.metrics import COLUMNS
from uvms_pin.results.atomic import write_text_atomic

__all__ = ["markdown_table", "write_table"]


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return "-" if math.isnan(value) else f"{value:.4g}"
    return str(value)


def markdown_table(rows: list[dict[str, Any]], columns: tuple[str, ...] = COLUMNS) -> str:
    """One line per controller, the ``columns`` (`COLUMNS` by default; NaN shown as '-')."""
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for row in rows:
        cells = [_text(row[c]).replace("|", "/") for c in columns]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_table(
    rows: list[dict[str, Any]], out: Path, header: str, columns: tuple[str, ...] = COLUMNS
) -> list[Path]:
    """``controllers.csv`` and ``controllers.md`` (``header`` above the Markdown table)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, extrasaction="ignore")
    writer.writeheader()
    writer.writerows(rows)
    return [
        write_text_atomic(out / "controllers.csv", buffer.getvalue()),
        write_text_atomic(out / "controllers.md", header + "\n\n" + markdown_table(rows, columns)),
    ]
