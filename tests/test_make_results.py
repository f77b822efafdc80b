"""`make results`: one script per result, all listed in scripts/make_results.py."""

from __future__ import annotations

import subprocess
import sys

from conftest import ROOT

sys.path.insert(0, str(ROOT / "scripts"))
from make_results import PRODUCERS


def test_every_result_script_is_listed_and_every_listed_result_has_a_script():
    scripts = {p.stem for p in (ROOT / "scripts" / "results").glob("*.py")}
    producers = {name for name in scripts if not name.startswith("_")}
    assert producers == set(PRODUCERS)


def test_the_makefile_runs_the_list():
    makefile = (ROOT / "Makefile").read_text()
    assert "scripts/make_results.py" in makefile and "\nresults:" in makefile


def test_list_and_bad_names():
    script = str(ROOT / "scripts" / "make_results.py")
    listed = subprocess.run([sys.executable, script, "--list"], capture_output=True, text=True)
    assert listed.returncode == 0
    assert [line.split()[0] for line in listed.stdout.splitlines()] == list(PRODUCERS)
    bad = subprocess.run([sys.executable, script, "--only", "nope"], capture_output=True, text=True)
    assert bad.returncode == 2 and "invalid choice: 'nope'" in bad.stderr
