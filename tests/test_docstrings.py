"""Every public function, class and method of riskrf and simulation has a docstring.

Public: module-level functions and classes, and methods of public classes, whose names do not start
with an underscore, in modules whose path has no part starting with an underscore (``__init__``
aside).  Dunder methods, properties' setters and test/script files under ``scenarios`` are exempt.  A method
that overrides a documented method of a base class inherits its docstring (as ``inspect.getdoc`` and the API
reference do), when the base is defined in the same module or imported into it from a module of the same package
(``from .base import OptionEffect``).
"""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("riskrf", "simulation")


def _inherits_doc(cls, name, classes, seen=()):
    """True when a base of ``cls`` defined in the same module documents method ``name``."""
    for base in cls.bases:
        parent = classes.get(getattr(base, "id", None))
        if parent is None or parent.name in seen:
            continue
        for sub in parent.body:
            if isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef)) and sub.name == name \
                    and ast.get_docstring(sub) is not None:
                return True
        if _inherits_doc(parent, name, classes, seen + (parent.name,)):
            return True
    return False


_CLASS_TABLES: dict = {}


def _class_table(path: Path, _open=()) -> dict:
    """Name -> ``ast.ClassDef`` of the classes a module defines, and of those it imports with a relative
    ``from .module import Name`` (followed into that module, so a base's own bases resolve too)."""
    if path in _CLASS_TABLES:
        return _CLASS_TABLES[path]
    if path in _open or not path.exists():
        return {}
    tree = ast.parse(path.read_text(encoding="utf-8"))
    table = {}
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.level:
            folder = path.parent
            for _ in range(node.level - 1):
                folder = folder.parent
            target = folder.joinpath(*(node.module or "").split("."))
            source = target / "__init__.py" if target.is_dir() else target.with_suffix(".py")
            imported = _class_table(source, _open + (path,))
            for alias in node.names:
                if alias.name in imported:
                    table.update(imported)
                    table[alias.asname or alias.name] = imported[alias.name]
    table.update({n.name: n for n in tree.body if isinstance(n, ast.ClassDef)})
    _CLASS_TABLES[path] = table
    return table


def _public_definitions_without_docstring():
    missing = []
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            rel = path.relative_to(ROOT)
            if any(p.startswith("_") and p != "__init__.py" for p in rel.parts) or "scenarios" in rel.parts:
                continue
            tree = ast.parse(path.read_text(encoding="utf-8"))
            classes = _class_table(path)
            for node in tree.body:
                if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                    continue
                if node.name.startswith("_"):
                    continue
                if ast.get_docstring(node) is None:
                    missing.append(f"{rel}:{node.lineno} {node.name}")
                if isinstance(node, ast.ClassDef):
                    for sub in node.body:
                        if (isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef)) and not sub.name.startswith("_")
                                and ast.get_docstring(sub) is None
                                and not _inherits_doc(node, sub.name, classes)
                                and not any(isinstance(d, ast.Attribute) and d.attr in ("setter", "deleter")
                                            for d in sub.decorator_list)):
                            missing.append(f"{rel}:{sub.lineno} {node.name}.{sub.name}")
    return missing


def test_every_public_definition_has_a_docstring():
    missing = _public_definitions_without_docstring()
    assert not missing, f"{len(missing)} public definitions lack a docstring:\n" + "\n".join(missing)


if __name__ == "__main__":
    print("\n".join(_public_definitions_without_docstring()))


# ---- numpydoc sections ---------------------------------------------------------------------------------------
#: Every public module of riskrf and simulation: its public functions and methods are written in numpydoc form.
NUMPYDOC_MODULES = tuple(
    str(p.relative_to(ROOT)) for pkg in PACKAGES for p in sorted((ROOT / pkg).rglob("*.py"))
    if not any(part.startswith("_") and part != "__init__.py" for part in p.relative_to(ROOT).parts)
    and "scenarios" not in p.relative_to(ROOT).parts)


def _section(doc: str, title: str) -> bool:
    """True when ``doc`` has a numpydoc section ``title`` (the title on its own line, underlined by dashes)."""
    lines = [line.strip() for line in doc.splitlines()]
    return any(a == title and b and set(b) == {"-"} for a, b in zip(lines, lines[1:]))


