"""MkDocs hooks of steerlab's documentation site (``mkdocs.yml``: ``hooks:``).

The site is built from files that live elsewhere in the repository, so that nothing is copied
by hand and nothing goes stale:

* ``index.md``: the README (its Reproductions section moves to its own page);
* ``reproductions.md``: the README's "Reproductions" section;
* ``validation.md``: the KVLCC2 validation of ``docs/ships-mmg.md`` and the cross-checks the
  test suite makes against independent references;
* ``gallery.md``: one section per ``examples/NN_*.py`` script (its docstring and its figure)
  and ``examples/README.md``. The figures are drawn during the build by running each script
  with ``--quick`` (in parallel); the runs are kept in ``out/docs-gallery/`` (or
  ``$STEERLAB_DOCS_GALLERY_CACHE``) under a key of the script, the examples' files and the
  library source (``tools/gallery_runs.py``, shared with the gallery tests), so a build after a
  docs-only change, or after the test suite, runs nothing;
* ``changelog.md``: ``CHANGELOG.md``.

Docstrings: reST roles (``:class:`X```) are shown as code (``on_page_content``).

Links: a relative link in any page that points at a repository file outside ``docs/`` (a
source file, ``examples/...``) becomes a link to that file in the public repository
(``repo_url`` of ``mkdocs.yml``); README links into ``docs/`` become links between pages.
"""

from __future__ import annotations

import ast
import concurrent.futures
import os
import re
import sys
from pathlib import Path, PurePosixPath

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File

sys.path.insert(0, str(Path(__file__).resolve().parent))
import gallery_runs  # noqa: E402  (tools/gallery_runs.py, shared with the tests)
from gallery_runs import gallery_scripts  # noqa: E402,F401

REPO = Path(__file__).resolve().parent.parent
EXAMPLES = REPO / "examples"
DOCS = REPO / "docs"
BRANCH = "main"

# repository files that are pages of the site under another name
PAGES_FOR = {"examples/README.md": "gallery.md", "README.md": "index.md", "CHANGELOG.md": "changelog.md"}

_LINK = re.compile(r"(!?\[[^\]]*\]\()([^)\s]+)(\))")


# ----------------------------------------------------------------- links
def _repo_url(config) -> str:
    return (config.get("repo_url") or "https://github.com/steerlab/steerlab").rstrip("/")


def rewrite_links(text: str, base: Path, page_dir: Path, repo_url: str) -> str:
    """Relative links of a Markdown text written at ``base`` (a directory of the repository),
    for a page that lives at ``page_dir`` (inside ``docs/``): links to Markdown files in
    ``docs/`` stay relative links between pages; links to other repository files go to the
    public repository."""

    def fix(m):
        target = m.group(2)
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("#", "/")):
            return m.group(0)
        path, _, anchor = target.partition("#")
        if not path:
            return m.group(0)
        resolved = (base / path).resolve()
        try:
            rel_repo = resolved.relative_to(REPO)
        except ValueError:
            return m.group(0)
        page = PAGES_FOR.get(str(PurePosixPath(rel_repo)))
        if page is not None:
            new = os.path.relpath(DOCS / page, page_dir).replace(os.sep, "/")
        elif resolved.is_relative_to(DOCS) and resolved.suffix == ".md" and resolved.exists():
            new = os.path.relpath(resolved, page_dir).replace(os.sep, "/")
        else:
            kind = "tree" if resolved.is_dir() else "blob"
            new = f"{repo_url}/{kind}/{BRANCH}/{PurePosixPath(rel_repo)}"
        return f"{m.group(1)}{new}{'#' + anchor if anchor else ''}{m.group(3)}"

    out, fenced = [], False
    for line in text.splitlines(keepends=True):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        out.append(line if fenced else _LINK.sub(fix, line))
    return "".join(out)


