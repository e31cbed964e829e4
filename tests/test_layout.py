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


def _runtime_nodes(tree: ast.AST) -> list[ast.AST]:
    """Every node of the tree outside `if TYPE_CHECKING:` blocks (their imports are for type checkers)."""
    nodes, todo = [], [tree]
    while todo:
        node = todo.pop()
        nodes.append(node)
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            todo.extend(node.orelse)
            continue
        todo.extend(ast.iter_child_nodes(node))
    return nodes


def import_graph() -> dict[str, set[str]]:
    """File-level first-party imports: module -> the modules it imports, lazy ones inside functions too.

    `from a.b import c` is an edge to the module `a.b.c` where that is a file, else to `a.b`.
    """
    files = {dotted(p): p for p in modules()}
    graph: dict[str, set[str]] = {name: set() for name in files}
    for name, path in files.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in _runtime_nodes(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join([*anchor, *([base] if base else [])])
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in files else base for a in node.names]
            else:
                continue
            graph[name].update(t for t in targets if t in files and t != name)
    return graph


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles: strongly connected components of more than one module (Tarjan), each sorted.

    Example:
        >>> circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}})
        [['a', 'b', 'c']]
    """
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for other in sorted(graph.get(node, ())):
            if other not in index:
                visit(other)
                low[node] = min(low[node], low[other])
            elif other in stack:
                low[node] = min(low[node], index[other])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(found)


def test_the_circle_finder_finds_a_planted_circle_and_lazy_imports():
    assert circles({"a": {"b"}, "b": {"a"}, "c": {"a"}}) == [["a", "b"]]
    assert circles({"a": {"b"}, "b": set()}) == []
    graph = import_graph()
    assert "scenes.catalog" in graph["scenes.spec"]  # the lazy import inside SceneSpec.load counts
    assert "nbv.experiments.ablate" not in graph["nbv.experiments.ablation_report"]  # type-only import


def test_no_import_circle_between_files():
    found = circles(import_graph())
    assert found == [], "import circles between files:\n" + "\n".join(" <-> ".join(c) for c in found)


MAX_FUNCTION_LINES = 60
"""The house limit on a function's length, from its `def` line to its last line."""


def long_functions(paths: list[Path]) -> list[str]:
    """`path:line name, N lines` for every function or method of `paths` over `MAX_FUNCTION_LINES`."""
    long = []
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}, {length} lines")
    return long


def test_no_function_is_over_60_lines():
    long = long_functions(modules() + sorted((ROOT / "scripts").rglob("*.py")))
    assert long == [], "functions over 60 lines:\n" + "\n".join(long)
