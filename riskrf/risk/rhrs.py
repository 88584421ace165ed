"""Rockfall Hazard Rating System (RHRS) category scores (Pierson et al. 1990; Pierson 1991, FHWA-OR-GI-92-05;
Pierson & Van Vickle 1993, FHWA-SA-93-057).

The RHRS screens the rock cuts of a corridor: every category scores on the exponential scale
3, 9, 27, 81 (``score = 3**x``), and the section's rating is the sum of the category scores.
The continuous categories have published formulas for ``x`` (in the manual's US units; this
module takes SI inputs and converts them exactly, 1 ft = 0.3048 m, 1 yd3 = 0.764554857984 m3):

====================================  ==================================  ========================
category                              x                                   3 / 9 / 27 / 81 points at
====================================  ==================================  ========================
slope height                          H [ft] / 25                         25 / 50 / 75 / 100 ft
average vehicle risk (AVR)            AVR [%] / 25                        25 / 50 / 75 / 100 %
percent decision sight distance       (120 - %DSD) / 20                   100 / 80 / 60 / 40 %
roadway width (incl. paved shoulders) (52 - W [ft]) / 8                   44 / 36 / 28 / 20 ft
block size                            size [ft]                           1 / 2 / 3 / 4 ft
volume per event                      volume [yd3] / 3                    3 / 6 / 9 / 12 yd3
====================================  ==================================  ========================

    AVR [%] = ADT [vehicles/day] x slope length [mi] / 24 [h/day] / posted speed [mph] x 100

(the length/speed ratio carries no units, so slope length in km over speed in km/h gives the same
number).  %DSD = actual sight distance / decision sight distance x 100.

The descriptive categories (ditch effectiveness, geologic character: structural condition and rock
friction [case 1] or structural condition and difference in erosion rates [case 2], climate and
presence of water, rockfall history) score 3, 9, 27 or 81 for the four published classes
(:data:`CLASSES`); a rater may place a slope between two classes with a fractional level
``x`` in [1, 4] (score 3**x), as the exponential scale allows.

Scores are not capped (a 130-ft slope scores 3**5.2 = 302); :func:`rate` reports each category
score and the total.  The formulas and class points are those listed in
shared/research/domain-methods.md section 4.3 [R] (Pierson & Van Vickle 1993 summary sheet): [R]
because no page of the manual itself could be read to cite (the copies of FHWA-SA-93-057 and
FHWA-OR-GI-92-05 found in the reference library hold only their title pages, abstracts, preface and
contents; see the README's RHRS section).  The 3 / 9 / 27 / 81-point benchmarks of every category
are checked against the SI criteria printed by Taherynia et al. (2014), Table 9.

Checked against a published rated slope: Taherynia, Mohammadi & Ajalloeian (2014), J. Geol. Res.
2014:763598, Table 10. With ``cap_points=100`` and scores rounded to integers, as that paper prints
them, all ten category ratings are reproduced (tests/test_rhrs_published.py;
tests/data/taherynia2014/README.md).

Variants: :func:`rate` implements the FHWA RHRS only (``variant="fhwa"``, :data:`VARIANTS`).  The ODOT and the
Colorado-modified RHRS (Santi et al. 2009; Russell et al. 2008, CDOT-2008-7) change and add categories; their
published tables were searched for and not found in any copy in reach, so they are refused with what is missing
(:data:`UNAVAILABLE_VARIANTS`) rather than guessed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import pandas as pd

from ..core.units import HOURS_PER_DAY, M_PER_KM
from ..core.validation import RiskrfError

FT_M = 0.3048                       # exact (international foot)
MILE_M = 1609.344                   # exact
YD3_M3 = 0.764554857984             # exact (0.9144 m)^3

#: The four published classes of each descriptive category, in increasing order of hazard (3, 9, 27, 81 points).
CLASSES = {
    "ditch_effectiveness": ("good catchment", "moderate catchment", "limited catchment", "no catchment"),
    "structural_condition_case1": ("discontinuous joints, favorable orientation",
                                   "discontinuous joints, random orientation",
                                   "discontinuous joints, adverse orientation",
                                   "continuous joints, adverse orientation"),
    "rock_friction": ("rough, irregular", "undulating", "planar", "clay infilling or slickensided"),
    "structural_condition_case2": ("few differential erosion features", "occasional erosion features",
                                   "many erosion features", "major erosion features"),
    "difference_in_erosion_rates": ("small difference", "moderate difference", "large difference",
                                    "extreme difference"),
    "climate_and_water": ("low to moderate precipitation; no freezing periods; no water on slope",
                          "moderate precipitation or short freezing periods or intermittent water on slope",
                          "high precipitation or long freezing periods or continual water on slope",
                          "high precipitation and long freezing periods or continual water on slope and long "
                          "freezing periods"),
    "rockfall_history": ("few falls", "occasional falls", "many falls", "constant falls"),
}
#: Rating systems :func:`rate` implements, by the name a corridor file gives (``corridor.rhrs_variant``).
VARIANTS = {"fhwa": "FHWA RHRS (Pierson & Van Vickle 1993, FHWA-SA-93-057; summary sheet, exponential 3-81 scores)"}
#: Agency variants that are known but not implemented, with what is missing (said when a corridor file or
#: :func:`rate` asks for one).  They stay refused until their published tables can be read and checked; the
#: documents searched for, and what the project's reference library returned, are listed in
#: docs/validation/corridor-programme.md.
UNAVAILABLE_VARIANTS = {
    "odot": "not implemented: ODOT's own rating tables (the Oregon DOT revisions after FHWA-OR-GI-92-05, i.e. "
            "its rockfall and unstable-slope rating forms) were not found in any copy in reach: the stored "
            "copies of Pierson (1991) FHWA-OR-GI-92-05 and Pierson & Van Vickle (1993) FHWA-SA-93-057 hold only "
            "their first pages, and ODOT's Unstable Slopes page publishes no table; no ODOT category table or "
            "ODOT-rated slope could be read, so nothing is encoded rather than guessed; rate with 'fhwa'",
    "colorado": "not implemented: the Colorado-modified RHRS category table and a slope rated with it (Santi, "
                "Russell, Higgins & Spriet 2009, Eng. Geol. 104: 55-65; Russell, Santi & Higgins 2008, "
                "CDOT-2008-7) were not found in any copy in reach: the stored copies of both hold only the title "
                "page and abstract, and the 2007 GSA abstract names factors (launching features, rockfall "
                "frequency, discontinuity sets, ...) but no criteria or points; nothing is encoded rather than "
                "guessed; rate with 'fhwa'",
}


class RHRSError(RiskrfError, ValueError):
    """An RHRS input is invalid or missing, or the rating system asked for is not implemented.  ``missing``
    lists the attributes (names of :data:`RATE_FIELDS`) that a rating needed and did not get."""

    def __init__(self, message: str, missing: tuple = ()):
        super().__init__(message)
        self.missing = tuple(missing)


def variant_problem(variant) -> str | None:
    """``None`` when :func:`rate` implements ``variant``, else what is wrong, as the end of an error message:
    ``"must be one of ['fhwa'] (<why the variant asked for is not implemented>)"``.

    Parameters
    ----------
    variant : object
        The rating system asked for (a key of :data:`VARIANTS` when implemented).

    Returns
    -------
    str or None
        None when implemented, else the end of an error message saying why not.
    """
    if isinstance(variant, str) and variant in VARIANTS:
        return None
    why = UNAVAILABLE_VARIANTS.get(variant) if isinstance(variant, str) else None
    return (f"must be one of {sorted(VARIANTS)} ("
            + (why if why else f"known but not implemented: {sorted(UNAVAILABLE_VARIANTS)}") + ")")


#: Short names accepted for the classes: the first word of a class when no other class of the category shares it
#: (e.g. "good", "limited", "occasional").
def _short_names(names):
    first = [n.replace(",", " ").replace(";", " ").split()[0].lower() for n in names]
    return {w: i + 1 for i, w in enumerate(first) if first.count(w) == 1}


_SHORT = {cat: _short_names(names) for cat, names in CLASSES.items()}


def _finite(value, name: str, *, lo: float | None = None, lo_open: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError(f"{name} must be a number; got {value!r}")
    v = float(value)
    if not math.isfinite(v) or (lo is not None and (v < lo or (lo_open and v == lo))):
        bound = "" if lo is None else f" {'>' if lo_open else '>='} {lo:g}"
        raise RHRSError(f"{name} must be a finite number{bound}; got {value!r}")
    return v


def score(x: float) -> float:
    """Exponential RHRS score 3**x (x = 1, 2, 3, 4 give 3, 9, 27, 81 points).

    Parameters
    ----------
    x : float
        Category level x [-].

    Returns
    -------
    float
        Score 3**x [points].

    Raises
    ------
    RHRSError
        When the input is not a finite number in range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    return 3.0 ** _finite(x, "x")


