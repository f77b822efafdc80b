"""Documentation that runs: every python, bash and console block of README.md, docs/*.md
and the repository's other Markdown files (models/README.md, ...) runs as written, in document order, in a fresh working copy of the
repository, with scenario runs shortened (and saying so) by UVMS_PIN_MAX_DURATION_S.

How blocks are found and what the ``<!-- doc-test: ... -->`` directives mean:
tests/doc_snippets.py. Skipped blocks are reported with their reasons (``pytest -ra``) and,
with the blocks that use placeholders, in the "documentation snippets" summary.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import socket
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from conftest import DOCS_RUN_SUMMARY, ROOT
from doc_snippets import (
    CAP_S,
    Snippet,
    all_snippets,
    commands,
    documents,
)

from uvms_pin.apps.cli.main import build_parser
from uvms_pin.sim.shortened import MAX_DURATION_ENV

SNIPPETS = all_snippets(ROOT)
DRIVER = Path(__file__).with_name("doc_snippets_run.py")
#: only to stop a hung document (a server that never ends); never a measure of speed
DOCUMENT_TIMEOUT_S = 3600


def working_copy(destination: Path) -> Path:
    """The repository's files as they are now (tracked or new, not ignored; edits
    included), modification times kept, and ``.venv`` linked to this interpreter's
    environment (the ``.venv/bin/...`` and ``make`` the documents use)."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        check=False,
    )
    if listed.returncode == 0:
        for name in filter(None, listed.stdout.decode().split("\0")):
            source = ROOT / name
            if source.is_file():
                (destination / name).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(source, destination / name)
    else:  # not a git checkout: everything but the environment and outputs
        skip = shutil.ignore_patterns(".git", ".venv", "out", "build", "__pycache__", "*.egg-info")
        shutil.copytree(ROOT, destination, ignore=skip, dirs_exist_ok=True)
    if sys.prefix != sys.base_prefix:
        (destination / ".venv").symlink_to(sys.prefix, target_is_directory=True)
    return destination


def environment() -> dict[str, str]:
    """This interpreter's scripts first on PATH, figures without a display, runs capped,
    old module paths refused."""
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    env.update({MAX_DURATION_ENV: CAP_S, "MPLBACKEND": "Agg", "PYTHONUNBUFFERED": "1"})
    env.pop("PYTHONPATH", None)
    return env


def _network() -> bool:
    try:
        socket.create_connection(("pypi.org", 443), timeout=5).close()
    except OSError:
        return False
    return True


def _install_is_current(copy: Path) -> str | None:
    """Why a block that runs ``make`` or ``.venv/bin/...`` cannot, or None: make would
    reinstall (the copy's sources are newer than .venv/.installed), or no venv."""
    if not (copy / ".venv").exists():
        return "needs the .venv that `make` creates (the tests do not run in a venv)"
    fresh = subprocess.run(["make", "-q", ".venv/.installed"], cwd=copy, capture_output=True)
    if fresh.returncode != 0:
        return "the install in .venv is older than its sources (run `make .venv/.installed`)"
    return None


def skip_reason(snippet: Snippet, copy: Path, available: dict[str, bool]) -> str | None:
    if snippet.skip:
        return snippet.skip
    if snippet.same_as:
        return f"the same commands as {same_block(snippet).id}, which runs them"
    for need in snippet.needs:
        if not available[need]:
            return f"needs {need}, not available here"
    uses_venv = ".venv/" in snippet.code or any(
        line.strip().startswith("make ") for line in snippet.code.splitlines()
    )
    if uses_venv:
        return _install_is_current(copy)
    return None


