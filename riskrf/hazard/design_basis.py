"""The design basis of a flexible rock fall barrier: one standard governs, and it gives REQUIRED values.

A checking engineer needs one stated basis, the design energy and height it gives, the checks it asks for
and the barrier it requires, not pass/fail on a few candidates.  Three bases are offered; the site file
chooses one (``[design] basis``, default ``"UNI 11211-4"``, the one whose partial factors are seen in a
public source) and every output names it.

``"UNI 11211-4"`` (UNI 11211-4:2012, rev. 2018; Peila & Ronco 2009, NHESS 9:1291-1298)
    E_d = 1/2 m_d v_d^2 with m_d = Vol rho gamma_VolF gamma_gamma and v_d = v_t gamma_Tr gamma_Dp, v_t the
    95th-percentile speed of the design block at the line; check E_d <= MEL / gamma_E (gamma_E = 1.2 against
    MEL).  Design height h_d = h_t gamma_Tr gamma_Dp (h_t the 95th-percentile passing height); design
    elongation D_d = D_MEL gamma_d (gamma_d = 1.3 at MEL) against the distance available to the road D_A; the net
    height H_tot >= h_d + f_min, the free border f_min at least 0.5 m and at most half the block size (the larger
    is taken).
    Factor values: gamma_Tr, gamma_Dp, gamma_VolF in {1.02, 1.10}, gamma_gamma 1.0 [V: the RocFall UNI 11211
    design page citing UNI 11211-4:2012]; gamma_E, gamma_d and the height factor [R].
``"ONR 24810"`` (ONR 24810:2021)
    The design block (the 95th-98th percentile of the block sizes by event frequency [V]) at the
    characteristic (95th or 99th [V]) percentile speed at the line, each with a partial factor:
    E_d = 1/2 (m_k gamma_m) (v_k gamma_v)^2.  The kit's MEL is used for rare design events, its
    SEL = MEL/3 for frequent ones (the design block's return period at the line below ``frequent_T_years``).
    The factor values gamma_m, gamma_v are riskrf defaults [R], NOT checked against the standard's tables: every
    output says so until the site file states them (``[design] gamma_m``, ``gamma_v``).  The distance to the
    element at risk is at least 1.2 times the kit's maximum elongation in the MEL test and at least that
    elongation + 1 m, D_min = max(1.2 D_MEL, D_MEL + 1 m) [V: Trumer Schutzbauten's summary of ONR 24810,
    "Constructive Rules", trumerschutzbauten.com/standards/rockfall-standards/onr-24810/constructive/]
    (:func:`onr24810_min_distance_m`).
``"return period"``
    E_d is the T-year impact energy at the line (``hazard.design_period_years``), checked against MEL without
    a factor.

Standards as written, owner choices as named options.  A rule that the governing standard does not set is an
**owner option** of ``[design]``, off by default, and labelled "owner option, not in <standard>" wherever it
governs (:data:`OWNER_OPTIONS`, :meth:`DesignBasis.rules`):

``frequent_events_sel`` (default false)
    the ``frequent_T_years`` impact energy at the line (default 30 years: the Swiss "high probability" class
    1-30 years, BUWAL 1997 [R]) against SEL = MEL/3, so that frequent impacts need no repair.  UNI 11211-4 asks
    for E_d <= MEL/gamma_E or E_d <= SEL/gamma_E (RocFall UNI 11211 design page [V]), not for a return-period
    energy; ONR 24810's own frequent/rare distinction is on the design block (below), not on a 30-year energy.
``residual_category`` (default "A")
    the residual-height category required of the kit (EAD 340059-00-0106 / ETAG 027 categories: A >= 50 %,
    B 30-50 %, C < 30 % of the nominal height [R]); EAD 340059 classifies kits, it requires none.

ONR 24810 (as summarised by Trumer Schutzbauten, trumerschutzbauten.com/standards/rockfall-standards/onr-24810/,
pages "Design Block" and "Consequence Class" [V]) sets the design-block SIZE fractile by the event-frequency
class of the site (:data:`ONR_EVENT_FREQUENCY_CLASSES`: EF4 n >= 10/yr V98, EF3 1 <= n < 10 V97, EF2
0.03 <= n < 1 V96, EF1 n < 0.03 V95) and borrows the consequence classes CC1-CC3 of EN 1990
(:data:`ONR_CONSEQUENCE_CLASSES`), which set its partial factors; the factor values per class were not readable
in any source reached, so every output says "[confirm against the standard]" until the site states
``gamma_m`` and ``gamma_v``.

This module holds the bases: their factors and sources, the ONR 24810 classes, the design-energy formulas, the
distance and elongation rules and :class:`DesignBasis` (read from the site file by :func:`design_basis_from_site`).
What a basis requires of a fence, :func:`~riskrf.hazard.design_requirement.design_requirement` (the required MEL
and the smallest product class that meets it, the required net height, the elongation the road clearance permits
and the checks of candidate fences) and :func:`~riskrf.hazard.design_requirement.position_search` (the
requirement along the profile from one simulation with collectors at several x), is in
:mod:`riskrf.hazard.design_requirement`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..core.file_schemas import DESIGN
from ..core.schema import as_record
from ..core.units import kinetic_energy_kj

BASES = ("ONR 24810", "UNI 11211-4", "return period")
DEFAULT_BASIS = "UNI 11211-4"

#: MEL classes [kJ] of certified kits: EAD 340059 / ETAG 027 classes 0-7 (100-4,500 kJ) and, in class 8
#: (> 4,500 kJ), kits certified at 5,000, 8,000 and 8,500 kJ [R: product catalogues].  ``[design]
#: mel_classes_kj`` replaces the list with the classes of the products the owner accepts.
MEL_PRODUCT_CLASSES_KJ = (100.0, 250.0, 500.0, 1000.0, 1500.0, 2000.0, 3000.0, 4500.0, 5000.0, 8000.0, 8500.0)
#: Residual height after the MEL test as a share of the nominal height: category A >= 0.5, B 0.3-0.5, C < 0.3
#: (EAD 340059-00-0106, ETAG 027) [R].
RESIDUAL_CATEGORIES = {"A": 0.5, "B": 0.3, "C": 0.0}
#: Net heights are chosen in steps of this [m] (kits come in 0.5 m or 1 m steps).
HEIGHT_STEP_M = 0.5

#: Rules no standard of :data:`BASES` sets: owner options of ``[design]`` with their default and meaning.  Each
#: is labelled "owner option, not in <basis>" wherever it governs.
OWNER_OPTIONS = {
    "frequent_events_sel": (False, "the frequent_T_years impact energy at the line <= SEL = MEL/3 (frequent impacts "
                                   "need no repair)"),
    "residual_category": ("A", "the residual-height category required of the kit after a MEL impact (EAD 340059 "
                               "classifies kits A/B/C, it requires none)"),
}

#: ONR 24810 event-frequency classes: (class, lowest n [falls/yr], design-block size fractile [%], name).  Table
#: "Event Frequency Class / Occurrence Frequency n (1/a) / Design Block Size Fractile" of Trumer Schutzbauten's
#: summary of ONR 24810, page "Design Block" (trumerschutzbauten.com/standards/rockfall-standards/onr-24810/
#: design-block/) [V]: EF4 n >= 10 V98, EF3 1 <= n < 10 V97, EF2 0.03 <= n < 1 V96, EF1 n < 0.03 V95.
ONR_EVENT_FREQUENCY_CLASSES = (("EF4", 10.0, 98.0, "very high"), ("EF3", 1.0, 97.0, "high"),
                               ("EF2", 0.03, 96.0, "low"), ("EF1", 0.0, 95.0, "rare"))
#: ONR 24810 consequence classes (from EN 1990:2002 Annex B), as summarised by Trumer Schutzbauten, page
#: "Consequence Class" (trumerschutzbauten.com/standards/rockfall-standards/onr-24810/consequence-class/) [V].
ONR_CONSEQUENCE_CLASSES = {
    "CC1": "low consequence: e.g. agricultural buildings rarely occupied, forest roads, freight roads with low traffic",
    "CC2": "medium consequence: e.g. residential and public buildings, regional and national roads with daily "
           "traffic < 50,000 vehicles",
    "CC3": "high consequence: high impact on human life, very large economic, social or environmental effects",
}
#: ONR 24810 partial factors on the design block's mass and speed by consequence class.  The standard's table was
#: not readable in any source reached (the published summaries name the classes, not the numbers; Moelk & Stelzer
#: 2013 only say the factors exist): no value is given, and every output says "[confirm against the standard]"
#: until the site file states gamma_m and gamma_v.
ONR_CONSEQUENCE_FACTORS: dict = {}
CONFIRM = "[confirm against the standard]"


def onr24810_event_frequency_class(falls_per_year: float) -> tuple:
    """ONR 24810 event-frequency class and design-block size fractile of a site with ``falls_per_year`` events.

    Parameters
    ----------
    falls_per_year : float
        Occurrence frequency n of rock fall events [1/yr].

    Returns
    -------
    tuple
        (class "EF1"-"EF4", design-block size fractile [%], class name): EF4 n >= 10 -> 98, EF3 1 <= n < 10 -> 97,
        EF2 0.03 <= n < 1 -> 96, EF1 n < 0.03 -> 95.

    References
    ----------
    ONR 24810:2021, design block, as summarised by Trumer Schutzbauten, "Design Block" table
    (trumerschutzbauten.com/standards/rockfall-standards/onr-24810/design-block/).
    """
    n = float(falls_per_year)
    if not (np.isfinite(n) and n >= 0):
        raise ValueError(f"falls_per_year = {falls_per_year!r} must be a number >= 0 [1/yr]")
    for cls, lo, fractile, name in ONR_EVENT_FREQUENCY_CLASSES:
        if n >= lo:
            return cls, fractile, name
    raise AssertionError("unreachable")  # pragma: no cover - EF1 starts at 0

#: Default partial factors per basis; [V] seen in a source, [R] recalled (see the module notes).
DEFAULT_FACTORS = {
    "UNI 11211-4": {"gamma_Tr": 1.10, "gamma_Dp": 1.10, "gamma_VolF": 1.10, "gamma_gamma": 1.0,
                    "gamma_E": 1.2, "gamma_d": 1.3, "velocity_percentile": 95.0, "height_percentile": 95.0},
    "ONR 24810": {"gamma_m": 1.0, "gamma_v": 1.0, "gamma_d": 1.2, "velocity_percentile": 95.0,
                  "height_percentile": 95.0},
    "return period": {"gamma_d": 1.0, "height_percentile": 95.0},
}
FACTOR_SOURCES = {
    "UNI 11211-4": ("gamma_Tr, gamma_Dp, gamma_VolF (1.02 / 1.10) and gamma_gamma (1.0): UNI 11211-4:2012 as quoted "
                    "by the RocFall UNI 11211 design page and Peila & Ronco (2009) [V]; gamma_E = 1.2 against MEL, "
                    "gamma_d = 1.3 at MEL and h_d = h_t gamma_Tr gamma_Dp [R: confirm against the standard]"),
    "ONR 24810": ("design block: the block-size fractile of the event-frequency class, EF4 V98, EF3 V97, EF2 V96, "
                  "EF1 V95 [V: Trumer Schutzbauten's ONR 24810 summary, 'Design Block']; characteristic speed "
                  "percentile 95/99 [V: Marchelli 2022]; distance to the element at risk >= max(1.2 D_MEL, "
                  "D_MEL + 1 m) [V: ONR 24810 constructive rules as summarised by Trumer Schutzbauten]; gamma_m and "
                  "gamma_v are riskrf defaults, NOT checked against the ONR 24810 tables by consequence class: state "
                  "them in [design] for a signed design"),
    "return period": "the T-year impact energy at the line against MEL, no partial factor",
}


def check_basis(basis, where: str = "design.basis") -> str:
    """The basis name if it is one of :data:`BASES`, else a ValueError naming the field and the choices.

    Parameters
    ----------
    basis : str
        Name of the design basis, one of :data:`BASES`.
    where : str, optional
        Name of the site-file field, for the error message.

    Returns
    -------
    str
        ``basis`` unchanged.
    """
    if basis not in BASES:
        raise ValueError(f"{where} = {basis!r} is not one of {', '.join(map(repr, BASES))}")
    return basis


def residual_height_category(residual_share: float) -> str:
    """EAD 340059 / ETAG 027 residual-height category of a kit from its residual height after the MEL test as a
    share of the nominal height [-]: "A" (>= 0.5), "B" (0.3-0.5) or "C" (< 0.3).

    Parameters
    ----------
    residual_share : float
        Residual height after the MEL test as a share of the nominal height [-].

    Returns
    -------
    str
        The category "A", "B" or "C".

    References
    ----------
    EAD 340059-00-0106 / ETAG 027, residual-height categories of flexible rock fall kits.
    """
    r = float(residual_share)
    if not (np.isfinite(r) and 0.0 <= r <= 1.0):
        raise ValueError(f"residual_share = {residual_share!r} must lie between 0 and 1 (residual / nominal height)")
    for cat, lo in RESIDUAL_CATEGORIES.items():
        if r >= lo:
            return cat
    return "C"  # pragma: no cover - lo of C is 0


def required_product_class(energy_kj: float, classes_kj=MEL_PRODUCT_CLASSES_KJ) -> float:
    """The smallest MEL class [kJ] at or above ``energy_kj``; NaN when the largest class is too small.

    Parameters
    ----------
    energy_kj : float
        Required energy [kJ].
    classes_kj : sequence of float, optional
        The MEL product classes [kJ], ascending.

    Returns
    -------
    float
        The smallest class at or above ``energy_kj`` [kJ], NaN when none is.
    """
    c = np.sort(np.asarray(classes_kj, dtype=float))
    above = c[c >= float(energy_kj) * (1 - 1e-12)]
    return float(above[0]) if above.size else float("nan")


def round_up(value: float, step: float = HEIGHT_STEP_M) -> float:
    """``value`` rounded up to a multiple of ``step`` (a kit's nominal height) [m].

    Parameters
    ----------
    value : float
        Value to round [m].
    step : float, optional
        Step [m] (a kit's nominal height step).

    Returns
    -------
    float
        ``value`` rounded up to a multiple of ``step`` [m].
    """
    return float(math.ceil(float(value) / step - 1e-9) * step)


def uni11211_energy(volume_m3, density_kg_m3, velocity_ms, *, gamma_Tr, gamma_Dp, gamma_VolF, gamma_gamma=1.0):
    """UNI 11211-4 design energy [kJ]: E_d = 1/2 (Vol rho gamma_VolF gamma_gamma) (v_t gamma_Tr gamma_Dp)^2.

    Parameters
    ----------
    volume_m3 : float or array_like
        Design block volume Vol [m3].
    density_kg_m3 : float or array_like
        Rock density rho [kg/m3].
    velocity_ms : float or array_like
        95th-percentile speed v_t at the line [m/s].
    gamma_Tr, gamma_Dp : float
        Partial factors on the speed for the trajectory calculation and the slope data [-].
    gamma_VolF : float
        Partial factor on the block volume [-].
    gamma_gamma : float, optional
        Partial factor on the rock density [-].

    Returns
    -------
    float or numpy.ndarray
        Design energy E_d [kJ].

    References
    ----------
    UNI 11211-4:2012 (rev. 2018); Peila D. & Ronco C. (2009), Technical Note: Design of rockfall net fences and the
    new ETAG 027 European guideline, NHESS 9:1291-1298.
    """
    return kinetic_energy_kj(volume_m3 * density_kg_m3 * gamma_VolF * gamma_gamma, velocity_ms * gamma_Tr * gamma_Dp)


#: ONR 24810 constructive rule: the distance to the element at risk is at least this many times the MEL elongation
#: and at least the elongation plus :data:`ONR_MIN_EXTRA_DISTANCE_M` (Trumer Schutzbauten's ONR 24810 summary [V]).
ONR_DISTANCE_FACTOR = 1.2
ONR_MIN_EXTRA_DISTANCE_M = 1.0


def onr24810_min_distance_m(elongation_m, factor: float = ONR_DISTANCE_FACTOR) -> float:
    """Least distance [m] from an ONR 24810 fence to the element at risk for a kit whose maximum elongation in the
    MEL test is ``elongation_m`` [m]: D_min = max(factor x D_MEL, D_MEL + 1 m), factor 1.2 (so D_MEL + 1 m governs
    below 5 m of elongation and 1.2 D_MEL above).

    Parameters
    ----------
    elongation_m : float
        Maximum elongation of the kit in the MEL test D_MEL [m].
    factor : float, optional
        Factor on the elongation [-] (1.2 in ONR 24810).

    Returns
    -------
    float
        Least distance D_min to the element at risk [m].

    References
    ----------
    ONR 24810:2013/2021, constructive rules for rock fall catchment fences, as summarised at
    trumerschutzbauten.com/standards/rockfall-standards/onr-24810/constructive/ ("1.2 times the maximum
    elongation ... and shall not be less than one meter greater than the maximum elongation").
    """
    d = float(elongation_m)
    if not (np.isfinite(d) and d > 0):
        raise ValueError(f"elongation_m = {elongation_m!r} must be a number > 0 m")
    return max(float(factor) * d, d + ONR_MIN_EXTRA_DISTANCE_M)


def permitted_elongation_m(basis: "DesignBasis", clearance_m: float) -> float:
    """The largest maximum elongation [m] of a kit that the clearance to the road [m] permits under ``basis``:
    clearance / gamma_d (UNI 11211-4, return period), and for ONR 24810 also clearance - 1 m
    (:func:`onr24810_min_distance_m` inverted).

    Parameters
    ----------
    basis : DesignBasis
        The governing design basis (gives gamma_d).
    clearance_m : float
        Distance available from the fence line to the road [m].

    Returns
    -------
    float
        The largest permitted maximum elongation of a kit [m].
    """
    g = basis.factors["gamma_d"]
    if basis.basis == "ONR 24810":
        return min(clearance_m / g, clearance_m - ONR_MIN_EXTRA_DISTANCE_M)
    return clearance_m / g


def required_distance_m(basis: "DesignBasis", elongation_m: float) -> float:
    """Distance [m] a kit of maximum elongation ``elongation_m`` needs to the road under ``basis``: D_MEL x gamma_d,
    and for ONR 24810 :func:`onr24810_min_distance_m` (gamma_d as the factor).

    Parameters
    ----------
    basis : DesignBasis
        The governing design basis (gives gamma_d).
    elongation_m : float
        Maximum elongation of the kit in the MEL test [m].

    Returns
    -------
    float
        Distance the kit needs to the road [m].
    """
    if basis.basis == "ONR 24810":
        return onr24810_min_distance_m(elongation_m, basis.factors["gamma_d"])
    return float(elongation_m) * basis.factors["gamma_d"]


def onr24810_energy(mass_kg, velocity_ms, *, gamma_m, gamma_v):
    """ONR 24810 design energy [kJ]: E_d = 1/2 (m_k gamma_m) (v_k gamma_v)^2.

    Parameters
    ----------
    mass_kg : float or array_like
        Characteristic mass of the design block m_k [kg].
    velocity_ms : float or array_like
        Characteristic speed at the line v_k [m/s].
    gamma_m, gamma_v : float
        Partial factors on the mass and on the speed [-].

    Returns
    -------
    float or numpy.ndarray
        Design energy E_d [kJ].

    References
    ----------
    ONR 24810:2021, Technical protection against rockfall.
    """
    return kinetic_energy_kj(mass_kg * gamma_m, velocity_ms * gamma_v)


def check_elongation(value, where: str = "design.elongation_m"):
    """The maximum elongation at MEL of the candidate kits in either documented form: one number [m] for every
    fence, or a table {fence name: metres}; a ValueError naming ``where`` otherwise.

    Parameters
    ----------
    value : float or dict
        One number > 0 [m], or {fence name: number > 0 [m]}.
    where : str, optional
        Name of the field, for the message.

    Returns
    -------
    float or dict
        The number [m], or the table {name: metres}.
    """
    def ok(v):
        return (not isinstance(v, (bool, np.bool_)) and isinstance(v, (int, float, np.integer, np.floating))
                and np.isfinite(float(v)) and float(v) > 0)
    if isinstance(value, dict):
        for name, d in value.items():
            if not ok(d):
                raise ValueError(f"{where}[{name!r}] = {d!r} must be a number > 0 m (the kit's maximum elongation "
                                 "in the MEL test)")
        return {str(k): float(v) for k, v in value.items()}
    if ok(value):
        return float(value)
    raise ValueError(f"{where} = {value!r} must be one number > 0 m for every fence, or a table "
                     "{fence name = metres} (the kits' maximum elongation in the MEL test)")


@dataclass(frozen=True)
class DesignBasis:
    """The chosen standard with its factors and limits (site file ``[design]``).

    basis : one of :data:`BASES`; factors : the partial factors in force (defaults of the basis, replaced by those
    the site states); stated : names of the factors the site file stated; frequent_T_years : return period [yr] of
    the frequent event (ONR 24810's frequent design block; the owner option below); frequent_events_sel : the
    owner option "frequent_T_years energy <= SEL" (default False: no standard of :data:`BASES` sets it);
    residual_category : the required residual-height category (an owner option, default "A");
    consequence_class : ONR 24810 consequence class "CC1"-"CC3" (None: not stated, flagged); clearance_m :
    distance [m] from the barrier to the road available for the net's elongation (None: from the scenario, barrier
    line to road line); free_board_m : free board [m] above the design block's top; mel_classes_kj : the product
    classes [kJ]; elongation_m : maximum elongation at MEL [m] of the candidate kits, one number for every fence or
    {fence name: metres}; design_T : return period [yr] of the return-period basis.
    """

    basis: str = DEFAULT_BASIS
    factors: dict = field(default_factory=dict)
    stated: tuple = ()
    frequent_T_years: float = 30.0
    residual_category: str = "A"
    clearance_m: float | None = None
    free_board_m: float = 0.5
    mel_classes_kj: tuple = MEL_PRODUCT_CLASSES_KJ
    elongation_m: dict | float = field(default_factory=dict)
    design_T: float = 100.0
    frequent_events_sel: bool = False
    consequence_class: str | None = None

    def __post_init__(self):
        check_basis(self.basis)
        merged = dict(DEFAULT_FACTORS[self.basis])
        for k, v in self.factors.items():
            if k not in merged:
                raise ValueError(f"design.{k}: not a factor of {self.basis} (its factors: {', '.join(merged)})")
            merged[k] = v
        for k, v in merged.items():
            if k.endswith("percentile"):
                if not 50.0 <= float(v) < 100.0:
                    raise ValueError(f"design.{k} = {v!r} must lie between 50 and 100 (exclusive) [%]")
            elif not (np.isfinite(float(v)) and 1.0 <= float(v) <= 2.0):
                raise ValueError(f"design.{k} = {v!r}: a partial factor lies between 1.0 and 2.0")
        object.__setattr__(self, "factors", {k: float(v) for k, v in merged.items()})
        if self.residual_category not in RESIDUAL_CATEGORIES:
            raise ValueError(f"design.residual_category = {self.residual_category!r} is not one of 'A', 'B', 'C'")
        if not (np.isfinite(self.frequent_T_years) and self.frequent_T_years > 1):
            raise ValueError(f"design.frequent_T_years = {self.frequent_T_years!r} must be a number > 1 year")
        if self.clearance_m is not None and not (np.isfinite(self.clearance_m) and self.clearance_m > 0):
            raise ValueError(f"design.clearance_m = {self.clearance_m!r} must be a number > 0 m")
        if not (np.isfinite(self.free_board_m) and self.free_board_m >= 0):
            raise ValueError(f"design.free_board_m = {self.free_board_m!r} must be a number >= 0 m")
        c = np.asarray(self.mel_classes_kj, dtype=float)
        if c.size == 0 or np.any(~np.isfinite(c) | (c <= 0)):
            raise ValueError(f"design.mel_classes_kj = {list(self.mel_classes_kj)!r} must be positive energies [kJ]")
        object.__setattr__(self, "mel_classes_kj", tuple(sorted(float(x) for x in c)))
        object.__setattr__(self, "elongation_m", check_elongation(self.elongation_m))
        if not isinstance(self.frequent_events_sel, (bool, np.bool_)):
            raise ValueError(f"design.frequent_events_sel = {self.frequent_events_sel!r} must be true or false "
                             "(an owner option, default false)")
        if self.consequence_class is not None and self.consequence_class not in ONR_CONSEQUENCE_CLASSES:
            raise ValueError(f"design.consequence_class = {self.consequence_class!r} is not one of "
                             f"{', '.join(map(repr, ONR_CONSEQUENCE_CLASSES))} (ONR 24810)")

    def kit_elongation_m(self, fence: str) -> float | None:
        """The stated maximum elongation at MEL [m] of ``fence``: its entry of the table, or the one number given
        for every fence; None when not stated.

        Parameters
        ----------
        fence : str
            Name of the candidate fence.

        Returns
        -------
        float or None
            Maximum elongation in the MEL test [m].
        """
        if isinstance(self.elongation_m, dict):
            return self.elongation_m.get(fence)
        return float(self.elongation_m)

    def rules(self) -> pd.DataFrame:
        """Every rule of the requirement, with where it comes from: the standard (and its source), an owner
        option (on or off), or a riskrf default to confirm.

        Returns
        -------
        pandas.DataFrame
            Columns ``rule``, ``source`` ("<basis>", "owner option, not in <basis>", "riskrf default, not checked
            against <basis>"), ``in force`` ("yes"/"no") and ``reference``.
        """
        b = self.basis
        rows = []

        def add(rule, source, on, ref):
            rows.append({"rule": rule, "source": source, "in force": "yes" if on else "no", "reference": ref})

        if b == "UNI 11211-4":
            f = self.factors
            add(f"E_d = 1/2 (Vol rho gamma_VolF gamma_gamma)(v{f['velocity_percentile']:g} gamma_Tr gamma_Dp)^2 "
                f"<= MEL / gamma_E", b, True, "RocFall UNI 11211 design page quoting UNI 11211-4:2012 [V]; gamma_E "
                f"= {f['gamma_E']:g} {CONFIRM}")
            add("net height >= h_d + f_min, f_min = max(0.5 m, block radius), h_d = h95 gamma_Tr gamma_Dp", b, True,
                f"free border [V]; h_d factors {CONFIRM}")
            add(f"elongation: D_MEL x gamma_d ({f['gamma_d']:g}) <= clearance D_A", b, True,
                f"check D_A >= D_d [V]; gamma_d {CONFIRM}")
        elif b == "ONR 24810":
            add("design block: the block-size fractile of the event-frequency class (EF4 V98, EF3 V97, EF2 V96, "
                "EF1 V95)", b, True, "Trumer Schutzbauten, ONR 24810 'Design Block' table [V]")
            add("E_d = 1/2 (m gamma_m)(v gamma_v)^2 <= MEL (rare design block) or <= SEL = MEL/3 (frequent: "
                f"the design block arrives at least once in {self.frequent_T_years:g} years)", b, True,
                f"MEL/SEL by design event: {CONFIRM} (riskrf reads 'frequent' as more often than 1/"
                f"{self.frequent_T_years:g} yr, the EF1/EF2 boundary 0.03/yr)")
            cc = self.consequence_class or "not stated"
            add(f"partial factors gamma_m, gamma_v of consequence class {cc}", b, True,
                "stated in the site file" if not self.unverified else
                f"riskrf default 1.0 {CONFIRM}: the factor table by consequence class was not read")
            add("net height >= h95 + block radius + free board", "riskrf default, not checked against ONR 24810",
                True, CONFIRM)
            add("distance to the road >= max(1.2 D_MEL, D_MEL + 1 m)", b, True,
                "Trumer Schutzbauten, ONR 24810 'Constructive Rules' [V]")
        else:
            add(f"{self.design_T:g}-year impact energy at the line <= MEL", "return period (an owner basis, not a "
                "standard)", True, "riskrf")
            add("net height >= h95 + block radius + free board", "return period (an owner basis, not a standard)",
                True, "riskrf")
        add(f"{self.frequent_T_years:g}-year impact energy <= SEL = MEL/3 (frequent_events_sel)",
            f"owner option, not in {b}", self.frequent_events_sel,
            "off by default" if not self.frequent_events_sel else "stated in the site file")
        add(f"residual-height category {self.residual_category} required after a MEL impact (residual_category)",
            f"owner option, not in {b}", True, "EAD 340059 categories A >= 50 %, B 30-50 %, C < 30 % [R]")
        return pd.DataFrame(rows)

    @property
    def unverified(self) -> list:
        """Factors in force that are riskrf defaults of [R] status and were not stated by the site file."""
        recalled = {"UNI 11211-4": ("gamma_E", "gamma_d"), "ONR 24810": ("gamma_m", "gamma_v"),
                    "return period": ()}[self.basis]
        return [k for k in recalled if k not in self.stated]

    def text(self) -> str:
        """The basis in one sentence, for every output.

        Returns
        -------
        str
            One sentence naming the basis, its factors and which of them are riskrf defaults.
        """
        f = ", ".join(f"{k} {v:g}" for k, v in self.factors.items())
        s = f"design basis {self.basis} ({f}); {FACTOR_SOURCES[self.basis]}"
        if self.basis == "ONR 24810":
            cc = self.consequence_class
            s += (f"; consequence class {cc} ({ONR_CONSEQUENCE_CLASSES[cc]})" if cc else
                  "; consequence class NOT STATED (design.consequence_class: CC1, CC2 or CC3)")
        if self.unverified:
            s += (f"; NOT STATED in the site file, riskrf defaults in force: {', '.join(self.unverified)} "
                  f"(confirm against the standard before signing) {CONFIRM}")
        r = self.rules()
        std = r[r["source"] == self.basis]["rule"].tolist()
        own = r[r["source"].str.startswith("owner option")]
        s += (f". Rules from {self.basis}: " + "; ".join(std) if std else "")
        s += ". Owner options (not in " + self.basis + "): " + "; ".join(
            f"{row['rule']} [{'ON' if row['in force'] == 'yes' else 'off'}]" for _, row in own.iterrows())
        other = r[r["source"].str.startswith("riskrf default")]["rule"].tolist()
        if other:
            s += f". riskrf defaults not checked against {self.basis}: " + "; ".join(other) + f" {CONFIRM}"
        return s


#: Fields of the ``[design]`` table that a :class:`DesignBasis` takes as they are (when given); the basis and its
#: factors are read apart, and ``positions_x_m`` and ``position_blocks`` belong to the position search
#: (:mod:`riskrf.app.site_design`).
_BASIS_FIELDS = ("frequent_T_years", "frequent_events_sel", "residual_category", "consequence_class", "clearance_m",
                "mel_classes_kj", "elongation_m")


def design_basis_from_site(design=None, *, design_T: float = 100.0, free_board_m: float = 0.5) -> DesignBasis:
    """A :class:`DesignBasis` from a site file's ``[design]`` table.

    Parameters
    ----------
    design : DesignTable, dict or None
        The checked ``[design]`` table (``site.design``, a :data:`riskrf.core.file_schemas.SITE_RECORDS` record),
        or the table as written (a dict of its fields, read into that record: fields left out take their
        defaults), or None (all defaults).  ``positions_x_m`` and ``position_blocks`` are not the basis's and
        are left to the position search.
    design_T : float, optional
        Design return period [years] (from ``hazard.design_period_years``).
    free_board_m : float, optional
        Least free border above the design height [m].

    Returns
    -------
    DesignBasis
        The stated basis with its partial factors.

    Raises
    ------
    TypeError
        For a dict key the ``[design]`` table does not declare.
    ValueError
        For an unknown basis, a factor that is not one of the basis, or a value out of range.
    """
    d = as_record(DESIGN, design, error=TypeError)
    basis = d.basis
    check_basis(basis)
    factor_names = set(DEFAULT_FACTORS[basis])
    all_factors = set().union(*DEFAULT_FACTORS.values())
    factors = {}
    for k in [f.name for f in DESIGN.fields if f.name in all_factors]:       # declaration order
        v = getattr(d, k)
        if v is None:
            continue
        if k not in factor_names:
            raise ValueError(f"design.{k} is not a factor of the basis {basis!r} (its factors: "
                             f"{', '.join(sorted(factor_names))})")
        factors[k] = v
    keep = {k: getattr(d, k) for k in _BASIS_FIELDS if getattr(d, k) is not None}
    if d.mel_classes_kj is not None:
        keep.update(mel_classes_kj=tuple(d.mel_classes_kj))
    if d.elongation_m is not None:
        keep.update(elongation_m=check_elongation(d.elongation_m))
    return DesignBasis(basis=basis, factors=factors, stated=tuple(factors), design_T=float(design_T),
                       free_board_m=free_board_m, **keep)


__all__ = ["BASES", "CONFIRM", "DEFAULT_BASIS", "DEFAULT_FACTORS", "DesignBasis", "OWNER_OPTIONS",
           "ONR_CONSEQUENCE_CLASSES", "ONR_CONSEQUENCE_FACTORS", "ONR_EVENT_FREQUENCY_CLASSES", "check_elongation",
           "onr24810_event_frequency_class", "MEL_PRODUCT_CLASSES_KJ", "RESIDUAL_CATEGORIES", "check_basis",
           "design_basis_from_site", "onr24810_energy", "onr24810_min_distance_m", "permitted_elongation_m",
           "required_distance_m", "required_product_class", "residual_height_category", "round_up", "uni11211_energy"]
