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

:func:`design_requirement` gives the required MEL (and the smallest product class that meets it), the required
net height, the elongation the road clearance permits and the checks of candidate fences;
:func:`position_search` repeats the requirement along the profile from one simulation with collectors at
several x.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from ..core.format import sig
from ..core.validation import DEFAULT_DENSITY_KG_M3
from ..core.units import SEL_PER_MEL, kinetic_energy_kj

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


def design_basis_from_site(cfg: dict | None, *, design_T: float = 100.0, free_board_m: float = 0.5) -> DesignBasis:
    """A :class:`DesignBasis` from a site file's ``[design]`` table (already checked for unknown keys).

    Parameters
    ----------
    cfg : dict or None
        The site file's ``[design]`` table (None: all defaults).
    design_T : float, optional
        Design return period [years] (from ``hazard.design_period_years``).
    free_board_m : float, optional
        Least free border above the design height [m].

    Returns
    -------
    DesignBasis
        The stated basis with its partial factors.
    """
    cfg = dict(cfg or {})
    basis = cfg.pop("basis", DEFAULT_BASIS)
    check_basis(basis)
    factor_names = set(DEFAULT_FACTORS[basis])
    all_factors = set().union(*DEFAULT_FACTORS.values())
    factors = {}
    for k in list(cfg):
        if k in all_factors:
            v = cfg.pop(k)
            if v is None:
                continue
            if k not in factor_names:
                raise ValueError(f"design.{k} is not a factor of the basis {basis!r} (its factors: "
                                 f"{', '.join(sorted(factor_names))})")
            factors[k] = v
    keep = {k: v for k, v in cfg.items() if v is not None}
    if "mel_classes_kj" in keep:
        keep["mel_classes_kj"] = tuple(keep["mel_classes_kj"])
    if "elongation_m" in keep:
        keep["elongation_m"] = check_elongation(keep["elongation_m"])
    keep.setdefault("free_board_m", free_board_m)
    return DesignBasis(basis=basis, factors=factors, stated=tuple(factors), design_T=float(design_T), **keep)


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
    (drawn by :func:`riskrf.report.design_figures.plot_position_search`; the science draws nothing).
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
        :func:`riskrf.report.design_figures.plot_position_search`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from ..core.figures import draw
        return draw("position_search", self, ax=ax)

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


__all__ = ["BASES", "CONFIRM", "DEFAULT_BASIS", "DEFAULT_FACTORS", "DesignBasis", "OWNER_OPTIONS",
           "ONR_CONSEQUENCE_CLASSES", "ONR_CONSEQUENCE_FACTORS", "ONR_EVENT_FREQUENCY_CLASSES", "check_elongation",
           "onr24810_event_frequency_class", "DesignRequirement", "MEL_PRODUCT_CLASSES_KJ",
           "PositionSearch", "RESIDUAL_CATEGORIES", "barrier_shares", "check_basis", "default_positions",
           "design_basis_from_site", "design_requirement", "frequent_energy", "onr24810_energy", "onr24810_min_distance_m",
           "permitted_elongation_m", "position_search", "required_distance_m",
           "required_product_class", "residual_height_category", "round_up", "uni11211_energy"]
