"""The dynamics benchmark: costs as ratios to one rigid-body pin.aba call."""

from __future__ import annotations

import json
import subprocess
import sys

from _common import ROOT, scratch, write_result

if __name__ == "__main__":
    out = scratch("bench") / "bench.json"
    command = [sys.executable, str(ROOT / "benchmarks" / "bench_dynamics.py"), "--json", str(out)]
    print("$ " + " ".join(command[1:]), flush=True)
    printed = subprocess.run(command, cwd=ROOT, check=True, capture_output=True, text=True)
    body = (
        "Timed in one process; the ratios are the numbers to compare across machines "
        "(absolute times depend on the machine and its load).\n\n```\n"
        + printed.stdout.strip()
        + "\n```\n"
    )
    json.loads(out.read_text())  # the benchmark wrote its table
    write_result("bench", "Dynamics benchmark", "python scripts/results/bench.py", body)
