"""mech's modules import each other in one direction: the dependency graph is a DAG.

Every import of a mech module counts, at the top or inside a function (an import inside
a function that only dodges a circle is still a circle). The ahead-of-time loader
(mech.aot) imports nothing of mech but the cache key, so loading the compiled module
never loads the solver; only its build child (mech.aot_build) does.
"""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "mech"


def mech_imports(path: Path) -> set[str]:
    """The mech modules ``path`` imports (relative or absolute), anywhere in the file; the
    just-in-time fallback of mech.compiled imports the kernel and the integrator by name."""
    names = {p.stem for p in PACKAGE.glob("*.py")}
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level == 1 or module == "mech" or module.startswith("mech."):
                head = module.split(".")[-1] if module not in ("", "mech") else ""
                if head in names:
                    out.add(head)
                else:
                    out |= {a.name for a in node.names if a.name in names}
        elif isinstance(node, ast.Import):
            out |= {a.name.split(".")[1] for a in node.names if a.name.startswith("mech.")}
    if path.stem == "compiled":
        out |= {"kernel", "integrator"}
    return out


def graph(package: Path = PACKAGE) -> dict[str, set[str]]:
    return {p.stem: mech_imports(p) for p in sorted(package.glob("*.py"))}


def cycle(g: dict[str, set[str]]) -> list[str] | None:
    """One import cycle of ``g`` as a list of modules, or None."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(v):
        state[v] = 1
        stack.append(v)
        for w in sorted(g.get(v, ())):
            if state.get(w) == 1:
                return stack[stack.index(w):] + [w]
            if w not in state:
                found = visit(w)
                if found:
                    return found
        state[v] = 2
        stack.pop()
        return None

    for v in sorted(g):
        if v not in state:
            found = visit(v)
            if found:
                return found
    return None


def test_mech_imports_form_no_cycle():
    assert cycle(graph()) is None, f"import cycle: {' -> '.join(cycle(graph()))}"


def test_the_loader_of_the_compiled_module_imports_only_the_cache_key():
    g = graph()
    assert g["aot"] == {"compiled_cache"}
    assert "aot_build" not in set().union(*(deps for name, deps in g.items() if name != "aot_build"))
    assert g["contact_laws"] == set()  # the pure laws: compiled into the kernel


def test_the_check_finds_a_cycle_closed_inside_a_function(tmp_path):
    """A copy of mech where contact_laws imports the compiled module inside a function (as
    the damping calibration once did) has the cycle compiled -> kernel -> contact_laws ->
    compiled, and the check names it."""
    pkg = tmp_path / "mech"
    pkg.mkdir()
    for path in PACKAGE.glob("*.py"):
        (pkg / path.name).write_text(path.read_text())
    laws = pkg / "contact_laws.py"
    laws.write_text(laws.read_text() + "\n\ndef _late():\n    from .compiled import scaled_rebound\n"
                    "    return scaled_rebound\n")
    found = cycle(graph(pkg))
    assert found is not None and "contact_laws" in found and "compiled" in found