# ----------------------------------------------------------------- sections
def split_section(text: str, heading: str) -> tuple[str, str, str]:
    """``(before, section, after)``: the section that starts at the line ``heading`` and ends
    at the next heading of the same or a higher level (outside code fences)."""
    lines = text.splitlines(keepends=True)
    level = len(heading) - len(heading.lstrip("#"))
    start = end = None
    fenced = False
    for i, line in enumerate(lines):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            continue
        if start is None and line.rstrip() == heading:
            start = i
        elif start is not None and line.startswith("#"):
            lev = len(line) - len(line.lstrip("#"))
            if lev <= level and line[lev:lev + 1] == " ":
                end = i
                break
    if start is None:
        raise PluginError(f"docs hook: heading {heading!r} not found")
    end = len(lines) if end is None else end
    return "".join(lines[:start]), "".join(lines[start:end]), "".join(lines[end:])


def shift_headings(text: str, by: int) -> str:
    """Every Markdown heading (outside code fences) ``by`` levels up (< 0) or down (> 0)."""
    out, fenced = [], False
    for line in text.splitlines(keepends=True):
        if line.lstrip().startswith("```"):
            fenced = not fenced
        elif not fenced and re.match(r"^#{1,6} ", line):
            lev = len(line) - len(line.lstrip("#"))
            line = "#" * min(6, max(1, lev + by)) + line[lev:]
        out.append(line)
    return "".join(out)


# ----------------------------------------------------------------- pages
def page_index(repo_url: str) -> str:
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    before, _, after = split_section(readme, "## Reproductions")
    text = rewrite_links(before + "<<REPRODUCTIONS>>" + after, REPO, DOCS, repo_url)
    text = text.replace("<<REPRODUCTIONS>>", "## Reproductions\n\nThe papers steerlab reproduces, next to the "
                        "published numbers with the gaps explained: [Paper reproductions](reproductions.md).\n\n")
    return text.replace("](#reproductions)", "](reproductions.md)")


def page_reproductions(repo_url: str) -> str:
    _, section, _ = split_section((REPO / "README.md").read_text(encoding="utf-8"), "## Reproductions")
    section = shift_headings(section, -1).replace("# Reproductions", "# Paper reproductions", 1)
    return rewrite_links(section, REPO, DOCS, repo_url)


VALIDATION_INTRO = """# Validation

What steerlab checks against references it did not write. The paper reproductions (each paper's
numbers next to steerlab's) are on [their own page](reproductions.md); here: a ship model
against an independent implementation of the same method, and the cross-checks the test suite
makes on every run of it.

## Cross-checks in the test suite

| what | reference | where |
|---|---|---|
| step metrics (overshoot, rise, settling) of the calm default run (`examples/scenarios/calm_default.toml`) | python-control's `step_info` | `tests/test_metrics.py` |
| the `lq_pd` gains | python-control's `lqr` | [PID-family controllers](controllers-pid.md) |
| a controller object stepped along an engine run | the engine's own rudder orders, bit for bit | [Components](components.md) |
| readable, compiled and batch engines | each other, bit for bit | [Architecture](architecture.md) |
| turning circle of a first-order Nomoto ship | the closed forms `r = K delta`, `D = 2U/(K delta)` | [Trials](trials.md) |
| reversed spiral against pull-out (Esso, 16 kn) | each other, residual rates within 1 % | [Trials](trials.md) |

"""


def page_validation(repo_url: str) -> str:
    text = (DOCS / "ships-mmg.md").read_text(encoding="utf-8")
    _, kv, _ = split_section(text, "## The MMG standard method (`ship.model = \"kvlcc2\"`, `\"kvlcc2-l7\"`)")
    kv = kv.replace("## The MMG standard method", "## KVLCC2 on the MMG standard method", 1)
    kv += "\nThe whole MMG chapter: [MMG ships](ships-mmg.md).\n"
    return VALIDATION_INTRO + rewrite_links(kv, DOCS, DOCS, repo_url)


def page_changelog(repo_url: str) -> str:
    return rewrite_links((REPO / "CHANGELOG.md").read_text(encoding="utf-8"), REPO, DOCS, repo_url)


# ----------------------------------------------------------------- gallery
def _run_script(script: Path) -> tuple[Path, Path | None, str]:
    """``(script, figure or None, note)`` of the script's ``--quick`` run (:mod:`gallery_runs`:
    stored under a key of its sources, shared with the test suite)."""
    run = gallery_runs.run_script(script)
    if run.returncode != 0:
        raise PluginError(f"docs gallery: {script.name} failed (exit {run.returncode}):\n{run.stderr[-2000:]}")
    if run.png is None:                     # the script skipped itself (an optional extra missing)
        return script, None, run.stdout.strip()
    return script, run.png, ""


