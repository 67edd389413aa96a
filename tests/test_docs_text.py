"""The user docs (README.md, docs/*.md) describe what is, not how it came to be: no dates and no
issue numbers (provenance is in git history)."""
import re

import pytest

from conftest import ROOT

DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
HISTORY = re.compile(r"\b20\d\d-\d\d-\d\d|\b[Ii]ssues? *#?\d+|(?<![\w&])#\d+\b")


def history(text):
    return HISTORY.findall(text)


@pytest.mark.parametrize("path", DOCUMENTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_dates_and_no_issue_numbers(path):
    assert history(path.read_text(encoding="utf-8")) == []


def test_dates_and_issue_numbers_are_seen():
    assert history("run of 2026-11-24, issue 18, issues 17 and (issue #20), see #21; seed 20241122") == [
        "2026-11-24", "issue 18", "issues 17", "issue #20", "#21"]
