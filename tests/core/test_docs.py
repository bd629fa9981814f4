"""The README and the guides as a newcomer meets them: every local link (and image) resolves,
anchors included (GitHub's heading slugs), no internal issue number reaches a user, and the
README is short, starts with its two commands and its Python example runs as written."""
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md")),
         *sorted((REPO / "scripts").rglob("*.md"))]
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"```.*?```", re.S)


def anchors(page: Path) -> set[str]:
    """The #anchors GitHub gives a page's headings (a repeated heading gets -1, -2, ...)."""
    found, seen = set(), {}
    for line in FENCE.sub("", page.read_text(encoding="utf-8")).splitlines():
        heading = re.match(r"#+\s+(.*)", line)
        if heading:
            slug = re.sub(r"[^\w\- ]", "", heading.group(1).replace("`", "").strip().lower())
            slug = slug.replace(" ", "-")
            count = seen.get(slug, 0)
            seen[slug] = count + 1
            found.add(slug if count == 0 else f"{slug}-{count}")
    return found


def broken_links(page: Path) -> list[str]:
    broken = []
    for match in LINK.finditer(FENCE.sub("", page.read_text(encoding="utf-8"))):
        target = match.group(1)
        if re.match(r"[a-z]+:", target):                 # http:, mailto: ...
            continue
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        if not dest.exists():
            broken.append(f"missing {target}")
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            broken.append(f"no heading for {target}")
    return broken


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_every_local_link_resolves(page):
    assert broken_links(page) == []


def test_a_broken_link_and_a_missing_anchor_are_found(tmp_path):
    (tmp_path / "a.md").write_text("# Start here\n[ok](#start-here) [gone](b.md) "
                                   "[bad](#nowhere) [web](https://example.org)\n")
    assert broken_links(tmp_path / "a.md") == ["missing b.md", "no heading for #nowhere"]


def test_users_never_see_internal_issue_numbers():
    places = PAGES + sorted((REPO / "econet_ros").rglob("*.py"))
    mentions = [f"{p.relative_to(REPO)}: {m.group(0)}" for p in places
                for m in re.finditer(r"\bissues? \d+", p.read_text(encoding="utf-8"))]
    assert mentions == []


def test_the_readme_is_short_and_starts_with_its_two_commands():
    lines = (REPO / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 150
    head = "\n".join(lines[:25])
    assert re.search(r"^scripts/run\b", head, re.M) and re.search(r"^scripts/test\b", head, re.M)


def test_the_readme_python_example_runs_as_written(tmp_path, monkeypatch, capsys):
    example = re.search(r"```python\n(.*?)```", (REPO / "README.md").read_text(encoding="utf-8"),
                        re.S).group(1)
    monkeypatch.chdir(tmp_path)
    exec(compile(example, "README.md", "exec"), {"__name__": "readme_example"})
    assert "trials" in capsys.readouterr().out
    rows = (tmp_path / "runs" / "run-01" / "metrics.csv").read_text().splitlines()
    assert rows[0].startswith("generation,") and len(rows) == 1 + 5