def slope_height_x(height_m: float) -> float:
    """x = H [ft] / 25 for the vertical slope height H (25 ft -> 3 points, 100 ft -> 81).

    Parameters
    ----------
    height_m : float
        Vertical slope height H [m], >= 0.

    Returns
    -------
    x : float
        Category level x [-] (score 3**x).

    Raises
    ------
    RHRSError
        When the input is not a finite number in range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    return _finite(height_m, "slope_height_m", lo=0) / FT_M / 25.0


def average_vehicle_risk(adt_vehicles_per_day: float, slope_length_m: float, speed_kmh: float) -> float:
    """AVR [%] = ADT x slope length / 24 / posted speed x 100: the share of time a vehicle is below the slope
    (may exceed 100 %: more than one vehicle on average).  SI inputs: the length/speed ratio is unit-free,
    so L [km] / V [km/h] equals L [mi] / V [mph].

    Parameters
    ----------
    adt_vehicles_per_day : float
        Average daily traffic ADT [vehicles/day], >= 0.
    slope_length_m : float
        Length of road below the slope [m], > 0.
    speed_kmh : float
        Posted speed [km/h], > 0.

    Returns
    -------
    float
        AVR [%].

    Raises
    ------
    RHRSError
        When an input is out of range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    adt = _finite(adt_vehicles_per_day, "adt_vehicles_per_day", lo=0)
    length_km = _finite(slope_length_m, "slope_length_m", lo=0, lo_open=True) / M_PER_KM
    v = _finite(speed_kmh, "speed_kmh", lo=0, lo_open=True)
    return adt * length_km / HOURS_PER_DAY / v * 100.0


