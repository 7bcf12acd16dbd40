"""The package's shape: layers without import cycles, small modules, explicit public names.

Every import inside ``synth/`` is read from the source (module-level and inside functions; imports
under ``if TYPE_CHECKING:`` are for type checkers only and not counted). Each module belongs to a
layer (the longest matching prefix in :data:`LAYERS`); a module may import from its own layer or a
lower one, never from a higher one, and no set of modules may import each other in a circle.
docs/architecture.md draws the same layers.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "synth"

# Lowest first. The data flow: spec -> requirements -> forms -> solvers -> result -> report;
# record -> identify -> model; model + record -> where -> effects -> attribution -> verdict.
LAYERS: dict[str, int] = {
    # 0 base: no synth imports but each other
    "synth.version": 0, "synth.errors": 0, "synth.polynomials": 0, "synth.rootfind": 0, "synth.tfparse": 0,
    "synth.distributions": 0, "synth.statespace": 0, "synth.outputs": 0, "synth.figure_files": 0, "synth.forked": 0,
    "synth.search": 0, "synth.jit": 0, "synth.polynomial_rows": 0, "synth.progress": 0, "synth.delayed_blocks": 0,
    "synth.disk_cache": 0, "synth.exact_steps": 0, "synth.stats_stand_in": 0, "synth.speculation": 0,
    "synth.worker_pool": 0,
    # 1 models: plants, controllers, the loop and its exact stability, records
    "synth.plant": 1, "synth.controllers": 1, "synth.stability": 1, "synth.stability_sets": 1, "synth.freqgrid": 1,
    "synth.unity_gain": 1, "synth.narrow_peaks": 1, "synth.first_crossing": 1,
    "synth.batch_bandwidth": 1,
    "synth.loop": 1, "synth.loop_batch": 1, "synth.loop_memo": 1, "synth.timeresp": 1, "synth.delayed_step": 1,
    "synth.settled_step": 1,
    "synth.objectives": 1, "synth.data": 1, "synth.gap.where.clipping": 1,
    # 2 analyses on a model: requirements, simulation, identification
    "synth.requirements": 2, "synth.sim": 2, "synth.ident": 2, "synth.edge": 2,
    # 3 the problem statement, parsed
    "synth.spec": 3,
    # 4 evaluation against the spec, and the result types
    "synth.check": 4, "synth.results": 4,
    # 5 solvers: one-parameter sets, convex, NLP, multi-parameter design
    "synth.synthesis": 5,
    # 6 the design dispatcher
    "synth.design": 6,
    # 7 what runs designs or models many times: trade-offs, published comparisons, the gap diagnosis
    "synth.tradeoff": 7, "synth.synthesis.tradeoff": 7, "synth.reference": 7, "synth.gap": 7,
    "synth.sizing": 7, "synth.paper_row": 7, "synth.paper_checks": 7,
    # 8 reports
    "synth.report": 8, "synth.gap.report": 8, "synth.gap.roundrobin_report": 8,
    # 9 the command line, 10 the package's front door
    "synth.cli": 9, "synth.__main__": 10, "synth": 10,
}

# one worker: the package's modules are parsed once per process (_tree), not once per test
pytestmark = pytest.mark.xdist_group("architecture")

MAX_LINES = 550  # "about 500": a module past this is split along its concepts


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


MODULES: dict[str, Path] = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def layer_of(module: str) -> int:
    """Layer of ``module``: the longest prefix of its dotted name listed in :data:`LAYERS`."""
    parts = module.split(".")
    for n in range(len(parts), 0, -1):
        key = ".".join(parts[:n])
        if key in LAYERS:
            return LAYERS[key]
    raise AssertionError(f"{module} is in no layer: add it to LAYERS in tests/test_architecture.py")


@cache
def _tree(path: Path) -> ast.Module:
    """The parsed source of ``path``, parsed once per process (the tests only walk the trees)."""
    return ast.parse(path.read_text())


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If):
            test = node.test
            name = test.id if isinstance(test, ast.Name) else getattr(test, "attr", None)
            if name == "TYPE_CHECKING":
                for child in node.body:
                    skip.update(id(n) for n in ast.walk(child))
    return skip


@cache
def _imports(module: str, path: Path) -> tuple[tuple[str, str, int], ...]:
    """(imported module, imported name or '', line) for every synth import of ``module``."""
    tree = _tree(path)
    skip = _type_checking_nodes(tree)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source != "synth" and not source.startswith("synth."):
                continue
            for alias in node.names:
                full = f"{source}.{alias.name}"
                found.append((full if full in MODULES else source, alias.name, node.lineno))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name == "synth" or alias.name.startswith("synth."):
                    found.append((alias.name, "", node.lineno))
    return tuple(found)


def _graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = defaultdict(set)
    for module, path in MODULES.items():
        for target, _name, _line in _imports(module, path):
            if target != module and target in MODULES:
                graph[module].add(target)
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(MODULES):
        if v not in index:
            visit(v)
    return found


def test_no_import_cycle():
    assert _cycles(_graph()) == []


def test_no_import_from_a_higher_layer():
    upward = []
    for module, path in MODULES.items():
        for target, name, line in _imports(module, path):
            if target in MODULES and target != module and layer_of(target) > layer_of(module):
                upward.append(f"{path.relative_to(ROOT)}:{line} imports {target}"
                              f"{'.' + name if name and target.rpartition('.')[2] != name else ''}"
                              f" (layer {layer_of(module)} -> {layer_of(target)})")
    assert upward == []


def test_no_private_name_crosses_a_module_line():
    crossing = []
    for module, path in MODULES.items():
        tree = _tree(path)
        aliases: dict[str, str] = {}
        for target, name, line in _imports(module, path):
            if name.startswith("_") and not name.startswith("__") and target != module:
                crossing.append(f"{path.relative_to(ROOT)}:{line} imports {name} from {target}")
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom | ast.Import):
                for alias in node.names:
                    bound = alias.asname or alias.name.split(".")[0]
                    aliases[bound] = alias.name
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.attr.startswith("_") and not node.attr.startswith("__")):
                source = aliases.get(node.value.id, "")
                if source.split(".")[0] == "synth" or f"{module.rpartition('.')[0]}.{source}" in MODULES:
                    crossing.append(f"{path.relative_to(ROOT)}:{node.lineno} uses {node.value.id}.{node.attr}")
    assert crossing == []


def test_every_module_is_small():
    long = {str(p.relative_to(ROOT)): n for p in MODULES.values() if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert long == {}


def test_every_public_module_declares_its_public_names():
    missing = []
    for path in MODULES.values():
        if any(part.startswith("_") and part != "__init__" for part in path.relative_to(ROOT).with_suffix("").parts):
            continue  # private modules (synth/sim/_kernel.py, ...) and __main__
        tree = _tree(path)
        names = {t.id for node in tree.body if isinstance(node, ast.Assign | ast.AnnAssign)
                 for t in (node.targets if isinstance(node, ast.Assign) else [node.target]) if isinstance(t, ast.Name)}
        if "__all__" not in names:
            missing.append(str(path.relative_to(ROOT)))
    assert missing == []


def test_all_lists_only_names_the_module_has():
    import importlib

    wrong = []
    for module, path in MODULES.items():
        if "__all__" not in path.read_text() or module.endswith("__main__"):
            continue
        mod = importlib.import_module(module)
        wrong += [f"{module}.{name}" for name in getattr(mod, "__all__", []) if not hasattr(mod, name)]
    assert wrong == []


def test_every_module_has_a_layer_and_the_test_sees_imports():
    for module in MODULES:
        layer_of(module)
    # the reader resolves a submodule imported by name, so the graph is not empty of real edges
    assert "synth.errors" in _graph()["synth.plant"]


def test_tests_and_benchmarks_use_only_public_names():
    """The rule holds outside the package too: tests and benchmarks go through public names."""
    crossing = []
    for folder in (ROOT / "tests", ROOT / "benchmarks"):
        for path in sorted(folder.rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("synth"):
                    crossing += [f"{path.relative_to(ROOT)}:{node.lineno} imports {a.name} from {node.module}"
                                 for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
    assert crossing == []


def test_import_synth_loads_no_solver_or_plotting_library():
    """``import synth`` stays light: cvxpy, casadi, numba, matplotlib and scipy.stats load on first use."""
    import subprocess
    import sys

    heavy = ("cvxpy", "casadi", "numba", "matplotlib", "scipy.stats", "scipy.signal", "jinja2")
    code = f"import sys, synth; print([m for m in {heavy!r} if m in sys.modules])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "[]"


def test_the_design_report_loads_no_signal_or_stats_package():
    """The design report's modules (the seed's gap case among them, which imports identification) load neither
    ``scipy.signal`` nor ``scipy.stats`` (0.34 s together): identification imports them where it calls them. A
    module-level import in ``synth.ident.start_state`` cost every X-4 report that (session 47)."""
    import subprocess
    import sys

    heavy = ("scipy.signal", "scipy.stats")
    code = ("import sys, synth.report.design_report, synth.gap.x4_case, synth.gap.diagnose, synth.design; "
            f"print([m for m in {heavy!r} if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "[]"


def test_the_check_and_its_requirements_load_no_matrix_exponential():
    """``synth check`` on a spec without time responses stays light: the requirement types load the step's
    modules (scipy.linalg among them, 0.1 s) only when a step is computed (a module-level import of
    ``synth.timeresp`` in the step limit's module once cost every check that)."""
    import subprocess
    import sys

    heavy = ("scipy.linalg", "synth.timeresp", "synth.exact_steps", "synth.statespace")
    code = f"import sys, synth.check, synth.requirements; print([m for m in {heavy!r} if m in sys.modules])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "[]"
