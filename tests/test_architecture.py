"""The layout keeps its promises: layers import only downward, no import circles, small files
and functions, and every package says in one line what it is and what it may import.

The allowed imports of each package are read from its ``__init__`` docstring ("Imports: ..."),
so the docs and this check cannot drift apart.
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TOP_PACKAGES = ("mission", "ground_station", "vehicle_sim")
MAX_FILE_LINES = 400
MAX_FUNCTION_LINES = 60
SHORT_NAMES = {  # the names the docstrings use for the project's packages
    "config": "mission.config",
    "world": "mission.world",
    "link": "mission.link",
    "procs": "mission.procs",
    "maths": "mission.maths",
    "codegen": "mission.codegen",
    "analysis": "mission.analysis",
    "planning": "mission.planning",
    "runs": "mission.runs",
    "bench": "mission.bench",
    "commands": "mission.commands",
    "studies": "mission.studies",
    "viewer": "mission.viewer",
    "ground_station": "ground_station",
    "state": "ground_station.state",
    "estimation": "ground_station.estimation",
    "integrity": "ground_station.integrity",
    "support_mpc": "ground_station.support_mpc",
    "roles": "ground_station.roles",
    "control": "ground_station.control",
    "links": "ground_station.links",
    "vehicle_sim": "vehicle_sim",
    "dynamics": "vehicle_sim.dynamics",
    "mavlink": "vehicle_sim.mavlink",
    "sensors": "vehicle_sim.sensors",
    "process": "vehicle_sim.process",
}


def source_files() -> list[Path]:
    return sorted(p for top in TOP_PACKAGES for p in (ROOT / top).rglob("*.py"))


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def packages() -> dict[str, Path]:
    """Every package of the project (``mission`` itself included), by dotted name."""
    return {module_name(p): p for p in source_files() if p.name == "__init__.py"}


def owner(module: str, names: set[str]) -> str:
    """The innermost package in ``names`` that holds ``module``."""
    parts = module.split(".")
    for end in range(len(parts), 0, -1):
        candidate = ".".join(parts[:end])
        if candidate in names:
            return candidate
    raise AssertionError(f"{module} belongs to no package")


def imported_modules(path: Path, known: set[str]) -> set[str]:
    """The project modules a file imports anywhere (top level, inside functions, and under
    TYPE_CHECKING: a circle of types is still a circle)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    this = module_name(path)
    package = this if path.name == "__init__.py" else this.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[: len(anchor) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            names = [base] + [f"{base}.{alias.name}" for alias in node.names]
        else:
            continue
        for name in names:
            while name and name not in known:
                name = name.rpartition(".")[0]
            if name and name != this:
                found.add(name)
    return found


def import_graph() -> dict[str, set[str]]:
    files = {module_name(p): p for p in source_files()}
    known = set(files)
    return {name: imported_modules(path, known) for name, path in files.items()}


def allowed_imports() -> dict[str, set[str] | None]:
    """Per package, the packages it may import besides its own (None: any)."""
    rules: dict[str, set[str] | None] = {}
    for name, path in packages().items():
        docstring = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
        match = re.search(r"Imports: (.+?)\.?$", docstring)
        assert match, f"{path}: the docstring must end with 'Imports: ...'"
        clause = match.group(1)
        if clause == "all":
            rules[name] = None
        elif clause == "nothing":
            rules[name] = set()
        elif clause.startswith("all but "):
            excluded = {e.strip() for e in clause.removeprefix("all but ").split(",")}
            rules[name] = {p for p in packages() if p not in excluded and p != "mission"}
        else:
            rules[name] = {SHORT_NAMES[item.strip()] for item in clause.split(",")}
    return rules


def test_every_package_says_in_one_line_what_it_is_and_what_it_may_import():
    for name, path in packages().items():
        docstring = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
        assert docstring and "\n" not in docstring, f"{name}: a one-line docstring"
    assert set(allowed_imports()) >= {f"mission.{p}" for p in ("config", "world", "link")}


def test_layers_import_only_what_their_package_allows():
    names = set(packages())
    rules = allowed_imports()
    forbidden = []
    for module, targets in import_graph().items():
        mine = owner(module, names)
        allowed = rules[mine]
        for target in targets:
            theirs = owner(target, names)
            inside = theirs == mine or theirs.startswith(mine + ".")
            if theirs == "mission" and target != "mission":  # mission.cli, mission.__main__
                theirs = target
            if allowed is not None and not inside and theirs not in allowed:
                forbidden.append(f"{module} -> {target}")
    assert not forbidden, "imports against the layering:\n" + "\n".join(sorted(forbidden))


def test_a_subpackage_never_imports_its_parents_modules():
    """Layers go down: a package's own modules use its subpackages, never the other way."""
    names = set(packages())
    upward = []
    for module, targets in import_graph().items():
        mine = owner(module, names)
        for target in targets:
            theirs = owner(target, names)
            if mine.startswith(theirs + "."):
                upward.append(f"{module} -> {target}")
    assert not upward, "subpackages importing their parents:\n" + "\n".join(sorted(upward))


def package_graph() -> dict[str, set[str]]:
    """Which packages each package's modules import (its own left out)."""
    names = set(packages())
    graph: dict[str, set[str]] = {name: set() for name in names}
    for module, targets in import_graph().items():
        mine = owner(module, names)
        graph[mine] |= {owner(target, names) for target in targets} - {mine}
    return graph


def test_no_import_circle_between_packages():
    assert circles(package_graph()) == []


def test_the_processes_never_import_each_other_and_the_floor_never_imports_the_roof():
    graph = import_graph()
    roof = (
        "ground_station",
        "vehicle_sim",
        "mission.runs",
        "mission.bench",
        "mission.commands",
        "mission.studies",
        "mission.analysis",
        "mission.cli",
    )
    floor = ("mission.world", "mission.config", "mission.link", "mission.procs", "mission.codegen")
    for module, targets in graph.items():
        for target in targets:
            if module.startswith(floor):
                assert not target.startswith(roof), f"{module} -> {target}"
            if module.startswith("ground_station"):
                assert not target.startswith("vehicle_sim"), f"{module} -> {target}"
            if module.startswith("vehicle_sim"):
                assert not target.startswith("ground_station"), f"{module} -> {target}"


def circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in graph.get(node, ()):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def test_no_import_circle_anywhere():
    # a package's __init__ is imported by its modules' imports; it imports nothing itself
    assert circles(import_graph()) == []


def test_the_circle_finder_finds_a_circle():
    assert circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def oversized(path: Path) -> list[str]:
    """What in one file is too long: the file itself, and each function (argument parsers
    excepted: one per sub-command)."""
    text = path.read_text(encoding="utf-8")
    where = path.relative_to(ROOT)
    found = []
    if len(text.splitlines()) > MAX_FILE_LINES:
        found.append(f"{where}: {len(text.splitlines())} lines (at most {MAX_FILE_LINES})")
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            length = node.end_lineno - node.lineno + 1
            if "parser" not in node.name and length > MAX_FUNCTION_LINES:
                found.append(f"{where}:{node.lineno} {node.name}: {length} lines")
    return found


def test_files_and_functions_stay_small():
    offenders = [line for path in source_files() for line in oversized(path)]
    assert not offenders, "too long:\n" + "\n".join(offenders)


def test_the_size_check_names_a_long_file_and_a_long_function(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    body = "".join(f"    x{i} = {i}\n" for i in range(MAX_FUNCTION_LINES))
    long = tmp_path / "long.py"
    long.write_text("def f():\n" + body + "\n" * MAX_FILE_LINES)
    assert oversized(long) == [
        f"long.py: {MAX_FUNCTION_LINES + 1 + MAX_FILE_LINES} lines (at most {MAX_FILE_LINES})",
        f"long.py:1 f: {MAX_FUNCTION_LINES + 1} lines",
    ]
    short = tmp_path / "short.py"
    short.write_text("def parser():\n" + body)
    assert oversized(short) == []