def avr_x(avr_percent: float) -> float:
    """x = AVR [%] / 25 (25 % -> 3 points, 100 % -> 81).

    Parameters
    ----------
    avr_percent : float
        Average vehicle risk AVR [%], >= 0.

    Returns
    -------
    x : float
        Category level x [-] (score 3**x).

    Raises
    ------
    RHRSError
        When the input is not a finite number in range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    return _finite(avr_percent, "avr_percent", lo=0) / 25.0


def percent_decision_sight_distance(sight_distance_m: float, decision_sight_distance_m: float) -> float:
    """%DSD = actual sight distance / decision sight distance x 100.

    Parameters
    ----------
    sight_distance_m : float
        Actual sight distance [m], >= 0.
    decision_sight_distance_m : float
        Decision sight distance for the speed [m], > 0.

    Returns
    -------
    float
        %DSD [%].

    Raises
    ------
    RHRSError
        When an input is out of range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    return _finite(sight_distance_m, "sight_distance_m", lo=0) / _finite(
        decision_sight_distance_m, "decision_sight_distance_m", lo=0, lo_open=True) * 100.0


def dsd_x(percent_dsd: float) -> float:
    """x = (120 - %DSD) / 20 (100 % -> 3 points, 40 % -> 81).

    Parameters
    ----------
    percent_dsd : float
        Percent decision sight distance %DSD [%], >= 0.

    Returns
    -------
    x : float
        Category level x [-] (score 3**x).

    Raises
    ------
    RHRSError
        When the input is not a finite number in range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    return (120.0 - _finite(percent_dsd, "percent_dsd", lo=0)) / 20.0


def roadway_width_x(width_m: float) -> float:
    """x = (52 - W [ft]) / 8 for the roadway width W including paved shoulders (44 ft -> 3 points, 20 ft -> 81).

    Parameters
    ----------
    width_m : float
        Roadway width W including paved shoulders [m], > 0.

    Returns
    -------
    x : float
        Category level x [-] (score 3**x).

    Raises
    ------
    RHRSError
        When the input is not a finite number in range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    return (52.0 - _finite(width_m, "roadway_width_m", lo=0, lo_open=True) / FT_M) / 8.0


