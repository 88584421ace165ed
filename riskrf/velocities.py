"""Reading velocity samples at a barrier line from files (riskrf simulate, RocFall, RAMMS exports)."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from .inventory import sniff_delimiter

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


def read_velocities(path, *, collector: str | None = None) -> pd.DataFrame:
    """Velocity samples [m/s] (and heights [m], angular velocities [rad/s], masses [kg] when present).

    Reads CSV or Parquet.  Columns are matched case-insensitively after removing
    units and punctuation: ``velocity_ms`` (or ``velocity``, ``Translational
    Velocity (m/s)``, ``speed``), ``height_m`` (``Bounce Height (m)``, ``jump
    height``), ``angular_velocity_rads`` (``Rotational Velocity (rad/s)``),
    ``mass_kg``, ``radius_m`` and ``collector``.  With ``collector`` only that
    collector's rows are kept.  Raises naming the file and the columns found.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"velocity file not found: {path}")
    if path.suffix.lower() == ".parquet":
        raw = pd.read_parquet(path)
    elif path.suffix.lower() in (".csv", ".txt"):
        raw = pd.read_csv(path, sep=sniff_delimiter(path))
    else:
        raise ValueError(f"{path}: unsupported velocity file type {path.suffix!r}; use .csv or .parquet")
    found = {}
    for col in raw.columns:
        n = _norm(col)
        for target, names in COLUMN_NAMES.items():
            if n in names and target not in found:
                found[target] = col
    if "velocity_ms" not in found:
        raise ValueError(f"{path}: no velocity column among {list(raw.columns)}; expected one named "
                         "'velocity_ms' (or 'velocity', 'Translational Velocity (m/s)', 'speed')")
    df = raw[list(found.values())].rename(columns={v: k for k, v in found.items()})
    if collector is not None:
        if "collector" not in df:
            raise ValueError(f"{path}: --collector {collector!r} given but the file has no 'collector' column")
        names = sorted(df["collector"].astype(str).unique())
        df = df[df["collector"].astype(str) == collector]
        if df.empty:
            raise ValueError(f"{path}: no rows for collector {collector!r}; collectors in the file: {names}")
    v = pd.to_numeric(df["velocity_ms"], errors="coerce")
    bad = v.isna() | (v < 0) | ~np.isfinite(v.fillna(0))
    if bad.any():
        i = int(np.argmax(bad.to_numpy()))
        raise ValueError(f"{path}: row {df.index[i] + 2}, column {found['velocity_ms']!r}: "
                         f"{df['velocity_ms'].iloc[i]!r} is not a velocity >= 0")
    if df.empty:
        raise ValueError(f"{path}: the file has no velocity samples")
    return df.reset_index(drop=True)