def _returns_value(fn: ast.FunctionDef) -> bool:
    """True when the function has a ``return <value>`` of its own (not in a nested function)."""
    stack = list(fn.body)
    while stack:
        node = stack.pop()
        if isinstance(node, ast.Return) and node.value is not None and not (
                isinstance(node.value, ast.Constant) and node.value.value is None):
            return True
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            stack.extend(ast.iter_child_nodes(node))
    return False


def _numpydoc_gaps(rel: str, root: Path = ROOT) -> list[str]:
    """Public functions and methods of module ``rel`` lacking a Parameters section (when they take arguments)
    or a Returns/Yields section (when they return a value).  Properties are documented as attributes (exempt),
    and so are dunder methods."""
    tree = ast.parse((root / rel).read_text(encoding="utf-8"))
    gaps = []

    def check(fn, owner=""):
        if fn.name.startswith("_") or any(isinstance(d, ast.Name) and d.id == "property" or
                                          isinstance(d, ast.Attribute) and d.attr in ("setter", "deleter")
                                          for d in fn.decorator_list):
            return
        doc = ast.get_docstring(fn) or ""
        a = fn.args
        args = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs if x.arg not in ("self", "cls")]
        if a.vararg:
            args.append(a.vararg.arg)
        if a.kwarg:
            args.append(a.kwarg.arg)
        if args and not _section(doc, "Parameters"):
            gaps.append(f"{rel}:{fn.lineno} {owner}{fn.name}: no Parameters section")
        if _returns_value(fn) and not (_section(doc, "Returns") or _section(doc, "Yields")):
            gaps.append(f"{rel}:{fn.lineno} {owner}{fn.name}: no Returns section")

    classes = _class_table(root / rel)
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            check(node)
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            for sub in node.body:
                # an override without its own docstring inherits the base's, which is checked where it is written
                if isinstance(sub, (ast.FunctionDef, ast.AsyncFunctionDef)) and not (
                        ast.get_docstring(sub) is None and _inherits_doc(node, sub.name, classes)):
                    check(sub, node.name + ".")
    return gaps


def test_numpydoc_sections_in_covered_modules():
    gaps = [g for rel in NUMPYDOC_MODULES for g in _numpydoc_gaps(rel)]
    assert not gaps, f"{len(gaps)} public callables lack numpydoc sections:\n" + "\n".join(gaps)


def test_numpydoc_check_finds_a_missing_section(tmp_path):
    """The section check itself: a function with arguments and a return value but prose only is caught."""
    (tmp_path / "m.py").write_text('def f(x):\n    """Twice x."""\n    return 2 * x\n\n\n'
                                   'def g(x):\n    """Twice x.\n\n    Parameters\n    ----------\n    x : float\n'
                                   '        A number.\n\n    Returns\n    -------\n    float\n    """\n    return 2 * x\n')
    assert _numpydoc_gaps("m.py", tmp_path) == ["m.py:1 f: no Parameters section", "m.py:1 f: no Returns section"]


def test_an_override_inherits_the_docstring_of_a_base_imported_from_another_module(tmp_path):
    """A kind's override without a docstring is documented by its base's in another module of the package; an
    override whose base documents nothing is still a gap."""
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "__init__.py").write_text("")
    (tmp_path / "pkg" / "base.py").write_text(
        'class Base:\n    """A base."""\n\n    def describe(self, x):\n        """What it is.\n\n'
        '        Parameters\n        ----------\n        x : float\n\n        Returns\n        -------\n'
        '        str\n        """\n        return ""\n\n    def stages(self, x):\n        return []\n')
    (tmp_path / "pkg" / "kind.py").write_text(
        'from .base import Base\n\n\nclass Kind(Base):\n    """A kind."""\n\n    def describe(self, x):\n'
        '        return "kind"\n\n    def stages(self, x):\n        return [x]\n')
    assert _numpydoc_gaps("pkg/kind.py", tmp_path) == ["pkg/kind.py:10 Kind.stages: no Parameters section",
                                                       "pkg/kind.py:10 Kind.stages: no Returns section"]
