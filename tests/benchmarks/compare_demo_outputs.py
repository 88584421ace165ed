"""Compare every CSV/JSON of two `riskrf demo` output folders, ignoring timing fields:

    python tests/benchmarks/compare_demo_outputs.py BEFORE_DIR AFTER_DIR
"""
import json, sys, math
from pathlib import Path
import pandas as pd
a, b = Path(sys.argv[1]), Path(sys.argv[2])
TIMING = ("timings", "time", "seconds", "elapsed", "duration_s", "stage_times", "created", "generated", "run_at", "timestamp")
files = sorted(p.relative_to(a) for p in a.rglob("*") if p.suffix in (".csv", ".json"))
assert files == sorted(p.relative_to(b) for p in b.rglob("*") if p.suffix in (".csv", ".json"))
worst, diffs, skipped = 0.0, [], set()
def walk(x, y, path):
    global worst
    if isinstance(x, dict):
        assert set(x) == set(y), (path, set(x) ^ set(y))
        for k in x:
            if any(t in k.lower() for t in TIMING):
                skipped.add(k); continue
            walk(x[k], y[k], f"{path}.{k}")
    elif isinstance(x, list):
        assert len(x) == len(y), path
        for i, (p, q) in enumerate(zip(x, y)): walk(p, q, f"{path}[{i}]")
    elif isinstance(x, float) or isinstance(y, float):
        if x != y and not (math.isnan(x) and math.isnan(y)):
            rel = abs(x - y) / max(abs(x), abs(y)); worst = max(worst, rel); diffs.append((path, x, y))
    elif x != y:
        diffs.append((path, x, y))
for f in files:
    if f.suffix == ".json":
        walk(json.loads((a / f).read_text()), json.loads((b / f).read_text()), str(f))
    else:
        ta, tb = (a / f).read_text(), (b / f).read_text()
        if ta != tb:
            da, db = pd.read_csv(a / f), pd.read_csv(b / f)
            walk(da.to_dict("list"), db.to_dict("list"), str(f))
print(f"{len(files)} CSV/JSON files compared; timing keys skipped: {sorted(skipped)}")
print(f"differences: {len(diffs)}; worst relative float difference {worst:g}")
for d in diffs[:20]: print("  ", d)
