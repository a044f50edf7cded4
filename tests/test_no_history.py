"""User-facing text (code, docstrings, READMEs, models, examples) speaks of the project alone:
no development history ("issue 6", "the issue's 10 Hz")."""

from __future__ import annotations

import re

from tests.test_citations import ROOT, project_files

HISTORY = re.compile(r"\bissue(?:'s|s)?\b(?:\s+\d+)?", re.IGNORECASE)
#: Text where "issue" is another project's words, quoted as a title.
TITLES = ("Rubin Observatory hexapods: issues and upgrades",)


def history(text: str) -> list[str]:
    for title in TITLES:
        text = text.replace(title, "")
    return [m.group(0) for m in HISTORY.finditer(text)]


def test_no_user_facing_text_names_development_history():
    found = {}
    for path in project_files():
        if path.parts[len(ROOT.parts)] == "tests":
            continue  # the tests are for developers
        words = history(path.read_text(errors="replace"))
        if words:
            found[str(path.relative_to(ROOT))] = words
    assert not found, found


def test_the_finder_finds_it():
    assert history("target <= 60 s, issue 6") == ["issue 6"]
    assert history("the issue's 150 ms") == ["issue's 150"]
    assert history('"Rubin Observatory hexapods: issues and upgrades", Proc. SPIE') == []
