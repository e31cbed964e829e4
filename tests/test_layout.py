"""The layout's rules, checked on the source: import direction, the CLI on top, module sizes, exports."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("common", "scenes", "render", "nbv")
LAYER = {name: i for i, name in enumerate(PACKAGES)}
"""common <- scenes <- render <- nbv: a module may import its own layer and those below."""
HEAVY = ("torch", "torchrl", "open3d", "kornia", "mitsuba", "drjit", "matplotlib", "trimesh", "cv2")


def modules() -> list[Path]:
    return sorted(p for pkg in PACKAGES for p in (ROOT / pkg).rglob("*.py"))


def imported(path: Path) -> set[str]:
    """Every module name an `import` or `from ... import` in the file names (any depth, lazy ones too)."""
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


def dotted(path: Path) -> str:
    return ".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")


def test_nothing_outside_the_cli_imports_the_cli():
    offenders = [dotted(p) for p in modules() if not dotted(p).startswith("nbv.cli")
                 and any(n == "nbv.cli" or n.startswith("nbv.cli.") for n in imported(p))]
    assert offenders == []


def test_imports_run_down_the_pipeline_only():
    upward = []
    for path in modules():
        own = dotted(path).split(".")[0]
        for name in imported(path):
            top = name.split(".")[0]
            if top in LAYER and LAYER[top] > LAYER[own]:
                upward.append(f"{dotted(path)} imports {name}")
    assert upward == []


def test_viz_is_a_leaf_and_planning_does_not_reach_into_experiments():
    def reaches(prefix: str, forbidden: tuple[str, ...]) -> list[str]:
        return [f"{dotted(p)} -> {n}" for p in modules() if dotted(p).startswith(prefix)
                for n in imported(p) if n.startswith(forbidden)]

    others = tuple(f"nbv.{s}" for s in ("features", "bov", "recon", "rl", "planning", "experiments", "bench"))
    assert reaches("nbv.viz", others) == []
    assert reaches("nbv.planning", ("nbv.experiments",)) == []


def test_no_module_is_over_450_lines():
    long = [f"{dotted(p)}: {n}" for p in modules() if (n := len(p.read_text().splitlines())) > 450]
    assert long == []


def test_every_package_reexports_names_that_resolve():
    for path in modules():
        if path.name != "__init__.py":
            continue
        package = importlib.import_module(dotted(path))
        for name in getattr(package, "__all__", ()):
            assert getattr(package, name) is not None, f"{dotted(path)}.{name}"


@pytest.mark.parametrize("argv", [["--help"], ["scene", "list"]])
def test_start_up_commands_import_nothing_heavy(argv):
    code = ("import sys; from nbv.cli import main; main(sys.argv[1:]); "
            f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().splitlines()[-1] == "[]"
