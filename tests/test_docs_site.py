"""The documentation site builds with --strict (`make docs`): every page of docs/ in the
navigation, no broken link or anchor, every docstring of the API reference readable; and
nothing in it is fetched from the network."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
import yaml
from conftest import ROOT

DOCS = ROOT / "docs"


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The site, built once into a temporary directory (the checkout's site/ untouched)."""
    out = tmp_path_factory.mktemp("site")
    built = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    assert built.returncode == 0, built.stderr[-6000:]
    return out


def _nav_files(items) -> list[str]:
    found = []
    for item in items:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        found += _nav_files(value) if isinstance(value, list) else [value]
    return found


def _config() -> dict:
    class Loader(yaml.SafeLoader):
        pass

    Loader.add_multi_constructor("!", lambda loader, suffix, node: None)
    return yaml.load((ROOT / "mkdocs.yml").read_text(), Loader=Loader)


def test_every_page_of_docs_is_in_the_navigation():
    """The build warns about an omitted page too; this names it without building."""
    listed = set(_nav_files(_config()["nav"]))
    pages = {p.name for p in DOCS.glob("*.md")}
    assert not pages - listed, f"add to mkdocs.yml's nav: {sorted(pages - listed)}"
    assert not {p for p in listed if not p.startswith("reference/")} - pages


def test_the_site_builds_strictly_with_every_page_and_the_api_reference(site):
    assert (site / "index.html").is_file() and (site / "search" / "search_index.json").is_file()
    for page in DOCS.glob("*.md"):
        name = "index" if page.stem == "README" else page.stem
        assert (site / f"{name}.html").is_file(), name
    reference = (site / "reference" / "physics.html").read_text()
    # a function of the public API, rendered from its docstring with its signature
    assert 'id="uvms_pin.physics.dynamics.mass_matrix"' in reference
    figures = {p.name for p in DOCS.glob("*.png")}
    assert figures <= {p.name for p in site.glob("*.png")}


def test_the_site_loads_nothing_from_the_network(site):
    """No font, script or style from another host: the site reads offline."""
    remote = re.compile(r"""<(?:script|link)[^>]+(?:src|href)=["']https?://""")
    offenders = [
        str(page.relative_to(site))
        for page in site.rglob("*.html")
        if remote.search(page.read_text())
    ]
    assert not offenders, offenders[:5]


def test_the_doc_test_directives_do_not_show_on_the_site(site):
    """The doc-test directives are HTML comments: hidden on the site as on GitHub."""
    page = (site / "getting_started.html").read_text()
    assert "<!-- doc-test:" in page
    assert "doc-test" not in re.sub(r"<!--.*?-->", "", page, flags=re.DOTALL)


def test_the_readme_stays_an_introduction():
    """At most 250 lines, the two set-up commands, and links into the site's pages."""
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 250
    assert "make demo" in text and "make test" in text
    linked = set(re.findall(r"\]\(docs/(\w+)\.md", text))
    assert {"getting_started", "reproduce", "scenarios", "api"} <= linked, linked