def run_document(doc: str, snippets: list[Snippet], copy: Path, work: Path) -> dict[str, dict]:
    """Run one document's snippets in a fresh interpreter (tests/doc_snippets_run.py)."""
    stem = doc.replace("/", "_")
    listed, results = work / f"{stem}.snippets.json", work / f"{stem}.results.json"
    listed.write_text(json.dumps([s.to_json() for s in snippets]))
    try:
        done = subprocess.run(
            [sys.executable, str(DRIVER), str(listed), str(results)],
            cwd=copy,
            env=environment(),
            capture_output=True,
            text=True,
            timeout=DOCUMENT_TIMEOUT_S,
            check=False,
        )
        crash = "" if done.returncode == 0 else done.stderr[-4000:]
    except subprocess.TimeoutExpired:
        crash = f"the document did not finish in {DOCUMENT_TIMEOUT_S} s"
    found = json.loads(results.read_text()) if results.exists() else {}
    for snippet in snippets:
        found.setdefault(snippet.id, {"status": "failed", "problems": [f"not run: {crash}"]})
    return found


def lanes(docs: list[str]) -> list[list[str]]:
    """Two lanes that run side by side, each in its own working copy (the suite is serial:
    this uses the second core): the documents in order, cut where each lane holds about half
    of the blocks that run. A document reads nothing another one wrote, so any cut works;
    blocks of different lanes never share an output (`test_no_two_blocks_write_one_output`)."""
    weights = [sum(s.doc == doc and not (s.skip or s.same_as) for s in SNIPPETS) for doc in docs]
    done, cut = 0, len(docs)
    for index, weight in enumerate(weights):
        done += weight
        if 2 * done >= sum(weights):
            cut = index + 1
            break
    return [docs[:cut], docs[cut:]]


def run_lane(docs: list[str], base: Path, available: dict[str, bool]) -> dict[str, dict]:
    copy = working_copy(base / "repository")
    results: dict[str, dict] = {}
    for doc in docs:
        runnable = []
        for snippet in (s for s in SNIPPETS if s.doc == doc):
            reason = skip_reason(snippet, copy, available)
            if reason:
                results[snippet.id] = {"status": "skipped", "reason": reason}
            else:
                runnable.append(snippet)
        if runnable:
            results.update(run_document(doc, runnable, copy, base))
    return results


@pytest.fixture(scope="session")
def doc_run(tmp_path_factory, pytestconfig) -> dict[str, dict]:
    """Every document's snippets, run once: snippet id -> result (or skip reason)."""
    available = {"chromium": bool(shutil.which("chromium") or shutil.which("chromium-browser"))}
    available["network"] = any("network" in s.needs for s in SNIPPETS) and _network()
    groups = lanes(documents(ROOT))
    with ThreadPoolExecutor(len(groups)) as pool:
        runs = [
            pool.submit(run_lane, docs, tmp_path_factory.mktemp("docs_run"), available)
            for docs in groups
        ]
        results = {k: v for run in runs for k, v in run.result().items()}
    pytestconfig.stash[DOCS_RUN_SUMMARY] = _summary(results)
    return results


def _summary(results: dict[str, dict]) -> list[str]:
    ran = [s for s in SNIPPETS if results[s.id]["status"] != "skipped"]
    lines = [
        f"{len(SNIPPETS)} blocks: {len(ran)} ran ({sum(results[s.id]['status'] == 'passed' for s in ran)} passed), "
        f"{len(SNIPPETS) - len(ran)} skipped; scenario runs capped at {MAX_DURATION_ENV}={CAP_S} s"
    ]
    for snippet in SNIPPETS:
        result = results[snippet.id]
        if result["status"] == "skipped":
            lines.append(f"  skipped {snippet.id} ({snippet.language}): {result['reason']}")
        else:
            took = "not run"
            if "seconds" in result:
                took = f"{result['seconds']:.1f} s ({result['cpu_seconds']:.1f} s CPU)"
            lines.append(f"  {result['status']} {snippet.id} ({snippet.language}): {took}")
        if snippet.placeholders:
            names = ", ".join(f"{name} (stand-in: {stand_in})" for name, stand_in in snippet.placeholders)  # fmt: skip
            lines.append(f"  placeholders {snippet.id}: {names}")
    return lines


