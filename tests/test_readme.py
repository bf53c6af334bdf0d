"""The README and docs/ as a user meets them: the commands they give, the code they show and the
links between them.

The README's first two lines are the commands a fresh machine runs (the second is what CI
runs), its Quick start is code a user pastes, and the measurements behind it live in docs/,
reached by relative links and section anchors; each can rot without any other test noticing.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
PAGES = [README, *sorted((ROOT / "docs").glob("*.md")), ROOT / "benchmarks" / "PROFILE.md"]


def _slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation other than '-' and '_' dropped,
    each space a '-'."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _links(page: Path) -> list[str]:
    """The relative link targets of a Markdown page (no scheme: not http:, mailto:, ...)."""
    targets = re.findall(r"\]\(([^)\s]+)\)", page.read_text(encoding="utf-8"))
    return [t for t in targets if not re.match(r"[a-z]+:", t)]


def _broken(page: Path) -> list[str]:
    """The relative links of a page whose file or heading anchor does not exist."""
    broken = []
    for target in _links(page):
        path, _, anchor = target.partition("#")
        linked = (page.parent / path) if path else page
        if not linked.exists():
            broken.append(f"{target}: no such file")
            continue
        if anchor:
            text = linked.read_text(encoding="utf-8")
            heads = {_slug(h) for h in re.findall(r"^#+ (.*)$", text, flags=re.M)}
            if anchor not in heads:
                broken.append(f"{target}: no heading with that anchor")
    return broken


def test_the_second_line_is_what_ci_runs():
    first, second = README.read_text(encoding="utf-8").splitlines()[:2]
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").strip().splitlines()[-1]
    assert first.startswith("    python3 -m venv .venv") and "chaoscam paper --quick" in first
    assert second.strip() == ci.strip()


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_relative_link_and_anchor_resolves(page):
    assert not _broken(page)


def test_the_link_check_finds_a_missing_file_and_a_missing_anchor(tmp_path):
    (tmp_path / "other.md").write_text("## The default response in the v_min → 0 limit\n")
    page = tmp_path / "page.md"
    page.write_text(
        "# A title\n\n[ok](#a-title) [bad](#no-such) [gone](missing.md) "
        "[there](other.md#the-default-response-in-the-v_min--0-limit) [off](https://x.org/#y)\n"
    )
    assert _broken(page) == ["#no-such: no heading with that anchor", "missing.md: no such file"]


def test_the_quick_start_runs():
    """The Quick start's Python block, as pasted: it simulates, classifies and extends a run
    (a few seconds once the kernel is compiled)."""
    text = README.read_text(encoding="utf-8")
    section = text.split("## Quick start", 1)[1]
    block = re.search(r"```python\n(.*?)```", section, flags=re.S).group(1)
    scope: dict = {}
    exec(compile(block, "README.md (Quick start)", "exec"), scope)  # noqa: S102
    traj, longer = scope["traj"], scope["longer"]
    assert len(traj.section) > 0 and traj.params.l_lambda == 0.015
    assert scope["verdict"].label in ("periodic", "quasiperiodic", "chaotic", "undetermined")
    assert longer.section["t"].max() > traj.section["t"].max()
