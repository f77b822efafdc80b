"""MkDocs hook: the API reference, generated from the package when the site is built.

One page per layer of ``uvms_pin`` (each top-level package or module), rendering every
public module in it with mkdocstrings, and an index naming the public names of ``up``
(``import uvms_pin as up``) with a link to each. A module added to the package appears by
itself; a package added at the top level gets its page and its line in the navigation.
GitHub anchors for headings (``slugify``): the links of the pages resolve the same way on
GitHub (tests/test_docs.py) and on the site.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

from markdown.inlinepatterns import ReferenceInlineProcessor
from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "uvms_pin"
REFERENCE = "reference"
#: the entry of mkdocs.yml's nav that the generated pages replace
NAV_ENTRY = f"{REFERENCE}/index.md"


def slugify(value: str, separator: str = "-") -> str:
    """A heading's anchor as GitHub makes it: lower case, punctuation dropped, each space a
    hyphen (runs of hyphens kept: ``a --b`` -> ``a---b``)."""
    return re.sub(r"[^\w\- ]", "", value.strip().lower()).replace(" ", separator)


def layers() -> list[str]:
    """The top-level packages and public modules of uvms_pin, by name."""
    names = [p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()]
    names += [p.stem for p in PACKAGE.glob("*.py") if not p.stem.startswith("_")]
    return sorted(names)


def modules(layer: str) -> list[str]:
    """The dotted paths of a layer's public modules, the package first, in path order."""
    top = PACKAGE / layer
    if not top.is_dir():
        return [f"uvms_pin.{layer}"]
    found = []
    for path in sorted(top.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if any(part.startswith("_") and part != "__init__" for part in parts):
            continue
        found.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return sorted(found, key=lambda name: (name.count(".") > 1, name))


def public_names() -> dict[str, str]:
    """The names of ``up`` -> the module defining each (read from uvms_pin/__init__.py)."""
    tree = ast.parse((PACKAGE / "__init__.py").read_text())
    found: dict[str, str] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and "._" not in node.module:
            found.update({alias.name: node.module for alias in node.names})
        elif isinstance(node, ast.Call) and getattr(node.func, "id", "") == "lazy_exports":
            table = node.args[1]
            assert isinstance(table, ast.Dict)
            for key, value in zip(table.keys, table.values, strict=True):
                module = ast.literal_eval(key)
                found.update({name: module for name in ast.literal_eval(value)})
    return dict(sorted(found.items(), key=lambda item: item[0].lower()))


def layer_page(layer: str) -> str:
    """A package shows its docstring alone: its names are those of its modules (re-exported),
    each shown once, where it is defined."""
    lines = [f"# `uvms_pin.{layer}`", ""]
    for module in modules(layer):
        package = (PACKAGE.parent / module.replace(".", "/")).is_dir()
        lines += [f"::: {module}", *(["    options:", "      members: false"] * package), ""]
    return "\n".join(lines)


def index_page() -> str:
    lines = [
        "# API reference",
        "",
        "Every public module of `uvms_pin`, one page per layer, from the docstrings (the",
        "[short API guide](../api.md) shows them at work; [Architecture](../architecture.md)",
        "explains the layers). The names of `up` (`import uvms_pin as up`):",
        "",
        "| name | defined in |",
        "|---|---|",
    ]
    for name, module in public_names().items():
        layer = module.split(".")[1]
        lines.append(f"| [`up.{name}`][{module}.{name}] | [`{module}`]({layer}.md) |")
    lines += ["", "The layers:", ""]
    lines += [f"- [`uvms_pin.{layer}`]({layer}.md)" for layer in layers()]
    return "\n".join(lines) + "\n"


def on_config(config):
    """GitHub's anchors for headings, GitHub's reference links (below); the nav's reference
    entry becomes the layer pages."""
    config.mdx_configs.setdefault("toc", {})["slugify"] = slugify
    # CommonMark (GitHub): no space between a link's text and its label, so `x[1] [m]` (an
    # index, then a unit) stays text, as on GitHub; Python-Markdown would read a reference
    # link there (and mkdocstrings a cross-reference to "m")
    ReferenceInlineProcessor.RE_LINK = re.compile(r"\[([^\]]*)\]", re.DOTALL | re.UNICODE)
    pages = [{"Overview": NAV_ENTRY}]
    pages += [{f"uvms_pin.{layer}": f"{REFERENCE}/{layer}.md"} for layer in layers()]

    def expand(items):
        for i, item in enumerate(items):
            if isinstance(item, dict):
                ((title, value),) = item.items()
                if value == NAV_ENTRY:
                    items[i] = {title: pages}
                elif isinstance(value, list):
                    expand(value)

    expand(config.nav or [])
    return config


def on_files(files: Files, config) -> Files:
    files.append(File.generated(config, NAV_ENTRY, content=index_page()))
    for layer in layers():
        files.append(File.generated(config, f"{REFERENCE}/{layer}.md", content=layer_page(layer)))
    return files
