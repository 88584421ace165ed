"""Every public function, class and method of riskrf and simulation has a docstring.

Public: module-level functions and classes, and methods of public classes, whose names do not start
with an underscore, in modules whose path has no part starting with an underscore (``__init__``
aside).  Dunder methods, properties' setters and test/script files under ``scenarios`` are exempt.  A method
that overrides a documented method of a base class defined in the same module inherits its docstring (as
``inspect.getdoc`` and the API reference do).
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


def _public_definitions_without_docstring():
    missing = []
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            rel = path.relative_to(ROOT)
            if any(p.startswith("_") and p != "__init__.py" for p in rel.parts) or "scenarios" in rel.parts:
                continue
            tree = ast.parse(path.read_text(encoding="utf-8"))
            classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
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
