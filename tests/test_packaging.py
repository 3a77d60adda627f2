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


def test_py_typed_marker_is_shipped():
    assert (REPO / "src" / "steerlab" / "py.typed").exists()
    assert "py.typed" in PROJECT["tool"]["setuptools"]["package-data"]["steerlab"]


def test_docs_cited_by_the_bench_exist():
    from steerlab.bench import C_REFERENCE_NOTE

    cited = re.findall(r"(?:docs/)?[\w.-]+\.md", C_REFERENCE_NOTE)
    assert cited, C_REFERENCE_NOTE
    for c in cited:
        assert (REPO / c).exists(), f"bench cites {c}, which is not in the repository"
