"""Bad inputs and misuses, typed at the installed ``uvms-pin`` as a user would.

Every case must exit with its status (2: bad input; 3: a run stopped, its rollout kept; 4:
the system failed; 130: Ctrl-C; 0: a run that warns), print only the project's messages (or
argparse's usage and message) naming the input and what is wrong, no traceback but the
user's own code's shown as such, and leave the results already on disk as they were (their
files hashed before and after); an ``--out`` that did not exist must still not exist, or
hold what the case says was kept (checked by its ``after``).

Most cases run in this process through the command's entry point (`run_cli_in_process`:
``main(ARGS)`` as the console script calls it, stdout, stderr and the exit status captured),
one after the other: a process per case would spend a second or two importing. The cases
that need a process run as one, concurrently: Ctrl-C (``interrupts``), a script of the user's
(``script``), and `IN_A_PROCESS`, one case of each kind of answer, which proves the process
says what the entry point says (`test_the_entry_point_answers_as_the_installed_command`).
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import paused_cli
import pytest
from bad_inputs_round2 import ROUND_TWO
from cli_support import STUDY, URDF, passive_scenario, run_cli, run_cli_in_process, tree_digest
from corpus import BAD_URDF, GOOD_BUT, Case, check_case
from corpus import copy_study_inputs as _copy_study_inputs
from corpus import mkdir as _mkdir
from corpus import steps as _steps
from corpus import write as _write

CASES = [
    # ---- run: the scenario -----------------------------------------------------------
    Case("run-missing-scenario", ("run", "nope.toml", "--out", "prior"), ("nope.toml", "file not found")),
    Case("run-not-utf8", ("run", "s.toml", "--out", "prior"), ("s.toml", "not UTF-8"), _write("s.toml", b"\xff\xfe[scenario]\n")),
    Case("run-invalid-toml", ("run", "s.toml", "--out", "prior"), ("s.toml", "not valid TOML"), _write("s.toml", "[scenario\n")),
    Case("run-unknown-key", ("run", "s.toml", "--out", "prior"), ("s.toml", "[water]", "unknown key(s): current_velocity"), _write("s.toml", GOOD_BUT(**{"[water]\n": "[water]\ncurrent_velocity = [1, 2, 3]\n"}))),
    Case("run-scenario-is-a-directory", ("run", "sdir", "--out", "prior"), ("sdir", "is a directory"), _mkdir("sdir")),
    Case("run-negative-duration", ("run", "s.toml", "--out", "prior"), ("s.toml", "duration_s", "must be positive"), _write("s.toml", GOOD_BUT(-1.0))),
    Case("run-missing-model", ("run", "s.toml", "--out", "prior"), ("scenario.model", "'missing.urdf' is neither a file", "nor a shipped model"), _write("s.toml", GOOD_BUT(**{str(URDF): "missing.urdf"}))),
    Case("run-urdfdom-error", ("run", "s.toml", "--out", "prior"), ("bad.urdf", "does not specify limits"), _steps(_write("bad.urdf", BAD_URDF), _write("s.toml", GOOD_BUT(**{str(URDF): "bad.urdf"})))),
    Case("run-bad-overwrite-keeps-results", ("run", "nope.toml", "--out", "prior", "--overwrite"), ("nope.toml", "file not found")),
    # ---- run: the output directory and options ---------------------------------------
    Case("run-out-is-a-file", ("run", "{good}", "--out", "f"), ("--out f", "is a file"), _write("f", "mine"), watch="f"),
    Case("run-out-under-a-file", ("run", "{good}", "--out", "f/sub"), ("f/sub", "under a file"), _write("f", "mine"), watch="f"),
    Case("run-out-not-writable", ("run", "{good}", "--out", "{ro}/out"), ("/out", "cannot write")),
    Case("run-out-holds-results", ("run", "{good}", "--out", "prior"), ("--out prior", "already holds a run's outputs", "--overwrite")),
    Case("run-out-holds-a-study", ("run", "{good}", "--out", "study_out", "--overwrite"), ("study_out", "holds a study's results"), watch="study_out"),
    Case("run-out-holds-a-comparison", ("run", "{good}", "--out", "cmp", "--overwrite"), ("cmp", "holds an arm comparison"), _write("cmp/comparison.csv", "arm\n"), watch="cmp"),
    Case("run-speed-zero", ("run", "{good}", "--out", "new", "--speed", "0"), ("--speed", "must be positive"), watch="new"),
    Case("run-speed-nan", ("run", "{good}", "--out", "new", "--speed", "nan"), ("--speed", "finite"), watch="new"),
    Case("run-port-out-of-range", ("run", "{good}", "--out", "new", "--port", "70000"), ("--port", "0..65535"), watch="new"),
    Case("run-no-out", ("run", "{good}"), ("--out", "required")),
    # ---- replay ------------------------------------------------------------------------
    Case("replay-missing-rollout", ("replay", "nodir", "--html"), ("nodir", "holds no rollout"), watch="nodir"),
    Case("replay-nothing-to-do", ("replay", "prior"), ("replay", "nothing to do", "--html")),
    Case("replay-fps-zero", ("replay", "prior", "--html", "--fps", "0"), ("--fps", "must be positive")),
    Case("replay-damaged-arrays", ("replay", "prior", "--html"), ("prior", "damaged rollout"), _write("prior/rollout.npz", b"not a zip")),
    Case("replay-damaged-metadata", ("replay", "prior", "--html"), ("prior", "damaged rollout"), _write("prior/rollout.json", b"{\xff")),
    Case("replay-page-exists", ("replay", "prior", "--html"), ("replay.html", "already exists", "--overwrite"), _write("prior/replay.html", "<html>earlier</html>")),
    Case("replay-out-is-a-directory", ("replay", "prior", "--html", "--out", "pagedir"), ("pagedir", "is a directory"), _mkdir("pagedir"), watch="pagedir"),
    Case("replay-out-under-a-file", ("replay", "prior", "--html", "--out", "f/page.html"), ("--out f/page.html", "under a file"), _write("f", "mine"), watch="f"),
    # ---- info --------------------------------------------------------------------------
    Case("info-missing", ("info", "nope.urdf"), ("'nope.urdf' is neither a file", "nor a shipped model (")),
    Case("info-not-xml", ("info", "x.urdf"), ("x.urdf", "not well-formed XML"), _write("x.urdf", "<robot")),
    Case("info-wrong-root", ("info", "x.urdf"), ("x.urdf", "expected <robot>"), _write("x.urdf", "<model/>")),
    Case("info-negative-density", ("info", "{urdf}", "--water-density", "-1"), ("--water-density", "must be positive")),
    # ---- sweep and report --------------------------------------------------------------
    Case("sweep-missing-study", ("sweep", "nope.toml", "--out", "study_out"), ("nope.toml", "file not found"), watch="study_out"),
    Case("sweep-study-not-utf8", ("sweep", "st.toml", "--out", "study_out"), ("st.toml", "not UTF-8"), _write("st.toml", b"[study]\nname = \"\xe9\"\n"), watch="study_out"),
    Case("sweep-negative-workers", ("sweep", "{study}", "--out", "study_out", "--workers", "-2"), ("--workers", ">= 0", "-2"), watch="study_out"),
    Case("sweep-workers-not-a-number", ("sweep", "{study}", "--out", "study_out", "--workers", "two"), ("--workers", "integer", "two"), watch="study_out"),
    Case("sweep-workers-and-scheduler", ("sweep", "{study}", "--out", "study_out", "--workers", "1", "--scheduler", "tcp://127.0.0.1:1"), ("--scheduler", "not allowed with", "--workers"), watch="study_out"),
    Case("sweep-another-study", ("sweep", "study.toml", "--out", "study_out", "--workers", "0"), ("study_out", "another study", "--overwrite"), _steps(_copy_study_inputs, _write("study.toml", STUDY.replace("[0.0, 0.1]", "[0.0, 0.2]"))), watch="study_out"),
    Case("sweep-base-changed", ("sweep", "study.toml", "--out", "study_out", "--workers", "0"), ("base.toml", "changed", "restore it"), _steps(_copy_study_inputs, _write("base.toml", passive_scenario(0.06))), watch="study_out"),
    Case("sweep-missing-base", ("sweep", "st.toml", "--out", "new"), ("st.toml", "study.base", "not found"), _write("st.toml", STUDY.replace("base.toml", "gone.toml")), watch="new"),
    Case("sweep-into-a-run", ("sweep", "{study}", "--out", "prior", "--workers", "0"), ("prior", "holds a run's outputs")),
    Case("sweep-out-is-a-file", ("sweep", "{study}", "--out", "f", "--workers", "0"), ("--out f", "is a file"), _write("f", "mine"), watch="f"),
    Case("sweep-damaged-table", ("sweep", "{study}", "--out", "study_out", "--workers", "0"), ("results.parquet", "not a readable Parquet table"), _write("study_out/results.parquet", b"PAR1 garbage"), watch="study_out"),
    Case("report-not-a-study", ("report", "prior"), ("prior", "not a study output directory")),
    # ---- compare-arms ------------------------------------------------------------------
    Case("arms-empty", ("compare-arms", "{good}", "--arms", "", "--out", "new"), ("--arms", "none empty"), watch="new"),
    Case("arms-twice", ("compare-arms", "{good}", "--arms", "reference,reference", "--out", "new"), ("reference", "given twice"), watch="new"),
    Case("arms-negative-jobs", ("compare-arms", "{good}", "--jobs", "-1", "--out", "new"), ("--jobs", ">= 1", "-1"), watch="new"),
    Case("arms-zero-jobs", ("compare-arms", "{good}", "--jobs", "0", "--out", "new"), ("--jobs", ">= 1"), watch="new"),
    Case("arms-zero-ik-starts", ("compare-arms", "{good}", "--ik-starts", "0", "--out", "new"), ("--ik-starts", ">= 1"), watch="new"),
    Case("arms-negative-duration", ("compare-arms", "{good}", "--duration", "-1", "--out", "new"), ("--duration", "must be positive"), watch="new"),
    Case("arms-infinite-rpy", ("compare-arms", "{good}", "--mount-rpy", "0", "inf", "0", "--out", "new"), ("--mount-rpy", "finite"), watch="new"),
    Case("arms-unknown-arm", ("compare-arms", "{good}", "--arms", "nosucharm", "--out", "new"), ("nosucharm", "unknown arm"), watch="new"),
    Case("arms-into-a-run", ("compare-arms", "{good}", "--arms", "reference", "--out", "prior"), ("prior", "holds a run's outputs")),
    Case("arms-no-scenario", ("compare-arms", "--out", "new"), ("SCENARIO", "required"), watch="new"),
    # ---- the command itself ------------------------------------------------------------
    Case("no-command", (), ("command", "required")),
    Case("unknown-command", ("frobnicate",), ("frobnicate", "invalid choice")),
]  # fmt: skip
CASES += ROUND_TWO
CASES_BY_NAME = {case.name: case for case in CASES}

#: run as the installed command in a process of their own, one of each kind of answer: an
#: argparse usage error, the project's error, a run stopped with the user's traceback, a
#: diverged run, a run that warns and succeeds, a model that warns (the others of these kinds
#: run in this process: `run_cli_in_process`)
IN_A_PROCESS = frozenset(
    (
        "no-command",
        "run-missing-scenario",
        "run-controller-raises-later",
        "run-current-of-1400-m-s",
        "run-fresh-water-density-warned",
        "info-flat-mesh-as-a-hull",
    )
)


def _needs_a_process(case: Case) -> bool:
    return bool(case.interrupts or case.script or case.name in IN_A_PROCESS)


@pytest.fixture(scope="module")
def workspace(tmp_path_factory) -> Path:
    """A valid scenario, a run's outputs and a study's results, made in-process."""
    from uvms_pin.apps.outputs import write_outputs
    from uvms_pin.apps.study import load_study
    from uvms_pin.apps.study.runner import run_study
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    ws = tmp_path_factory.mktemp("corpus")
    (ws / "good.toml").write_text(passive_scenario(0.1))
    write_outputs(simulate(load_scenario(ws / "good.toml")), ws / "prior_run")
    (ws / "study").mkdir()
    (ws / "study" / "base.toml").write_text(passive_scenario(0.04))
    (ws / "study" / "study.toml").write_text(STUDY)
    run_study(
        load_study(ws / "study" / "study.toml"), ws / "prior_study", workers=0, progress=False
    )
    return ws


def _not_writable(ws: Path) -> Path:
    """A directory this process cannot create files in (root may write a 0555 one)."""
    if os.geteuid() == 0:
        return Path("/sys")  # sysfs: not even root creates files there
    ro = ws / "read_only"
    ro.mkdir(exist_ok=True)
    ro.chmod(0o555)
    return ro


@pytest.fixture(scope="module")
def outcomes(workspace) -> dict[str, tuple]:
    """Each case run once, all concurrently: name -> (result, watched before, after, existed)."""
    values = {
        "good": str(workspace / "good.toml"),
        "study": str(workspace / "study" / "study.toml"),
        "urdf": str(URDF),
        "ro": str(_not_writable(workspace)),
    }

    def one(case: Case, root: str = "cases"):
        case_dir = workspace / root / case.name
        case_dir.mkdir(parents=True)
        shutil.copytree(workspace / "prior_run", case_dir / "prior")
        shutil.copytree(workspace / "prior_study", case_dir / "study_out")
        if case.setup is not None:
            case.setup(case_dir)
        watched = case_dir / case.watch
        existed, before = watched.exists(), tree_digest(watched)
        args = [a.format(**values) for a in case.args]
        if case.interrupts:
            result = _interrupted(args, case_dir, case.interrupts)
        elif case.script is not None:
            result = subprocess.run(
                [sys.executable, case.script, *args],
                cwd=case_dir, capture_output=True, text=True, timeout=300, check=False,
            )  # fmt: skip
        elif root == "in_process" or not _needs_a_process(case):
            result = run_cli_in_process(args, cwd=case_dir)
        else:
            result = run_cli(args, cwd=case_dir)
        return result, before, tree_digest(watched), existed, watched.exists()

    with ThreadPoolExecutor(max_workers=2 * (os.cpu_count() or 1)) as pool:
        in_processes = {c.name: pool.submit(one, c) for c in CASES if _needs_a_process(c)}
        found = {c.name: one(c) for c in CASES if not _needs_a_process(c)}
        found.update({name: future.result() for name, future in in_processes.items()})
        for name in IN_A_PROCESS:  # the same case through the entry point, for the comparison
            found[f"{name} (in process)"] = one(CASES_BY_NAME[name], "in_process")
        return found


def _interrupted(args: list[str], cwd: Path, delays: tuple[float, ...]):
    """``uvms-pin ARGS`` with Ctrl-C while its 500th sample is being logged (the run paused
    there by a test hook, tests/paused_cli.py: the same point however fast the machine),
    then again after each delay [s] (a user pressing again while the first is handled)."""
    proc = paused_cli.start(["--pause-at-sample", "500"], args, cwd)
    try:
        paused_cli.wait_until_paused(proc)
        for delay_s in (0.0, *delays):
            time.sleep(delay_s)
            if proc.poll() is None:  # (one that ended early fails on its exit status)
                os.killpg(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


def test_the_corpus_is_large_and_its_names_unique():
    assert len(CASES) >= 100
    assert len(CASES_BY_NAME) == len(CASES)
    assert IN_A_PROCESS <= set(CASES_BY_NAME)


@pytest.mark.parametrize("name", sorted(IN_A_PROCESS))
def test_the_entry_point_answers_as_the_installed_command(name: str, outcomes):
    """The in-process runner is faithful: a case of each kind of answer gives the same exit
    status, stderr and stdout (the case's directory, the run's duration aside) and leaves the
    same files. (Every case of the corpus was compared so once, when the corpus moved in.)"""
    process, in_process = outcomes[name], outcomes[f"{name} (in process)"]
    (ran, *process_files), (called, *in_process_files) = process, in_process
    assert called.returncode == ran.returncode
    for stream in ("stderr", "stdout"):
        assert _comparable(getattr(called, stream), "in_process") == _comparable(
            getattr(ran, stream), "cases"
        )
    assert in_process_files == process_files


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_a_bad_input_is_refused_cleanly(case: Case, outcomes, workspace):
    result, before, after, existed, exists = outcomes[case.name]
    err = result.stderr
    assert result.returncode == case.code, err
    message = check_case(case, err)
    for needle in case.needles:
        assert needle in message, f"{needle!r} not in {message!r}"
    assert after == before, f"{case.watch} was modified"
    assert exists == existed, f"{case.watch} was {'created' if exists else 'removed'}"
    if case.after is not None:
        case.after(workspace / "cases" / case.name)


def _comparable(text: str, root: str) -> str:
    """``text`` with what differs between two runs of a case masked: the case's directory
    (``.../ROOT/<case>``), how long the run took, how much memory was free."""
    text = re.sub(rf"\S*/{root}/[^/\s]+", "<case dir>", text)
    text = re.sub(
        r"in [\d.]+ s \(real-time factor [\d.]+\)", "in <t> s (real-time factor <r>)", text
    )
    return re.sub(r"[\d.]+ GiB available", "<m> GiB available", text)
