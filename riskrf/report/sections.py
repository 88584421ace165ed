"""The sections of an assessment report, in one place for both formats (report.html and report.pdf).

:func:`report_sections` lists, for one assessment, the sections both writers render, in order, with their titles,
the tables each must carry (:attr:`Section.tables`, by caption) and its figures.  The HTML writer
(:mod:`riskrf.report.html`) and the PDF writer (:mod:`riskrf.report.pdf`) open every section from this list and
each has one body function per :attr:`Section.key`, so the two documents cannot drift apart: a section added here
appears in both, in the same place and under the same title (a test compares the HTML headings with the PDF
outline).  The tables the checking engineer signs (road-user risk, Bunce per lane, the design checks of every
option, the catchment widths beside the Modified Ritchie Criterion, the recommendation) are built here as
DataFrames, once, and each writer only formats them.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from .format import probability

#: Rows of the simulation's summary that measure the software, not the slope: kept out of the engineering tables.
SOFTWARE_METRICS = ("run time [s]", "impacts per second", "blocks per second")

# ---- captions shared by both writers (a test looks for each in both documents) -------------------------------------
T_CANDIDATES = "Checks of the candidate fences against the design basis"
T_POSITIONS = "Required MEL and net height by barrier position"
T_CATCHMENT_WIDTHS = "Catchment width needed for each retention"
T_RITCHIE = "Modified Ritchie Criterion beside the re-simulated catchment"
T_BUNCE = "Bunce et al. (1997) per lane: probability that a vehicle is hit"
T_RISK = "Risk to road users by option"
T_DESIGN_CHECKS = "Design checks of every option"
T_RANKING = "Mitigation options ranked by expected total cost"
T_BREAK_EVEN = "Break-even values of single inputs"
SLOPE_VERTEX_COLUMNS = ("vertex", "x [m]", "z [m]", "dip of the segment to the next vertex [°]",
                        "material of that segment")
SLOPE_MATERIAL_COLUMNS = ("material", "normal restitution e_N", "tangential: e_T or friction", "roughness [m]",
                          "ground motion", "ground friction φ_g [°]", "source or calibration")
RITCHIE_CAVEAT = ("The Modified Ritchie Criterion is a rule for a cut face above a flat catchment; on the ODOT test "
                  "cut the re-simulation retains fewer blocks than the rule implies (validation: design standards "
                  "and ditch charts).  Where the ground beyond the toe is a talus apron or a bench, the rule does "
                  "not apply and the re-simulated widths govern.")
F_FN = "F-N curves of the options with the societal-risk criterion"
F_OPTIONS = "Every option's geometry on the slope profile, and the barrier the design basis requires (dashed)"
F_CATCHMENT = "Catchment retention against width from the toe"
F_TORNADO = "Tornado: the lowest cost at central values as each input moves over its stated range"


@dataclass(frozen=True)
class Section:
    """One section of the report.

    Attributes
    ----------
    key : str
        Name of the body function of each writer (``riskrf.report.html.BODIES[key]``,
        ``riskrf.report.pdf.BODIES[key]``).
    title : str
        Heading, identical in both formats (numbered by the writer: "3. title" in HTML, "3  title" in the PDF).
    appendix : str or None
        Appendix letter ("A", "B", ...) for an appendix, None for a numbered section.
    tables : tuple of str
        Captions of the tables both formats must carry in this section.
    figures : tuple of (str, str)
        (file name in the figures folder, caption) of the figures both formats carry, when the file exists.
    """

    key: str
    title: str
    appendix: str | None = None
    tables: tuple = ()
    figures: tuple = ()

    @property
    def label(self) -> str:
        """The heading without its number: ``title``, or "Appendix A. title"."""
        return self.title if self.appendix is None else f"Appendix {self.appendix}. {self.title}"


def _design(a):
    return getattr(a, "design", None)


def _requirement(a):
    d = _design(a)
    return None if d is None else d.requirement


def other_site_data(a) -> bool:
    """Whether the assessment carries data of other sites (a regional record of annual maxima, a rate model).

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.

    Returns
    -------
    bool
    """
    return a.maxima_frequency is not None or rates_transferred(a)


def rates_transferred(a) -> bool:
    """Whether the assessment's rate model is fitted to another record than the site's inventory (then it is
    reported with the data of other sites).

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.

    Returns
    -------
    bool
    """
    if a.rates is None:
        return False
    return Path(str(a.rates.record)).name != Path(str(a.inventory.source)).name


#: (key, title, applies(a), tables, figures) of the numbered sections, in report order; then the appendices.
_SECTIONS: tuple = (
    ("design_values", "Design values sheet", lambda a: _requirement(a) is not None, (), ()),
    ("design_basis", "Design basis and checks", lambda a: _design(a) is not None,
     (T_CANDIDATES,), ()),
    ("positions", "Barrier position along the profile",
     lambda a: _design(a) is not None and a.design.positions is not None, (T_POSITIONS,),
     (("barrier_positions.png", "Required MEL and net height by barrier position"),)),
    ("slope_model", "Slope model", lambda a: bool(a.site.hazard.scenario),
     ("Profile vertices and segment angles", "Materials and the source of their values"), ()),
    ("options_profile", "Mitigation options on the profile", lambda a: True, (),
     (("options_profile.png", F_OPTIONS),)),
    ("runout", "Stop points and run-out", lambda a: True, (),
     (("stop_points.png", "Where the simulated blocks stopped, on the existing slope and with the recommended "
                          "option where it changes the slope"),)),
    ("catchment", "Catchment ditch at the toe of the cut",
     lambda a: _design(a) is not None and a.design.catchment is not None, (T_CATCHMENT_WIDTHS, T_RITCHIE),
     (("catchment_retention.png", F_CATCHMENT),)),
    ("trajectories", "Trajectories at the barrier line (Wyllie 2014, ch. 3-7)", lambda a: True, (),
     (("profile_trajectories.png", "Slope profile and a sample of trajectories"),)),
    ("hazard", "Impact energy hazard at the barrier line (Wyllie 2014, 8.1-8.3)", lambda a: True,
     ("Design energies by return period",),
     (("energy_exceedance.png", "Annual frequency of impacts above each energy at the barrier line"),)),
    ("fence_checks", "Fence checks (ETAG 027 / EAD 340059: MEL, SEL = MEL/3; for comparison, the design basis "
                     "governs)", lambda a: bool(a.energy.fences), (), ()),
    ("road_risk", "Risk to road users (Bunce et al. 1997; individual and societal risk)", lambda a: True,
     (T_BUNCE, T_RISK), (("fn_curve.png", F_FN),)),
    ("decision", "Mitigation decision (Wyllie 2014, 8.5.5)", lambda a: True,
     (T_DESIGN_CHECKS, T_RANKING, T_BREAK_EVEN), (("tornado.png", F_TORNADO),)),
    ("model_uncertainty", "Trajectory model uncertainty",
     lambda a: getattr(a, "model_uncertainty", None) is not None, (), ()),
    ("site_data", "Site data: the inventory and its completeness", lambda a: True, (), ()),
    ("magnitude_frequency", "Magnitude-frequency relation (Wyllie 2014, 8.4.1)", lambda a: True, (),
     (("magnitude_frequency.png", "Magnitude - cumulative frequency with the fitted law and the interval of b"),)),
    ("annual_maxima", "Extreme values of annual maxima (Wyllie 2014, 8.4.2)", lambda a: True, (), ()),
    ("assumptions", "Assumptions, defaults and warnings", lambda a: True, (), ()),
)
_APPENDICES: tuple = (
    ("other_sites", "Data from other sites (reference only)", other_site_data, (), ()),
    ("run_record", "Run record", lambda a: True, (), ()),
)


def report_sections(a) -> list:
    """The sections of the report of assessment ``a``, in order: the numbered sections that apply, then the
    appendices lettered A, B, ... in order.

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.

    Returns
    -------
    list of Section
    """
    out = [Section(key, _title(a, key, title), None, tables, figures)
           for key, title, applies, tables, figures in _SECTIONS if applies(a)]
    letters = iter("ABCDEFGH")
    out += [Section(key, title, next(letters), tables, figures)
            for key, title, applies, tables, figures in _APPENDICES if applies(a)]
    return out


def _title(a, key: str, title: str) -> str:
    if key == "design_basis":
        return f"{title}: {a.design.basis.basis} governs"
    return title


def section_number(a, key: str) -> str:
    """How the text refers to section ``key``: "section 5" or "appendix A" ("" when the report has no such section).

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.
    key : str
        A :attr:`Section.key`.

    Returns
    -------
    str
    """
    n = 0
    for s in report_sections(a):
        n += s.appendix is None
        if s.key == key:
            return f"section {n}" if s.appendix is None else f"appendix {s.appendix}"
    return ""


def render(a, bodies: dict, open_section: Callable) -> None:
    """Render every section of ``a``: ``open_section(section)`` writes its heading, ``bodies[key](section)`` its
    content.  Both writers call this, so neither can leave a section out or change the order.

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.
    bodies : dict
        :attr:`Section.key` -> callable(section) writing the section's content.
    open_section : callable
        callable(section) writing the section's heading.

    Raises
    ------
    KeyError
        When a writer has no body for a section (a programming error, caught by the parity test).
    """
    for s in report_sections(a):
        body = bodies[s.key]
        open_section(s)
        body(s)


def run_record(a) -> list:
    """(item, value) rows of the run record: riskrf version, seed, simulated blocks, site file, outputs.

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.

    Returns
    -------
    list of (str, str)
    """
    from .. import __version__
    return [("riskrf version", str(__version__)), ("seed", str(a.seed)), ("simulated blocks", f"{a.n_blocks:,}"),
            ("site file", a.site.path.name), ("outputs", "report.html, report.pdf, summary.json, CSV tables, figures/")]


# ---- tables both writers carry -------------------------------------------------------------------------------------
def bunce_table(a) -> pd.DataFrame:
    """Bunce et al. (1997) per lane: P(S:T) = q N_v L_v / (24 x 1000 x V_v) for each lane, with the total per fall
    reaching the road and the probability that a vehicle strikes a rock lying on the road.

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment (its study's exposure).

    Returns
    -------
    pandas.DataFrame
        ``lane``, ``vehicles per day``, ``speed [km/h]``, ``share of the falls landing in it``, ``P(S:T) in the
        lane [-]`` and ``probability per fall reaching the road [-]`` (q P(S:T)); the last two rows give the
        totals over the lanes (direct hit; a vehicle striking a rock lying on the road).
    """
    from ..risk.road_users import _shares, lane_hit_probability, lane_strike_probability
    ex = a.study.exposure
    lanes = ex.lane_list()
    q = _shares(lanes)
    st = "P(S:T) in the lane [-]"
    per = "probability per fall reaching the road [-]"
    rows = [{"lane": la.direction, "vehicles per day": la.vehicles_per_day, "speed [km/h]": la.speed_kmh,
             "share of the falls landing in it": float(qi),
             st: la.vehicles_per_day * ex.vehicle_length_m / (24 * 1000 * la.speed_kmh),
             per: float(qi) * la.vehicles_per_day * ex.vehicle_length_m / (24 * 1000 * la.speed_kmh)}
            for qi, la in zip(q, lanes)]
    rows.append({"lane": f"all lanes: direct hit on a moving vehicle (L_v = {ex.vehicle_length_m:g} m)",
                 "vehicles per day": ex.vehicles_per_day, "speed [km/h]": np.nan,
                 "share of the falls landing in it": 1.0, st: np.nan,
                 per: lane_hit_probability(lanes, ex.vehicle_length_m)})
    rows.append({"lane": f"all lanes: a vehicle strikes the fallen rock ({ex.hours_rock_on_road:g} h on the road, "
                         f"P(cannot stop) {ex.p_cannot_stop:g})", "vehicles per day": ex.vehicles_per_day,
                 "speed [km/h]": np.nan, "share of the falls landing in it": 1.0, st: np.nan,
                 per: lane_strike_probability(lanes, ex.hours_rock_on_road, ex.p_cannot_stop)})
    return pd.DataFrame(rows)


def road_risk_table(a) -> pd.DataFrame:
    """Individual and societal risk to road users of every option, with the tolerability verdicts.

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.

    Returns
    -------
    pandas.DataFrame
        One row per option in ranking order.
    """
    ranking = a.decision["ranking"]
    crit = a.study.criteria
    risk = ranking[["option", "road_falls_per_year", "deaths_per_year", "individual_risk"]].copy()
    risk[f"meets {probability(crit.individual_risk_per_year)}/yr"] = \
        risk["individual_risk"] <= crit.individual_risk_per_year
    risk["F(N≥1) [1/yr]"] = ranking["F_N1_per_year"]
    risk[f"F-N zone ({crit.fn_diagram})"] = ranking["fn_zone"]
    return risk.rename(columns={"individual_risk": "individual risk [1/yr]", "deaths_per_year": "deaths [1/yr]",
                                "road_falls_per_year": "falls reaching the road [1/yr]"})


def design_checks_table(a) -> pd.DataFrame:
    """The design checks of every option as the ranking uses them: adequate or not, and the verdict.

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.

    Returns
    -------
    pandas.DataFrame
        ``rank``, ``option``, ``design adequate`` (yes/NO), ``design check`` (the verdict; "-" where the option
        has no structure to check), ``recommended``.
    """
    ranking = a.decision["ranking"]
    rec = a.decision["recommendation"].get("option")
    check = ranking["design_check"] if "design_check" in ranking else pd.Series("-", index=ranking.index)
    adequate = ranking["design_adequate"] if "design_adequate" in ranking else \
        ~check.astype(str).str.contains("NOT ADEQUATE", regex=False)
    return pd.DataFrame({"rank": ranking["rank"], "option": ranking["option"],
                         "design adequate": ["yes" if ok else "NO" for ok in adequate],
                         "design check": check.astype(str),
                         "recommended": ["yes" if o == rec else "" for o in ranking["option"]]})


def recommendation_lines(a) -> list:
    """The recommendation as sentences: the choice and its basis, the reason, the options not recommended because
    they fail their design checks, and the required barrier (where it is ranked, or why none can be placed).

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.

    Returns
    -------
    list of str
        The first line names the recommended option (or says none is adequate).
    """
    rec = a.decision["recommendation"]
    reason = str(rec.get("reason") or "")
    rb = rec.get("required_barrier")
    resolution = (rec.get("resolution") or {}).get("text") if isinstance(rec.get("resolution"), dict) else None
    markers = [m for m in ("Not recommended, whatever their cost", rb, resolution) if m and m in reason]
    cuts = sorted({reason.index(m) for m in markers} | {0, len(reason)})
    lines = [f"Recommendation: {rec['option'] or 'none'} ({rec['basis']})."]
    lines += [reason[i:j].strip() for i, j in zip(cuts, cuts[1:])]
    if rec.get("not_recommended") and "fail their design checks" not in reason:
        lines.append("Not recommended, whatever their cost, because they fail their design checks: "
                     + "; ".join(f"{k} ({v})" for k, v in rec["not_recommended"].items()) + ".")
    if rb and rb not in reason:
        lines.append(rb)
    return [x for x in lines if x]


def catchment_text(c) -> str:
    """What the catchment study measures, in one paragraph.

    Parameters
    ----------
    c : riskrf.hazard.catchment.CatchmentStudy
        The design's catchment study.

    Returns
    -------
    str
    """
    applies = c.to_dict()["odot_chart_geometry"]
    return (f"Retention against catchment width beyond the toe of the cut (x = {c.toe_x_m:.4g} m; cut "
            f"{c.cut_height_m:.3g} m high at {c.face_angle_deg:.3g}°), re-simulated with the site's slope model.  "
            f"Pierson, Gullixson & Chassie (2001, FHWA-OR-RD-02-04) charts: {applies}.  Beside it, the published "
            "width rule: the Modified Ritchie Criterion W = 0.2 H + 4.5 m (Ryan & Pryor 2000, after Ritchie 1963).")


def road_risk_text(a) -> str:
    """How the risk to road users is computed (Bunce et al. 1997 per lane, individual and societal risk).

    Parameters
    ----------
    a : riskrf.app.assess.result.Assessment
        The assessment.

    Returns
    -------
    str
    """
    ex, crit = a.study.exposure, a.study.criteria
    return (f"Bunce et al. (1997): P(S:T) = N_v L_v / (24 × 1000 × V_v) per lane, for {ex.vehicles_per_day:,.0f} "
            f"vehicles a day over {int(ex.lanes)} lane(s) of vehicles {ex.vehicle_length_m:g} m long at "
            f"{ex.speed_kmh:g} km/h; a vehicle striking a rock on the road; individual risk of a commuter making "
            f"{ex.commuter_trips_per_day:g} trips a day (AGS 2007), tolerable at "
            f"{probability(crit.individual_risk_per_year)}/yr.  Both individual and societal risk count direct hits "
            "and strikes on fallen rocks, falls of every size reaching the road (the power law above m_min and the "
            "inventory's smaller falls below it), a probability of death that grows with block mass (an "
            "assumption anchored to AGS 2000 / Finlay et al. 1999, see the defaults) and occupants per vehicle as "
            f"a distribution.  Societal risk (F-N) against the {crit.fn_diagram} criterion ([criteria] set = "
            f"{crit.set}).")


def catchment_tables(c) -> tuple:
    """The catchment widths for each retention, and the Modified Ritchie Criterion beside the re-simulation.

    Parameters
    ----------
    c : riskrf.hazard.catchment.CatchmentStudy
        The design's catchment study.

    Returns
    -------
    (pandas.DataFrame, pandas.DataFrame)
        Widths (``retention``, ``catchment width needed [m]``) and the rule (``quantity``, ``value``).
    """
    widths = pd.DataFrame([{"retention": f"{q:g} %",
                            "catchment width needed [m]": w if np.isfinite(w) else "not reached on the profile"}
                           for q, w in c.widths.items()])
    d = c.to_dict()
    mrc = d["modified_ritchie_criterion"]
    rule = pd.DataFrame([
        ("cut height H [m]", c.cut_height_m), ("face angle [°]", c.face_angle_deg),
        ("toe of the cut, x [m]", c.toe_x_m),
        ("Modified Ritchie width W = 0.2 H + 4.5 m [m]", mrc["width_m"]),
        ("blocks over the face retained within W, re-simulated [%]", mrc["simulated_retained_percent"]),
        ("rule's source", mrc["source"]), ("where the rule applies", mrc["note"]),
        ("Pierson et al. (2001) chart geometry", d["odot_chart_geometry"])], columns=["quantity", "value"])
    return widths, rule


__all__ = ["Section", "bunce_table", "catchment_tables", "design_checks_table", "other_site_data", "rates_transferred",
           "recommendation_lines", "render", "report_sections", "road_risk_table", "run_record", "section_number"]
