"""The Gymnasium environments' step rate: steps per second and pin.aba calls per step."""

from __future__ import annotations

import json
import subprocess
import sys

from _common import ROOT, scratch, write_result

if __name__ == "__main__":
    out = scratch("bench_gym") / "bench_gym.json"
    command = [
        sys.executable,
        str(ROOT / "benchmarks" / "bench_gym.py"),
        "--steps",
        "500",
        "--json",
        str(out),
    ]
    print("$ " + " ".join(command[1:]), flush=True)
    printed = subprocess.run(command, cwd=ROOT, check=True, capture_output=True, text=True)
    json.loads(out.read_text())  # the benchmark wrote its results
    body = (
        "Process CPU time; the ratio to one `pin.aba` call is the number to compare across "
        "machines.\n\n```\n" + printed.stdout.strip() + "\n```\n"
    )
    write_result("bench_gym", "Gymnasium step rate", "python scripts/results/bench_gym.py", body)
