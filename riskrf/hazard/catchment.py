"""Catchment (ditch) retention by re-simulation, laid beside a published catchment design chart.

The Oregon DOT / FHWA Rockfall Catchment Area Design Guide (Pierson, Gullixson & Chassie 2001,
FHWA-OR-RD-02-04) rolled about 11,250 rocks off cuts 40, 60 and 80 ft high (vertical to 1H:1V) into flat,
6H:1V and 4H:1V catchments and plots the cumulative percentage of rocks retained against the catchment width
measured from the toe.  :func:`catchment_retention` computes the same curve for a scenario by simulation: a
block is retained within width w when it stops no farther than w beyond the toe of the cut.  As in the ODOT
tests, where every rock was rolled off the top of the cut, the shares are of the blocks that went over the
cut face (a block that stops on the crest above the face never tested the catchment; how many did is
recorded).  The widths that retain 90, 95 and 99 % are read off it; chart values (width, percent retained),
when the user gives them with their source, are set beside the simulated percentages at the same widths.

The published width rule set beside every study is the Modified Ritchie Criterion (Ryan & Pryor 2000, from
Ritchie's 1963 highway ditch tests): catchment width W = 0.2 H + 4.5 m for a face H metres high, quoted in
Warren et al. (2025), whose regressions on the ODOT data set use 90 % retention as the performance level
(:func:`modified_ritchie_width_m`).  The ODOT chart values themselves could not be retrieved for riskrf
(docs/validation/design-standards.md).

References
----------
Pierson, L.A., Gullixson, C.F. & Chassie, R.G. (2001) Rockfall Catchment Area Design Guide. Oregon DOT / FHWA,
FHWA-OR-RD-02-04.
Ritchie, A.M. (1963) Evaluation of rockfall and its control. Highway Research Record 17: 13-28.
Ryan, T.M. & Pryor, P.R. (2000) Designing catch benches and interramp slopes. In Slope Stability in Surface
Mining, SME, 27-38.
Warren, S., McNabb, J.C., Meyer, B.J., Potter, J.J., Sbai, S., Reasoner, A.E. & Ryan, T. (2025) Preliminary
expansion of the Modified Ritchie Criterion. SSIM 2025, ACG Perth, doi 10.36487/ACG_repo/2535_04 (abstract).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

RETENTION_LEVELS = (90.0, 95.0, 99.0)
#: Modified Ritchie Criterion (Ryan & Pryor 2000, quoted in Warren et al. 2025 abstract): W = a H + b [m].
MRC_SLOPE, MRC_INTERCEPT_M = 0.2, 4.5
#: Segments at least this steep [deg] next to the steepest one belong to the cut face (1H:1V, the flattest
#: face of the ODOT tests).
CUT_FACE_MIN_DEG = 45.0


@dataclass(frozen=True)
class CatchmentStudy:
    """Retention against catchment width for one cut.

    ``title``; ``toe_x_m`` of the cut; ``cut_height_m`` and ``face_angle_deg``; ``n`` blocks simulated;
    ``curve`` (width_m, retained share); ``widths`` {percent: width [m]} (NaN when the simulated catchment never
    retains that share, e.g. blocks leave the profile); ``chart`` (width_m, retained_percent, simulated_percent,
    difference_points) or None; ``chart_source``; ``n_over_face``: blocks that went over the cut face (the shares
    are of these; the others stopped on the crest).  Its figure: :meth:`plot`
    (:func:`riskrf.hazard.figures.plot_catchment`).
    """

    title: str
    toe_x_m: float
    cut_height_m: float
    face_angle_deg: float
    n: int
    curve: pd.DataFrame
    widths: dict
    chart: pd.DataFrame | None = None
    chart_source: str = ""
    n_over_face: int | None = None

    def retained_at(self, width_m) -> np.ndarray:
        """Share [-] of the released blocks retained within ``width_m`` of the toe.

        Parameters
        ----------
        width_m : float or array_like
            Catchment width measured from the toe [m].

        Returns
        -------
        numpy.ndarray
            Share of the released blocks retained within the width [-].
        """
        return np.interp(np.asarray(width_m, dtype=float), self.curve["width_m"], self.curve["retained"])

    @property
    def ritchie_width_m(self) -> float:
        """The Modified Ritchie Criterion's ditch width for this cut [m] (:func:`modified_ritchie_width_m`)."""
        return modified_ritchie_width_m(self.cut_height_m)

    def summary(self) -> pd.DataFrame:
        """One row per compared width: the re-simulated widths for 90/95/99 % retention, the Modified Ritchie
        Criterion width and (when given) the chart values, each with the simulated retention at that width.

        Columns: ``source``, ``width_m``, ``retained_percent`` (what the source says is retained at that width;
        NaN for the Ritchie rule, which states no level), ``simulated_percent`` (re-simulated share at the width).

        Returns
        -------
        pandas.DataFrame
            One row per compared width with the columns above.
        """
        rows = [{"source": f"re-simulated ({self.blocks_counted} blocks over the face)", "width_m": w,
                 "retained_percent": q,
                 "simulated_percent": 100.0 * float(self.retained_at(w)) if np.isfinite(w) else np.nan}
                for q, w in self.widths.items()]
        w_mrc = modified_ritchie_width_m(self.cut_height_m)
        rows.append({"source": "Modified Ritchie Criterion W = 0.2 H + 4.5 m (Ryan & Pryor 2000)", "width_m": w_mrc,
                     "retained_percent": np.nan, "simulated_percent": 100.0 * float(self.retained_at(w_mrc))})
        if self.chart is not None:
            for r in self.chart.itertuples():
                rows.append({"source": f"chart: {self.chart_source}", "width_m": r.width_m,
                             "retained_percent": r.retained_percent, "simulated_percent": r.simulated_percent})
        return pd.DataFrame(rows, columns=["source", "width_m", "retained_percent", "simulated_percent"])

    @property
    def blocks_counted(self) -> int:
        """Blocks the shares are of: those that went over the cut face (all released blocks for older studies)."""
        return int(self.n if self.n_over_face is None else self.n_over_face)

    def plot(self, ax=None):
        """Retention against catchment width with the Ritchie width and chart values; returns the matplotlib axes
        (drawn by :func:`riskrf.hazard.figures.plot_catchment`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on.
        """
        from .figures import plot_catchment
        return plot_catchment(self, ax=ax)

    def to_dict(self) -> dict:
        """JSON-ready summary: geometry, widths for 90/95/99 %, chart comparison (or why there is none).

        Returns
        -------
        dict
            Geometry [m, deg], widths for 90/95/99 % retention [m] and the chart comparison.
        """
        w_mrc = modified_ritchie_width_m(self.cut_height_m)
        return {"title": self.title, "toe_x_m": self.toe_x_m, "cut_height_m": self.cut_height_m,
                "face_angle_deg": self.face_angle_deg, "blocks_simulated": self.n,
                "blocks_over_face": self.blocks_counted,
                "modified_ritchie_criterion": {
                    "source": "W = 0.2 H + 4.5 m, Ryan & Pryor (2000) after Ritchie (1963), quoted by Warren et al. "
                              "(2025, SSIM, doi 10.36487/ACG_repo/2535_04)",
                    "width_m": w_mrc, "simulated_retained_percent": 100.0 * float(self.retained_at(w_mrc)),
                    "note": "a rule for a cut face above a flat catchment or bench; the ODOT 60 ft cut re-simulated "
                            "with the data-derived presets is compared with it in docs/validation/design-standards.md"},
                "width_for_retention_m": {f"{q:g}": (None if not np.isfinite(w) else w)
                                          for q, w in self.widths.items()},
                "chart_source": self.chart_source or None,
                "odot_chart_geometry": odot_chart_applies(self.cut_height_m, self.face_angle_deg)
                or "within the ODOT charts' cut heights and face angles",
                "chart_comparison": (self.chart.to_dict(orient="records") if self.chart is not None else
                                     "no chart values given: the Pierson et al. (2001) chart values were not "
                                     "available to riskrf; pass them as chart= with their source")}


