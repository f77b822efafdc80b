"""CPU time of a study's runs in one process, on the compiled and on the Python closed loop.

    .venv/bin/python benchmarks/bench_study.py [--study studies/paper_claims.toml] [--runs N]

Each run is what a sweep's worker does (`uvms_pin.apps.study.execute.execute_runs`: load the
scenario with the run's overrides, scale the plant, simulate, the row and its metrics); the
same runs are executed twice, with ``simulate(..., compiled_loop=True)`` (the default) and
``False``, and the process's CPU time is reported for each (not the wall time: the machine
may be shared). Dask's own cost (starting workers, scheduling) is not included.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from unittest import mock

import uvms_pin.sim.batch as batch
from uvms_pin.apps.study import load_study
from uvms_pin.apps.study.execute import execute_runs

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--study", type=Path, default=ROOT / "studies" / "paper_claims.toml")
    parser.add_argument("--runs", type=int, default=None, help="the first N runs (default all)")
    args = parser.parse_args()
    study = load_study(args.study)
    runs, base = study.runs()[: args.runs], str(study.base)
    execute_runs(base, runs[:2])  # imports, the compiled model: once per process
    simulate = batch.simulate
    seconds = {}
    for compiled in (True, False):

        def chosen(scenario, compiled=compiled, **kwargs):
            return simulate(scenario, **{**kwargs, "compiled_loop": compiled})

        with mock.patch.object(batch, "simulate", chosen):
            start = time.process_time()
            rows = execute_runs(base, runs)
            seconds[compiled] = time.process_time() - start
        ok = sum(r["status"] == "ok" for r in rows)
        label = "compiled loop" if compiled else "Python loop"
        print(f"{label}: {seconds[compiled]:.1f} s CPU for {len(rows)} runs ({ok} ok)")
    print(f"Python loop / compiled loop: {seconds[False] / seconds[True]:.2f}x")


if __name__ == "__main__":
    main()
