"""The code blocks of the documentation as the doc test runs them (tests/test_docs_run.py).

Every fenced block of README.md, docs/*.md and the other Markdown files (`documents`)
whose language is ``python``, ``bash`` (``sh``, ``shell``) or ``console`` is a snippet: it
runs as written, in document order, the documents one after the other, in one fresh working
copy of the repository (its outputs never meet a developer's ``out/``). The python blocks of one
document share one namespace, as in one interpreter session. A ``console`` block shows
commands (``$ ...``) and what they print: the printed text must match, ``...`` standing
for any text.

Long runs are shortened by one mechanism, the package's own: ``UVMS_PIN_MAX_DURATION_S``
(`uvms_pin.sim.shortened`) is set to `CAP_S` for every snippet, and every shortened run
says so in its output.

Directives are HTML comments on the lines right above a block's opening fence (invisible
on GitHub, visible in the source), one per line:

    <!-- doc-test: skip: REASON -->                 not run; the reason is listed
    <!-- doc-test: needs: chromium -->              skipped, with the reason, when absent
    <!-- doc-test: needs: network -->
    <!-- doc-test: placeholder: NAME = STAND-IN --> NAME is a file the reader supplies; the
                                                    test copies STAND-IN (in the repository)
                                                    there first, and lists it
    <!-- doc-test: output: TEXT -->                 TEXT appears in what the block prints
    <!-- doc-test: assert: EXPRESSION -->           python: true in the block's namespace
                                                    after it ran (a number the text quotes)
    <!-- doc-test: same-as: DOC -->                 not run: a block of DOC runs the same
                                                    commands (comments aside; checked)

An unknown directive, or one that is not right above a runnable block, is an error.
"""

from __future__ import annotations

import os
import re
import shlex
from dataclasses import asdict, dataclass
from pathlib import Path

#: the cap on every scenario run's simulated duration [s] while the snippets run
CAP_S = "2"

#: fence language -> how the block runs
LANGUAGES = {
    "python": "python",
    "bash": "bash",
    "sh": "bash",
    "shell": "bash",
    "console": "console",
}
DIRECTIVES = ("skip", "needs", "placeholder", "output", "assert", "same-as")
NEEDS = ("chromium", "network")

_FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>`{3,}|~{3,})\s*(?P<info>[^`\s]*)")
_DIRECTIVE = re.compile(r"^\s*<!--\s*doc-test:\s*(?P<kind>[\w-]+)\s*:\s*(?P<value>.*?)\s*-->\s*$")
_ANY_DIRECTIVE = re.compile(r"^\s*<!--\s*doc-test\b")


@dataclass(frozen=True)
class Snippet:
    """One runnable block: where it is, how it runs and what its directives ask.

    Attributes:
        doc: the document, relative to the repository. line: its opening fence (1-based).
        language: "python", "bash" or "console". code: the block's text.
        skip: why it is not run (None: it runs). needs: "chromium" / "network".
        placeholders: (file the reader supplies, the repository file standing in for it).
        outputs: texts its output contains. asserts: python expressions that hold after it.
        same_as: a document with a block of the same commands, run instead of this one.
    """

    doc: str
    line: int
    language: str
    code: str
    skip: str | None = None
    needs: tuple[str, ...] = ()
    placeholders: tuple[tuple[str, str], ...] = ()
    outputs: tuple[str, ...] = ()
    asserts: tuple[str, ...] = ()
    same_as: str | None = None

    @property
    def id(self) -> str:
        return f"{self.doc}:{self.line}"

    def to_json(self) -> dict:
        return asdict(self)

    @classmethod
    def from_json(cls, data: dict) -> Snippet:
        data = dict(data)
        data["needs"] = tuple(data["needs"])
        data["placeholders"] = tuple(tuple(p) for p in data["placeholders"])
        data["outputs"], data["asserts"] = tuple(data["outputs"]), tuple(data["asserts"])
        return cls(**data)


class DirectiveError(ValueError):
    """A doc-test directive that is unknown, malformed or not above a runnable block."""


#: folders whose Markdown is not documentation a reader follows: generated results (their
#: numbers come from `make results`), environments, outputs, build trees
NOT_DOCUMENTS = ("docs/results", ".venv", "out", "build", "node_modules")


def documents(root: Path) -> list[str]:
    """The documents, in the order they run: README.md, docs/*.md, then every other
    Markdown file of the repository (models/README.md, and whatever a later change adds),
    each group sorted; hidden folders and `NOT_DOCUMENTS` aside."""
    found = []
    for folder, subfolders, files in os.walk(root):
        here = Path(folder).relative_to(root).as_posix()
        subfolders[:] = sorted(
            name
            for name in subfolders
            if not name.startswith(".")
            and not name.endswith(".egg-info")
            and (Path(here) / name).as_posix().removeprefix("./") not in NOT_DOCUMENTS
        )
        found += [(Path(here) / name).as_posix().removeprefix("./") for name in files if name.endswith(".md")]  # fmt: skip
    docs = sorted(name for name in found if name.startswith("docs/") and name.count("/") == 1)
    others = sorted(name for name in found if name != "README.md" and name not in docs)
    return ["README.md", *docs, *others]


def all_snippets(root: Path) -> list[Snippet]:
    return [s for doc in documents(root) for s in parse_markdown((root / doc).read_text(), doc)]


