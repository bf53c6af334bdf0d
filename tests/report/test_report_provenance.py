"""A report's provenance names the commit its numbers come from, and says when they do not."""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from chaoscam.report._html import git_commit, uncommitted_sources

ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "reports" / "paper.html"

needs_git = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def _git(cwd: Path, *args: str) -> str:
    return subprocess.run(
        ["git", *args], cwd=cwd, capture_output=True, text=True, check=True
    ).stdout.strip()


@needs_git
def test_uncommitted_source_changes_are_named(tmp_path):
    """A clean checkout has none; an edited module is named; an edited report is not."""
    (tmp_path / "chaoscam").mkdir()
    (tmp_path / "reports").mkdir()
    module, report = tmp_path / "chaoscam" / "model.py", tmp_path / "reports" / "paper.html"
    module.write_text("XI = 0.42\n")
    report.write_text("<p>old</p>\n")
    _git(tmp_path, "init", "-q")
    _git(tmp_path, "add", ".")
    _git(tmp_path, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "m")
    assert uncommitted_sources(module) == []
    assert git_commit(module) == _git(tmp_path, "rev-parse", "HEAD")
    report.write_text("<p>new</p>\n")
    assert uncommitted_sources(module) == []
    module.write_text("XI = 0.5\n")
    assert uncommitted_sources(module) == ["chaoscam/model.py"]


def test_outside_a_checkout_there_is_nothing_to_say(tmp_path):
    assert uncommitted_sources(tmp_path / "x.py") is None


@needs_git
def test_committed_report_names_a_commit_of_this_history():
    """reports/paper.html names a commit that exists and that HEAD descends from."""
    if not (ROOT / ".git").exists() or (ROOT / ".git" / "shallow").exists():
        pytest.skip("not a full git checkout")
    found = re.search(r"commit ([0-9a-f]{40})", PAPER.read_text(encoding="utf-8"))
    assert found, "reports/paper.html names no commit"
    commit = found.group(1)
    _git(ROOT, "cat-file", "-e", f"{commit}^{{commit}}")
    assert _git(ROOT, "merge-base", "--is-ancestor", commit, "HEAD") == ""
    assert "uncommitted changes" not in PAPER.read_text(encoding="utf-8")