def modified_ritchie_width_m(height_m: float) -> float:
    """Catchment width [m] of the Modified Ritchie Criterion for a face ``height_m`` metres high.

    W = 0.2 H + 4.5 m (Ryan & Pryor 2000, the mining form of Ritchie's 1963 highway ditch rule, as quoted in the
    abstract of Warren et al. 2025, who measure catch benches against 90 % retention).  A single linear rule: it
    takes no account of rock size, face angle or catchment material, which Warren et al. found also govern rollout.

    Parameters
    ----------
    height_m : float
        Height of the cut face H [m].

    Returns
    -------
    float
        Catchment width W [m].

    References
    ----------
    Ryan, T.M. & Pryor, P.R. (2000) Designing catch benches and interramp slopes. In Slope Stability in Surface
    Mining, SME, 27-38.
    Ritchie, A.M. (1963) Evaluation of rockfall and its control. Highway Research Record 17: 13-28.
    Warren, S. et al. (2025) Preliminary expansion of the Modified Ritchie Criterion. SSIM 2025, ACG Perth,
    doi 10.36487/ACG_repo/2535_04 (abstract).
    """
    h = float(height_m)
    if not (np.isfinite(h) and h > 0):
        raise ValueError(f"height_m = {height_m!r} must be a number > 0 m")
    return MRC_SLOPE * h + MRC_INTERCEPT_M


