"""The import graph of the leas_jax package, from its source (ast; nothing is imported).

Every `import` and `from ... import` of a leas_jax module counts, at module level, inside
a function (a lazy import is still a dependency) or under `if TYPE_CHECKING:` (two modules
whose annotations name each other still know each other). `from package import name` is an
edge to the submodule `package.name` when there is one, else to the package. Importing a
submodule implicitly runs its parents' `__init__`; those implicit edges are left out (they
would make every package a cycle with its own submodules).

    python tests/import_graph.py          # prints each cycle, exit 1 if there is one
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "leas_jax"


def modules(root: Path = ROOT) -> dict[str, Path]:
    """{dotted module name: file} of every module of the package."""
    found = {}
    for path in sorted((root / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


def _resolve(module: str, is_package: bool, level: int, target: str | None) -> str:
    """Absolute name of `from <level dots><target> import ...` in `module`."""
    if level == 0:
        return target or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ([target] if target else []))


def imports(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The leas_jax modules that module `name` (file `path`) imports."""
    tree = ast.parse(path.read_text(), filename=str(path))
    is_package = path.name == "__init__.py"
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in known:
                    out.add(alias.name)
        elif isinstance(node, ast.ImportFrom):
            source = _resolve(name, is_package, node.level, node.module)
            if not source.startswith(PACKAGE):
                continue
            for alias in node.names:
                sub = f"{source}.{alias.name}"
                out.add(sub if sub in known else source)
    out.discard(name)
    return {m for m in out if m in known}


def graph(root: Path = ROOT) -> dict[str, set[str]]:
    """{module: modules it imports} over the whole package."""
    known = modules(root)
    return {name: imports(name, path, known) for name, path in known.items()}


def reached(edges: dict[str, set[str]], prefix: str) -> set[str]:
    """The modules named `prefix`... and every module they import, directly or not."""
    found, pending = set(), [m for m in edges if m == prefix or m.startswith(prefix + ".")]
    while pending:
        module = pending.pop()
        if module not in found:
            found.add(module)
            pending.extend(edges[module])
    return found


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges.get(v, ())):
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

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return sorted(found)


def main() -> int:
    found = cycles(graph())
    for component in found:
        print("import cycle: " + " <-> ".join(component))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
