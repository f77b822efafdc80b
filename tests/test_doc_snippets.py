"""The doc test's own machinery (tests/doc_snippets.py, tests/doc_snippets_run.py): which
blocks are found, what the directives mean, how console output is matched, and that a
snippet's failure, a false assert or a missing output is reported as a failure."""

from __future__ import annotations

import sys

import pytest
from doc_snippets import (
    DirectiveError,
    Snippet,
    commands,
    console_commands,
    documents,
    output_matches,
    parse_markdown,
)
from doc_snippets_run import run_snippet

DOC = """# Title

```python
x = 1
```

Text.

<!-- doc-test: skip: too long -->
```bash
sleep 1000
```

```toml
a = 1
```

```
plain
```

<!-- doc-test: placeholder: mine.txt = data.txt -->
<!-- doc-test: needs: chromium -->
<!-- doc-test: output: hello -->
<!-- doc-test: assert: y == 2 -->
```python
y = 2
```

~~~console
$ echo hi
hi
~~~
"""


def test_runnable_blocks_and_their_directives_are_found():
    found = parse_markdown(DOC, "doc.md")
    assert [(s.line, s.language) for s in found] == [
        (3, "python"),
        (10, "bash"),
        (26, "python"),
        (30, "console"),
    ]
    assert found[0].code == "x = 1\n" and found[0].skip is None
    assert found[1].skip == "too long"
    last = found[2]
    assert last.placeholders == (("mine.txt", "data.txt"),) and last.needs == ("chromium",)
    assert last.outputs == ("hello",) and last.asserts == ("y == 2",)
    assert Snippet.from_json(last.to_json()) == last


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("<!-- doc-test: skp: typo -->\n```bash\ntrue\n```\n", "not a doc-test directive"),
        ("<!-- doc-test: skip: why -->\n```toml\na = 1\n```\n", "does not run"),
        ("<!-- doc-test: skip: why -->\n\n```bash\ntrue\n```\n", "not right above"),
        ("<!-- doc-test: assert: 1 -->\n```bash\ntrue\n```\n", "only for python"),
        ("<!-- doc-test: needs: gpu -->\n```bash\ntrue\n```\n", "needs: one of"),
        ("<!-- doc-test: placeholder: a.txt -->\n```bash\ntrue\n```\n", "NAME = STAND-IN"),
        ("<!-- doc-test: skip: -->\n```bash\ntrue\n```\n", "needs a value"),
    ],
)
def test_bad_directives_are_errors_naming_the_line(text, match):
    with pytest.raises(DirectiveError, match=match):
        parse_markdown(text, "doc.md")


def test_a_directive_mentioned_inline_is_not_one():
    assert parse_markdown("Write `<!-- doc-test: skip: REASON -->` above.\n", "d.md") == []


def test_console_blocks_split_into_commands_and_shown_output():
    code = "$ echo a \\\n  b\na b\n$ true\n$ printf 'x\\ny\\n'\nx\n...\n"
    assert console_commands(code) == [
        ("echo a \\\n  b", "a b"),
        ("true", ""),
        ("printf 'x\\ny\\n'", "x\n..."),
    ]
    with pytest.raises(DirectiveError, match="before the first"):
        console_commands("output\n$ true\n")


@pytest.mark.parametrize(
    ("shown", "printed", "matches"),
    [
        ("a = 1\nb = 2", "a = 1  \nb = 2\n\n", True),
        ("a = ...\nb = 2", "a = 3.14\nb = 2\n", True),
        ("...\nlast", "first\nsecond\nlast\n", True),
        ("a = 1", "a = 1\nextra\n", False),
        ("a = 1.0", "a = 1.05\n", False),
        ("x (0.31) mm", "x (0.31) mm\n", True),  # regex characters are literal
        ("x (0.31) mm", "x 0.31 mm\n", False),
    ],
)
def test_console_output_matching(shown, printed, matches):
    assert output_matches(shown, printed) is matches


def _snippet(language: str, code: str, **kw) -> Snippet:
    return Snippet("doc.md", 1, language, code, **kw)


