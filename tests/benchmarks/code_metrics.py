"""Lines of the mitigation modules and the longest functions and classes of riskrf (ast walk):

    python tests/benchmarks/code_metrics.py .
"""
import ast, sys
from pathlib import Path
root = Path(sys.argv[1]) / "riskrf"
funcs, classes = [], []
for p in sorted(root.rglob("*.py")):
    tree = ast.parse(p.read_text())
    for n in ast.walk(tree):
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)):
            funcs.append((n.end_lineno - n.lineno + 1, f"{p.relative_to(root.parent)}:{n.name}"))
        elif isinstance(n, ast.ClassDef):
            nm = sum(isinstance(b, (ast.FunctionDef, ast.AsyncFunctionDef)) for b in n.body)
            classes.append((n.end_lineno - n.lineno + 1, f"{p.relative_to(root.parent)}:{n.name} ({nm} methods)"))
for f in ["mitigation", "options", "slope_models", "loss_engine", "mitigation_inputs"]:
    q = root / "risk" / f"{f}.py"
    if q.exists():
        print(f"lines riskrf/risk/{f}.py: {len(q.read_text().splitlines())}")
print("longest functions:", sorted(funcs)[-3:][::-1])
print("longest classes:", sorted(classes)[-3:][::-1])
mit = [c for c in classes if "risk/mitigation.py" in c[1] or "risk/options/" in c[1] or "risk/loss_engine.py" in c[1] or "risk/slope_models.py" in c[1]]
print("classes in the mitigation modules:", sorted(mit)[::-1][:6])
fm = [f for f in funcs if any(s in f[1] for s in ("risk/mitigation.py", "risk/options/", "risk/loss_engine.py", "risk/slope_models.py"))]
print("longest functions in the mitigation modules:", sorted(fm)[-3:][::-1])
