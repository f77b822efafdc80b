"""`make results`: one script per result, all listed in scripts/make_results.py."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from conftest import ROOT

sys.path.insert(0, str(ROOT / "scripts"))
from make_results import PRODUCERS


def test_every_result_script_is_listed_and_every_listed_result_has_a_script():
    scripts = {p.stem for p in (ROOT / "scripts" / "results").glob("*.py")}
    producers = {name for name in scripts if not name.startswith("_")}
    assert producers == set(PRODUCERS)


def test_every_result_is_quoted_beside_its_command_on_a_page_of_the_site():
    """Each table `make results` writes (docs/results/<name>.md) is quoted by a page of the
    documentation, and docs/reproduce.md names every result with its page: no result is
    written for a page that no longer exists."""
    docs = ROOT / "docs"
    pages = {p.name: p.read_text() for p in docs.glob("*.md") if p.name != "reproduce.md"}
    rows = [line.split("|") for line in (docs / "reproduce.md").read_text().splitlines()]
    results = [cells[3] for cells in rows if len(cells) == 5 and cells[1].strip().startswith("[")]
    named = {word for cell in results for word in cell.strip(" `").split()}
    assert named == set(PRODUCERS), sorted(named ^ set(PRODUCERS))
    for name in PRODUCERS:
        assert (docs / "results" / f"{name}.md").is_file(), name
        assert any(f"results/{name}.md" in text for text in pages.values()), name


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


def _runnable_scripts() -> list:
    """Every script a user or `make results` runs: benchmarks/ and scripts/, helpers aside."""
    found = [*(ROOT / "benchmarks").glob("*.py"), *(ROOT / "scripts").rglob("*.py")]
    return sorted(p for p in found if '__name__ == "__main__"' in p.read_text())


def test_the_runnable_scripts_are_found():
    names = {p.relative_to(ROOT).as_posix() for p in _runnable_scripts()}
    assert {"benchmarks/bench_controller.py", "scripts/results/paper.py"} <= names
    assert "benchmarks/timing.py" not in names


@pytest.fixture(scope="module")
def helps() -> dict[str, dict]:
    """Every runnable script's ``--help``, run as ``python SCRIPT --help`` would, all in one
    fresh interpreter (tests/script_help_driver.py: each script with its own sys.path and
    none of another's helpers): script path -> exit code, stdout, stderr."""
    scripts = [str(p) for p in _runnable_scripts()]
    driver = ROOT / "tests" / "script_help_driver.py"
    ran = subprocess.run(
        [sys.executable, str(driver), *scripts], cwd=ROOT, capture_output=True, text=True
    )
    assert ran.returncode == 0, ran.stderr[-2000:]
    return json.loads(ran.stdout)


@pytest.mark.parametrize(
    "script", _runnable_scripts(), ids=lambda p: p.relative_to(ROOT).as_posix()
)
def test_every_script_starts_and_answers_help_without_running(script, helps):
    """Imports resolve after a move (sys.path included), and --help runs nothing."""
    started = helps[str(script)]
    assert started["code"] == 0, started["stderr"][-2000:]
    assert started["stdout"].startswith("usage:"), started["stdout"][:500]


def test_the_help_driver_reports_a_script_that_cannot_start(tmp_path):
    """A script whose helper is missing (an import that resolved only beside another script)
    fails in the driver as it would on its own."""
    (tmp_path / "one").mkdir()
    (tmp_path / "two").mkdir()
    (tmp_path / "one" / "helper_of_one.py").write_text("NAME = 'one'\n")
    main = "import argparse\nargparse.ArgumentParser().parse_args()\n"
    (tmp_path / "one" / "a.py").write_text("import helper_of_one\n" + main)
    (tmp_path / "two" / "b.py").write_text("import helper_of_one\n" + main)
    driver = ROOT / "tests" / "script_help_driver.py"
    scripts = [str(tmp_path / "one" / "a.py"), str(tmp_path / "two" / "b.py")]
    ran = subprocess.run([sys.executable, str(driver), *scripts], capture_output=True, text=True)
    found = json.loads(ran.stdout)
    assert found[scripts[0]]["code"] == 0 and found[scripts[0]]["stdout"].startswith("usage:")
    assert found[scripts[1]]["code"] == 1
    assert "No module named 'helper_of_one'" in found[scripts[1]]["stderr"]


def test_make_demo_runs_twice(tmp_path):
    """The second ``make demo`` replaces the first's outputs (it refused the directory)."""
    import shutil

    if shutil.which("make") is None:
        pytest.skip("make is not installed")
    scenario = tmp_path / "short.toml"
    scenario.write_text(
        (ROOT / "scenarios" / "passive_current.toml")
        .read_text()
        .replace('"uvms_lbv150"', f'"{ROOT / "models" / "uvms_lbv150.urdf"}"')
        .replace("duration_s = 20.0", "duration_s = 0.1")
    )
    out = tmp_path / "demo"
    command = [
        "make", "-C", str(ROOT), "-o", ".venv/.installed", "-o", ".venv/.installed-base", "demo",
        f"DEMO_SCENARIO={scenario}", f"DEMO_OUT={out}",
    ]  # fmt: skip
    for _ in range(2):
        result = subprocess.run(command, capture_output=True, text=True, timeout=600)
        assert result.returncode == 0, result.stderr
    assert (out / "replay.html").is_file() and (out / "rollout.npz").is_file()


def _benchmarks() -> list:
    return [p for p in _runnable_scripts() if p.parent.name == "benchmarks"]


@pytest.mark.parametrize("script", _benchmarks(), ids=lambda p: p.name)
def test_every_benchmark_runs_to_its_end(script):
    """Each benchmark measured once (``--repeat 1`` where it takes one): a benchmark written
    against an API that has since moved fails here, not at the next `make results` (the
    dynamics benchmark called Plant.advance for four days after the plant stopped stepping
    itself, and docs/results/bench.md was not regenerated)."""
    args = ["--repeat", "1"] if "--repeat" in script.read_text() else []
    ran = subprocess.run(
        [sys.executable, str(script), *args], cwd=ROOT, capture_output=True, text=True,
        timeout=900,
    )  # fmt: skip
    assert ran.returncode == 0, ran.stderr[-3000:]
    assert ran.stdout.strip(), "the benchmark printed nothing"