def test_a_snippet_passes_only_if_it_runs_and_its_checks_hold(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "data.txt").write_text("stand-in\n")
    namespace: dict = {}
    ok = run_snippet(
        _snippet(
            "python",
            "print(open('mine.txt').read().strip())\ny = 2\n",
            placeholders=(("mine.txt", "data.txt"),),
            outputs=("stand-in",),
            asserts=("y == 2",),
        ),
        namespace,
    )
    assert ok["status"] == "passed", ok
    assert namespace["y"] == 2  # the document's blocks share it
    false = run_snippet(_snippet("python", "z = 1\n", asserts=("z == 2",)), namespace)
    assert false["status"] == "failed" and false["problems"] == ["assert: z == 2 is false"]
    raised = run_snippet(_snippet("python", "raise SystemExit(3)\n"), namespace)
    assert raised["status"] == "failed" and "SystemExit" in raised["stderr"]
    silent = run_snippet(_snippet("bash", "echo bye\n", outputs=("hello",)), namespace)
    assert silent["problems"] == ["output: 'hello' not printed"]


def test_a_bash_block_stops_at_its_first_failing_command(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = run_snippet(_snippet("bash", "false\ntouch after\n"), {})
    assert result["status"] == "failed" and "[exit status 1]" in result["stderr"]
    assert not (tmp_path / "after").exists()


def test_a_console_block_must_print_what_it_shows(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert run_snippet(_snippet("console", "$ echo 4.44e-16\n4.44e-16\n"), {})["status"] == (
        "passed"
    )
    wrong = run_snippet(_snippet("console", "$ echo 4.44e-16\n2.22e-16\n"), {})
    assert wrong["status"] == "failed" and "but it printed" in wrong["stderr"]


def test_an_old_module_path_fails_a_block(tmp_path, monkeypatch):
    """The module paths from before the layers are gone (CHANGELOG.md): a block using one
    fails."""
    monkeypatch.chdir(tmp_path)
    python = sys.executable
    new = run_snippet(_snippet("bash", f"{python} -c 'import uvms_pin.apps.gym'\n"), {})
    assert new["status"] == "passed", new
    old = run_snippet(_snippet("bash", f"{python} -c 'import uvms_pin.gym'\n"), {})
    assert old["status"] == "failed" and "No module named 'uvms_pin.gym'" in old["stderr"]


def test_commands_leave_out_comments_prompts_and_shown_output():
    bash = _snippet(
        "bash", "uvms-pin sweep a.toml \\\n    --out out/a   # or: --scheduler X\n\n# note\n"
    )
    same = _snippet("bash", "uvms-pin sweep a.toml --out out/a\n")
    assert commands(bash) == commands(same) == [["uvms-pin", "sweep", "a.toml", "--out", "out/a"]]
    console = _snippet("console", "$ echo 'a b'  # says a b\na b (it's printed)\n")
    assert commands(console) == [["echo", "a b"]]
    found = parse_markdown("<!-- doc-test: same-as: docs/x.md -->\n```bash\ntrue\n```\n", "d.md")
    assert found[0].same_as == "docs/x.md" and found[0].skip is None


def test_every_markdown_file_of_the_repository_is_a_document(tmp_path):
    """A Markdown file a later change adds anywhere is run too (README first, then docs/,
    then the rest); generated results, hidden folders, environments and outputs are not."""
    for name in [
        "README.md", "docs/b.md", "docs/a.md", "models/README.md", "benchmarks/NOTES.md",
        "docs/results/paper.md", "docs/deeper/c.md", ".github/x.md", ".venv/lib/y.md",
        "out/run/z.md", "pkg.egg-info/w.md", "src/uvms_core/notes.txt",
    ]:  # fmt: skip
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("# x\n")
    assert documents(tmp_path) == [
        "README.md", "docs/a.md", "docs/b.md",
        "benchmarks/NOTES.md", "docs/deeper/c.md", "models/README.md",
    ]  # fmt: skip
