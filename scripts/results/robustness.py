"""The robustness table of the realistic design (scripts/robustness_table.py --paper-gains)."""

from __future__ import annotations

import json
import subprocess
import sys

from _common import ROOT, producer_cli, scratch, write_result

if __name__ == "__main__":
    producer_cli(__doc__)
    out = scratch("robustness")
    command = [
        sys.executable,
        str(ROOT / "scripts" / "robustness_table.py"),
        "--paper-gains",
        "--jobs",
        "2",
        "--out",
        str(out),
    ]
    print("$ " + " ".join(command[1:]), flush=True)
    subprocess.run(command, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    rows = json.loads((out / "robustness.json").read_text())
    held = [r["case"] for r in rows if r["holds"]]
    body = (
        "Each row: one 10 s run of `scenarios/realistic_force_tracking.toml` (same gains) with "
        "one change. For a run that stopped, the margins are those of the samples logged "
        "before the stop and no force RMS is given.\n\n"
        + (out / "robustness.md").read_text()
        + f"\nFunnels held in {len(held)} of {len(rows)} cases: {', '.join(held)}.\n"
    )
    write_result(
        "robustness",
        "Robustness of the realistic design",
        "python scripts/results/robustness.py",
        body,
    )
