"""uvms-pin side by side with MuJoCo on the same UVMS: ratios only."""

from __future__ import annotations

import subprocess
import sys

from _common import ROOT, producer_cli, scratch, write_result

if __name__ == "__main__":
    producer_cli(__doc__)
    out = scratch("bench_mujoco") / "mujoco.md"
    command = [sys.executable, str(ROOT / "benchmarks" / "bench_mujoco.py"), "--out", str(out)]
    print("$ " + " ".join(command[1:]), flush=True)
    subprocess.run(command, cwd=ROOT, check=True)
    body = (
        "Timed in one process (CPU time, best of interleaved rounds); ratios to one `pin.aba` "
        "call on the same model or to MuJoCo doing the same job.\n\n" + out.read_text()
    )
    write_result(
        "bench_mujoco", "uvms-pin vs MuJoCo", "python scripts/results/bench_mujoco.py", body
    )
