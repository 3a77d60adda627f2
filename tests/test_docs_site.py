"""The documentation site builds with warnings as errors (``mkdocs build --strict``), has the
pages it promises, and strict mode does catch a broken link; the hook's link rewriting."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
MISSING = [m for m in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")
           if importlib.util.find_spec(m.split(".")[0]) is None]
pytestmark = pytest.mark.skipif(bool(MISSING), reason=f"docs extra not installed ({', '.join(MISSING)}): "
                                                      "pip install -e '.[docs]'")
ENV = {**os.environ, "NO_MKDOCS_2_WARNING": "1", "MPLBACKEND": "Agg"}


def _build(config: Path, site: Path):
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)],
                          cwd=REPO, env=ENV, capture_output=True, text=True, timeout=1200)


@pytest.mark.slow
def test_site_builds_strictly_with_every_promised_page(tmp_path):
    site = tmp_path / "site"
    proc = _build(REPO / "mkdocs.yml", site)
    assert proc.returncode == 0, proc.stderr[-4000:]
    pages = {p: (site / p / "index.html") for p in ("gallery", "reproductions", "validation", "api", "changelog",
                                                    "components", "ships-mmg", "trials")}
    for name, path in pages.items():
        assert path.exists(), name
    home = (site / "index.html").read_text(encoding="utf-8")
    assert "Quick start" in home and 'href="reproductions/"' in home
    repro = pages["reproductions"].read_text(encoding="utf-8")
    assert "Zwierzewicz" in repro and "Morawski" in repro and "Table 5" in repro
    assert "KVLCC2" in pages["validation"].read_text(encoding="utf-8")
    api = pages["api"].read_text(encoding="utf-8")
    for name in ("simulate", "simulate_batch", "vary", "controller", "ship", "linearize", "register_ship",
                 "register_controller", "load_scenario", "default_scenario", "check_controller", "Layout"):
        assert f'id="steerlab.' in api and re.search(rf'id="steerlab\.[\w.]*\b{name}"', api), name
    assert not re.search(r":(class|func|meth):<code>", api)        # reST roles shown as code
    gallery = pages["gallery"].read_text(encoding="utf-8")
    scripts = sorted((REPO / "examples").glob("[0-9][0-9]_*.py"))
    for s in scripts:
        png = site / "gallery" / f"{s.stem}.png"
        if s.name == "10_rl_episode.py" and importlib.util.find_spec("gymnasium") is None:
            assert "gymnasium is not installed" in gallery
            continue
        assert f'src="{s.stem}.png"' in gallery, s.name
        assert png.exists() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000


@pytest.mark.slow
def test_strict_mode_refuses_a_broken_link(tmp_path):
    # the same configuration on a copy of docs/ with one page that links to nothing
    docs = tmp_path / "docs"
    subprocess.run(["cp", "-r", str(REPO / "docs"), str(docs)], check=True)
    (docs / "broken.md").write_text("# Broken\n\nSee [a page that does not exist](no-such-page.md).\n")
    cfg = (REPO / "mkdocs.yml").read_text(encoding="utf-8")
    cfg = cfg.replace("docs_dir: docs", f"docs_dir: {docs}").replace("- tools/docs_hooks.py",
                                                                      f"- {REPO / 'tools' / 'docs_hooks.py'}")
    cfg = cfg.replace("  - Changelog: changelog.md", "  - Changelog: changelog.md\n  - Broken: broken.md")
    config = tmp_path / "mkdocs.yml"
    config.write_text(cfg)
    proc = _build(config, tmp_path / "site")
    assert proc.returncode != 0
    assert "no-such-page.md" in proc.stderr


def _hooks():
    from conftest import import_tool

    return import_tool("docs_hooks")


def test_links_to_repository_files_go_to_the_repository_and_docs_links_stay_pages():
    h = _hooks()
    url = "https://github.com/steerlab/steerlab"
    text = ("[a](docs/trials.md#figures) [b](examples/README.md) [c](src/steerlab/records.py) "
            "[d](https://x.org/y.md) [e](#usage) [f](examples/user_plugin/)\n"
            "```\n[not a link](src/x.py)\n```\n")
    out = h.rewrite_links(text, h.REPO, h.DOCS, url)
    assert "[a](trials.md#figures)" in out
    assert "[b](gallery.md)" in out
    assert f"[c]({url}/blob/main/src/steerlab/records.py)" in out
    assert "[d](https://x.org/y.md)" in out and "[e](#usage)" in out
    assert f"[f]({url}/tree/main/examples/user_plugin)" in out
    assert "[not a link](src/x.py)" in out                    # code fences untouched
    # from a page inside docs/: ../examples/... goes to the repository
    out = h.rewrite_links("[p](../examples/user_plugin/) [q](ships.md)", h.DOCS, h.DOCS, url)
    assert out == f"[p]({url}/tree/main/examples/user_plugin) [q](ships.md)"


def test_sections_are_cut_at_the_next_heading_of_the_same_level():
    h = _hooks()
    text = "# T\n## A\na\n### A1\n```\n## not a heading\n```\nx\n## B\nb\n"
    before, sec, after = h.split_section(text, "## A")
    assert before == "# T\n" and after == "## B\nb\n"
    assert "### A1" in sec and "## not a heading" in sec
    assert h.shift_headings(sec, -1).startswith("# A\na\n## A1\n")
    with pytest.raises(Exception, match="not found"):
        h.split_section(text, "## C")