def block_size_x(size_m: float) -> float:
    """x = block size [ft] (1 ft -> 3 points, 4 ft -> 81).

    Parameters
    ----------
    size_m : float
        Block size [m], > 0.

    Returns
    -------
    x : float
        Category level x [-] (score 3**x).

    Raises
    ------
    RHRSError
        When the input is not a finite number in range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    return _finite(size_m, "block_size_m", lo=0, lo_open=True) / FT_M


def volume_x(volume_m3: float) -> float:
    """x = volume per event [yd3] / 3 (3 yd3 -> 3 points, 12 yd3 -> 81).

    Parameters
    ----------
    volume_m3 : float
        Volume per event [m3], > 0.

    Returns
    -------
    x : float
        Category level x [-] (score 3**x).

    Raises
    ------
    RHRSError
        When the input is not a finite number in range.

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    return _finite(volume_m3, "volume_m3", lo=0, lo_open=True) / YD3_M3 / 3.0


def class_x(category: str, value) -> float:
    """Level x of a descriptive category: a class name of :data:`CLASSES` (or its first word), or a number in
    [1, 4] (fractional allowed: between two classes).

    Parameters
    ----------
    category : str
        A descriptive category, a key of :data:`CLASSES`.
    value : str or float
        A class name of the category (or its first word), or a level in [1, 4] [-].

    Returns
    -------
    float
        Category level x [-] (score 3**x).

    Raises
    ------
    RHRSError
        When the category or class is unknown or the level lies outside [1, 4].

    References
    ----------
    Pierson, L. A. and Van Vickle, R. (1993). Rockfall Hazard Rating System: participant's manual.
    FHWA-SA-93-057, Federal Highway Administration.
    """
    if category not in CLASSES:
        raise RHRSError(f"unknown RHRS category {category!r}; categories: {sorted(CLASSES)}")
    if isinstance(value, str):
        key = value.strip().lower()
        for i, name in enumerate(CLASSES[category]):
            if key == name.lower():
                return float(i + 1)
        if key in _SHORT[category]:
            return float(_SHORT[category][key])
        raise RHRSError(f"{category} = {value!r} is not one of {list(CLASSES[category])} "
                         f"(or {sorted(_SHORT[category])})")
    x = _finite(value, category)
    if not 1.0 <= x <= 4.0:
        raise RHRSError(f"{category} = {value!r}: a class level must lie in [1, 4] (3 to 81 points)")
    return x


