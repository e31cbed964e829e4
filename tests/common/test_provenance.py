"""The commit a result records: a run rewriting committed results does not mark the code dirty."""

import subprocess

from common.provenance import git_commit, portable_path, portable_record, portable_text


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


def test_portable_paths_keep_no_machine_folders(tmp_path):
    root = tmp_path / "repo"
    assert portable_path(root / "paper_results" / "online", root) == "paper_results/online"
    assert portable_path(root, root) == "."
    assert portable_path("/home/ann/runs/r1/policy.pt", root) == "ELSEWHERE/r1/policy.pt"
    command = (f"python scripts/looks_eval.py --policy candN=/home/ann/runs/m0/policy.pt --out "
               f"{root}/paper_results/r15 --work /scratch/work --scenes policy:/x/y.pt out/online "
               "https://example.org/a/b 1/8 a / b")
    assert portable_text(command, root) == (
        "python scripts/looks_eval.py --policy candN=ELSEWHERE/m0/policy.pt --out paper_results/r15 "
        "--work ELSEWHERE/scratch/work --scenes policy:ELSEWHERE/x/y.pt out/online https://example.org/a/b "
        "1/8 a / b")
    record = {"command": ["scripts/x.py", "--out", "/data/o"], "n": 3, "nested": {"p": f"{root}/a.pt"}}
    assert portable_record(record, root) == {"command": ["scripts/x.py", "--out", "ELSEWHERE/data/o"], "n": 3,
                                             "nested": {"p": "a.pt"}}