def gallery_figures() -> dict[str, tuple[Path | None, str]]:
    """``{script name: (figure or None, note)}``, running the scripts whose figure is stale."""
    scripts = gallery_scripts()
    workers = max(1, min(len(scripts), os.cpu_count() or 1))
    # each script's run is locked on its own (gallery_runs): two builds, or a build and the
    # gallery tests, run every script once between them
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        done = list(pool.map(_run_script, scripts))
    return {s.name: (png, note) for s, png, note in done}


def _docstring(script: Path) -> tuple[str, str]:
    doc = ast.get_docstring(ast.parse(script.read_text(encoding="utf-8"))) or script.stem
    title, _, body = doc.partition("\n")
    return title.strip().rstrip("."), body.strip()


def page_gallery(figures: dict, repo_url: str) -> str:
    parts = ["# Examples gallery\n\n",
             "Each script in [`examples/`](https://github.com/steerlab/steerlab/tree/main/examples) "
             "runs from the repository root (`python3 examples/NN_name.py [--quick] [--out DIR]`) "
             "and writes one figure. The figures below were drawn while this site was built, by the "
             "scripts' `--quick` runs (shorter simulations than the full runs); the test suite runs "
             "every script too (`tests/test_examples_gallery.py`).\n\n"]
    for script in gallery_scripts():
        title, body = _docstring(script)
        png, note = figures[script.name]
        parts.append(f"## {script.stem[:2]}. {title}\n\n{body}\n\n")
        if png is not None:
            parts.append(f"![{title}](gallery/{script.stem}.png)\n\n")
        else:
            parts.append(f"!!! note \"No figure in this build\"\n    {note}\n\n")
        parts.append(f"Source: [`examples/{script.name}`]({repo_url}/blob/{BRANCH}/examples/{script.name}) - "
                     f"`python3 examples/{script.name}`\n\n")
    readme = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    readme = shift_headings(readme, 1).replace("## steerlab examples", "## The examples folder", 1)
    parts.append(rewrite_links(readme, EXAMPLES, DOCS, repo_url))
    return "".join(parts)


# ----------------------------------------------------------------- hooks
def on_files(files, config):
    """Add the generated pages and the gallery figures."""
    repo_url = _repo_url(config)
    figures = gallery_figures()
    pages = {"index.md": page_index(repo_url), "reproductions.md": page_reproductions(repo_url),
             "validation.md": page_validation(repo_url), "gallery.md": page_gallery(figures, repo_url),
             "changelog.md": page_changelog(repo_url)}
    for uri, content in pages.items():
        if files.get_file_from_path(uri) is not None:
            raise PluginError(f"docs hook: docs/{uri} is generated; remove the file")
        files.append(File.generated(config, uri, content=content))
    for name, (png, _) in figures.items():
        if png is not None:
            files.append(File.generated(config, f"gallery/{Path(name).stem}.png", abs_src_path=str(png)))
    return files


def on_page_markdown(markdown, page, config, files):
    """Links from the user guide (``docs/*.md``) to repository files outside ``docs/``."""
    if page.file.generated_by is not None or page.file.abs_src_path is None:
        return markdown
    src = Path(page.file.abs_src_path)
    return rewrite_links(markdown, src.parent, src.parent, _repo_url(config))


_ROLE = re.compile(r":(?:py:)?(?:class|func|meth|mod|attr|data|exc|obj|const):<code>(~?)([^<]+)</code>")


def _role(m):
    name = m.group(2)
    return f"<code>{name.rsplit('.', 1)[-1] if m.group(1) else name}</code>"


def on_page_content(html, page, config, files):
    """Docstrings are numpydoc (reStructuredText roles): ``:class:`~a.B``` shows as ``B`` and
    a paragraph's ``::`` (the reST code-block marker) as ``:``."""
    html = _ROLE.sub(_role, html)
    return html.replace("::</p>", ":</p>")
