"""Runs ``SCRIPT --help`` for each script named on the command line, one after the other in
this one interpreter, as ``python SCRIPT --help`` would (tests/test_make_results.py): the
script's folder first on sys.path, run as ``__main__``, its output captured. Between two
scripts, sys.path, sys.argv and every module imported from outside the installed packages
(the scripts' own helpers) are put back, so that no script finds a helper another one
imported. Prints one JSON object: script -> {"code", "stdout", "stderr"}.

One interpreter for all of them: uvms_pin, numpy and matplotlib are imported once (about
0.6 s a script otherwise, some 50 scripts)."""

from __future__ import annotations

import contextlib
import io
import json
import runpy
import sys
import traceback
from pathlib import Path

import uvms_pin

#: where the modules that stay loaded live: the interpreter's (standard library, the
#: environment's packages) and uvms_pin's
KEPT = tuple(
    str(Path(p).resolve())
    for p in (sys.prefix, sys.base_prefix, sys.exec_prefix, Path(uvms_pin.__file__).parent)
)


def _installed(module) -> bool:
    """A built-in module or one under `KEPT` (not a script's helper)."""
    path = getattr(module, "__file__", None)
    return not path or str(Path(path).resolve()).startswith(KEPT)


def help_of(script: Path) -> dict:
    saved_path, saved_argv = list(sys.path), list(sys.argv)
    before = set(sys.modules)
    out, err = io.StringIO(), io.StringIO()
    sys.argv, sys.path[0] = [str(script), "--help"], str(script.parent)
    code = 0
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            runpy.run_path(str(script), run_name="__main__")
    except SystemExit as stop:
        code = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
    except BaseException:  # any failure is the script's: report it, go on with the next
        code, err = 1, io.StringIO(err.getvalue() + traceback.format_exc())
    finally:
        sys.path[:], sys.argv = saved_path, saved_argv
        for name in set(sys.modules) - before:
            if not _installed(sys.modules[name]):
                del sys.modules[name]
    return {"code": code, "stdout": out.getvalue(), "stderr": err.getvalue()}


def main() -> None:
    results = {name: help_of(Path(name)) for name in sys.argv[1:]}
    sys.stdout.write(json.dumps(results))


if __name__ == "__main__":
    main()
