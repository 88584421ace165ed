"""The barrier the governing design basis requires, as a costed option of the ranking, and the governing basis's
checks of the site's own fences.

The design basis (:mod:`riskrf.hazard.design_basis`, applied by :mod:`riskrf.hazard.design_requirement`) gives,
at the barrier line and at every position of its position search, the required MEL, the smallest certified product
class meeting it and the required net height.
:func:`required_barrier` turns that into one option of the mitigation study: the smallest certified class that
meets the required MEL and height, at the position of the search where it costs least, with a cost from a
:class:`BarrierCostModel` (the site file's ``[required_barrier]`` table, or riskrf's default price table, labelled
ASSUMED in every output).  Its effect is derived like any fence's: the simulated speeds and bounce heights at its
own line.  Where no certified barrier can be placed (the required MEL above the largest class, or the blocks in
first flight above the tallest catalogue net at every position), it says so, position by position, and what would
work instead.

:func:`basis_design_checks` gives each site fence the verdict of the governing basis's checks
(:attr:`riskrf.hazard.design_requirement.DesignRequirement.candidates`): these, not the legacy "100-year energy vs MEL"
comparison of :mod:`riskrf.hazard.energy_study`, decide whether an option may be recommended.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..core.file_schemas import REQUIRED_BARRIER
from ..core.format import money, sig
from ..core.schema import as_record
from ..hazard.design_basis import MEL_PRODUCT_CLASSES_KJ
from .options.base import MitigationError

#: riskrf's default unit price of a certified flexible barrier [study currency per metre of barrier] at
#: :data:`DEFAULT_REFERENCE_HEIGHT_M` net height, by MEL class [kJ] (the classes of
#: :data:`riskrf.hazard.design_basis.MEL_PRODUCT_CLASSES_KJ`).  ASSUMPTION [R]: an order of magnitude for supply
#: and installation on accessible ground, no access works, anchors in sound rock; NOT a quotation.  Where the site
#: prices its own fence options, the table is scaled to them (:func:`cost_model_from_site`).  State
#: ``[required_barrier] cost_classes_kj`` and ``cost_per_m`` for a signed estimate.
DEFAULT_COST_PER_M = dict(zip(MEL_PRODUCT_CLASSES_KJ,
                              (300.0, 400.0, 550.0, 750.0, 900.0, 1050.0, 1350.0, 1800.0, 1950.0, 2900.0, 3050.0)))
#: Net height [m] the unit prices refer to; a price scales as (H / reference)^height_exponent.
DEFAULT_REFERENCE_HEIGHT_M = 5.0
#: Tallest net of the usual certified kits [m] (ASSUMPTION [R]: catalogues list nets up to about 8 m); blocks whose
#: required net height exceeds it cannot be stopped by a catalogue barrier at that position.
DEFAULT_MAX_NET_HEIGHT_M = 8.0

#: The ``[required_barrier]`` fields with their defaults (money in the study currency, lengths m, energies kJ).
COST_FIELDS = {
    "include": True,                    # enter the required barrier in the ranking
    "cost_classes_kj": None,            # MEL classes [kJ] of the unit prices (default: riskrf's table)
    "cost_per_m": None,                 # unit prices [currency/m] at reference_height_m, one per class
    "reference_height_m": DEFAULT_REFERENCE_HEIGHT_M,
    "height_exponent": 1.0,             # price ~ (H / reference)^exponent
    "length_m": None,                   # barrier length [m] (default: traffic.exposed_length_m)
    "fixed_cost": 0.0,                  # access, mobilisation [currency]
    "annual_maintenance_share": 0.01,   # of the capital cost, per year
    "life_years": 25.0,                 # renewal period [yr]
    "repair_share": 0.05,               # of the capital cost, per impact held above SEL
    "replacement_share": 0.3,           # of the capital cost, per impact above MEL
    "cost_range": [0.7, 1.5],           # capital cost range as factors of the central cost (uncertainty study)
    "max_net_height_m": DEFAULT_MAX_NET_HEIGHT_M,
}


@dataclass(frozen=True)
class BarrierCostModel:
    """Capital and running costs of a certified barrier of MEL class [kJ] and net height [m].

    capital = fixed_cost + length_m x unit(MEL) x (H / reference_height_m)^height_exponent, with unit(MEL) the
    price per metre [currency/m] interpolated linearly in the class between the table's classes and held
    proportional to sqrt(MEL) beyond its ends.  Maintenance, repairs and replacements are shares of the capital
    cost.  ``basis`` says where the numbers come from ("site file" or the ASSUMED default); ``scale`` is the factor
    applied to riskrf's default table to match the site's own fence prices (1 without them).
    """

    classes_kj: tuple = tuple(DEFAULT_COST_PER_M)
    cost_per_m: tuple = tuple(DEFAULT_COST_PER_M.values())
    reference_height_m: float = DEFAULT_REFERENCE_HEIGHT_M
    height_exponent: float = 1.0
    length_m: float | None = None
    fixed_cost: float = 0.0
    annual_maintenance_share: float = 0.01
    life_years: float = 25.0
    repair_share: float = 0.05
    replacement_share: float = 0.3
    cost_range: tuple = (0.7, 1.5)
    max_net_height_m: float = DEFAULT_MAX_NET_HEIGHT_M
    from_site: bool = False
    scale: float = 1.0
    scale_note: str = ""

    def unit_cost(self, mel_kj: float, height_m: float) -> float:
        """Price per metre [currency/m] of a barrier of MEL ``mel_kj`` [kJ] and net height ``height_m`` [m].

        Parameters
        ----------
        mel_kj : float
            MEL class [kJ] (> 0).
        height_m : float
            Net height [m] (> 0).

        Returns
        -------
        float
            Price per metre of barrier [study currency/m].
        """
        c = np.asarray(self.classes_kj, dtype=float)
        p = np.asarray(self.cost_per_m, dtype=float) * self.scale
        if mel_kj < c[0]:
            unit = p[0] * np.sqrt(mel_kj / c[0])
        elif mel_kj > c[-1]:
            unit = p[-1] * np.sqrt(mel_kj / c[-1])
        else:
            unit = float(np.interp(mel_kj, c, p))
        return float(unit * (height_m / self.reference_height_m) ** self.height_exponent)

    def capital(self, mel_kj: float, height_m: float, length_m: float) -> float:
        """Capital cost [currency] of ``length_m`` [m] of barrier (MEL [kJ], net height [m]).

        Parameters
        ----------
        mel_kj : float
            MEL class [kJ].
        height_m : float
            Net height [m].
        length_m : float
            Barrier length [m] (``length_m`` of the model replaces it when stated).

        Returns
        -------
        float
            Capital cost [study currency].
        """
        length = self.length_m if self.length_m is not None else length_m
        return float(self.fixed_cost + length * self.unit_cost(mel_kj, height_m))

    @property
    def label(self) -> str:
        """Where the cost comes from, in words (ASSUMED unless the site file states the unit prices)."""
        if self.from_site:
            return "cost from the site file's [required_barrier] unit prices"
        return ("ASSUMED cost: riskrf's default unit prices per MEL class and net height (riskrf.risk.required_barrier."
                "DEFAULT_COST_PER_M, an order of magnitude, not a quotation)" + (f", {self.scale_note}"
                                                                                  if self.scale_note else "")
                + "; state [required_barrier] cost_per_m for a signed estimate")


def _number(v, where: str, *, low: float = 0.0, open_low: bool = False) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) or v < low \
            or (open_low and v <= low):
        raise MitigationError(f"{where} = {v!r} must be a number {'>' if open_low else '>='} {low:g}")
    return float(v)


def cost_model_from_site(table=None, *, site_fences=(), source: str = "") -> tuple:
    """The :class:`BarrierCostModel` of a site's ``[required_barrier]`` table (None or absent: the defaults), and
    whether the required barrier enters the ranking.

    Without stated unit prices the default table is scaled to the site's own fence and attenuator options at the
    barrier line (the median ratio of their capital cost to the default price of their class, height and length),
    so the required barrier is priced like the site's fences; without such options the table is used as it is.

    Parameters
    ----------
    table : RequiredBarrierTable, dict or None
        The checked ``[required_barrier]`` table (``site.required_barrier``, a
        :data:`riskrf.core.file_schemas.SITE_RECORDS` record), or the table as written (a dict of the fields of
        :data:`COST_FIELDS`, read into that record: fields left out take their defaults), or None (all defaults).
    site_fences : sequence of (capacity [kJ], height [m], capital cost [currency], length [m]), optional
        The site's priced fences.
    source : str, optional
        The site file, named in errors.

    Returns
    -------
    model : BarrierCostModel
        The cost model.
    include : bool
        Whether the required barrier is ranked.

    Raises
    ------
    MitigationError
        An unknown field, or a value out of range (naming file, field and value).
    """
    t = as_record(REQUIRED_BARRIER, table, source=source, error=MitigationError)
    at = f"{source}: required_barrier"
    include = t.include
    if not isinstance(include, bool):
        raise MitigationError(f"{at}.include = {include!r} must be true or false")
    kw = {}
    classes, prices = t.cost_classes_kj, t.cost_per_m
    if (classes is None) != (prices is None):
        raise MitigationError(f"{at}: cost_classes_kj = {classes!r} and cost_per_m = {prices!r} go together "
                              "(unit prices per metre, one per MEL class)")
    if classes is not None:
        for name, v in (("cost_classes_kj", classes), ("cost_per_m", prices)):
            if not isinstance(v, list) or not v:
                raise MitigationError(f"{at}.{name} = {v!r} must be a list of numbers")
            for x in v:
                _number(x, f"{at}.{name}", open_low=True)
        if len(classes) != len(prices):
            raise MitigationError(f"{at}: cost_classes_kj has {len(classes)} values and cost_per_m {len(prices)}; "
                                  "give one price per class")
        if np.any(np.diff(np.asarray(classes, dtype=float)) <= 0):
            raise MitigationError(f"{at}.cost_classes_kj = {classes!r} must increase")
        kw.update(classes_kj=tuple(map(float, classes)), cost_per_m=tuple(map(float, prices)), from_site=True)
    for name, value in (("reference_height_m", t.reference_height_m), ("life_years", t.life_years),
                        ("max_net_height_m", t.max_net_height_m), ("length_m", t.length_m)):
        if value is not None:
            kw[name] = _number(value, f"{at}.{name}", open_low=True)
    for name, value in (("height_exponent", t.height_exponent), ("fixed_cost", t.fixed_cost),
                        ("annual_maintenance_share", t.annual_maintenance_share), ("repair_share", t.repair_share),
                        ("replacement_share", t.replacement_share)):
        if value is not None:
            kw[name] = _number(value, f"{at}.{name}")
    if t.cost_range is not None:
        r = t.cost_range
        if not (isinstance(r, (list, tuple)) and len(r) == 2):      # a tuple: the declared default
            raise MitigationError(f"{at}.cost_range = {r!r} must be [low, high] factors of the central cost")
        lo, hi = (_number(x, f"{at}.cost_range", open_low=True) for x in r)
        if not lo <= 1.0 <= hi:
            raise MitigationError(f"{at}.cost_range = {r!r} must bracket 1 (low <= 1 <= high)")
        kw.update(cost_range=(lo, hi))
    model = BarrierCostModel(**kw)
    if not model.from_site:
        ratios = [cost / model.capital(cap, h, length) for cap, h, cost, length in site_fences
                  if cost and cap and h and length and model.capital(cap, h, length) > 0]
        if ratios:
            k = float(np.median(ratios))
            model = BarrierCostModel(**kw, scale=k, scale_note=f"scaled by {sig(k, 3)} to the site's own "
                                     f"{len(ratios)} priced fence option(s)")
    return model, include


@dataclass(frozen=True)
class RequiredBarrier:
    """The required barrier as an option, or why none can be placed.

    ``option`` (:class:`~riskrf.risk.mitigation_inputs.Option` or None), ``verdict`` (its design check in words),
    ``positions`` (one row per searched position: x [m], required MEL [kJ], class [kJ], net height [m], capital
    cost [currency] where placeable, and why not), ``reason`` (why none can be placed, empty when one can),
    ``alternatives`` (what would work instead) and ``cost_basis`` (the cost model's label).
    """

    option: object
    verdict: str
    positions: pd.DataFrame
    basis: str
    reason: str = ""
    alternatives: str = ""
    cost_basis: str = ""
    x_m: float | None = None
    notes: tuple = field(default_factory=tuple)

    @property
    def placeable(self) -> bool:
        """Can a certified barrier meeting the basis be placed at some searched position?"""
        return self.option is not None

    def text(self, currency: str = "") -> str:
        """The required barrier in one or two sentences (what it is and costs, or why there is none).

        Parameters
        ----------
        currency : str, optional
            Currency code printed after money amounts.

        Returns
        -------
        str
            The sentence(s).
        """
        if self.option is None:
            return f"No certified barrier meets {self.basis}: {self.reason} What would work instead: {self.alternatives}"
        o = self.option
        where = f"x = {self.x_m:g} m" if self.x_m is not None else "the barrier line"
        return (f"The barrier {self.basis} requires is ranked as {o.name!r}: the smallest certified class that meets "
                f"the required MEL and net height, {o.capacity_kj:,.0f} kJ and {o.height_m:g} m, at {where} (the "
                f"cheapest placeable position of the search), capital {money(o.capital_cost, currency, sig=3)} "
                f"({self.cost_basis}).")

    def to_dict(self) -> dict:
        """JSON-ready: the option's name, class [kJ], net height [m], position [m], capital [currency], verdict,
        cost basis, the reason and alternatives when none can be placed, and the positions table.

        Returns
        -------
        dict
            The entries above.
        """
        o = self.option
        return {"placeable": self.placeable, "basis": self.basis,
                "option": None if o is None else o.name,
                "mel_class_kj": None if o is None else o.capacity_kj,
                "net_height_m": None if o is None else o.height_m,
                "x_m": self.x_m, "capital_cost": None if o is None else o.capital_cost,
                "design_check": self.verdict, "cost_basis": self.cost_basis, "reason": self.reason or None,
                "alternatives": self.alternatives or None,
                "positions": self.positions.replace({np.nan: None}).to_dict(orient="records"),
                "notes": list(self.notes)}


def _candidates(requirement, positions) -> list:
    """(x [m] or None at the barrier line, required MEL [kJ], class [kJ], net height [m], clearance [m], permitted
    elongation [m] or None) per position: the position search's rows, the barrier line's taken from the
    requirement itself (the hazard's own simulation)."""
    rows = [(None, requirement.required_mel_kj, requirement.required_class_kj, requirement.required_net_height_m,
             requirement.clearance_m, requirement.permitted_elongation_m)]
    if positions is not None:
        gamma_d = positions.basis.factors.get("gamma_d", 1.0)
        for _, r in positions.table.iterrows():
            if abs(float(r["x_m"]) - requirement.x_m) < 1e-9:
                continue                           # the barrier line: the requirement above
            clear = float(r["clearance_m"]) if np.isfinite(r["clearance_m"]) else None
            rows.append((float(r["x_m"]), float(r["required_mel_kj"]), float(r["required_class_kj"]),
                         float(r["required_net_height_m"]), clear,
                         clear / gamma_d if clear is not None and gamma_d else None))
    return rows


def _why_none(table: pd.DataFrame, top_kj: float, hmax_m: float) -> str:
    """Why no position takes a certified barrier, one clause per kind of reason with its positions and range."""
    kinds = (("above the largest", lambda r: r["required_mel_kj"],
              lambda lo, hi: f"the required MEL ({_span(lo, hi, ',.0f')} kJ) is above the largest certified class "
                             f"({top_kj:,.0f} kJ)"),
             ("blocks pass too high", lambda r: r["net_height_m"],
              lambda lo, hi: f"the blocks pass too high (required net height {_span(lo, hi, 'g')} m, the tallest "
                             f"catalogue net is {hmax_m:g} m)"))
    clauses, done = [], set()
    for key, value, words in kinds:
        hit = table[table["why_not"].str.contains(key, regex=False)]
        if len(hit):
            v = hit.apply(value, axis=1).astype(float)
            clauses.append(f"{words(v.min(), v.max())} at x = {_positions(hit['x_m'])} m")
            done.update(hit.index)
    rest = table.drop(index=sorted(done))
    for why, rows in rest.groupby("why_not", sort=False):
        clauses.append(f"{why} at x = {_positions(rows['x_m'])} m")
    return f"at none of the {len(table)} searched positions: " + "; ".join(clauses) + "."


def _span(lo: float, hi: float, fmt: str) -> str:
    return f"{lo:{fmt}}" if lo == hi else f"{lo:{fmt}} to {hi:{fmt}}"


def _positions(xs) -> str:
    return ", ".join(f"{x:g}" for x in sorted(float(x) for x in xs))


def required_barrier(requirement, positions, cost_model: BarrierCostModel, *, exposed_length_m: float,
                     currency: str = "", source: str = "", name: str | None = None) -> RequiredBarrier:
    """The required barrier of the governing basis as a ranked option (see the module notes).

    At each position (the barrier line, from ``requirement``; the others from ``positions``) the barrier is the
    smallest certified class at or above the required MEL and the required net height; it can be placed when
    there is such a class and the net height is at most the cost model's ``max_net_height_m``.  Of the placeable
    positions the one with the lowest capital cost is taken (the barrier line on a tie).

    Parameters
    ----------
    requirement : riskrf.hazard.design_requirement.DesignRequirement
        The governing basis's requirement at the barrier line (energies kJ, heights m).
    positions : riskrf.hazard.design_requirement.PositionSearch or None
        The position search (None: the barrier line only).
    cost_model : BarrierCostModel
        Unit prices and running-cost shares.
    exposed_length_m : float
        Length of exposed road [m]: the barrier length unless the cost model states one.
    currency : str, optional
        Study currency (for the texts).
    source : str, optional
        The site file (the option's source).
    name : str, optional
        Name of the option (default ``"required barrier <class> kJ / <height> m"``).

    Returns
    -------
    RequiredBarrier
        The option (or None with the reason and the alternatives), its verdict and the positions table.
    """
    from .mitigation_inputs import parse_option
    basis = requirement.basis.basis
    hmax = cost_model.max_net_height_m
    top = max(requirement.basis.mel_classes_kj)
    rows = []
    for x, need, cls, h, clear, permitted in _candidates(requirement, positions):
        row = {"x_m": requirement.x_m if x is None else x, "barrier_line": x is None, "required_mel_kj": need,
               "class_kj": cls, "net_height_m": h, "clearance_m": clear, "capital_cost": np.nan, "placeable": False}
        if not np.isfinite(need):
            row["why_not"] = "no requirement here (no simulated block reaches this line)"
        elif not np.isfinite(cls):
            row["why_not"] = f"required MEL {need:,.0f} kJ above the largest certified class ({top:,.0f} kJ)"
        elif not np.isfinite(h):
            row["why_not"] = "no simulated passing heights"
        elif h > hmax:
            row["why_not"] = (f"blocks pass too high: required net height {h:g} m above the tallest catalogue net "
                              f"({hmax:g} m)")
        elif clear is not None and clear <= 0:
            row["why_not"] = f"no clearance to the road ({clear:g} m)"
        else:
            row.update(placeable=True, why_not="", permitted_elongation_m=permitted,
                       capital_cost=cost_model.capital(cls, h, exposed_length_m))
        rows.append(row)
    table = pd.DataFrame(rows)
    ok = table[table["placeable"]]
    if ok.empty:
        reason = _why_none(table, top, hmax)
        too_high = table["why_not"].str.startswith("blocks pass too high").any()
        alternatives = (("a barrier at another position, where the blocks pass lower (higher on the slope while they "
                         "still bounce on the face, or further out where they have landed; add positions with "
                         "[design] positions_x_m); " if too_high else "a barrier at another position, where the "
                         "blocks arrive slower (add positions with [design] positions_x_m); ")
                        + "a catch ditch or a bund (embankment) at the toe, sized for the run-out (see the catchment "
                        "study); a drape or an attenuator on the face, which keeps the blocks from taking flight; "
                        "or a rigid barrier or rock shed designed outside the certified-kit classes.")
        return RequiredBarrier(None, f"no certified barrier can be placed: {reason}", table, basis, reason=reason,
                               alternatives=alternatives, cost_basis=cost_model.label)
    best = ok.sort_values(["capital_cost", "barrier_line", "x_m"], ascending=[True, False, True]).iloc[0]
    cls, h = float(best["class_kj"]), float(best["net_height_m"])
    x = None if best["barrier_line"] else float(best["x_m"])
    cap = float(best["capital_cost"])
    lo, hi = cost_model.cost_range
    spec = {"name": name or f"required barrier {cls:,.0f} kJ / {h:g} m", "kind": "fence",
            "description": (f"the barrier {basis} requires: smallest certified class meeting the required MEL "
                            f"{float(best['required_mel_kj']):,.0f} kJ and net height {h:g} m"
                            + (f" at x = {x:g} m (position search)" if x is not None else "")
                            + f"; {cost_model.label}"),
            "capital_cost": cap, "capital_cost_range": [cap * lo, cap * hi],
            "annual_maintenance": cap * cost_model.annual_maintenance_share, "life_years": cost_model.life_years,
            "repair_cost_per_impact": cap * cost_model.repair_share,
            "replacement_cost": cap * cost_model.replacement_share, "capacity_kj": cls, "height_m": h}
    if x is not None:
        spec["x_m"] = x
    option = parse_option(spec, 0, source or "<required barrier>")
    permitted = best.get("permitted_elongation_m")
    verdict = (f"adequate under {basis} by construction: MEL {cls:,.0f} kJ >= required "
               f"{float(best['required_mel_kj']):,.0f} kJ; net height {h:g} m >= required"
               + ("" if permitted is None or not np.isfinite(permitted) else
                  f"; elongation not checked (no kit named): the kit's maximum elongation at MEL must not exceed "
                  f"{permitted:.2f} m"))
    return RequiredBarrier(option, verdict, table, basis, cost_basis=cost_model.label, x_m=x)


def basis_design_checks(requirement) -> dict:
    """Option name -> the verdict of the governing basis's checks of that candidate fence
    (``requirement.candidates``): ``"adequate under <basis>"`` (with the checks it could not run), or
    ``"NOT ADEQUATE under <basis>: <check> (demand <d> > capacity <c> <unit>); ..."``.

    Parameters
    ----------
    requirement : riskrf.hazard.design_requirement.DesignRequirement
        The requirement at the barrier line with its candidate checks (demand and capacity in kJ or m).

    Returns
    -------
    dict
        Fence name -> verdict.
    """
    cand = requirement.candidates
    if cand is None or cand.empty:
        return {}
    basis = requirement.basis.basis
    out = {}
    for name, rows in cand.groupby("fence", sort=False):
        known = rows["adequate"].map(lambda v: v is not None and not pd.isna(v))
        failed = rows[known & ~rows["adequate"].map(lambda v: bool(v) if v is not None and not pd.isna(v) else True)]
        unchecked = rows[~known]
        if len(failed):
            out[name] = f"NOT ADEQUATE under {basis}: " + "; ".join(
                f"{r['check']} (demand {sig(r['demand'], 3)} > capacity {sig(r['capacity'], 3)} {r['unit']})"
                for _, r in failed.iterrows())
        else:
            out[name] = f"adequate under {basis}" + ("" if unchecked.empty else "; not checked: " + "; ".join(
                unchecked["check"].str.split(":").str[0]))
    return out


__all__ = ["BarrierCostModel", "COST_FIELDS", "DEFAULT_COST_PER_M", "DEFAULT_MAX_NET_HEIGHT_M",
           "DEFAULT_REFERENCE_HEIGHT_M", "RequiredBarrier", "basis_design_checks", "cost_model_from_site",
           "required_barrier"]
