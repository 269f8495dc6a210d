"""The package's seams have names: what one module takes from another is public or internal by name.

Every import of a coursekit module, function-level ones included, is read with `ast`. A name taken
from another coursekit module must be in that module's `__all__`, or come from a module whose file
name marks it internal (``_filter_ode.py``, ``exercises/_answers.py``): a helper shared under a plain
name that `__all__` leaves out is a hidden layer a reader cannot see. A private attribute
(``obj._x``) may be read only in the module that defines it. And the modules import one another
in at most one circle.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "coursekit"


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def _is_package(module: str) -> bool:
    return MODULES[module].name == "__init__.py"


def _is_internal(module: str) -> bool:
    """A module whose file name says it is internal: ``_name.py`` (not ``__init__.py``)."""
    return MODULES[module].name.startswith("_") and not _is_package(module)


def _resolve(module: str, node: ast.ImportFrom) -> str:
    """The absolute name of the module an ``ImportFrom`` in `module` reads from."""
    if not node.level:
        return node.module or ""
    base = module.split(".")
    base = base[:len(base) - node.level + (1 if _is_package(module) else 0)]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(module: str):
    """(source module, name, line) for every name `module` takes from another coursekit module.

    ``from x import name`` gives one; ``import coursekit.x as m`` / ``from . import x`` make an
    alias whose attributes ``m.name`` count as names taken from x. A submodule is a name too.
    """
    tree = ast.parse(MODULES[module].read_text(encoding="utf-8"))
    aliases = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name in MODULES:
                    yield alias.name, None, node.lineno
                    if alias.asname:
                        aliases[alias.asname] = alias.name
        elif isinstance(node, ast.ImportFrom):
            source = _resolve(module, node)
            for alias in node.names:
                if f"{source}.{alias.name}" in MODULES:
                    yield f"{source}.{alias.name}", None, node.lineno
                    aliases[alias.asname or alias.name] = f"{source}.{alias.name}"
                elif source in MODULES:
                    yield source, alias.name, node.lineno
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id in aliases and f"{aliases[node.value.id]}.{node.attr}" not in MODULES:
            yield aliases[node.value.id], node.attr, node.lineno


def _hidden_imports() -> list[str]:
    found = []
    for module in MODULES:
        for source, name, line in _imports(module):
            if name is None or source == module or name.startswith("__"):
                continue
            exported = getattr(importlib.import_module(source), "__all__", ())
            if name in exported or (_is_internal(source) and not name.startswith("_")):
                continue
            found.append(f"{MODULES[module].relative_to(PACKAGE.parent)}:{line}: {name} from {source}")
    return found


def _private_attributes_defined(module: str) -> set[str]:
    """The ``_x`` names `module` defines: functions, classes, assignments, ``self._x = ...``."""
    names = set()
    for node in ast.walk(ast.parse(MODULES[module].read_text(encoding="utf-8"))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif isinstance(node, ast.arg):
            names.add(node.arg)
    return {name for name in names if name.startswith("_") and not name.startswith("__")}


def _private_attribute_reads() -> list[str]:
    defined = {module: _private_attributes_defined(module) for module in MODULES}
    found = []
    for module, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Attribute) or not node.attr.startswith("_") \
                    or node.attr.startswith("__") or node.attr in defined[module]:
                continue
            owners = sorted(other for other, names in defined.items() if node.attr in names)
            if owners:
                found.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno}: .{node.attr} "
                             f"defined in {', '.join(owners)}")
    return found


def _import_circles() -> list[list[str]]:
    """The strongly connected groups of two or more modules in the graph of imports (Tarjan)."""
    graph = {module: {source for source, _, _ in _imports(module) if source != module} for module in MODULES}
    index, low, stack, on_stack, circles = {}, {}, [], set(), []

    def visit(module):
        index[module] = low[module] = len(index)
        stack.append(module)
        on_stack.add(module)
        for other in sorted(graph[module]):
            if other not in index:
                visit(other)
                low[module] = min(low[module], low[other])
            elif other in on_stack:
                low[module] = min(low[module], index[other])
        if low[module] == index[module]:
            group = []
            while not group or group[-1] != module:
                group.append(stack.pop())
                on_stack.discard(group[-1])
            if len(group) > 1:
                circles.append(sorted(group))

    for module in sorted(graph):
        if module not in index:
            visit(module)
    return circles


def test_names_taken_across_modules_are_public_or_internal_by_name():
    found = _hidden_imports()
    assert not found, (f"{len(found)} imports of names that the source module's __all__ leaves out "
                       "(export a user-facing name, or move the shared helper into a module named "
                       "_something.py):\n" + "\n".join(found))


def test_no_private_attribute_is_read_outside_its_module():
    found = _private_attribute_reads()
    assert not found, (f"{len(found)} private attributes read outside the module that defines them "
                       "(give the class a public method):\n" + "\n".join(found))


def test_at_most_one_import_circle():
    circles = _import_circles()
    assert len(circles) <= 1, f"{len(circles)} import circles: {circles}"


def test_the_scan_sees_a_hidden_import_a_private_read_and_a_circle(tmp_path, monkeypatch):
    """The scan itself: a small package with each defect is caught (so the tests above can fail)."""
    package = tmp_path / "seamkit"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("__all__ = []\n")
    (package / "a.py").write_text("__all__ = ['f']\ndef f(): pass\ndef helper(): pass\n"
                                  "class T:\n    def __init__(self): self._h = 1\n")
    (package / "sub" / "__init__.py").write_text("__all__ = []\n")
    (package / "sub" / "_shared.py").write_text("__all__ = []\ndef tool(): from .. import b\n")
    (package / "b.py").write_text("__all__ = []\nfrom .a import f, helper\nfrom .sub._shared import tool\n"
                                  "def g(t):\n    from . import a as m\n    return m.helper, t._h\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(globals(), "PACKAGE", package)
    monkeypatch.setitem(globals(), "MODULES", {_module_name(p): p for p in sorted(package.rglob("*.py"))})
    assert _hidden_imports() == ["seamkit/b.py:2: helper from seamkit.a", "seamkit/b.py:6: helper from seamkit.a"]
    assert _private_attribute_reads() == ["seamkit/b.py:6: ._h defined in seamkit.a"]
    assert _import_circles() == [["seamkit.b", "seamkit.sub._shared"]]
