"""Packaging hygiene: the licence, changelog, metadata and typing marker a user checks first,
and every repository file the package's own outputs cite exists."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
PROJECT = tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))


def test_license_file_matches_the_declared_licence():
    assert PROJECT["project"]["license"]["text"] == "MIT"
    text = (REPO / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License") and "WITHOUT WARRANTY OF ANY KIND" in text
    assert "License :: OSI Approved :: MIT License" in PROJECT["project"]["classifiers"]


def test_metadata_names_authors_keywords_and_classifiers():
    p = PROJECT["project"]
    assert p["authors"] and all(a.get("name") for a in p["authors"])
    assert "autopilot" in p["keywords"]
    py = re.search(r">=\s*3\.(\d+)", p["requires-python"]).group(1)
    assert f"Programming Language :: Python :: 3.{py}" in p["classifiers"]


def test_changelog_covers_the_current_version():
    version = PROJECT["project"]["version"]
    log = (REPO / "CHANGELOG.md").read_text(encoding="utf-8")
    assert f"## [{version}]" in log


def test_the_rl_extra_installs_gymnasium_and_gym_is_its_alias():
    extras = PROJECT["project"]["optional-dependencies"]
    assert extras["rl"][0] == "gymnasium>=1.1"              # AutoresetMode; what steerlab.gym's import error names
    # numba's TBB threading layer for the vector env's threaded step (steerlab.jit.threading_layer)
    assert extras["rl"][1:] == ["tbb>=2021.6; sys_platform == 'linux' and platform_machine == 'x86_64'"]
    assert extras["gym"] == extras["rl"]


def test_py_typed_marker_is_shipped():
    assert (REPO / "src" / "steerlab" / "py.typed").exists()
    assert "py.typed" in PROJECT["tool"]["setuptools"]["package-data"]["steerlab"]


def test_docs_cited_by_the_bench_exist():
    from steerlab.bench import C_REFERENCE_NOTE

    cited = re.findall(r"(?:docs/)?[\w.-]+\.md", C_REFERENCE_NOTE)
    assert cited, C_REFERENCE_NOTE
    for c in cited:
        assert (REPO / c).exists(), f"bench cites {c}, which is not in the repository"


def test_project_urls_point_at_the_intended_public_address():
    urls = PROJECT["project"]["urls"]
    assert {"Homepage", "Documentation", "Source", "Issues"} <= set(urls)
    assert all(u.startswith("https://github.com/steerlab/steerlab") for u in urls.values())
    # the address is a placeholder until publication, and the README and changelog say so
    for doc in ("README.md", "CHANGELOG.md"):
        text = (REPO / doc).read_text(encoding="utf-8")
        assert "https://github.com/steerlab/steerlab" in text and "placeholder" in text, doc


def test_built_metadata_shows_author_licence_and_urls(tmp_path):
    # what `pip show steerlab` prints comes from this core metadata (built from a copy of the
    # project files, so the work tree gets no egg-info)
    import shutil
    import subprocess
    import sys

    proj = tmp_path / "proj"
    (proj / "src" / "steerlab").mkdir(parents=True)
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(REPO / name, proj / name)
    (proj / "src" / "steerlab" / "__init__.py").write_text("")
    (proj / "src" / "steerlab" / "py.typed").write_text("")
    (tmp_path / "meta").mkdir()
    proc = subprocess.run([sys.executable, "-c", "from setuptools import setup; setup()", "egg_info",
                           "--egg-base", str(tmp_path / "meta")], cwd=proj, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    meta = (tmp_path / "meta" / "steerlab.egg-info" / "PKG-INFO").read_text(encoding="utf-8")
    assert "Author: the steerlab maintainers" in meta
    assert re.search(r"^License(-Expression)?: MIT$", meta, re.M)
    for key in ("Homepage", "Documentation", "Source", "Issues"):
        assert re.search(rf"^Project-URL: {key}, https://github\.com/steerlab/steerlab", meta, re.M), key
