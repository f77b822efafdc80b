"""The Hinsdale 2023 pool trials against the simulator: per-trial table and two figures."""

from __future__ import annotations

import csv
import json

from _common import producer_cli, publish_figure, scratch, uvms_pin, write_result

FIGURES = ("_alt_011-2", "_alt_002-0")  # docs/validation.md shows these two

if __name__ == "__main__":
    producer_cli(__doc__)
    out = scratch("pool_validation")
    uvms_pin("validate", "pool", "data/hinsdale2023", "--out", str(out))
    summary = json.loads((out / "pool_validation.json").read_text())
    with (out / "pool_validation.csv").open() as f:
        rows = list(csv.DictReader(f))
    columns = list(rows[0])
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(row[c] for c in columns) + " |" for row in rows]
    body = (
        "`uvms-pin validate pool data/hinsdale2023 --out out/results/pool_validation` "
        f"(RMSE in deg): mean roll {summary['mean_roll_rmse_deg']:.2f}, mean pitch "
        f"{summary['mean_pitch_rmse_deg']:.2f}.\n\n" + "\n".join(lines) + "\n"
    )
    for trial in FIGURES:
        publish_figure(out / f"{trial}.png", f"pool{trial}.png")
    write_result(
        "pool_validation",
        "Pool trials: BlueROV2 Heavy + Alpha 5",
        "python scripts/results/pool_validation.py",
        body,
    )
