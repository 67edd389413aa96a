"""Every relative link in README.md and docs/*.md points to a file that exists, and every
`#anchor` into a Markdown file names one of its headings (GitHub's anchors)."""
import re

import pytest

from conftest import ROOT

DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^(```|~~~).*?^\1", re.S | re.M)


def links(text):
    """The link targets of Markdown text, outside fenced code blocks."""
    return LINK.findall(FENCE.sub("", text))


def anchor(heading):
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(path):
    text = FENCE.sub("", path.read_text(encoding="utf-8"))
    return {anchor(h) for h in re.findall(r"^#{1,6}\s+(.*?)\s*#*$", text, re.M)}


def broken_links(path):
    """(target, why) of every relative link of the Markdown file at path that leads nowhere."""
    out = []
    for target in links(path.read_text(encoding="utf-8")):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto: ...
            continue
        file_part, _, fragment = target.partition("#")
        dest = (path.parent / file_part).resolve() if file_part else path
        if not dest.exists():
            out.append((target, "no such file"))
        elif fragment and dest.suffix == ".md" and fragment not in anchors(dest):
            out.append((target, f"no heading with the anchor #{fragment} in {dest.name}"))
    return out


@pytest.mark.parametrize("path", DOCUMENTS, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_leads_to_an_existing_file(path):
    assert broken_links(path) == []


def test_a_link_to_a_missing_file_or_heading_is_reported(tmp_path):
    (tmp_path / "there.md").write_text("# A page\n\n## Its section: one\n")
    page = tmp_path / "page.md"
    page.write_text("[ok](there.md) [ok](there.md#its-section-one) [web](https://example.org/x)\n"
                    "[gone](missing.md) [no heading](there.md#elsewhere)\n"
                    "```\n[in code](not-a-link.md)\n```\n")
    assert broken_links(page) == [("missing.md", "no such file"),
                                  ("there.md#elsewhere", "no heading with the anchor #elsewhere in there.md")]
