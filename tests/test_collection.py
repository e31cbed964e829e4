"""No folder name hides code from the tools: every test file and doctest module is collected by pytest as
`make test` runs it, and every source file is linted by ruff.

A package once named `dist/` was skipped by both (pytest's default `norecursedirs` and ruff's default
`exclude`): its tests, doctests and lint never ran. The checkers below compare the tree on disk with
what the tools actually see, and the last test shows they catch such a folder in a planted tree.
"""

from __future__ import annotations

import ast
import fnmatch
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("common", "scenes", "render", "nbv")
"""The folders whose modules' doctests `make test` runs (pyproject's `testpaths` beside `tests`)."""
RUFF_DEFAULT_EXCLUDE = (".bzr", ".direnv", ".eggs", ".git", ".git-rewrite", ".hg", ".ipynb_checkpoints",
                        ".mypy_cache", ".nox", ".pants.d", ".pyenv", ".pytest_cache", ".pytype",
                        ".ruff_cache", ".svn", ".tox", ".venv", ".vscode", "__pypackages__", "_build",
                        "buck-out", "dist", "node_modules", "site-packages", "venv")
"""Folder names ruff skips unless told otherwise (ruff's `exclude` default, docs.astral.sh/ruff/settings)."""


def source_files(root: Path) -> list[str]:
    """The .py files of the tree, relative to `root`: git's tracked ones in a checkout, else every one."""
    if (root / ".git").exists():
        listed = subprocess.run(["git", "ls-files", "*.py"], cwd=root, capture_output=True, text=True,
                                check=True).stdout.split()
        return sorted(p for p in listed if (root / p).exists())
    return sorted(str(p.relative_to(root)) for p in root.rglob("*.py"))


def has_doctest(path: Path) -> bool:
    """Whether a docstring of the module, or of a class or function in it, holds a `>>>` example."""
    tree = ast.parse(path.read_text())
    nodes = [tree, *(n for n in ast.walk(tree)
                     if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef))]
    return any(">>>" in (ast.get_docstring(n, clean=False) or "") for n in nodes)


def expected_collected(root: Path, packages: tuple[str, ...] = PACKAGES) -> set[str]:
    """Files pytest must collect: every tests/**/test_*.py, and every module under `packages` with a
    doctest (`__main__.py` aside: pyproject's `--ignore-glob` leaves them out on purpose)."""
    files = source_files(root)
    tests = {p for p in files if p.startswith("tests/") and fnmatch.fnmatch(Path(p).name, "test_*.py")}
    doctests = {p for p in files if p.split("/")[0] in packages and Path(p).name != "__main__.py"
                and has_doctest(root / p)}
    return tests | doctests


def collected_files(root: Path) -> set[str]:
    """Files pytest collects at least one item from when run as `make test` runs it (from `root`)."""
    done = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider"],
                          cwd=root, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return {line.split("::")[0] for line in done.stdout.splitlines() if "::" in line}


def uncollected(root: Path, collected: set[str], packages: tuple[str, ...] = PACKAGES) -> list[str]:
    """Test files and doctest modules on disk that pytest did not collect."""
    return sorted(expected_collected(root, packages) - collected)


def unlinted(root: Path) -> list[str]:
    """Source files ruff does not check when run as `make test` runs it (`ruff check .` from `root`)."""
    done = subprocess.run([sys.executable, "-m", "ruff", "check", "--show-files", "."], cwd=root,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    seen = {str(Path(line).resolve().relative_to(root.resolve())) for line in done.stdout.splitlines()
            if line.strip()}
    return sorted(set(source_files(root)) - seen)


def hidden_folders(root: Path, norecursedirs: list[str]) -> list[str]:
    """Folders holding .py files whose name pytest (`norecursedirs`) or ruff (its default exclude) skips."""
    patterns = (*norecursedirs, *RUFF_DEFAULT_EXCLUDE)
    folders = {part for path in source_files(root) for part in _folders(path)}
    return sorted(f for f in folders if any(fnmatch.fnmatch(Path(f).name, p) for p in patterns))


def _folders(path: str) -> list[str]:
    parts = Path(path).parts[:-1]
    return ["/".join(parts[:i + 1]) for i in range(len(parts))]


@pytest.fixture(scope="module")
def collected() -> set[str]:
    """pytest's collection of the repository, once per session (it imports every module: ~10 s)."""
    return collected_files(ROOT)


def test_every_test_file_and_doctest_module_is_collected(collected):
    assert uncollected(ROOT, collected) == []
    assert "tests/nbv/fanout/test_executor.py" in collected
    assert "nbv/fanout/executor.py" in collected  # a doctest module


def test_no_package_or_test_folder_has_a_name_the_tools_skip(request):
    norecursedirs = request.config.getini("norecursedirs")
    assert "dist" in norecursedirs  # pytest's default, which pyproject keeps
    assert hidden_folders(ROOT, norecursedirs) == []


def test_every_source_file_is_linted():
    assert unlinted(ROOT) == []


def test_the_checkers_catch_a_folder_named_dist(tmp_path, request):
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]
    (tmp_path / "pyproject.toml").write_text(
        "[tool.pytest.ini_options]\n"
        f"testpaths = {config['pytest']['ini_options']['testpaths']!r}\n"
        f"addopts = {config['pytest']['ini_options']['addopts']!r}\n"
        "[tool.ruff]\nline-length = 110\n")
    planted = {"tests/ok/test_seen.py": "def test_seen():\n    pass\n",
               "tests/dist/test_x.py": "def test_hidden():\n    pass\n",
               "nbv/ok.py": '"""Seen.\n\n>>> 1 + 1\n2\n"""\n',
               "nbv/dist/tool.py": '"""Hidden.\n\n>>> 1 + 1\n2\n"""\n'}
    for name, text in planted.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)

    collected = collected_files(tmp_path)
    assert collected == {"tests/ok/test_seen.py", "nbv/ok.py"}
    assert uncollected(tmp_path, collected, ("nbv",)) == ["nbv/dist/tool.py", "tests/dist/test_x.py"]
    assert hidden_folders(tmp_path, request.config.getini("norecursedirs")) == ["nbv/dist", "tests/dist"]
    assert unlinted(tmp_path) == ["nbv/dist/tool.py", "tests/dist/test_x.py"]
