"""The commit a result records: a run rewriting committed results does not mark the code dirty."""

import subprocess

from common.provenance import git_commit


def test_only_changes_outside_the_results_make_the_commit_dirty(tmp_path, monkeypatch):
    def git(*args):
        subprocess.run(["git", *args], cwd=tmp_path, check=True, capture_output=True)

    git("init", "-q")
    (tmp_path / "paper_results").mkdir()
    (tmp_path / "paper_results" / "table2.md").write_text("old")
    (tmp_path / "code.py").write_text("x = 1\n")
    git("add", ".")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "first")
    monkeypatch.chdir(tmp_path)
    clean = git_commit()
    assert len(clean) >= 7 and "+" not in clean
    (tmp_path / "paper_results" / "table2.md").write_text("new")  # a run writing its results
    assert git_commit() == clean
    (tmp_path / "code.py").write_text("x = 2\n")
    assert git_commit() == clean + "+dirty"