@dataclass(frozen=True)
class RHRSRating:
    """RHRS rating of one slope: level x and score 3**x of each category, and the total.

    ``inputs`` keeps what was given (SI units) and derived quantities (AVR %, %DSD); ``variant`` names the
    rating system (a key of :data:`VARIANTS`).
    """

    x: dict
    inputs: dict = field(default_factory=dict)
    cap_points: float | None = None
    variant: str = "fhwa"

    @property
    def scores(self) -> dict:
        """Score of each category, 3**x, limited to ``cap_points`` when a cap was chosen."""
        cap = math.inf if self.cap_points is None else self.cap_points
        return {k: min(3.0 ** v, cap) for k, v in self.x.items()}

    @property
    def total(self) -> float:
        """The RHRS rating: sum of the category scores."""
        return float(sum(self.scores.values()))

    @property
    def integer_scores(self) -> dict:
        """Score of each category as a rating sheet prints it: the nearest whole point (halves up), e.g. 5.67 -> 6
        (Taherynia et al. 2014, Table 10 prints the roadway score 5.67 as 6 and the block score 36.76 as 37)."""
        return {k: int(math.floor(v + 0.5)) for k, v in self.scores.items()}

    @property
    def integer_total(self) -> int:
        """The rating as a sheet prints it: the sum of the whole-point category scores (453 for Table 10's rows)."""
        return int(sum(self.integer_scores.values()))

    def sheet(self) -> pd.DataFrame:
        """The rating sheet: one row per category with the rated value (SI, as given or derived), level x, score
        and the whole-point score; last row the totals.

        Returns
        -------
        pandas.DataFrame
            Columns ``category``, ``rated_value`` (SI units), ``x`` [-], ``score`` [points], ``points`` (whole points).
        """
        return pd.DataFrame(self.sheet_rows())

    def sheet_rows(self) -> list:
        """The rows of :meth:`sheet` as plain dicts (category, rated_value, x, score, points).

        Returns
        -------
        list of dict
            One dict per category (keys ``category``, ``rated_value``, ``x``, ``score`` [points], ``points``), then the
            totals.
        """
        value_of = {"slope_height": "slope_height_m", "ditch_effectiveness": "ditch_effectiveness",
                    "average_vehicle_risk": "avr_percent", "percent_decision_sight_distance": "percent_dsd",
                    "roadway_width": "roadway_width_m", "structural_condition": ("structural_condition_case1",
                                                                                 "structural_condition_case2"),
                    "rock_friction": "rock_friction", "difference_in_erosion_rates": "difference_in_erosion_rates",
                    "block_size_or_volume": ("block_size_m", "volume_m3"), "climate_and_water": "climate_and_water",
                    "rockfall_history": "rockfall_history"}
        rows, scores, points = [], self.scores, self.integer_scores
        for cat, x in self.x.items():
            keys = value_of.get(cat, cat)
            keys = keys if isinstance(keys, tuple) else (keys,)
            given = [f"{k} = {self.inputs[k]:.4g}" if isinstance(self.inputs[k], float) else
                     f"{k} = {self.inputs[k]}" for k in keys if k in self.inputs]
            rows.append({"category": cat, "rated_value": "; ".join(given), "x": x, "score": scores[cat],
                         "points": points[cat]})
        rows.append({"category": "total", "rated_value": "", "x": float("nan"), "score": self.total,
                     "points": self.integer_total})
        return rows

    def summary(self) -> pd.DataFrame:
        """One row per category: x, score (points); last row the total.

        Returns
        -------
        pandas.DataFrame
            Columns ``category``, ``x`` [-] and ``score`` [points]; last row the total.
        """
        df = pd.DataFrame({"category": list(self.x), "x": list(self.x.values()),
                           "score": list(self.scores.values())})
        return pd.concat([df, pd.DataFrame({"category": ["total"], "x": [float("nan")], "score": [self.total]})],
                         ignore_index=True)


#: Attribute names accepted by :func:`rate` (SI units); the geologic character is case 1 (structural condition +
#: rock friction) or case 2 (structural condition + difference in erosion rates).
RATE_FIELDS = ("slope_height_m", "ditch_effectiveness", "adt_vehicles_per_day", "slope_length_m", "speed_kmh",
               "avr_percent", "sight_distance_m", "decision_sight_distance_m", "percent_dsd", "roadway_width_m",
               "structural_condition_case1", "rock_friction", "structural_condition_case2",
               "difference_in_erosion_rates", "block_size_m", "volume_m3", "climate_and_water", "rockfall_history")


