"""Run one document's snippets in the current directory (a working copy), in order, and
write what happened as JSON: ``python doc_snippets_run.py SNIPPETS.json RESULTS.json``.

Started by tests/test_docs_run.py in a fresh process per document (one python namespace
per document, as a reader's interpreter session). Every snippet runs even after one
failed; the results file is rewritten after each snippet.
"""

from __future__ import annotations

import contextlib
import io
import json
import resource
import shutil
import subprocess
import sys
import time
import traceback
from pathlib import Path

from doc_snippets import Snippet, console_commands, output_matches

#: how much of a failed snippet's output the report keeps (its end)
TAIL_CHARS = 6000


def run_bash(code: str) -> tuple[bool, str, str]:
    """(exit status 0, stdout, stderr) of ``code`` in bash, stopping at the first failure."""
    done = subprocess.run(
        ["bash", "-e", "-o", "pipefail", "-c", code],
        capture_output=True,
        text=True,
        stdin=subprocess.DEVNULL,
        check=False,
    )
    failed = f"\n[exit status {done.returncode}]" if done.returncode else ""
    return done.returncode == 0, done.stdout, done.stderr + failed


def run_python(snippet: Snippet, namespace: dict) -> tuple[bool, str, str]:
    out, err = io.StringIO(), io.StringIO()
    ok = True
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            exec(compile(snippet.code, snippet.id, "exec"), namespace)
        except BaseException:  # a snippet's failure is a result, SystemExit too
            traceback.print_exc(file=err)
            ok = False
    return ok, out.getvalue(), err.getvalue()


def run_console(snippet: Snippet) -> tuple[bool, str, str]:
    """Each ``$ command`` in turn; what it prints (stdout) must match what the block shows."""
    stdout, stderr = [], []
    for command, shown in console_commands(snippet.code):
        ok, out, err = run_bash(command)
        stdout.append(f"$ {command}\n{out}")
        stderr.append(err)
        if not ok:
            return False, "".join(stdout), "".join(stderr)
        if shown.strip() and not output_matches(shown, out):
            note = f"\n[the block shows, for '$ {command}':]\n{shown}\n[but it printed:]\n{out}"
            return False, "".join(stdout), "".join(stderr) + note
    return True, "".join(stdout), "".join(stderr)


def checks_failed(snippet: Snippet, printed: str, namespace: dict) -> list[str]:
    """The snippet's ``output:`` and ``assert:`` directives that do not hold."""
    failed = [f"output: {text!r} not printed" for text in snippet.outputs if text not in printed]
    for expression in snippet.asserts:
        try:
            holds = bool(eval(expression, namespace))
        except Exception as exc:  # reported as the failed check it is
            holds, expression = False, f"{expression} ({type(exc).__name__}: {exc})"
        if not holds:
            failed.append(f"assert: {expression} is false")
    return failed


def place_stand_ins(snippet: Snippet) -> None:
    """Copy each placeholder's stand-in (a repository file) to the name the reader
    supplies, relative to the working copy."""
    for name, stand_in in snippet.placeholders:
        target = Path(name)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(stand_in, target)


def _cpu_s() -> float:
    """CPU time [s] of this process and of its finished children (machine-load aside)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def run_snippet(snippet: Snippet, namespace: dict) -> dict:
    start, cpu = time.monotonic(), _cpu_s()
    place_stand_ins(snippet)
    if snippet.language == "python":
        ok, out, err = run_python(snippet, namespace)
    elif snippet.language == "console":
        ok, out, err = run_console(snippet)
    else:
        ok, out, err = run_bash(snippet.code)
    problems = checks_failed(snippet, out + err, namespace) if ok else []
    return {
        "status": "passed" if ok and not problems else "failed",
        "problems": problems,
        "stdout": out[-TAIL_CHARS:],
        "stderr": err[-TAIL_CHARS:],
        "seconds": time.monotonic() - start,
        "cpu_seconds": _cpu_s() - cpu,
    }


def main(snippets_file: str, results_file: str) -> int:
    snippets = [Snippet.from_json(s) for s in json.loads(Path(snippets_file).read_text())]
    namespace = {"__name__": "__main__"}
    results: dict[str, dict] = {}
    for snippet in snippets:
        results[snippet.id] = run_snippet(snippet, namespace)
        Path(results_file).write_text(json.dumps(results))
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
