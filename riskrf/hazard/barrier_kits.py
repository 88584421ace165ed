"""The certified-kit table of the design checks: MEL, SEL, nominal height, maximum elongation at MEL and the
residual-height category of flexible rock fall barrier kits (EAD 340059-00-0106 / ETAG 027).

The table shipped (``riskrf/data/barrier_kits.csv``, provenance in ``riskrf/data/barrier_kits_README.md``) holds
GENERIC kits only: their MEL levels are the EAD 340059 energy levels [published, secondary], SEL = MEL/3
[published], and their heights, elongations and residual categories are ASSUMED typical magnitudes, not a
product's values.  A site option names a kit with ``kit = "..."`` (:func:`riskrf.risk.mitigation_inputs.parse_option`);
the design checks (:func:`riskrf.hazard.design_requirement.design_requirement`) then use the kit's SEL, elongation and
residual category instead of generic rules.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd

#: The table shipped with riskrf.
KITS_PATH = Path(__file__).resolve().parents[1] / "data" / "barrier_kits.csv"
#: Columns of a kit table (energies kJ, lengths m).
KIT_COLUMNS = ("kit", "mel_kj", "sel_kj", "nominal_height_m", "max_elongation_mel_m", "residual_category", "eta",
               "source")


@dataclass(frozen=True)
class Kit:
    """One certified (or generic) barrier kit.

    Attributes
    ----------
    name : str
        Name of the kit (what an option's ``kit`` field names).
    mel_kj, sel_kj : float
        Maximum and service energy levels [kJ] (EAD 340059-00-0106).
    nominal_height_m : float
        Nominal height of the kit [m].
    max_elongation_mel_m : float
        Maximum elongation in the MEL test [m].
    residual_category : str
        Residual-height category after the MEL test: "A" (>= 50 %), "B" (30-50 %) or "C" (< 30 % of the nominal
        height) (EAD 340059-00-0106 / ETAG 027).
    eta : str
        European Technical Assessment number ("none" for a generic kit).
    source : str
        Where the values come from.
    """

    name: str
    mel_kj: float
    sel_kj: float
    nominal_height_m: float
    max_elongation_mel_m: float
    residual_category: str
    eta: str = "none"
    source: str = ""

    @property
    def generic(self) -> bool:
        """True for a generic kit (no ETA number): its values are not a product's."""
        return self.eta.strip().lower() in ("", "none")

    def label(self) -> str:
        """The kit's name with its ETA number, or "GENERIC kit (not a product)".

        Returns
        -------
        str
            E.g. ``"kit 'generic 2000 kJ' (GENERIC kit, not a product: ASSUMED height, elongation and category)"``.
        """
        if self.generic:
            return (f"kit {self.name!r} (GENERIC kit, not a product: ASSUMED height, elongation and residual "
                    "category)")
        return f"kit {self.name!r} ({self.eta})"


def read_kits(path=None) -> dict:
    """Read a kit table (CSV with the columns of :data:`KIT_COLUMNS`; default the table shipped).

    Parameters
    ----------
    path : str or path, optional
        The kit table (default :data:`KITS_PATH`).

    Returns
    -------
    dict
        {kit name: :class:`Kit`} in the table's order.

    Raises
    ------
    ValueError
        Naming the file, row and column of a missing or invalid value (energies and lengths > 0, SEL <= MEL,
        category A/B/C, names unique).
    """
    p = Path(path) if path is not None else KITS_PATH
    t = pd.read_csv(p, dtype={"kit": str, "residual_category": str, "eta": str, "source": str})
    missing = [c for c in KIT_COLUMNS if c not in t.columns]
    if missing:
        raise ValueError(f"{p}: kit table lacks column(s) {', '.join(missing)} (columns: {', '.join(KIT_COLUMNS)})")
    kits = {}
    for i, r in t.iterrows():
        row = i + 2                                  # 1-based, after the header line
        name = str(r["kit"]).strip()
        if not name or name == "nan":
            raise ValueError(f"{p}: row {row}: kit needs a name")
        if name in kits:
            raise ValueError(f"{p}: row {row}: kit {name!r} is given twice")
        vals = {}
        for c in ("mel_kj", "sel_kj", "nominal_height_m", "max_elongation_mel_m"):
            v = pd.to_numeric(r[c], errors="coerce")
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"{p}: row {row} (kit {name!r}): {c} = {r[c]!r} must be a number > 0")
            vals[c] = float(v)
        if vals["sel_kj"] > vals["mel_kj"]:
            raise ValueError(f"{p}: row {row} (kit {name!r}): sel_kj = {vals['sel_kj']:g} exceeds mel_kj = "
                             f"{vals['mel_kj']:g}")
        cat = str(r["residual_category"]).strip().upper()
        if cat not in ("A", "B", "C"):
            raise ValueError(f"{p}: row {row} (kit {name!r}): residual_category = {r['residual_category']!r} must be "
                             "A, B or C (EAD 340059)")
        kits[name] = Kit(name=name, residual_category=cat, eta=str(r["eta"]).strip(),
                         source=str(r["source"]).strip(), **vals)
    return kits


@lru_cache(maxsize=1)
def _shipped() -> dict:
    return read_kits()


def known_kits() -> tuple:
    """Names of the kits in the table shipped.

    Returns
    -------
    tuple of str
        The kit names, in the table's order.
    """
    return tuple(_shipped())


def get_kit(name: str, where: str = "kit") -> Kit:
    """The kit ``name`` of the table shipped; a ValueError naming ``where`` and listing the known kits otherwise.

    Parameters
    ----------
    name : str
        Name of the kit.
    where : str, optional
        The file and field that named it, for the message.

    Returns
    -------
    Kit
        The kit.
    """
    kits = _shipped()
    if not isinstance(name, str) or name not in kits:
        raise ValueError(f"{where} = {name!r} is not in the kit table ({KITS_PATH.name}); known kits: "
                         f"{', '.join(map(repr, kits))}")
    return kits[name]


__all__ = ["KITS_PATH", "KIT_COLUMNS", "Kit", "get_kit", "known_kits", "read_kits"]