def rate(*, variant: str = "fhwa", cap_points: float | None = None, **attrs) -> RHRSRating:
    """Rate one slope from its attributes (names in :data:`RATE_FIELDS`, SI units).

    Parameters
    ----------
    variant : str
        The rating system, a key of :data:`VARIANTS`: only ``"fhwa"`` (Pierson & Van Vickle 1993).  ``"odot"``
        and ``"colorado"`` are refused with what is missing (:data:`UNAVAILABLE_VARIANTS`).
    cap_points : float, optional
        Upper limit of each category score [points], >= 81 (a user's choice, e.g. 100, so that one continuous
        category far beyond the 81-point class cannot dominate the total); default uncapped.
    **attrs
        slope_height_m [m]; ditch_effectiveness (class); the AVR (``avr_percent`` [%], or
        ``adt_vehicles_per_day`` [vehicles/day], ``slope_length_m`` [m] and ``speed_kmh`` [km/h]); the %DSD
        (``percent_dsd`` [%], or ``sight_distance_m`` and ``decision_sight_distance_m`` [m]);
        roadway_width_m [m]; the geologic character (case 1 or case 2 pair, classes); block_size_m [m] or
        volume_m3 [m3] (the larger score counts when both are given, as the manual rates the greater of the
        two); climate_and_water and rockfall_history (classes).  A class is a name of :data:`CLASSES` (or its
        first word) or a level x in [1, 4].

    Returns
    -------
    RHRSRating
        Level x and score 3**x of every category, the total, whole points and the rating sheet.

    Raises
    ------
    RHRSError
        An unknown or unimplemented variant, an unknown attribute, a missing one (listed in ``.missing``) or a
        value out of range.

    References
    ----------
    Pierson, L.A. & Van Vickle, R. (1993). Rockfall Hazard Rating System - Participant's Manual. FHWA-SA-93-057
    (summary sheet, as listed in shared/research/domain-methods.md section 4.3 [R]).
    """
    why = variant_problem(variant)
    if why:
        raise RHRSError(f"RHRS variant = {variant!r} {why}")
    if cap_points is not None:
        cap_points = _finite(cap_points, "cap_points", lo=81)
    unknown = sorted(set(attrs) - set(RATE_FIELDS))
    if unknown:
        raise RHRSError(f"unknown RHRS attribute(s) {unknown}; allowed: {list(RATE_FIELDS)}")
    a = {k: v for k, v in attrs.items() if v is not None and not (isinstance(v, float) and math.isnan(v))}

    def need(*names):
        missing = [n for n in names if n not in a]
        if missing:
            raise RHRSError(f"{variant.upper()} RHRS rating needs {', '.join(missing)}", missing=missing)

    x, inputs = {}, dict(a)
    need("slope_height_m")
    x["slope_height"] = slope_height_x(a["slope_height_m"])
    need("ditch_effectiveness")
    x["ditch_effectiveness"] = class_x("ditch_effectiveness", a["ditch_effectiveness"])
    if "avr_percent" in a:
        avr = _finite(a["avr_percent"], "avr_percent", lo=0)
    else:
        need("adt_vehicles_per_day", "slope_length_m", "speed_kmh")
        avr = average_vehicle_risk(a["adt_vehicles_per_day"], a["slope_length_m"], a["speed_kmh"])
    inputs["avr_percent"] = avr
    x["average_vehicle_risk"] = avr_x(avr)
    if "percent_dsd" in a:
        dsd = _finite(a["percent_dsd"], "percent_dsd", lo=0)
    else:
        need("sight_distance_m", "decision_sight_distance_m")
        dsd = percent_decision_sight_distance(a["sight_distance_m"], a["decision_sight_distance_m"])
    inputs["percent_dsd"] = dsd
    x["percent_decision_sight_distance"] = dsd_x(dsd)
    need("roadway_width_m")
    x["roadway_width"] = roadway_width_x(a["roadway_width_m"])
    case1 = "structural_condition_case1" in a or "rock_friction" in a
    case2 = "structural_condition_case2" in a or "difference_in_erosion_rates" in a
    if case1 == case2:
        raise RHRSError("RHRS geologic character: give case 1 (structural_condition_case1 and rock_friction) or "
                         "case 2 (structural_condition_case2 and difference_in_erosion_rates), not both or neither")
    if case1:
        need("structural_condition_case1", "rock_friction")
        x["structural_condition"] = class_x("structural_condition_case1", a["structural_condition_case1"])
        x["rock_friction"] = class_x("rock_friction", a["rock_friction"])
    else:
        need("structural_condition_case2", "difference_in_erosion_rates")
        x["structural_condition"] = class_x("structural_condition_case2", a["structural_condition_case2"])
        x["difference_in_erosion_rates"] = class_x("difference_in_erosion_rates", a["difference_in_erosion_rates"])
    if "block_size_m" not in a and "volume_m3" not in a:
        raise RHRSError(f"{variant.upper()} RHRS rating needs block_size_m or volume_m3",
                        missing=("block_size_m or volume_m3",))
    xs = [f(a[k]) for k, f in (("block_size_m", block_size_x), ("volume_m3", volume_x)) if k in a]
    x["block_size_or_volume"] = max(xs)
    need("climate_and_water", "rockfall_history")
    x["climate_and_water"] = class_x("climate_and_water", a["climate_and_water"])
    x["rockfall_history"] = class_x("rockfall_history", a["rockfall_history"])
    return RHRSRating(x=x, inputs=inputs, cap_points=cap_points, variant=variant)