def _face_span(profile) -> tuple:
    """(index of the first, index of the last) segment of the cut face (see :func:`cut_geometry`)."""
    x, z = np.asarray(profile.x, dtype=float), np.asarray(profile.z, dtype=float)
    ang = np.degrees(np.arctan2(-np.diff(z), np.diff(x)))
    i = int(np.argmax(ang))
    lo, hi = i, i
    while lo > 0 and ang[lo - 1] >= CUT_FACE_MIN_DEG:          # the face continues up ...
        lo -= 1
    while hi < ang.size - 1 and ang[hi + 1] >= CUT_FACE_MIN_DEG:   # ... and down
        hi += 1
    return lo, hi


def cut_geometry(profile) -> tuple:
    """(toe x [m], cut height [m], overall face angle [deg]) of the cut face: the steepest segment of a profile with
    the segments of at least :data:`CUT_FACE_MIN_DEG` next to it.

    Parameters
    ----------
    profile : TerrainProfile
        Slope profile with vertices ``x``, ``z`` [m].

    Returns
    -------
    tuple of float
        Toe x [m], cut height [m] and overall face angle [deg].
    """
    x, z = np.asarray(profile.x, dtype=float), np.asarray(profile.z, dtype=float)
    lo, hi = _face_span(profile)
    height = float(z[lo] - z[hi + 1])
    return float(x[hi + 1]), height, float(np.degrees(np.arctan2(height, x[hi + 1] - x[lo])))


def catchment_retention(scenario, *, n: int = 2000, seed=1, toe_x_m: float | None = None, chart=None,
                        chart_source: str = "", max_width_m: float | None = None) -> CatchmentStudy:
    """Re-simulate ``scenario`` and measure how far beyond the toe of its cut the blocks stop.

    Parameters
    ----------
    scenario : simulation.Scenario (or path): a cut above a catchment (e.g. ``odot_catchment_cut.toml``)
    n, seed : blocks simulated and seed
    toe_x_m : toe of the cut [m] (default: the lower end of the profile's steepest segment)
    chart : optional table or sequence of (width [m], percent retained) read from a published chart
    chart_source : where the chart values come from (figure and page), required with ``chart``
    max_width_m : widest catchment of the curve [m] (default: to the end of the profile)

    Returns
    -------
    CatchmentStudy
        Retention curve against width [m], widths for 90/95/99 % retention and the chart comparison.

    References
    ----------
    Pierson, L.A., Gullixson, C.F. & Chassie, R.G. (2001) Rockfall Catchment Area Design Guide. Oregon DOT / FHWA,
    FHWA-OR-RD-02-04.
    """
    import simulation
    sc = scenario if isinstance(scenario, simulation.Scenario) else simulation.load_scenario(scenario)
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 100:
        raise ValueError(f"n = {n!r}: simulate at least 100 blocks")
    toe, height, angle = cut_geometry(sc.profile)
    if toe_x_m is not None:
        toe = float(toe_x_m)
    res = simulation.run(sc, n=int(n), seed=seed)
    study = retention_from_result(res, toe_x_m=toe, max_width_m=max_width_m)
    if chart is not None:
        study = with_chart(study, chart, chart_source)
    return study


#: The geometry the ODOT charts cover (Pierson et al. 2001): cut heights 40-80 ft, faces vertical to 1H:1V.
ODOT_HEIGHTS_M = (12.19, 24.38)
ODOT_FACE_DEG = (45.0, 90.0)