def parse_markdown(text: str, doc: str) -> list[Snippet]:
    """The runnable blocks of one Markdown text, with their directives.

    Raises:
        DirectiveError: naming ``doc`` and the line.
    """
    lines = text.splitlines()
    snippets, used = [], set()
    number = 0
    while number < len(lines):
        opening = _FENCE.match(lines[number])
        if not opening:
            number += 1
            continue
        end = _closing_line(lines, number, opening.group("fence"))
        language = opening.group("info").lower()
        directives, where = _directives_above(lines, number, doc)
        used |= where
        if language in LANGUAGES:
            code = "\n".join(lines[number + 1 : end]) + "\n"
            snippets.append(_snippet(doc, number + 1, LANGUAGES[language], code, directives))
        elif directives:
            raise DirectiveError(f"{doc}:{number + 1}: doc-test directives above a block that does not run ({language or 'no language'})")  # fmt: skip
        number = end + 1
    orphans = [i + 1 for i, line in enumerate(lines) if _ANY_DIRECTIVE.search(line) and i not in used]  # fmt: skip
    if orphans:
        raise DirectiveError(f"{doc}: doc-test directives not right above a code block, lines {orphans}")  # fmt: skip
    return snippets


def _closing_line(lines: list[str], opening: int, fence: str) -> int:
    for number in range(opening + 1, len(lines)):
        stripped = lines[number].strip()
        if stripped.startswith(fence[0] * len(fence)) and not stripped.strip(fence[0]):
            return number
    return len(lines)


def _directives_above(lines: list[str], fence: int, doc: str) -> tuple[list[tuple], set[int]]:
    found, where = [], set()
    number = fence - 1
    while number >= 0 and _ANY_DIRECTIVE.search(lines[number]):
        match = _DIRECTIVE.match(lines[number])
        if not match or match.group("kind") not in DIRECTIVES:
            raise DirectiveError(
                f"{doc}:{number + 1}: not a doc-test directive: {lines[number].strip()!r} "
                f"(<!-- doc-test: KIND: VALUE -->, KIND one of {', '.join(DIRECTIVES)})"
            )
        found.append((number + 1, match.group("kind"), match.group("value")))
        where.add(number)
        number -= 1
    return found[::-1], where


def _snippet(doc: str, line: int, language: str, code: str, directives: list[tuple]) -> Snippet:
    fields: dict = {"needs": [], "placeholders": [], "outputs": [], "asserts": []}
    for at, kind, value in directives:
        where = f"{doc}:{at}"
        if not value:
            raise DirectiveError(f"{where}: doc-test {kind} needs a value")
        if kind in ("skip", "same-as"):
            fields[kind.replace("-", "_")] = value
        elif kind == "needs":
            if value not in NEEDS:
                raise DirectiveError(f"{where}: needs: one of {', '.join(NEEDS)}, got {value!r}")
            fields["needs"].append(value)
        elif kind == "placeholder":
            name, _, stand_in = (part.strip() for part in value.partition("="))
            if not (name and stand_in):
                raise DirectiveError(f"{where}: placeholder: NAME = STAND-IN, got {value!r}")
            fields["placeholders"].append((name, stand_in))
        elif kind == "assert" and language != "python":
            raise DirectiveError(f"{where}: assert: only for python blocks")
        else:
            fields[f"{kind}s"].append(value)
    return Snippet(doc, line, language, code, **{k: tuple(v) if isinstance(v, list) else v for k, v in fields.items()})  # fmt: skip


# ---- console blocks ---------------------------------------------------------------------
def console_commands(code: str) -> list[tuple[str, str]]:
    """(command, the output shown under it) for each ``$ command`` of a console block; a
    command line ending in a backslash continues on the next line."""
    steps: list[tuple[str, list[str]]] = []
    continuing = False
    for line in code.splitlines():
        if continuing:
            steps[-1] = (steps[-1][0] + "\n" + line, steps[-1][1])
        elif line.startswith("$ "):
            steps.append((line[2:], []))
        elif steps:
            steps[-1][1].append(line)
        elif line.strip():
            raise DirectiveError(f"console block: output before the first '$ ' command: {line!r}")
        continuing = bool(steps) and not steps[-1][1] and line.endswith("\\")
    return [(command, "\n".join(shown)) for command, shown in steps]


def output_matches(shown: str, printed: str) -> bool:
    """Whether ``printed`` is what ``shown`` shows: the same lines (trailing spaces and
    blank lines at either end aside), ``...`` standing for any text, across lines too."""

    def tidy(text: str) -> str:
        return "\n".join(line.rstrip() for line in text.strip("\n").splitlines())

    pattern = ".*?".join(re.escape(part) for part in tidy(shown).split("..."))
    return re.fullmatch(pattern, tidy(printed), flags=re.DOTALL) is not None


def commands(snippet: Snippet) -> list[list[str]]:
    """A shell or console block's commands as words: comments, prompts, the output a
    console block shows and line continuations aside."""
    if snippet.language == "console":
        texts = [command for command, _ in console_commands(snippet.code)]
    else:
        texts = [snippet.code]
    lines = (line for text in texts for line in text.replace("\\\n", " ").splitlines())
    return [words for words in (shlex.split(line, comments=True) for line in lines) if words]
