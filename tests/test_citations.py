"""Every document and file the project cites is in the project.

Code, READMEs, models and examples cite files: documents by name (``REFERENCE.md``,
``README.md``), files by their path from the repository's root (``models/hexapod/README.md``,
``sims/hexapod/plan_checks.py``), and sections by a quoted title after the document
(``REFERENCE.md, "Rubin hexapod"``). Each must exist: a name in the citing file's folder or
at the root, a path from the root or from the mechanism root holding the citing file
(tests/mechanisms/*/; a ``*`` matches as in a glob), a section as a heading or
quoted text of that document. Files of other projects (``constants.py`` of ts_mthexapod)
are named without a path of this repository and are not checked.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Top-level folders a path citation starts with; "shared" is no folder of the project, so a
#: citation of it fails as any other missing path.
TOP = ("planners", "models", "sims", "tests", "examples", "shared")
DOCUMENT = re.compile(r"(?<![\w/.-])([A-Z][A-Z_]*\.md)\b")
PATH = re.compile(r"(?<![\w/.-])((?:" + "|".join(TOP) + r")/[\w.*/-]*[\w*])")
SECTION = re.compile(r"((?:[\w.*-]+/)*[A-Z][A-Z_]*\.md)[,:]?\s*\(?[\"\u201c]([^\"\u201d\n]{3,80})[\"\u201d]")
SUFFIXES = (".py", ".md", ".toml", ".xml", ".cfg", ".txt")


def project_files() -> list[Path]:
    """The repository's tracked text files (and new ones not ignored)."""
    out = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    return [ROOT / f for f in out if f.endswith(SUFFIXES) and (ROOT / f).is_file()]


def _resolve(name: str, citing: Path) -> Path | None:
    """The cited file: a bare document name in the citing file's folder or at the root, a
    path from the root (with glob wildcards)."""
    if "/" not in name:
        for folder in (citing.parent, ROOT):
            if (folder / name).is_file():
                return folder / name
        return None
    # A path from the root, or from the mechanism root that holds the citing file (a root
    # PLANBENCH_MECHANISMS names has models/, planners/, sims/ of its own: tests/mechanisms/*/).
    for base in [ROOT, *(p for p in citing.parents if p != ROOT and ROOT in p.parents and (p / "models").is_dir())]:
        if "*" in name:
            matches = sorted(base.glob(name))
            if matches:
                return matches[0]
        elif (base / name.rstrip("/")).exists():
            return base / name.rstrip("/")
    return None


def bad_citations(text: str, citing: Path) -> list[str]:
    """What ``text`` (of file ``citing``) cites that is not in the project."""
    bad = []
    for pattern in (DOCUMENT, PATH):
        for match in pattern.finditer(text):
            name = match.group(1).rstrip(".")
            if _resolve(name, citing) is None:
                bad.append(f"{name} (no such file)")
    for match in SECTION.finditer(text):
        name, section = match.group(1), match.group(2)
        target = _resolve(name, citing)
        if target is None or not target.is_file():
            continue  # reported above
        document = target.read_text()
        headings = [line.lstrip("#").strip() for line in document.splitlines() if line.startswith("#")]
        if not any(section in h for h in headings) and section not in document:
            bad.append(f'{name}, "{section}" (no such section or text in {target.relative_to(ROOT)})')
    return bad


def test_every_citation_is_in_the_project():
    found = {}
    for path in project_files():
        if path.name == "test_citations.py":
            continue  # its docstring and cases cite missing files on purpose
        bad = bad_citations(path.read_text(errors="replace"), path)
        if bad:
            found[str(path.relative_to(ROOT))] = sorted(set(bad))
    assert not found, found


@pytest.mark.parametrize(
    "text, missing",
    [
        ("see ARCHITECTURE.md, Conventions", "ARCHITECTURE.md"),
        ("the paper (shared/papers/fast-feed-support-motion-planning.txt)", "shared/papers/"),
        ('limits: REFERENCE.md, "Rubin hexapods and rotators"', "no such section"),
        ("models/robot/README.md lists the gains", "models/robot/README.md"),
        ("examples/*/nothing.toml", "examples/*/nothing.toml"),
    ],
)
def test_a_citation_of_a_missing_file_or_section_is_found(text, missing):
    bad = bad_citations(text, ROOT / "sims" / "cli.py")
    assert any(missing in b for b in bad), bad


@pytest.mark.parametrize(
    "text",
    [
        'REFERENCE.md, "Rubin hexapod"',
        "models/hexapod/README.md and sims/hexapod/plan_checks.py",
        "models/*/README.md",
        'README.md, "How the hexapod is judged"',
        "ts_mthexapod's constants.py (another project's file)",
    ],
)
def test_citations_in_the_project_pass(text):
    assert bad_citations(text, ROOT / "sims" / "cli.py") == []
