"""Reading velocity samples at a barrier line from files (riskrf simulate, RocFall, RAMMS exports)."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from .tables import sniff_delimiter  # noqa: F401 (re-exported: public before)
from ..core.units import STANDARD_GRAVITY_MS2

#: Accepted column names after normalisation (lower case, units and punctuation stripped).
COLUMN_NAMES = {
    "velocity_ms": ("velocity_ms", "velocity", "translational_velocity", "speed", "v", "v_ms",
                    "velocity_m_s", "translational_velocity_m_s", "v_m_s"),
    "height_m": ("height_m", "height", "bounce_height", "bounce_height_m", "jump_height", "jump_height_m",
                 "passing_height", "passing_height_m"),
    "angular_velocity_rads": ("angular_velocity_rads", "angular_velocity", "rotational_velocity",
                              "rotational_velocity_rad_s", "angular_velocity_rad_s", "omega"),
    "mass_kg": ("mass_kg", "mass", "mass_kg_"),
    "radius_m": ("radius_m", "radius"),
    "collector": ("collector", "data_collector", "barrier"),
}


def _norm(name: str) -> str:
    s = str(name).strip().lower()
    s = re.sub(r"[\[\]\(\)/]", "_", s)
    s = re.sub(r"[^0-9a-z]+", "_", s).strip("_")
    return s


#: Velocity units accepted by ``velocity_unit`` and recognised at the end of a column name.
VELOCITY_UNITS = {"m/s": 1.0, "ms": 1.0, "km/h": 1 / 3.6, "kmh": 1 / 3.6}
_KMH_NAMES = ("velocity_kmh", "velocity_km_h", "speed_kmh", "speed_km_h", "v_kmh", "v_km_h",
              "translational_velocity_km_h", "translational_velocity_kmh")
#: Above this median, velocities "in m/s" are probably km/h: a free fall of 130 m gives 50 m/s, and rock fall
#: velocities at barriers are mostly 5-35 m/s (Wyllie 2014, chapter 5).
PLAUSIBLE_MEDIAN_MS = 50.0
#: Without a drop height, single velocities above this are flagged: 50 m/s is a free fall of
#: 50^2 / (2 x 9.81) = 127 m, more than the slopes above most roads (ASSUMPTION, stated in the warning).
PLAUSIBLE_MAX_MS = 50.0
#: Margin on the free-fall speed sqrt(2 g H) before a velocity is called implausible: 10 %
#: (release speed, rotation turned into translation and survey error; a rolling or bouncing block
#: loses energy, so it cannot exceed the speed of a free fall from its release height).
FREE_FALL_MARGIN = 0.10


def _practical_bounds(dist) -> tuple[float, float]:
    """``Distribution.bounds()`` of a scenario distribution with an unbounded end replaced by 4 spreads from the
    centre (mean +- 4 sd; median x e^(4 sigma) for a lognormal)."""
    lo, hi = dist.bounds()
    p = dist.params
    if not np.isfinite(hi):
        hi = p["mean"] + 4 * p["std"] if dist.kind == "normal" else p["median"] * np.exp(4 * p["sigma"])
    if not np.isfinite(lo):
        lo = p["mean"] - 4 * p["std"]
    return float(lo), float(hi)


def _largest_magnitude(dist) -> float:
    """Largest |value| a scenario distribution gives: a release velocity component may be negative (thrown
    downward, or towards -x)."""
    return max(abs(v) for v in _practical_bounds(dist))


def free_fall_drop_m(scenario, collector: str) -> tuple[float, float]:
    """Height drop H [m] from the highest release point to the ground at ``collector``, and the release speed [m/s].

    The release point is the highest profile vertex within the seeder's x range (ends
    included) plus the seeder's largest release height; the release speed is the largest
    of ``sqrt(vx^2 + vz^2)`` the seeder can draw (from the largest magnitudes: a component may be
    negative).  A block cannot pass the collector faster than ``sqrt(v0^2 + 2 g H)`` (energy
    conservation without losses).

    Parameters
    ----------
    scenario : simulation.Scenario or path
        The scenario, or its TOML file.
    collector : str
        The collector's name.

    Returns
    -------
    tuple of float
        (H [m], v0 [m/s]); H is 0 where the line stands above the release.
    """
    import simulation
    sc = scenario if isinstance(scenario, simulation.Scenario) else simulation.load_scenario(scenario)
    col = sc.collectors[sc.collector_index(collector)]
    prof, seed = sc.profile, sc.seeder
    xs = np.concatenate([[seed.x_low, seed.x_high], prof.x[(prof.x >= seed.x_low) & (prof.x <= seed.x_high)]])
    z_release = float(np.max(np.interp(xs, prof.x, prof.z))) + _practical_bounds(seed.height_m)[1]
    z_line = float(np.interp(col.x, prof.x, prof.z))
    vx, vz = _largest_magnitude(seed.vx_ms), _largest_magnitude(seed.vz_ms)
    return max(z_release - z_line, 0.0), float(np.hypot(vx, vz))


def plausible_velocity_ms(drop_height_m=None, release_speed_ms: float = 0.0) -> tuple[float, str]:
    """Largest plausible velocity at a barrier line [m/s] and how it was obtained (for the warning).

    With a height drop H [m]: ``(1 + FREE_FALL_MARGIN) sqrt(v0^2 + 2 g H)``; without one:
    :data:`PLAUSIBLE_MAX_MS` (50 m/s, a free fall of about 127 m), an assumption.

    Parameters
    ----------
    drop_height_m : float, optional
        Height drop H from the release to the line [m], > 0; None for the assumed 50 m/s.
    release_speed_ms : float
        Largest release speed v0 [m/s].

    Returns
    -------
    tuple of (float, str)
        The limit [m/s] and a sentence saying how it was obtained (labelled ASSUMPTION without a drop height).

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, chapter 3 (free fall, v = sqrt(2 g H)).
    """
    g = STANDARD_GRAVITY_MS2
    if drop_height_m is None:
        return PLAUSIBLE_MAX_MS, (f"{PLAUSIBLE_MAX_MS:g} m/s, the speed of a free fall of "
                                  f"{PLAUSIBLE_MAX_MS ** 2 / (2 * g):.0f} m (ASSUMPTION: no drop height given; "
                                  "give drop_height_m, CLI --drop-height)")
    h = float(drop_height_m)
    if not np.isfinite(h) or h <= 0:
        raise ValueError(f"drop_height_m = {drop_height_m!r} must be a finite height > 0 m")
    v = (1 + FREE_FALL_MARGIN) * np.sqrt(release_speed_ms ** 2 + 2 * g * h)
    start = f" from {release_speed_ms:.3g} m/s" if release_speed_ms else ""
    return float(v), (f"{v:.3g} m/s, a free fall of {h:.4g} m{start} (sqrt(2 g H)) plus "
                      f"{FREE_FALL_MARGIN:.0%}")


def read_velocities(path, *, collector: str | None = None, velocity_unit: str | None = None, decimal=None,
                    sheet=None, header_row=None, encoding=None, drop_height_m=None,
                    release_speed_ms: float = 0.0) -> pd.DataFrame:
    """Velocity samples [m/s] (and heights [m], angular velocities [rad/s], masses [kg] when present).

    Reads CSV/TXT, Excel or Parquet with the rules of :mod:`riskrf.io.tables` (separators,
    decimal commas, encodings).  Columns are matched case-insensitively after removing
    units and punctuation: ``velocity_ms`` (or ``velocity``, ``Translational
    Velocity (m/s)``, ``speed``; ``Velocity (km/h)`` is converted), ``height_m``
    (``Bounce Height (m)``, ``jump height``), ``angular_velocity_rads`` (``Rotational
    Velocity (rad/s)``), ``mass_kg``, ``radius_m`` and ``collector``.  With
    ``collector`` only that collector's rows are kept.

    ``velocity_unit`` ("m/s" or "km/h") declares the unit of the velocity column.
    Without it, a median velocity above 50 m/s is refused as probable km/h.
    Velocities must be finite and >= 0, heights finite and >= 0, every cell filled.
    Raises naming the file, row, column and value.

    Plausibility: a velocity above what a free fall from the profile could give is
    warned about (:class:`~riskrf.RiskrfWarning`, naming the row, the value and the
    plausible limit; also listed in ``result.attrs["warnings"]``).  The limit is
    ``1.1 sqrt(v0^2 + 2 g H)`` with ``drop_height_m`` H [m] (e.g. from
    :func:`free_fall_drop_m` of the scenario) and ``release_speed_ms`` v0, else
    50 m/s (a 127 m free fall; an assumption the warning states).

    Parameters
    ----------
    path : str or path
        CSV/TXT, Excel or Parquet file.
    collector : str, optional
        Keep only this collector's rows.
    velocity_unit : {"m/s", "km/h"}, optional
        Unit of the velocity column when its header does not say.
    decimal, sheet, header_row, encoding : optional
        Table-reading options (:func:`riskrf.io.tables.read_table`).
    drop_height_m : float, optional
        Height drop to the line [m] for the plausibility limit.
    release_speed_ms : float
        Largest release speed [m/s] for the plausibility limit.

    Returns
    -------
    pandas.DataFrame
        ``velocity_ms`` [m/s] and, when present, ``height_m`` [m], ``angular_velocity_rads`` [rad/s],
        ``mass_kg`` [kg], ``radius_m`` [m], ``collector``; ``attrs["warnings"]`` lists the warnings raised.
    """
    from .tables import parse_numbers, read_table
    path = Path(path)
    if velocity_unit is not None and velocity_unit not in VELOCITY_UNITS:
        raise ValueError(f"velocity_unit = {velocity_unit!r} is not one of 'm/s', 'km/h'")
    raw, first_row, _ = read_table(path, sheet=sheet, header_row=header_row, encoding=encoding,
                                   what="velocity")
    found = {}
    factor = VELOCITY_UNITS[velocity_unit] if velocity_unit else 1.0
    for col in raw.columns:
        n = _norm(col)
        if n in _KMH_NAMES and "velocity_ms" not in found:
            found["velocity_ms"] = col
            if velocity_unit is None:
                factor, velocity_unit = 1 / 3.6, "km/h"
            continue
        for target, names in COLUMN_NAMES.items():
            if n in names and target not in found:
                found[target] = col
    if "velocity_ms" not in found:
        raise ValueError(f"{path}: no velocity column among {list(raw.columns)}; expected one named "
                         "'velocity_ms' (or 'velocity', 'Translational Velocity (m/s)', 'speed', 'velocity_kmh')")
    df = raw[list(found.values())].rename(columns={v: k for k, v in found.items()})
    rows = np.arange(len(df)) + first_row
    if collector is not None:
        if "collector" not in df:
            raise ValueError(f"{path}: --collector {collector!r} given but the file has no 'collector' column")
        names = sorted(df["collector"].astype(str).unique())
        keep = (df["collector"].astype(str) == collector).to_numpy()
        df, rows = df[keep], rows[keep]
        if df.empty:
            raise ValueError(f"{path}: no rows for collector {collector!r}; collectors in the file: {names}")
    if df.empty:
        raise ValueError(f"{path}: the file has no velocity samples")
    df = df.reset_index(drop=True)
    out = pd.DataFrame(index=df.index)
    for target in ("velocity_ms", "height_m", "angular_velocity_rads", "mass_kg", "radius_m"):
        if target not in df:
            continue
        col = found[target]
        values = parse_numbers(df[target], path, col, rows, decimal=decimal)
        lower = None if target == "angular_velocity_rads" else 0.0
        bad = ~np.isfinite(values.to_numpy(dtype=float))
        if lower is not None:
            bad |= values.to_numpy(dtype=float) < lower
        if target in ("mass_kg", "radius_m"):
            bad |= values.to_numpy(dtype=float) <= 0
        if bad.any():
            i = int(np.argmax(bad))
            need = {"velocity_ms": "a velocity >= 0", "height_m": "a height >= 0 (m above the slope)",
                    "angular_velocity_rads": "a finite angular velocity", "mass_kg": "a mass > 0",
                    "radius_m": "a radius > 0"}[target]
            raise ValueError(f"{path}: row {rows[i]}, column {col!r}: {df[target].iloc[i]!r} is not {need}")
        out[target] = values.to_numpy(dtype=float)
    if "collector" in df:
        out["collector"] = df["collector"].astype(str).to_numpy()
    out["velocity_ms"] = out["velocity_ms"] * factor
    med = float(np.median(out["velocity_ms"]))
    if velocity_unit is None and med > PLAUSIBLE_MEDIAN_MS:
        raise ValueError(f"{path}: column {found['velocity_ms']!r}: median {med:.3g} m/s is more than a free fall of "
                         f"{med ** 2 / (2 * STANDARD_GRAVITY_MS2):.0f} m gives and looks like km/h entered as m/s "
                         "(rock fall velocities are mostly 5-35 m/s).  Declare the unit: velocity_unit='km/h' or, "
                         "if the values "
                         "are right, 'm/s' (CLI --velocity-unit)")
    limit, how = plausible_velocity_ms(drop_height_m, release_speed_ms)
    v = out["velocity_ms"].to_numpy()
    fast = v > limit
    out.attrs["warnings"] = []
    if fast.any():
        i = int(np.argmax(v))
        shown = f"{v[i]:.4g} m/s" + (f" (= {df['velocity_ms'].iloc[i]} km/h)" if factor != 1.0 else "")
        msg = (f"{path}: {int(fast.sum()):,} of {v.size:,} velocities exceed what a free fall could give; the "
               f"largest, row {rows[i]}, column {found['velocity_ms']!r}: {shown}; plausible at most {how}.  "
               "Check the units, the collector and the drop height")
        out.attrs["warnings"] = [msg]
        from ..core.validation import warn
        warn(msg)
    return out
