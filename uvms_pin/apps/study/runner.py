"""Run a study on local processes or ``dask.distributed`` into one Parquet table, resumably.

Layout of an output directory::

    study.toml          a copy of the study file (what was asked)
    study_inputs.json   the study settings and the digests of its base scenario and model
    results.parquet     THE table: one row per finished run, sorted by run index
    parts/<id>.parquet  rows finished since the last compaction (one file per run)
    rollouts/<id>/      rollouts, only with keep_rollouts

Every file is written to a temporary name and renamed (atomic on POSIX), so a crash or
Ctrl-C leaves the table as it was at its last compaction plus whole part files. On start
the table and the part files are merged (deduplicated by run id) and the recorded runs
are skipped: a rerun finishes the study without repeating or losing a run.

A row holds the run id, index, sample, seed, every parameter value (column = its path),
status (``ok``, ``FunnelViolation``, ``diverged`` for any other `SimulationError`,
``error`` for any other exception, with ``error`` the message), the violation's level,
component and time, derived quantities (net buoyancy, initial orientation error, actuator
saturation), every metric of `Rollout.metrics`, the run's wall time and host.
"""

from __future__ import annotations

import logging
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

# the runs as they execute on a worker (re-exported: part of the runner's interface)
from uvms_pin.apps.study.execute import (
    RUNS_PER_TASK,
    base_row,
    error_row,
    execute_run,
    execute_runs,
    rollout_quantities,
)
from uvms_pin.apps.study.identity import check_same_study, file_sha256, record_study_inputs
from uvms_pin.apps.study.spec import Run, Study
from uvms_pin.apps.workers import stop_pool, workers_signals
from uvms_pin.checks import check_memory
from uvms_pin.errors import StudyError
from uvms_pin.results.atomic import atomic_path

__all__ = [
    "STATUSES",
    "ResultStore",
    "Summary",
    "base_row",
    "error_row",
    "execute_run",
    "execute_runs",
    "load_results",
    "rollout_quantities",
    "run_study",
]

RESULTS_FILE = "results.parquet"
PARTS_DIR = "parts"
ROLLOUTS_DIR = "rollouts"
STATUSES = ("ok", "FunnelViolation", "diverged", "error")

RunFunction = Callable[[str, Run, "str | None"], dict[str, Any]]
BatchFunction = Callable[[str, list[Run], "str | None"], list[dict[str, Any]]]


# ---- the table -----------------------------------------------------------------------------


def _atomic_parquet(frame: pd.DataFrame, path: Path) -> None:
    with atomic_path(path) as tmp:
        frame.to_parquet(tmp, index=False)


#: memory of a table read into pandas per byte of its columns in the file (uncompressed):
#: the columns, their object strings and the copies concat and sorting make
_TABLE_EXPANSION = 4


def _read_parquet(path: Path) -> pd.DataFrame:
    import pyarrow.parquet as pq

    try:
        metadata = pq.ParquetFile(path).metadata
        size = sum(metadata.row_group(k).total_byte_size for k in range(metadata.num_row_groups))
        check_memory(
            _TABLE_EXPANSION * size,
            f"{path} ({metadata.num_rows} rows, {metadata.num_columns} columns) read into memory",
            "report on a machine with more memory, or split the study",
            StudyError,
        )
        return pd.read_parquet(path)
    except StudyError:
        raise
    except Exception as exc:  # pyarrow raises several types for a damaged file
        raise StudyError(
            f"{path}: not a readable Parquet table ({type(exc).__name__}: {exc}); "
            "it was not written by uvms-pin or was damaged: move it away and rerun"
        ) from exc