def odot_chart_applies(cut_height_m: float, face_angle_deg: float) -> str:
    """'' when a cut lies within the ODOT charts' geometry, else why not (in words).

    Parameters
    ----------
    cut_height_m : float
        Height of the cut [m].
    face_angle_deg : float
        Overall face angle [deg].

    Returns
    -------
    str
        Empty when the cut lies within the charts' geometry, else the reasons in words.

    References
    ----------
    Pierson, L.A., Gullixson, C.F. & Chassie, R.G. (2001) Rockfall Catchment Area Design Guide. Oregon DOT / FHWA,
    FHWA-OR-RD-02-04.
    """
    why = []
    if not ODOT_HEIGHTS_M[0] - 0.5 <= cut_height_m <= ODOT_HEIGHTS_M[1] + 0.5:
        why.append(f"cut height {cut_height_m:.1f} m outside the charts' 40-80 ft (12.2-24.4 m)")
    if not ODOT_FACE_DEG[0] - 1 <= face_angle_deg <= ODOT_FACE_DEG[1]:
        why.append(f"face angle {face_angle_deg:.0f} deg outside the charts' 1H:1V to vertical (45-90 deg)")
    return "; ".join(why)


def with_chart(study, chart, chart_source: str):
    """``study`` with chart values (width [m], percent retained) and the simulated percent at the same widths.

    Parameters
    ----------
    study : CatchmentStudy
        The re-simulated study.
    chart : pandas.DataFrame or sequence of (float, float)
        Chart values (width [m], percent retained [%]).
    chart_source : str
        Where the chart values come from (figure and page).

    Returns
    -------
    CatchmentStudy
        A copy of ``study`` with the chart values and the simulated percent at the same widths.
    """
    if not chart_source:
        raise ValueError("chart values need chart_source (the chart's report, figure and page)")
    c = pd.DataFrame(chart, columns=["width_m", "retained_percent"]) if not isinstance(chart, pd.DataFrame) \
        else chart[["width_m", "retained_percent"]].copy()
    c["simulated_percent"] = 100.0 * study.retained_at(c["width_m"])
    c["difference_points"] = c["simulated_percent"] - c["retained_percent"]
    from dataclasses import replace
    return replace(study, chart=c, chart_source=chart_source)


def retention_from_result(res, *, toe_x_m: float | None = None, max_width_m: float | None = None) -> CatchmentStudy:
    """:class:`CatchmentStudy` from a simulation already run (its blocks' stop points beyond the toe).

    Parameters
    ----------
    res : SimulationResult
        A simulation of a cut above a catchment.
    toe_x_m : float, optional
        Toe of the cut [m] (default: from :func:`cut_geometry`).
    max_width_m : float, optional
        Widest catchment of the curve [m] (default: to the end of the profile).

    Returns
    -------
    CatchmentStudy
        The retention curve and the widths for 90/95/99 % retention.
    """
    sc = res.scenario
    toe, height, angle = cut_geometry(sc.profile)
    if toe_x_m is not None:
        toe = float(toe_x_m)
    ro = res.runout
    x_stop = ro["x_stop_m"].to_numpy(dtype=float)
    left = (ro["reason"].astype(str) == "left profile").to_numpy()
    face_top = float(sc.profile.x[_face_span(sc.profile)[0]])
    over = left | ~np.isfinite(x_stop) | (x_stop > face_top)     # went over the face (or left the profile)
    beyond = x_stop[over] - toe
    gone = left[over] | ~np.isfinite(beyond)
    beyond[gone] = np.inf                                   # never retained within the profile
    if beyond.size == 0:
        raise ValueError(f"{sc.name}: no simulated block went over the cut face (top at x = {face_top:g} m); "
                         "the catchment is not tested")
    top = float(sc.profile.x[-1] - toe) if max_width_m is None else float(max_width_m)
    w = np.linspace(0.0, top, 401)
    s = np.sort(beyond)
    retained = np.searchsorted(s, w, side="right") / s.size
    widths = {}
    for q in RETENTION_LEVELS:
        k = int(np.ceil(q / 100.0 * s.size)) - 1
        widths[q] = float(max(s[k], 0.0)) if np.isfinite(s[k]) else float("nan")
    return CatchmentStudy(title=f"{sc.name}: {height:.1f} m cut at {angle:.0f} deg, catchment retention",
                          toe_x_m=toe, cut_height_m=height, face_angle_deg=angle, n=int(res.n),
                          curve=pd.DataFrame({"width_m": w, "retained": retained}), widths=widths,
                          n_over_face=int(beyond.size))


__all__ = ["CatchmentStudy", "MRC_INTERCEPT_M", "MRC_SLOPE", "ODOT_FACE_DEG", "ODOT_HEIGHTS_M", "RETENTION_LEVELS",
           "catchment_retention", "cut_geometry", "modified_ritchie_width_m", "odot_chart_applies",
           "retention_from_result", "with_chart"]
