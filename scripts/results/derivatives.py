"""The cost of the derivatives of the underwater dynamics and of one MPC re-plan: ratios."""

from __future__ import annotations

import subprocess
import sys

from _common import ROOT, producer_cli, scratch, write_result

if __name__ == "__main__":
    producer_cli(__doc__)
    out = scratch("derivatives") / "derivatives.md"
    command = [sys.executable, str(ROOT / "benchmarks" / "bench_derivatives.py"), "--out", str(out)]
    print("$ " + " ".join(command[1:]), flush=True)
    subprocess.run(command, cwd=ROOT, check=True)
    body = (
        "Timed in one process (CPU time, best of interleaved rounds, one BLAS thread) on the "
        "reference model in a 0.3 m/s current; ratios to one rigid-body `pin.aba` call timed "
        "in the same run (benchmarks/bench_derivatives.py).\n\n" + out.read_text()
    )
    write_result(
        "derivatives",
        "Derivatives of the underwater dynamics: cost",
        "python scripts/results/derivatives.py",
        body,
    )