@pytest.mark.parametrize("snippet", SNIPPETS, ids=[s.id for s in SNIPPETS])
def test_snippet_runs_as_written(snippet: Snippet, doc_run):
    result = doc_run[snippet.id]
    if result["status"] == "skipped":
        pytest.skip(f"{snippet.id} ({snippet.language}): {result['reason']}")
    if result["status"] != "passed":
        pytest.fail(
            f"{snippet.id} ({snippet.language}) failed: {'; '.join(result['problems'])}\n"
            f"--- the block:\n{snippet.code}--- stdout (end):\n{result.get('stdout', '')}\n"
            f"--- stderr (end):\n{result.get('stderr', '')}",
            pytrace=False,
        )


def test_the_documents_have_runnable_blocks():
    """The extraction finds the blocks (a renamed fence language would silently drop them)."""
    counts = {doc: sum(s.doc == doc for s in SNIPPETS) for doc in documents(ROOT)}
    assert counts["README.md"] >= 3 and counts["docs/getting_started.md"] >= 5, counts
    assert counts["docs/api.md"] >= 5, counts
    assert counts["models/README.md"] >= 1, counts


# ---- commands quoted inline --------------------------------------------------------------
def _inline_commands() -> list[tuple[str, str]]:
    """(document, command) for every inline ``uvms-pin ...`` naming a repository path (a
    command to copy, not a mention such as `uvms-pin run`)."""
    found = []
    for doc in documents(ROOT):
        for command in re.findall(r"`(uvms-pin [^`]+)`", (ROOT / doc).read_text()):
            words = shlex.split(command)[1:]
            if "..." not in words and any("/" in w and (ROOT / w).exists() for w in words):
                found.append((doc, command))
    return found


@pytest.mark.parametrize(("doc", "command"), _inline_commands())
def test_inline_commands_are_complete(doc, command, capsys):
    """Inline commands naming files of the repository parse (no required option missing)."""
    try:
        build_parser().parse_args(shlex.split(command)[1:])
    except SystemExit:
        pytest.fail(f"{doc}: `{command}` does not parse: {capsys.readouterr().err.strip()}")


def same_block(snippet: Snippet) -> Snippet:
    """The runnable block of ``snippet.same_as`` with ``snippet``'s commands."""
    for other in SNIPPETS:
        runs = not (other.skip or other.same_as) and other.language != "python"
        if other.doc == snippet.same_as and runs and commands(other) == commands(snippet):
            return other
    raise AssertionError(f"{snippet.id}: no block of {snippet.same_as} runs its commands")


def test_a_block_said_to_be_the_same_as_another_is():
    for snippet in (s for s in SNIPPETS if s.same_as):
        assert same_block(snippet).id.startswith(snippet.same_as)


# ---- outputs: no two blocks write the same place -----------------------------------------
def outputs_written(snippet: Snippet) -> list[str]:
    """Where a block writes, in order: ``--out DIR`` (and DIR/replay.html with ``--html``),
    ``replay DIR --html`` (DIR/replay.html), ``.save("DIR")``; commands with --overwrite
    aside."""
    if snippet.language == "python":
        return re.findall(r"\.save\(\s*[\"']([^\"']+)[\"']", snippet.code)
    written = []
    for words in commands(snippet):
        if "--overwrite" in words:
            continue
        out = words[words.index("--out") + 1].rstrip("/") if "--out" in words else None
        if out:
            written.append(out)
        if "--html" in words and out and words[1:2] == ["run"]:
            written.append(f"{out}/replay.html")
        if words[:2] == ["uvms-pin", "replay"] and "--html" in words and not out:
            written.append(f"{words[2].rstrip('/')}/replay.html")
    return written


def test_no_two_blocks_write_one_output():
    """A reader runs the README and then the docs in one clone: no block may write where an
    earlier one did (`uvms-pin` refuses a directory holding a run, and says so)."""
    first: dict[str, str] = {}
    clashes = []
    for snippet in (s for s in SNIPPETS if not (s.skip or s.same_as)):
        for path in outputs_written(snippet):
            if path in first:
                clashes.append(f"{snippet.id} writes {path}, as {first[path]} does")
            first.setdefault(path, snippet.id)
    assert len(first) >= 15, sorted(first)  # the outputs are found
    assert not clashes, clashes