class ResultStore:
    """The rows of one output directory: the compacted table plus one part file per run."""

    def __init__(self, out: str | Path):
        self.out = Path(out)
        self.table_path = self.out / RESULTS_FILE
        self.parts = self.out / PARTS_DIR
        self.parts.mkdir(parents=True, exist_ok=True)
        for stale in self.parts.glob(".*.tmp"):  # an interrupted write, never renamed
            stale.unlink()

    def _part_files(self) -> list[Path]:
        return sorted(self.parts.glob("*.parquet"))

    def load(self) -> pd.DataFrame:
        """Every recorded row (table and parts), one per run id, sorted by run index."""
        frames = []
        if self.table_path.is_file():
            frames.append(_read_parquet(self.table_path))
        frames += [_read_parquet(p) for p in self._part_files()]
        frames = [f for f in frames if len(f)]
        if not frames:
            return pd.DataFrame()
        table = pd.concat(frames, ignore_index=True)
        # a part is newer than the table (a retried run, or a crash before its unlink)
        table = table.drop_duplicates("run_id", keep="last")
        return table.sort_values("run_index", kind="stable").reset_index(drop=True)

    def record(self, rows: dict[str, Any] | list[dict[str, Any]]) -> None:
        """Durably add one row, or the rows of one task together (a part file named after
        the first one's run id: one write for a task's runs)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        rows = [rows] if isinstance(rows, dict) else rows
        # straight to Arrow: the table pandas would write (every row's columns in order of
        # appearance, a missing value null), without its per-column conversion (a task's
        # part is written while the workers run)
        names = dict.fromkeys(name for row in rows for name in row)
        columns = {name: [row.get(name) for row in rows] for name in names}
        with atomic_path(self.parts / f"{rows[0]['run_id']}.parquet") as tmp:
            pq.write_table(pa.Table.from_pydict(columns), tmp)

    def compact(self) -> pd.DataFrame:
        """Rewrite the table with every row, atomically; then drop the merged parts."""
        parts = self._part_files()
        table = self.load()
        if parts or not self.table_path.is_file():
            _atomic_parquet(table, self.table_path)
            for p in parts:
                p.unlink()
        return table


def load_results(out: str | Path) -> pd.DataFrame:
    """The study table of an output directory (parts not yet compacted included)."""
    out = Path(out)
    if not (out / RESULTS_FILE).is_file() and not (out / PARTS_DIR).is_dir():
        raise StudyError(f"{out}: no {RESULTS_FILE}: not a study output directory")
    return ResultStore(out).load()


# ---- the study -----------------------------------------------------------------------------


class Summary(dict):
    """Counts of a sweep: total, skipped (already recorded), run now, and per status."""


#: the only interface a local cluster listens on
LOOPBACK = "127.0.0.1"


def _client(workers: int | None, scheduler: str | None):
    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            return Client(scheduler, timeout=30), None
        except (OSError, TimeoutError, ValueError) as exc:
            raise StudyError(
                f"--scheduler {scheduler}: cannot connect ({type(exc).__name__}: {exc}); "
                "is the scheduler running at that address?"
            ) from exc
    with workers_signals():
        # every server of the local cluster (scheduler, workers, dashboard) on the loopback
        # interface: nothing of a study listens on the network (docs/security.md)
        cluster = LocalCluster(
            n_workers=workers or os.cpu_count() or 1,
            threads_per_worker=1,
            processes=True,
            host=LOOPBACK,
            dashboard_address=f"{LOOPBACK}:0",
            silence_logs=logging.ERROR,
        )
    return Client(cluster), cluster


def run_study(
    study: Study,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    keep_rollouts: bool = False,
    progress: bool = True,
    retry_errors: bool = False,
    compact_every: int = 100,
    compact_interval_s: float = 60.0,
    run_fn: RunFunction = execute_run,
    on_result: Callable[[dict[str, Any]], None] | None = None,
    batch_fn: BatchFunction | None = None,
) -> Summary:
    """Run every run of ``study`` not yet recorded in ``out``; return the counts.

    Args:
        workers: local worker processes (forked from this one; a Dask LocalCluster where
            processes cannot be forked), 1 thread each; 0 runs serially in this process
            (for debugging and tests). Default: the CPU count.
        scheduler: address of a running Dask scheduler (overrides ``workers``).
        keep_rollouts: save each run's rollout under ``out/rollouts/<run id>/``.
        retry_errors: rerun recorded runs whose status is ``error`` (not the funnel
            violations and divergences, which are results).
        compact_every, compact_interval_s: rewrite the table after this many new rows or
            this much time, whichever comes first (rows are durable before that anyway).
        run_fn: what each task executes (tests inject failures through it).
        on_result: called with each new row after it is recorded.
        batch_fn: what a task executes for a few runs at once (`RUNS_PER_TASK`), their rows
            in order, each ``run_fn``'s row of the run (default: `execute_runs` for
            `execute_run`; None for another ``run_fn``: one run per task).
    """
    out = Path(out)
    store, recorded = _open_store(study, out)
    runs = study.runs()
    done_ids, counts = _recorded_runs(recorded, retry_errors)
    todo = [r for r in runs if r.run_id not in done_ids]
    base_sha = file_sha256(study.base)
    rollout_dir = str(out / ROLLOUTS_DIR) if keep_rollouts else None
    summary = Summary(total=len(runs), skipped=len(runs) - len(todo), run=0, **counts)
    if not todo:
        return summary

    bar = _progress_bar(study.name, len(runs), len(runs) - len(todo), progress, counts)
    compaction = _Compaction(store, compact_every, compact_interval_s)
    recorder = _Recorder(base_sha, counts, summary, bar, compaction, on_result)
    base = str(study.base)
    if batch_fn is None and run_fn is execute_run:
        batch_fn = execute_runs
    try:
        tasks = (run_fn, batch_fn)
        if workers == 0 and scheduler is None:
            for runs in _chunks(todo, batch_fn):
                for row in _task(run_fn, batch_fn, base, runs, rollout_dir):
                    recorder.record([row])  # row by row: what was seen is what is stored
        elif scheduler is None and _can_fork():
            _run_on_forked_processes(todo, base, rollout_dir, tasks, recorder.record, workers)
        else:
            _run_on_dask(todo, base, rollout_dir, tasks, recorder.record, workers, scheduler)
    finally:
        bar.close()
        store.compact()
    return summary


def _open_store(study: Study, out: Path) -> tuple[ResultStore, pd.DataFrame]:
    """The output directory's store and its rows, compacted, after checking that they are
    rows of this study (before anything is written) and recording the study's inputs."""
    out.mkdir(parents=True, exist_ok=True)
    store = ResultStore(out)
    recorded = store.load()
    base_hashes = recorded.get("base_sha256", pd.Series(dtype=object)).dropna()
    check_same_study(out, study, set(base_hashes))  # before anything is written
    record_study_inputs(out, study)
    return store, store.compact()


