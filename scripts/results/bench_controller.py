"""The prescribed-performance controller's cost per compute: ratios to one pin.aba call."""

from __future__ import annotations

import json
import subprocess
import sys

from _common import ROOT, scratch, write_result

if __name__ == "__main__":
    out = scratch("bench_controller") / "bench_controller.json"
    command = [
        sys.executable,
        str(ROOT / "benchmarks" / "bench_controller.py"),
        "--json",
        str(out),
    ]
    print("$ " + " ".join(command[1:]), flush=True)
    printed = subprocess.run(command, cwd=ROOT, check=True, capture_output=True, text=True)
    json.loads(out.read_text())  # the benchmark wrote its results
    body = (
        "Process CPU time, best batch; the ratio to one `pin.aba` call is the number to "
        "compare across machines.\n\n```\n" + printed.stdout.strip() + "\n```\n"
    )
    write_result(
        "bench_controller",
        "Controller benchmark",
        "python scripts/results/bench_controller.py",
        body,
    )
