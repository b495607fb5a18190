"""The package's shape: no import cycles between geardyn's modules, no private names imported across
modules, gear science that knows no paper, and a solver core that knows no model family."""

import ast
import pathlib

import pytest

SRC = pathlib.Path(__file__).resolve().parents[1] / "src" / "geardyn"


def _modules() -> dict[str, pathlib.Path]:
    out = {}
    for path in SRC.rglob("*.py"):
        rel = path.relative_to(SRC.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _imports(name: str, path: pathlib.Path) -> list[tuple[str, list[str]]]:
    """(imported module, imported names) for every import of ``path``, function-level ones included."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, []) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.split(".")
                parent = parent[: len(parent) - node.level + 1]
                base = ".".join(parent + ([base] if base else []))
            names = [alias.name for alias in node.names]
            found.append((base, names))
            # "from geardyn.khv import design" imports the module geardyn.khv.design
            found += [(f"{base}.{n}", []) for n in names if f"{base}.{n}" in MODULES]
    return [(m, n) for m, n in found if m.startswith("geardyn")]


GRAPH = {
    name: sorted({m for m, _ in _imports(name, path) if m in MODULES and m != name}) for name, path in MODULES.items()
}


def _cycle() -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in GRAPH[node]:
            if state.get(nxt) == 1:
                return [*stack[stack.index(nxt) :], nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = 2
        return None

    for node in GRAPH:
        if node not in state and (found := visit(node)):
            return found
    return None


def test_the_walk_sees_the_package():
    assert {"geardyn.solve.simulate", "geardyn.khv.point", "geardyn.runs.sweep", "geardyn.papers.li2013"} <= set(
        MODULES
    )
    assert "geardyn.khv.model" in GRAPH["geardyn.khv.point"]


def test_no_import_cycle():
    assert _cycle() is None, " -> ".join(_cycle() or [])


def test_the_cycle_finder_finds_a_cycle():
    GRAPH["geardyn.solve.base"].append("geardyn.runs.sweep")
    try:
        assert _cycle() is not None
    finally:
        GRAPH["geardyn.solve.base"].remove("geardyn.runs.sweep")


@pytest.mark.parametrize("name", sorted(MODULES))
def test_no_private_name_imported_from_another_module(name):
    for module, names in _imports(name, MODULES[name]):
        package = name.rpartition(".")[0]
        own_package = module == package or module.rpartition(".")[0] == package
        # a package may use its own private modules (geardyn.solve._kernel), never another's private names
        private = [
            n
            for n in names
            if n.startswith("_") and n != "__version__" and not (own_package and f"{module}.{n}" in MODULES)
        ]
        assert not private, f"{name} imports {private} from {module}"
        if module.rpartition(".")[2].startswith("_"):
            assert own_package, f"{name} imports the private module {module}"


def _reaches(name: str) -> set[str]:
    seen, todo = set(), [name]
    while todo:
        for nxt in GRAPH[todo.pop()]:
            if nxt not in seen:
                seen.add(nxt)
                todo.append(nxt)
    return seen


@pytest.mark.parametrize("name", [m for m in sorted(MODULES) if m.startswith("geardyn.gears")])
def test_gear_science_knows_no_paper_and_no_model_family(name):
    assert not {m for m in _reaches(name) if m.startswith(("geardyn.papers", "geardyn.khv", "geardyn.plus"))}


@pytest.mark.parametrize("name", [m for m in sorted(MODULES) if m.startswith("geardyn.solve")])
def test_the_solver_core_knows_no_model_family_and_no_run(name):
    bad = {m for m in _reaches(name) if m.startswith(("geardyn.khv", "geardyn.plus", "geardyn.runs", "geardyn.papers"))}
    assert not bad, bad


def test_papers_are_data():
    for name in ("geardyn.papers.li2013", "geardyn.papers.yue2014"):
        tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
        assert not [n for n in tree.body if isinstance(n, ast.FunctionDef | ast.ClassDef)], name
        assert GRAPH[name] == [], name