def _recorded_runs(recorded: pd.DataFrame, retry_errors: bool) -> tuple[set[str], dict[str, int]]:
    """The ids of the recorded runs not to run again (with ``retry_errors``, the errors
    are run again), and their counts per status (every status of `STATUSES` included)."""
    done_ids: set[str] = set()
    counts = dict.fromkeys(STATUSES, 0)
    if len(recorded):
        keep = recorded
        if retry_errors:
            keep = recorded[recorded["status"] != "error"]
        done_ids = set(keep["run_id"])
        for status in keep["status"]:
            counts[status] = counts.get(status, 0) + 1
    return done_ids, counts


def _failures(counts: dict[str, int]) -> str:
    """The progress bar's postfix: the count of each status other than ok."""
    return " ".join(f"{k}={counts[k]}" for k in STATUSES[1:])


def _progress_bar(name: str, total: int, done: int, progress: bool, counts: dict[str, int]):
    """A tqdm bar over the runs (disabled without ``progress``), the recorded ones done."""
    from tqdm.auto import tqdm

    bar = tqdm(
        total=total,
        initial=done,
        unit="run",
        desc=name,
        disable=not progress,
        dynamic_ncols=True,
        # in a log file (nohup) one line every 30 s rather than a redraw per run
        mininterval=0.5 if sys.stderr.isatty() else 30.0,
    )
    bar.set_postfix_str(_failures(counts), refresh=False)
    return bar


@dataclass
class _Compaction:
    """Rewrites the table after ``every`` new rows or ``interval_s`` seconds since the
    last rewrite, whichever comes first."""

    store: ResultStore
    every: int
    interval_s: float
    since: int = 0
    last: float = field(default_factory=time.monotonic)

    def row_added(self) -> None:
        """Count one new row; rewrite the table if it is due."""
        self.since += 1
        if self.since >= self.every or time.monotonic() - self.last > self.interval_s:
            self.store.compact()
            self.since = 0
            self.last = time.monotonic()


