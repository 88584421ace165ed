"""What the governing design basis requires of a flexible rock fall barrier, at one line and along the profile.

:func:`design_requirement` applies a :class:`~riskrf.hazard.design_basis.DesignBasis` (ONR 24810, UNI 11211-4 or
the return-period basis; the standards, their partial factors and owner options are in
:mod:`riskrf.hazard.design_basis`) to the hazard at one barrier line: the governing block (ONR 24810's
event-frequency fractile, the design block or the T-year block), the characteristic and design speeds, energies
and passing heights, the required MEL and the smallest product class that meets it, the required net height, the
elongation the road clearance permits, and the checks of candidate fences (kits of
:mod:`riskrf.hazard.barrier_kits` or stated capacities).  Its result is a :class:`DesignRequirement`.

:func:`position_search` repeats the requirement along the profile from one simulation with collectors at several
x (:class:`PositionSearch`, positions by :func:`default_positions`).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from ..core.format import sig
from ..core.validation import DEFAULT_DENSITY_KG_M3
from ..core.units import SEL_PER_MEL, kinetic_energy_kj
from .design_basis import (CONFIRM, DesignBasis, onr24810_energy, onr24810_event_frequency_class,
                           permitted_elongation_m, required_distance_m, required_product_class, round_up,
                           uni11211_energy)


# ---- the requirement at one line ------------------------------------------------------------------------
@dataclass(frozen=True)
class DesignRequirement:
    """What the chosen basis requires of a fence at one line, and the checks of candidate fences.

    Fields (energies kJ, lengths m): ``basis`` (:class:`DesignBasis`), ``x_m`` of the line, the governing
    ``block_mass_kg`` and its ``block_diameter_m``, characteristic speed ``v_k_ms`` and design speed ``v_d_ms``,
    characteristic ``E_k_kj`` and design energy ``E_d_kj``, ``frequent_energy_kj`` (the frequent-event energy,
    NaN when fewer than one fall reaches the line in that time), ``design_event`` ("rare": MEL, "frequent": SEL),
    ``required_mel_kj`` (exact), ``required_class_kj`` (smallest product class; NaN above the largest),
    ``h_k_m`` and ``h_d_m`` (characteristic and design passing heights of the block centre), ``required_height_m``
    (exact) and ``required_net_height_m`` (rounded up to 0.5 m), ``clearance_m`` and ``permitted_elongation_m``
    (= clearance / gamma_d), ``residual_category``, ``governs`` (which check sets the MEL) and ``candidates``
    (one row per candidate check).
    """

    basis: DesignBasis
    x_m: float
    block_mass_kg: float
    block_diameter_m: float
    block_rule: str
    v_k_ms: float
    v_d_ms: float
    E_k_kj: float
    E_d_kj: float
    frequent_energy_kj: float
    design_event: str
    required_mel_kj: float
    required_class_kj: float
    governs: str
    h_k_m: float
    h_d_m: float
    required_height_m: float
    required_net_height_m: float
    clearance_m: float | None
    permitted_elongation_m: float | None
    residual_category: str
    shares: dict = field(default_factory=dict)
    candidates: pd.DataFrame = field(default_factory=pd.DataFrame, repr=False)
    #: ONR 24810: the event-frequency class of the site and its design-block size fractile [%] (else "" and NaN)
    event_frequency_class: str = ""
    design_block_fractile: float = float("nan")
    #: statements about the requirement a checker must read (fractile replaced, factors not stated, ...)
    notes: tuple = ()

    def summary(self) -> pd.DataFrame:
        """The requirement as a one-column table with plain-language row names and units.

        Returns
        -------
        pandas.DataFrame
            One column ``value``, one row per quantity with its unit in the row name.
        """
        rows = {
            "design basis (governs)": self.basis.basis,
            "barrier line x [m]": self.x_m,
            "governing block": f"{self.block_rule}: {sig(self.block_mass_kg)} kg, diameter {sig(self.block_diameter_m)} m",
            "characteristic speed v_k [m/s]": self.v_k_ms,
            "design speed v_d [m/s]": self.v_d_ms,
            "characteristic energy E_k [kJ]": self.E_k_kj,
            "design energy E_d [kJ]": self.E_d_kj,
            "design event (kit level used)": "rare: MEL" if self.design_event == "rare" else "frequent: SEL = MEL/3",
            (f"{self.basis.frequent_T_years:g}-year energy [kJ] (owner option frequent_events_sel "
             f"{'ON: checked against SEL' if self.basis.frequent_events_sel else 'off: for information'}; "
             f"not in {self.basis.basis})"): self.frequent_energy_kj,
            "required MEL [kJ]": self.required_mel_kj,
            "required product class MEL [kJ]": self.required_class_kj,
            "MEL set by": self.governs,
            "characteristic passing height h_k [m]": self.h_k_m,
            "design passing height h_d [m]": self.h_d_m,
            "required height: design passing height + free border [m]": self.required_height_m,
            "required net height (0.5 m steps) [m]": self.required_net_height_m,
            "clearance to the road D_A [m]": self.clearance_m,
            "permitted maximum elongation [m] (D_A / gamma_d; ONR 24810 also D_A - 1 m)": self.permitted_elongation_m,
            f"required residual-height category (owner option, not in {self.basis.basis})": self.residual_category,
        }
        if self.event_frequency_class:
            rows["ONR 24810 event-frequency class (falls per year)"] = self.event_frequency_class
            rows["ONR 24810 design-block size fractile [%]"] = self.design_block_fractile
        if self.basis.basis == "ONR 24810":
            rows["ONR 24810 consequence class"] = self.basis.consequence_class or f"not stated {CONFIRM}"
        for i, n in enumerate(self.notes):
            rows[f"note {i + 1}"] = n
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def text(self) -> str:
        """The requirement in one sentence.

        Returns
        -------
        str
            The governing basis, E_d [kJ], the required MEL [kJ], product class and net height [m] in one sentence.
        """
        cls = (f"{self.required_class_kj:,.0f} kJ class" if np.isfinite(self.required_class_kj)
               else f"above the largest product class ({max(self.basis.mel_classes_kj):,.0f} kJ): no single kit")
        return (f"{self.basis.basis} governs: E_d = {self.E_d_kj:,.0f} kJ; required MEL {self.required_mel_kj:,.0f} kJ "
                f"({cls}; set by {self.governs}), required net height {self.required_net_height_m:g} m at x = {self.x_m:g} m"
                + (f", maximum elongation {self.permitted_elongation_m:.2f} m" if self.permitted_elongation_m else "")
                + f", residual-height category {self.residual_category}")

    def to_dict(self) -> dict:
        """JSON-ready: every field, the basis with its factors, the candidate checks as records.

        Returns
        -------
        dict
            Every field, the basis with its factors and the candidate checks as records.
        """
        out = {k: getattr(self, k) for k in (
            "x_m", "block_mass_kg", "block_diameter_m", "block_rule", "v_k_ms", "v_d_ms", "E_k_kj", "E_d_kj",
            "frequent_energy_kj", "design_event", "required_mel_kj", "required_class_kj", "governs", "h_k_m",
            "h_d_m", "required_height_m", "required_net_height_m", "clearance_m", "permitted_elongation_m",
            "residual_category", "event_frequency_class", "design_block_fractile")}
        out = {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in out.items()}
        out["basis"] = self.basis.basis
        out["basis_text"] = self.basis.text()
        out["factors"] = dict(self.basis.factors)
        out["factors_not_stated"] = self.basis.unverified
        out["frequent_T_years"] = self.basis.frequent_T_years
        out["owner_options"] = {"frequent_events_sel": bool(self.basis.frequent_events_sel),
                                "residual_category": self.basis.residual_category}
        out["consequence_class"] = self.basis.consequence_class
        out["rules"] = self.basis.rules().to_dict(orient="records")
        out["notes"] = list(self.notes)
        out["required_barrier_shares"] = dict(self.shares)
        out["candidates"] = self.candidates.to_dict(orient="records")
        return out



def _block_for_basis(hazard, basis: DesignBasis, block, density_kg_m3: float):
    """(mass [kg], rule text) of the block the basis designs for: the design block for ONR/UNI, the T-year block
    reaching the line for the return-period basis (the one whose class gives the height)."""
    if basis.basis != "return period" and block is not None:
        return float(block.mass_kg), f"design block ({block.rule})"
    from .design_block import line_return_period_mass
    m = float(line_return_period_mass(hazard, [basis.design_T])[0])
    if not np.isfinite(m):
        if block is None:
            raise ValueError(f"no design block and no {basis.design_T:g}-year block at the line (fewer than one fall "
                             f"reaches it in {basis.design_T:g} years): the {basis.basis} basis needs one")
        return float(block.mass_kg), f"design block ({block.rule})"
    return m, f"{basis.design_T:g}-year block reaching the line"



def _class_value(hazard, what: str, q: float, mass_kg: float) -> float:
    """The q-th percentile speed [m/s] or height [m] of the simulated blocks of ``mass_kg``'s class (mass-coupled),
    else of all arriving blocks."""
    if what == "speed":
        return float(hazard.velocity_percentile(q, mass_kg=mass_kg))
    if hazard.mass_coupled:
        return float(hazard.velocity.height_percentile(q, mass_kg))
    if hazard.heights_m is None:
        return float("nan")
    return float(hazard.height_percentile(q))



def frequent_energy(hazard, T: float) -> float:
    """The T-year impact energy at the line [kJ]; NaN when fewer than one fall reaches it in T years.

    Parameters
    ----------
    hazard : EnergyHazard
        Impact-energy hazard at the line.
    T : float
        Return period [years].

    Returns
    -------
    float
        The T-year impact energy [kJ], NaN when fewer than one fall reaches the line in T years.
    """
    return float(hazard.energy_at_return_period(T)) if T * hazard.arrival_rate > 1 else float("nan")



def barrier_shares(hazard, mel_kj: float, height_m: float, *, block_top_m: float = 0.0) -> dict:
    """Shares [-] of the falls reaching the line that a fence of MEL [kJ] and height [m] stops, that pass over
    it (centre + ``block_top_m`` above the height) and that break through it (energy above MEL, not over; height and
    energy taken as independent).  NaN shares without simulated heights.

    Parameters
    ----------
    hazard : EnergyHazard
        Impact-energy hazard at the line (with simulated passing heights).
    mel_kj : float
        Maximum energy level of the fence [kJ].
    height_m : float
        Net height of the fence [m].
    block_top_m : float, optional
        Height of the block top above its centre [m].

    Returns
    -------
    dict
        Shares [-] under "stopped", "over" and "through".
    """
    p_e = float(hazard.exceedance_probability(mel_kj))
    over = float(hazard.height_exceedance(height_m - block_top_m)) if hazard.heights_m is not None else float("nan")
    through = (1.0 - over) * p_e if np.isfinite(over) else p_e
    return {"stopped": 1.0 - over - through if np.isfinite(over) else float("nan"), "over": over,
            "through": through}



def design_requirement(hazard, basis: DesignBasis, *, block=None, density_kg_m3: float = DEFAULT_DENSITY_KG_M3,
                       x_m: float = float("nan"), clearance_m: float | None = None,
                       candidates=()) -> DesignRequirement:
    """The barrier the chosen basis requires at one line (see the module notes), with candidate checks.

    Parameters
    ----------
    hazard : EnergyHazard at the line (mass-coupled: speeds and heights of the design block's own mass class)
    basis : DesignBasis
    block : DesignBlock or None (needed by ONR 24810 and UNI 11211-4; the return-period basis uses the T-year block)
    density_kg_m3 : rock density [kg/m3]
    x_m : position of the line [m] (for the outputs)
    clearance_m : distance [m] from the line to the road (``basis.clearance_m`` replaces it when stated)
    candidates : sequence of (name, MEL [kJ], height [m]) or (name, MEL, height, kit) fences to check against the
        requirement; a kit (:class:`~riskrf.hazard.barrier_kits.Kit` or a name of the kit table) gives its SEL,
        maximum elongation at MEL and residual-height category (and the MEL and height where these are None)

    Returns
    -------
    DesignRequirement
        Design energy [kJ], required MEL [kJ] and product class, required net height [m], permitted elongation [m]
        and the candidate checks.

    References
    ----------
    UNI 11211-4:2012 (rev. 2018); Peila & Ronco (2009), NHESS 9:1291-1298; ONR 24810:2021.
    """
    f = basis.factors
    notes = []
    ef_cls, ef_q = "", float("nan")
    if basis.basis == "ONR 24810":
        block, ef_cls, ef_q = _onr_design_block(hazard, block, notes)
        if basis.consequence_class is None:
            notes.append(f"ONR 24810 consequence class not stated (design.consequence_class = CC1, CC2 or CC3) "
                         f"{CONFIRM}")
        if basis.unverified:
            notes.append(f"ONR 24810 partial factors {', '.join(basis.unverified)} = 1.0 are riskrf defaults; the "
                         f"standard's factors for consequence class {basis.consequence_class or '(not stated)'} "
                         f"were not read: state them in [design] {CONFIRM}")
    m, rule = _block_for_basis(hazard, basis, block, density_kg_m3)
    d = float((6.0 * m / density_kg_m3 / np.pi) ** (1.0 / 3.0))
    qv = f.get("velocity_percentile", 95.0)
    v_k = _class_value(hazard, "speed", qv, m)
    e_freq = frequent_energy(hazard, basis.frequent_T_years)
    if basis.basis == "UNI 11211-4":
        v_d = v_k * f["gamma_Tr"] * f["gamma_Dp"]
        E_k = kinetic_energy_kj(m, v_k)
        E_d = uni11211_energy(m / density_kg_m3, density_kg_m3, v_k, gamma_Tr=f["gamma_Tr"], gamma_Dp=f["gamma_Dp"],
                              gamma_VolF=f["gamma_VolF"], gamma_gamma=f["gamma_gamma"])
        event, need = "rare", E_d * f["gamma_E"]
        what = f"E_d x gamma_E ({f['gamma_E']:g}) <= MEL (UNI 11211-4)"
        h_factor = f["gamma_Tr"] * f["gamma_Dp"]
    elif basis.basis == "ONR 24810":
        v_d = v_k * f["gamma_v"]
        E_k = kinetic_energy_kj(m, v_k)
        E_d = onr24810_energy(m, v_k, gamma_m=f["gamma_m"], gamma_v=f["gamma_v"])
        rate_block = float(hazard.rate_per_year * (hazard.velocity.arrival_sf(m, _mass_model(hazard))
                                                     if hazard.mass_coupled else
                                                     hazard.reach_probability * _mass_model(hazard).sf(m)))
        T_block = 1.0 / rate_block if rate_block > 0 else float("inf")
        event = "frequent" if T_block < basis.frequent_T_years else "rare"
        need = E_d / SEL_PER_MEL if event == "frequent" else E_d
        what = (f"E_d <= SEL = MEL/3 (ONR 24810; design block arrives every {sig(T_block)} yr, frequent: more often "
                f"than every {basis.frequent_T_years:g} yr {CONFIRM})" if event == "frequent"
                else f"E_d <= MEL (ONR 24810; design block arrives every {sig(T_block)} yr, rare)")
        h_factor = 1.0
    else:
        T = basis.design_T
        E_d = float(hazard.energy_at_return_period(T)) if T * hazard.arrival_rate > 1 else float("nan")
        if not np.isfinite(E_d):
            raise ValueError(f"the {T:g}-year energy at x = {x_m:g} m is not defined: fewer than one fall reaches the "
                             f"line in {T:g} years; choose another basis or return period")
        E_k, v_k, v_d = E_d, float("nan"), float("nan")
        event, need = "rare", E_d
        what = f"{T:g}-year energy <= MEL (return-period basis, an owner basis)"
        h_factor = 1.0
    governs = what
    frequent_rule = (f"{basis.frequent_T_years:g}-year energy <= SEL = MEL/3 (frequent events; owner option "
                     f"frequent_events_sel, not in {basis.basis})")
    if basis.frequent_events_sel and np.isfinite(e_freq) and e_freq / SEL_PER_MEL > need:
        need, governs = e_freq / SEL_PER_MEL, frequent_rule
    cls = required_product_class(need, basis.mel_classes_kj)
    qh = f.get("height_percentile", 95.0)
    h_k = _class_value(hazard, "height", qh, m)
    h_d = h_k * h_factor
    if basis.basis == "UNI 11211-4":
        # H_tot >= H_d + f_min, the free border at least 0.5 m and at most half the block size (the radius):
        # the larger of the two (RocFall UNI 11211 design page quoting UNI 11211-4:2012 [V])
        border = max(basis.free_board_m, d / 2.0)
        border_text = f"h_d + free border f_min = max({basis.free_board_m:g} m, radius)"
    else:
        border = d / 2.0 + basis.free_board_m      # the block's top and a free board above it
        border_text = f"h_d + radius + free board ({basis.free_board_m:g} m)"
    H = h_d + border
    clear = basis.clearance_m if basis.clearance_m is not None else clearance_m
    permitted = permitted_elongation_m(basis, clear) if clear is not None else None
    shares = barrier_shares(hazard, cls if np.isfinite(cls) else need, round_up(H), block_top_m=0.0) \
        if np.isfinite(H) else {}
    rows = []
    for cand in candidates:
        name, mel, height = cand[:3]
        kit = _kit_of(cand[3] if len(cand) > 3 else None)
        if kit is not None:
            mel = kit.mel_kj if mel is None else mel
            height = kit.nominal_height_m if height is None else height
        sel = kit.sel_kj if kit is not None else mel * SEL_PER_MEL
        of = f" [{kit.label()}]" if kit is not None else ""
        rows.append({"fence": name, "check": f"energy: {governs}{of}", "demand": need, "capacity": mel, "unit": "kJ",
                     "adequate": bool(need <= mel * (1 + 1e-12))})
        if basis.frequent_events_sel and np.isfinite(e_freq):
            rows.append({"fence": name, "check": f"frequent events: {frequent_rule}{of}",
                         "demand": e_freq, "capacity": sel, "unit": "kJ", "adequate": bool(e_freq <= sel)})
        rows.append({"fence": name, "check": f"height: {border_text}{of}",
                     "demand": H, "capacity": height, "unit": "m",
                     "adequate": bool(H <= height) if np.isfinite(H) else None})   # no simulated heights
        elong = basis.kit_elongation_m(name)
        elong_from = "stated in design.elongation_m"
        if elong is None and kit is not None:
            elong, elong_from = kit.max_elongation_mel_m, kit.label()
        if kit is not None:
            need_cat = basis.residual_category
            rows.append({"fence": name, "check": f"residual height: category {kit.residual_category} vs required "
                                                 f"{need_cat} (owner option, not in {basis.basis}){of}",
                         "demand": float("nan"), "capacity": float("nan"), "unit": "",
                         "adequate": bool(kit.residual_category <= need_cat)})   # A is the best, C the worst
        if elong is not None and clear is not None:
            need_d = required_distance_m(basis, elong)
            rule_d = (f"max({f['gamma_d']:g} D_MEL, D_MEL + 1 m)" if basis.basis == "ONR 24810"
                      else f"D_MEL x gamma_d ({f['gamma_d']:g})")
            rows.append({"fence": name, "check": f"elongation: {rule_d} vs clearance (D_MEL {elong:g} m, "
                                                 f"{elong_from})",
                         "demand": need_d, "capacity": clear, "unit": "m", "adequate": bool(need_d <= clear)})
        elif clear is not None:
            rows.append({"fence": name, "check": "elongation: the kit's maximum elongation at MEL must not exceed",
                         "demand": float("nan"), "capacity": permitted, "unit": "m", "adequate": None})
    return DesignRequirement(
        basis=basis, x_m=float(x_m), block_mass_kg=m, block_diameter_m=d, block_rule=rule, v_k_ms=v_k, v_d_ms=v_d,
        E_k_kj=float(E_k), E_d_kj=float(E_d), frequent_energy_kj=e_freq, design_event=event,
        required_mel_kj=float(need), required_class_kj=cls, governs=governs, h_k_m=h_k, h_d_m=h_d,
        required_height_m=float(H), required_net_height_m=round_up(H) if np.isfinite(H) else float("nan"),
        clearance_m=clear, permitted_elongation_m=permitted, residual_category=basis.residual_category,
        shares=shares, candidates=pd.DataFrame(rows), event_frequency_class=ef_cls, design_block_fractile=ef_q,
        notes=tuple(notes))



def _kit_of(kit):
    """A :class:`~riskrf.hazard.barrier_kits.Kit` from a kit or its name (None stays None)."""
    if kit is None:
        return None
    from .barrier_kits import Kit, get_kit
    return kit if isinstance(kit, Kit) else get_kit(kit)



def _onr_design_block(hazard, block, notes: list):
    """ONR 24810's design block: the block-size fractile of the site's event-frequency class.

    The class follows from the hazard's rate of falls (``hazard.rate_per_year`` [1/yr], the site's events).  A
    percentile design block built from block sizes (``block.inputs``) is re-derived at the class's fractile when
    its percentile differs; a block of another rule is kept and flagged.  Returns (block, class, fractile [%]).
    """
    n = float(hazard.rate_per_year)
    cls, q, name = onr24810_event_frequency_class(n)
    head = f"ONR 24810 event-frequency class {cls} ({name}; n = {sig(n)} falls/yr)"
    if block is None:
        return block, cls, q
    if block.rule == "percentile" and block.inputs:
        stated = float(block.inputs.get("percentile", q))
        if abs(stated - q) > 1e-9:
            from .design_block import design_block
            block = design_block(hazard, **{**block.inputs, "percentile": q})
            notes.append(f"{head}: the design block is the V{q:g} of the block sizes, replacing "
                         f"design_block.percentile = {stated:g}")
        else:
            notes.append(f"{head}: design block V{q:g} of the block sizes")
    elif block.rule == "percentile":
        notes.append(f"{head} asks for the V{q:g} of the block sizes; the design block's percentile could not be "
                     f"checked {CONFIRM}")
    else:
        notes.append(f"{head} asks for the V{q:g} of the block sizes (the standard approach); the design block is "
                     f"the {block.rule!r} block (design_block.rule): not the standard approach, unless the simplified "
                     f"approach applies (CC1, EF1-EF2 or < 100 jointed bodies) {CONFIRM}")
    return block, cls, q



def _mass_model(hazard):
    from .mass_models import mass_model
    return mass_model(hazard.mass)


# ---- position search ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class PositionSearch:
    """The requirement at several barrier positions along the profile (one simulation, collectors at each x).

    ``table``: one row per position: x [m], ground z [m], share of released blocks reaching it, arrivals per year,
    E_d [kJ], required MEL [kJ] and product class [kJ], required net height [m], clearance [m]; ``profile``:
    (x, z) of the slope; ``basis``: the :class:`DesignBasis`; ``n``: blocks simulated.  Its figure: :meth:`plot`
    (drawn by :func:`riskrf.hazard.figures.plot_position_search`; the science draws nothing).
    """

    table: pd.DataFrame
    profile: tuple
    basis: DesignBasis
    n: int
    road_x_m: float | None = None

    def summary(self) -> pd.DataFrame:
        """The per-position table with plain-language headers and units, one row per position, the cheapest
        position marked (column "cheapest").

        Returns
        -------
        pandas.DataFrame
            One row per position [m] with the required MEL [kJ], class [kJ] and net height [m]; column "cheapest" marks
            the cheapest position.
        """
        names = {"x_m": "position x [m]", "ground_z_m": "ground z [m]", "reach_share": "share of blocks reaching",
                 "arrivals_per_year": "arrivals per year", "E_d_kj": "design energy E_d [kJ]",
                 "required_mel_kj": "required MEL [kJ]", "required_class_kj": "product class MEL [kJ]",
                 "required_net_height_m": "required net height [m]", "clearance_m": "clearance to the road [m]",
                 "note": "note"}
        t = self.table.rename(columns=names)
        best = self.cheapest()
        t["cheapest"] = (self.table["x_m"] == best["x_m"]).to_numpy() if best is not None else False
        return t

    def plot(self, ax=None):
        """Required MEL, product class and net height per position; returns the matplotlib axes (drawn by
        :func:`riskrf.hazard.figures.plot_position_search`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from .figures import plot_position_search
        return plot_position_search(self, ax=ax)

    def cheapest(self) -> pd.Series | None:
        """The position with the smallest required class, then the lowest net height (None when no position has a
        class).

        Returns
        -------
        pandas.Series or None
            The row of the cheapest position, None when no position has a class.
        """
        t = self.table.dropna(subset=["required_class_kj"])
        if t.empty:
            return None
        return t.sort_values(["required_class_kj", "required_net_height_m", "x_m"]).iloc[0]



def default_positions(scenario, barrier_x: float, road_x: float | None, k: int = 9) -> list:
    """``k`` positions [m] between a quarter of the way from the release zone to the road and 2 m before the road,
    with the barrier line among them.

    Parameters
    ----------
    scenario : Scenario
        The site's simulation scenario (gives the release zone).
    barrier_x : float
        Position of the barrier line along the profile [m].
    road_x : float or None
        Position of the road along the profile [m] (None: the profile end).
    k : int, optional
        Number of positions.

    Returns
    -------
    list of float
        Sorted positions along the profile [m].
    """
    start = float(scenario.seeder.x_high)
    end = (road_x if road_x is not None else float(scenario.profile.x[-1])) - 2.0
    lo = start + 0.25 * (end - start)
    xs = set(np.round(np.linspace(lo, end, k), 1).tolist()) | {float(barrier_x)}
    return sorted(x for x in xs if start < x < end + 2.0)



def position_search(hazard, scenario, basis: DesignBasis, *, block=None, density_kg_m3: float = DEFAULT_DENSITY_KG_M3,
                    positions_m=None, road_collector: str | None = "road", barrier_x: float | None = None,
                    n: int = 10_000, seed=1) -> PositionSearch:
    """:func:`design_requirement` at several positions along the profile from one simulation.

    The blocks are simulated over the hazard's own mass range (log-uniform, stratified, as the mass-coupled
    hazard) with a collector at each position; each position's reach, speeds and heights by mass class give its
    hazard under the site's mass law and rate, and the chosen basis gives the required MEL and height there.

    Parameters
    ----------
    hazard : EnergyHazard
        Mass-coupled hazard at the barrier line (gives the mass range, mass law and rate).
    scenario : Scenario
        The site's simulation scenario.
    basis : DesignBasis
        The governing design basis.
    block : DesignBlock, optional
        The design block (needed by ONR 24810 and UNI 11211-4).
    density_kg_m3 : float, optional
        Rock density [kg/m3].
    positions_m : sequence of float, optional
        Positions along the profile [m] (default :func:`default_positions`).
    road_collector : str or None, optional
        Name of the road collector (gives the clearance).
    barrier_x : float, optional
        Position of the barrier line [m].
    n : int, optional
        Number of simulated blocks.
    seed : int, optional
        Random seed.

    Returns
    -------
    PositionSearch
        The requirement per position, the profile and the basis.
    """
    import simulation

    from .annual_hazard import EnergyHazard
    from .mass_coupling import stratified_log_uniform
    from .simulated import coupled_samples

    if not hazard.mass_coupled:
        raise ValueError("the position search needs a mass-coupled hazard (hazard.mass_coupling = 'simulated')")
    names = [c.name for c in scenario.collectors]
    road_x = scenario.collectors[names.index(road_collector)].x if road_collector in names else None
    if barrier_x is None:
        barrier_x = scenario.collectors[scenario.collector_index(hazard.collector)].x
    xs = list(positions_m) if positions_m is not None else default_positions(scenario, barrier_x, road_x)
    if not xs:
        raise ValueError("design.positions_x_m: no position to search")
    px = np.asarray(scenario.profile.x, dtype=float)
    for x in xs:
        if not px[0] < float(x) < px[-1]:
            raise ValueError(f"design.positions_x_m: x = {x!r} m lies outside the profile ({px[0]:g} - {px[-1]:g} m)")
    cols = tuple(simulation.scenario.Collector(name=f"position_{i}", x=float(x)) for i, x in enumerate(xs))
    sc = replace(scenario, collectors=cols)
    edges = hazard.velocity.edges_kg
    rng = np.random.default_rng(np.random.SeedSequence([0 if seed is None else int(seed), 11]))
    masses = stratified_log_uniform(float(edges[0]), float(edges[-1]), int(n), rng)
    result = simulation.run(sc, seed=seed, masses_kg=masses)
    mm = _mass_model(hazard)
    pz = np.asarray(scenario.profile.z, dtype=float)
    rows = []
    for i, x in enumerate(xs):
        row = {"x_m": float(x), "ground_z_m": float(np.interp(x, px, pz)),
               "reach_share": float(result.reach_probability(f"position_{i}")[0])}
        samples = coupled_samples(result, f"position_{i}", masses, edges, mm)
        if samples is None:
            rows.append(row | {"arrivals_per_year": 0.0, "E_d_kj": np.nan, "required_mel_kj": np.nan,
                               "required_class_kj": np.nan, "required_net_height_m": np.nan,
                               "clearance_m": (road_x - x) if road_x is not None else np.nan,
                               "note": "no simulated block reaches this line"})
            continue
        reach = samples.reach_probability(mm)
        hz = EnergyHazard(mass=hazard.mass, velocity=samples, rate_per_year=hazard.rate_per_year,
                          reach_probability=max(reach, 1e-300), n_released=result.n, heights_m=samples.heights_m,
                          collector=f"position_{i}")
        clear = (road_x - x) if road_x is not None else None
        try:
            req = design_requirement(hz, basis, block=block, density_kg_m3=density_kg_m3, x_m=x, clearance_m=clear)
        except ValueError as exc:
            rows.append(row | {"arrivals_per_year": hz.arrival_rate, "E_d_kj": np.nan, "required_mel_kj": np.nan,
                               "required_class_kj": np.nan, "required_net_height_m": np.nan,
                               "clearance_m": clear if clear is not None else np.nan, "note": str(exc)})
            continue
        rows.append(row | {"arrivals_per_year": hz.arrival_rate, "E_d_kj": req.E_d_kj,
                           "required_mel_kj": req.required_mel_kj, "required_class_kj": req.required_class_kj,
                           "required_net_height_m": req.required_net_height_m,
                           "clearance_m": clear if clear is not None else np.nan,
                           "note": "barrier line of the hazard" if abs(x - barrier_x) < 1e-9 else ""})
    return PositionSearch(table=pd.DataFrame(rows), profile=(px, pz), basis=basis, n=int(n), road_x_m=road_x)


__all__ = ["DesignRequirement", "PositionSearch", "barrier_shares", "default_positions", "design_requirement",
           "frequent_energy", "position_search"]
