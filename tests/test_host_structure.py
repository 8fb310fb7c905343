"""The host package's shape: its import graph has no cycle (a module importing another, even inside a
function, counts), no layer imports one above it (the fixed-point kernel at the bottom, imports nothing
of quadstep), and ruff (format and lint) and mypy find nothing in it (pyproject.toml: [tool.ruff],
[tool.mypy]; `make lint` runs the same)."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "host" / "quadstep"


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path, modules: set[str]) -> set[str]:
    """The package's modules that `path` imports, anywhere in it."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, *([base] if base else [])])
            targets = [f"{base}.{alias.name}" for alias in node.names] + [base]
        elif isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        else:
            continue
        for target in targets:
            if target in modules and target != name:
                found.add(target)
                break
    return found


def test_the_host_package_has_no_import_cycle() -> None:
    paths = sorted(PACKAGE.rglob("*.py"))
    modules = {module_name(p) for p in paths}
    graph = {module_name(p): imports(p, modules) for p in paths}
    # A module's package __init__ re-exporting it is not a cycle of code: only module → module edges count.
    graph = {m: {t for t in targets if not m.startswith(t + ".")} for m, targets in graph.items()}
    cycles: list[list[str]] = []
    state: dict[str, int] = {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for target in sorted(graph[node]):
            if state.get(target) == 1:
                cycles.append(stack[stack.index(target):] + [target])
            elif target not in state:
                visit(target, [*stack, target])
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])
    print(f"\nhost package: {len(paths)} modules, {sum(len(t) for t in graph.values())} imports, "
          f"{len(cycles)} cycles")
    assert cycles == []


# Lowest first: a module of the package may import only from layers below its own (and from its own
# package). A new top-level module or package is placed here, or this test fails.
LAYERS: tuple[frozenset[str], ...] = tuple(frozenset(names.split()) for names in (
    "quadstep kernel",  # the fixed-point numbers, motion models, cubic chain and step prediction
    "protocol coordinates textfile validation macro_settings touch_off_settings port_process raster_image give_way",
    "config link",
    "config_file default_machine emulator planner",
    "backlash gcode movefile toolpath",
    "job job_scan macro_check",
    "machine mdi",
    "jog grbl",
    "tui",
    "cli",
))


def layer_of(module: str) -> str:
    """The package's top-level module or package that `module` belongs to ("quadstep" for its face)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def test_no_layer_imports_one_above_it() -> None:
    paths = sorted(PACKAGE.rglob("*.py"))
    modules = {module_name(p) for p in paths}
    rank = {name: i for i, layer in enumerate(LAYERS) for name in layer}
    unplaced = sorted({layer_of(m) for m in modules} - set(rank))
    assert unplaced == [], f"place these in LAYERS: {unplaced}"
    upward = []
    edges = 0
    for path in paths:
        source = layer_of(module_name(path))
        for target in imports(path, modules):
            if layer_of(target) == source:
                continue
            edges += 1
            if rank[layer_of(target)] >= rank[source]:
                upward.append(f"{module_name(path)} -> {target}")
    print(f"\nhost package: {len(LAYERS)} layers, {edges} imports between them, {len(upward)} not downward")
    assert upward == []
    kernel_imports = {t for p in PACKAGE.joinpath("kernel").rglob("*.py") for t in imports(p, modules)}
    assert {layer_of(t) for t in kernel_imports} <= {"kernel"}


def run_tool(*args: str) -> subprocess.CompletedProcess[str]:
    """A tool of the test extra on the host package, with the repository's configuration."""
    return subprocess.run([sys.executable, "-m", *args], cwd=ROOT, capture_output=True, text=True)


def test_ruff_and_mypy_find_nothing_in_the_host_package() -> None:
    check = run_tool("ruff", "check", "--output-format", "concise", "host/quadstep")
    lint = [line for line in check.stdout.splitlines() if re.match(r"\S+\.py:\d+:\d+: ", line)]
    form = run_tool("ruff", "format", "--check", "host/quadstep")
    unformatted = [line for line in form.stdout.splitlines() if line.startswith("Would reformat")]
    types = run_tool("mypy", "host/quadstep")
    errors = [line for line in types.stdout.splitlines() if ": error:" in line]
    print(f"\nhost package: ruff check {len(lint)} findings, ruff format {len(unformatted)} files to "
          f"reformat, mypy {len(errors)} errors")
    for line in [*lint, *unformatted, *errors]:
        print(line)
    # each tool also says so by its exit status (a tool that did not run fails here too)
    assert (lint, check.returncode) == ([], 0), check.stdout + check.stderr
    assert (unformatted, form.returncode) == ([], 0), form.stdout + form.stderr
    assert (errors, types.returncode) == ([], 0), types.stdout + types.stderr