@dataclass
class _Recorder:
    """Takes each finished run's row: stamps the base scenario's digest, stores it, counts
    it (``counts``, ``summary``, the progress bar), lets the table be compacted, then
    calls ``on_result``."""

    base_sha256: str
    counts: dict[str, int]
    summary: Summary
    bar: Any
    compaction: _Compaction
    on_result: Callable[[dict[str, Any]], None] | None

    def record(self, rows: list[dict[str, Any]]) -> None:
        """Record the rows of one task's finished runs, stored together (see the class)."""
        for row in rows:
            row["base_sha256"] = self.base_sha256
        self.compaction.store.record(rows)
        counts = self.counts
        for row in rows:
            counts[row["status"]] = counts.get(row["status"], 0) + 1
            self.summary["run"] += 1
            self.summary[row["status"]] = counts[row["status"]]
            self.bar.update(1)
            self.bar.set_postfix_str(_failures(counts), refresh=False)
            self.compaction.row_added()
            if self.on_result is not None:
                self.on_result(row)


def _can_fork() -> bool:
    """Whether worker processes can be forked from this one (POSIX but macOS, where forking
    a process that has loaded system frameworks is unsafe)."""
    import multiprocessing

    return sys.platform != "darwin" and "fork" in multiprocessing.get_all_start_methods()


def _chunks(todo: list[Run], batch_fn: BatchFunction | None) -> list[list[Run]]:
    """The runs of each task: `RUNS_PER_TASK` with a batch function, else one."""
    per_task = RUNS_PER_TASK if batch_fn is not None else 1
    return [todo[start : start + per_task] for start in range(0, len(todo), per_task)]


def _run_on_forked_processes(todo, base, rollout_dir, tasks, finished, workers) -> None:
    """The tasks on ``workers`` processes forked from this one (the local case): they start
    with this process's modules imported, where a Dask LocalCluster's spawned workers import
    everything again and its scheduler and nannies start and stop (seconds, which a study of
    short runs notices). A worker that dies (killed, a crash in compiled code) breaks the
    pool: the runs not finished then are recorded as errors, which ``--retry-errors`` runs
    again."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    run_fn, batch_fn = tasks
    context = multiprocessing.get_context("fork")
    pool = ProcessPoolExecutor(workers or os.cpu_count() or 1, mp_context=context)
    futures = {}
    try:
        with workers_signals():  # the first submit forks every worker
            for runs in _chunks(todo, batch_fn):
                futures[pool.submit(_task, run_fn, batch_fn, base, runs, rollout_dir)] = runs
        _collect(as_completed(futures), futures, finished)
    except BaseException:  # Ctrl-C: the workers (which ignore it) are stopped, not awaited
        stop_pool(pool)
        raise
    pool.shutdown(wait=True)


def _collect(completed, futures: dict, finished) -> None:
    """Each task's rows to ``finished`` as its future completes (``completed``, in that
    order; error rows when the task itself failed, e.g. its worker died)."""
    for future in completed:
        runs = futures[future]
        try:
            rows = future.result()
        except Exception as exc:
            rows = [error_row(run, exc) for run in runs]
        finished(rows)
        if hasattr(future, "release"):  # a Dask future: its result freed on the cluster now
            future.release()


def _run_on_dask(todo, base, rollout_dir, tasks, finished, workers, scheduler) -> None:
    from dask.distributed import as_completed

    run_fn, batch_fn = tasks
    client, cluster = _client(workers, scheduler)
    futures = {}
    # runs go a few per task when there is a batch function (`execute_runs`); a worker with
    # several threads runs several tasks at once, in parallel in the compiled loop (the GIL
    # released)
    try:
        for runs in _chunks(todo, batch_fn):
            future = client.submit(
                _task, run_fn, batch_fn, base, runs, rollout_dir,
                key=f"uvms-run-{runs[0].run_id}", pure=False,
            )  # fmt: skip
            futures[future] = runs
        _collect(as_completed(futures), futures, finished)
    finally:
        for future in futures:
            if not future.done():
                future.cancel()
        client.close()
        if cluster is not None:
            cluster.close()


def _task(
    run_fn: RunFunction, batch_fn: BatchFunction | None, base, runs, rollout_dir
) -> list[dict[str, Any]]:
    """The rows of one task's runs: ``batch_fn``'s (a batch), or one by one through
    ``run_fn``."""
    if batch_fn is not None:
        return batch_fn(base, runs, rollout_dir)
    return [run_fn(base, run, rollout_dir) for run in runs]
