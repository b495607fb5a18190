"""The package's shape: no import cycles between geardyn's modules, no private names imported across
modules, gear science that knows no paper, and a solver core that knows no model family."""

import ast
import pathlib
import re

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
    assert {"geardyn.solve.run", "geardyn.khv.point", "geardyn.runs.sweep", "geardyn.papers.li2013"} <= set(MODULES)
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


PAPER_MODULES = sorted(m for m in MODULES if m.startswith("geardyn.papers."))
#: The design keys of the papers (``paper: li2013``): the names of their modules.
PAPER_KEYS = [m.rpartition(".")[2] for m in PAPER_MODULES]


def _code_strings(tree: ast.AST) -> list[ast.Constant]:
    """The string constants of a module's code: f-string parts included, docstrings left out."""
    docstrings = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef) and body:
            first = body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                docstrings.add(id(first.value))
    return [
        n
        for n in ast.walk(tree)
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docstrings
    ]


def test_the_paper_keys_are_the_papers_modules():
    assert {"li2013", "yue2014"} <= set(PAPER_KEYS)


@pytest.mark.parametrize("name", [m for m in sorted(MODULES) if not m.startswith("geardyn.papers")])
def test_no_generic_module_names_a_paper(name):
    """Outside geardyn.papers no module imports one paper's module (a design names its paper, and
    ``geardyn.papers.paper_of`` finds it) and no string of the code names a paper's design key (the papers'
    values and claims are data in their modules; docstrings may cite a design as an example)."""
    imported = {m for m, _ in _imports(name, MODULES[name])}
    assert not imported & set(PAPER_MODULES), f"{name} imports {sorted(imported & set(PAPER_MODULES))}"
    tree = ast.parse(MODULES[name].read_text(encoding="utf-8"))
    named = [f"line {n.lineno}: {n.value!r}" for n in _code_strings(tree) if any(key in n.value for key in PAPER_KEYS)]
    assert not named, f"{name} names a paper's design in its code: {named}"


def test_the_paper_check_sees_a_string_and_an_import(tmp_path):
    """The check above finds a paper's key in a string of code (not in a docstring) and a paper imported."""
    path = tmp_path / "fake.py"
    path.write_text(
        '"""Docstring about li2013."""\n\nfrom geardyn.papers import li2013, paper_of\n\n'
        'X = f"results/{paper_of}/li2013.nc"\n\n\ndef f():\n    """yue2014"""\n'
    )
    tree = ast.parse(path.read_text())
    assert [n.value for n in _code_strings(tree) if any(k in n.value for k in PAPER_KEYS)] == ["/li2013.nc"]
    assert set(PAPER_MODULES) & {m for m, _ in _imports("geardyn.fake", path)} == {"geardyn.papers.li2013"}


# --- one home for every number ------------------------------------------------------------------------------

#: The parameter names of a tolerance or an iteration limit.
_LIMIT_NAME = re.compile(r"(^|_)(tol|rtol|atol|xtol|maxiter|max_iter|iterations|max_points|max_corrector|max_step)$")
#: The packages whose functions write no tolerance and no iteration limit.
NUMBERS_HOMED = ("geardyn.solve", "geardyn.runs.continuation", "geardyn.label")


def _is_number(node: ast.AST | None) -> bool:
    return isinstance(node, ast.Constant) and type(node.value) in (int, float)


def _tolerance(node: ast.AST | None) -> bool:
    """A float literal of magnitude below 1e-3 (a tolerance, not a coefficient such as 0.5 or a count)."""
    return isinstance(node, ast.Constant) and type(node.value) is float and 0.0 < abs(node.value) < 1e-3


def _numbers_in_functions(path: pathlib.Path) -> list[str]:
    """Every tolerance or iteration limit written inside a function of ``path``: a small float in its body or its
    defaults, a number as the default of a parameter named like one, or passed to a keyword named like one."""
    found = []
    for fn in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(fn, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        a = fn.args
        positional = a.posonlyargs + a.args
        defaults = list(zip(positional[len(positional) - len(a.defaults) :], a.defaults, strict=True))
        defaults += [(arg, d) for arg, d in zip(a.kwonlyargs, a.kw_defaults, strict=True) if d is not None]
        found += [
            f"line {d.lineno}: {fn.name}({arg.arg}={d.value!r})"
            for arg, d in defaults
            if _tolerance(d) or (_is_number(d) and _LIMIT_NAME.search(arg.arg))
        ]
        for node in (n for stmt in fn.body for n in ast.walk(stmt)):
            if isinstance(node, ast.keyword) and node.arg and _LIMIT_NAME.search(node.arg) and _is_number(node.value):
                found.append(f"line {node.value.lineno}: {node.arg}={node.value.value!r} in {fn.name}")
            elif _tolerance(node):
                found.append(f"line {node.lineno}: {node.value!r} in {fn.name}")
    return sorted(set(found))


_CONSTANT = re.compile(r"^[A-Z][A-Z0-9_]* = ")


def _unexplained_constants(path: pathlib.Path) -> list[str]:
    """The module-level constants of ``path`` that hold a tolerance without a comment on their line or above their
    group (consecutive constants)."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out = []
    for node in ast.parse("\n".join(lines)).body:
        if isinstance(node, ast.Assign | ast.AnnAssign) and any(_tolerance(n) for n in ast.walk(node)):
            k = node.lineno - 2  # up through the constants of its group to the comment above them
            while k >= 0 and _CONSTANT.match(lines[k]):
                k -= 1
            if not ((k >= 0 and lines[k].startswith("#")) or "#" in lines[node.lineno - 1]):
                out.append(f"line {node.lineno}")
    return out


@pytest.mark.parametrize("name", [m for m in sorted(MODULES) if m.startswith(NUMBERS_HOMED)])
def test_no_tolerance_or_iteration_limit_inside_a_function(name):
    """In the solver, the continuation engine and the labeller every tolerance and iteration limit is a settings
    field or a named module-level constant whose comment gives its reason; none is written inside a function."""
    assert not _numbers_in_functions(MODULES[name]), _numbers_in_functions(MODULES[name])
    assert not _unexplained_constants(MODULES[name]), _unexplained_constants(MODULES[name])


def test_the_number_check_sees_a_tolerance_a_limit_and_a_bare_constant(tmp_path):
    path = tmp_path / "fake.py"
    path.write_text(
        "import scipy\n\n#: why\nGOOD = 1e-9\n\nBARE = 1e-12\n\n\n"
        "def f(x, tol=1e-6, max_iter=30, scale=0.5):\n"
        "    return scipy.optimize.brentq(x, 0.0, 1.0, maxiter=60) < 1e-9 * scale + GOOD\n"
    )
    assert _numbers_in_functions(path) == [
        "line 10: 1e-09 in f",
        "line 10: maxiter=60 in f",
        "line 9: f(max_iter=30)",
        "line 9: f(tol=1e-06)",
    ]
    assert _unexplained_constants(path) == ["line 6"]
