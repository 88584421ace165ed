"""Does the numerical contact velocity decide the runout?  A sweep over ``settings.contact_velocity_ms``.

    python validation/contact_velocity.py                       # the scenarios as shipped
    python validation/contact_velocity.py --tangential coulomb  # the presets' constant e_T bounded by friction
    python validation/contact_velocity.py --hop roughness       # hop height = roughness where none is stated
    python validation/contact_velocity.py --roughness 0         # no roughness tilt at impacts

For each shipped 2-D scenario (``simulation/scenarios/*.toml``) and the Authume P1 and P2 sections, the median
runout at contact velocities 0.01, 0.05, 0.1 and 0.5 m/s (n blocks, one seed), its change against 0.5 m/s (the
default) and the mean number of impacts per block.  The contact velocity is meant to be numerical: below it a
rebound becomes ground contact, and a converged model gives the same runout for any value small enough.  A
change of more than 5 % between 0.01 and 0.5 m/s is flagged.

The variants change the model, not the scenario files:

* ``--tangential coulomb``: every material with the constant tangential law (the natural-ground presets, e_T 0.55
  +- 0.12) takes the Coulomb-bounded law instead (``law = "coulomb"``, friction 35 +- 3 deg, the data-derived
  presets' law, :func:`simulation.contact.coulomb_tangential`);
* ``--hop roughness``: every material without a ``contact_hop_height_m`` takes its roughness height as the hop
  height (a rebound that does not clear the asperities is rolling over them);
* ``--roughness 0``: every material's roughness set to 0 (no tilt of the surface at impacts).

Runs in about half a minute.
"""
from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import simulation  # noqa: E402
from simulation.materials import resolve_material  # noqa: E402

SCENARIOS = ROOT / "simulation" / "scenarios"
VELOCITIES = (0.01, 0.05, 0.1, 0.5)
COULOMB = {"law": "coulomb", "mean": 0.55, "std": 0.12, "friction_angle_deg": 35.0, "std_deg": 3.0}


def scenario_paths() -> list[Path]:
    """The shipped 2-D scenarios (those with a ``[profile]``) and the Authume P1 and P2 sections."""
    out = []
    for path in sorted(SCENARIOS.glob("*.toml")) + [SCENARIOS / "authume" / "authume_p1.toml",
                                                   SCENARIOS / "authume" / "authume_p2.toml"]:
        if "profile" in tomllib.loads(path.read_text()):
            out.append(path)
    return out


def variant(data: dict, source: str, tangential: str, hop: str, roughness: float | None) -> dict:
    """The scenario table ``data`` with the model variant of the command line applied to its materials."""
    for name, spec in data.get("materials", {}).items():
        full = resolve_material(spec, f"materials.{name}", source)
        if tangential == "coulomb" and full.get("tangential", {}).get("law") == "constant":
            spec["tangential"] = dict(COULOMB)
        if hop == "roughness" and "contact_hop_height_m" not in full:
            spec["contact_hop_height_m"] = float(full.get("roughness_m", 0.0))
        if roughness is not None:
            spec["roughness_m"] = roughness
    return data


def sweep(path: Path, n: int, seed: int, **model) -> list[tuple[float, float, float]]:
    """(contact velocity, median runout [m], mean impacts per block) for each of :data:`VELOCITIES`."""
    rows = []
    for vc in VELOCITIES:
        data = variant(tomllib.loads(path.read_text()), str(path), **model)
        data.setdefault("settings", {})["contact_velocity_ms"] = vc
        res = simulation.run(simulation.scenario_from_dict(data, source=str(path)), n=n, seed=seed, record_paths=0)
        rows.append((vc, float(np.median(res.per_block["x"])), float(np.mean(res.per_block["impacts"]))))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-n", type=int, default=1000, help="blocks per run (default 1,000)")
    ap.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    ap.add_argument("--tangential", choices=["as-given", "coulomb"], default="as-given",
                    help="the presets' constant e_T as given, or bounded by Coulomb friction")
    ap.add_argument("--hop", choices=["as-given", "roughness"], default="as-given",
                    help="hop heights as given, or the roughness where a material states none")
    ap.add_argument("--roughness", type=float, default=None, help="set every material's roughness [m]")
    args = ap.parse_args(argv)
    model = dict(tangential=args.tangential, hop=args.hop, roughness=args.roughness)
    print(f"median runout [m] by contact velocity, n {args.n:,}, seed {args.seed}; model: {model}")
    print("| scenario | " + " | ".join(f"{v:g} m/s" for v in VELOCITIES) + " | change 0.01 vs 0.5 | impacts per "
          "block at 0.01 / 0.5 |")
    print("|---|" + "---|" * (len(VELOCITIES) + 2))
    worst = 0.0
    for path in scenario_paths():
        rows = sweep(path, args.n, args.seed, **model)
        change = rows[0][1] / rows[-1][1] - 1.0
        worst = max(worst, abs(change))
        flag = " (> 5 %)" if abs(change) > 0.05 else ""
        print(f"| {path.stem} | " + " | ".join(f"{m:.2f}" for _, m, _ in rows) +
              f" | {100 * change:+.1f} %{flag} | {rows[0][2]:.1f} / {rows[-1][2]:.1f} |", flush=True)
    print(f"largest change between 0.01 and 0.5 m/s: {100 * worst:.1f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
