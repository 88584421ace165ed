"""Figure files written by ``riskrf fit``, ``energy``, ``simulate``, ``decide`` and ``assess``.

Figures are written as PNG at :data:`FIGURE_DPI` (sharp on screen and in print) and
closed after writing; the plotting backend is never changed here (the command line
selects a non-interactive one once, at start-up).
"""
from __future__ import annotations

import os
from contextlib import contextmanager
from contextvars import ContextVar
from functools import lru_cache
from pathlib import Path

import numpy as np

FIGURE_DPI = 200

#: A line printed at the foot of every figure :func:`save_figure` writes while it is set (:func:`figure_note`):
#: an assessment whose trajectory model is uncalibrated stamps it on each figure drawn from the trajectories.
_FIGURE_NOTE: ContextVar[str | None] = ContextVar("riskrf_figure_note", default=None)


@contextmanager
def figure_note(text: str | None):
    """Stamp ``text`` at the foot of every figure :func:`save_figure` writes inside the ``with`` block (in this
    process and in processes forked inside it); None stamps nothing.

    Parameters
    ----------
    text : str or None
        One short line (it is wrapped to the figure's width).
    """
    token = _FIGURE_NOTE.set(text)
    try:
        yield
    finally:
        _FIGURE_NOTE.reset(token)


_SUPERSCRIPT = str.maketrans("-0123456789", "\u207b\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079")


def _power_label(x: float) -> str:
    """A log-axis tick label in plain Unicode: 10 to a superscript power, or c\u00d710 to the power."""
    exponent = int(np.floor(np.log10(x) + 1e-9))
    coeff = x / 10.0 ** exponent
    power = "10" + str(exponent).translate(_SUPERSCRIPT)
    return power if round(coeff) == 1 and abs(coeff - 1) < 1e-6 else f"{coeff:.0f}\u00d7{power}"


def _plain_log_labels(fig) -> None:
    """Log-axis tick labels as plain Unicode text instead of matplotlib's mathtext (same ticks, same look, but
    each label is not parsed as TeX: that parsing was a third of the time spent drawing the report's figures)."""
    from matplotlib.ticker import LogFormatter, LogFormatterSciNotation

    class _Formatter(LogFormatter):
        def _num_to_string(self, x, vmin, vmax):
            return _power_label(x)

    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() != "log":
                continue
            for get, put in ((axis.get_major_formatter, axis.set_major_formatter),
                             (axis.get_minor_formatter, axis.set_minor_formatter)):
                f = get()
                if type(f) is LogFormatterSciNotation:
                    put(_Formatter(base=f._base, labelOnlyBase=f.labelOnlyBase,
                                   minor_thresholds=f.minor_thresholds, linthresh=f._linthresh))


def prepare_drawing() -> None:
    """Import matplotlib's pyplot once, in this process, before work that draws in forked processes (so each
    fork does not import it again).  The backend is not changed: matplotlib picks it as usual."""
    import matplotlib.pyplot  # noqa: F401


def _sparse_minor_log_ticks(fig) -> None:
    """On log axes spanning more than two decades, minor ticks and grid lines at 2 and 5 times each power of ten
    instead of at 2, 3, ..., 9: the same reading aid with a quarter of the tick artists, which halves the time
    to draw such a figure."""
    from matplotlib.ticker import LogLocator

    for ax in fig.axes:
        for axis, lim in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            if axis.get_scale() != "log" or type(axis.get_minor_locator()) is not LogLocator:
                continue
            lo, hi = sorted(lim)
            if lo > 0 and np.log10(hi / lo) > 2:
                axis.set_minor_locator(LogLocator(base=10.0, subs=(2.0, 5.0), numticks=12))


#: Font size of the :func:`figure_note` line [points].
_NOTE_FONTSIZE = 6.5


@lru_cache(maxsize=64)
def _wrapped_note(text: str, width_px: float, fontsize: float, dpi: float) -> str:
    """``text`` with line breaks so that each line fits ``width_px`` pixels in the default font at ``fontsize``
    points and ``dpi``: the greedy rule of matplotlib's ``Text(wrap=True)`` (as many words per line as fit, a
    word wider than the width on a line of its own), the longest fitting run of words found by bisection.

    Parameters
    ----------
    text : str
        The line to wrap (explicit line breaks are kept).
    width_px : float
        Available width [pixels].
    fontsize : float
        Font size [points].
    dpi : float
        Resolution [dots per inch].

    Returns
    -------
    str
        The wrapped text.
    """
    import math

    from matplotlib import cbook
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.font_manager import FontProperties

    renderer, prop = RendererAgg(1, 1, dpi), FontProperties(size=fontsize)

    def width(words) -> int:
        s = " ".join(words)
        return math.ceil(renderer.get_text_width_height_descent(s, prop, ismath=cbook.is_math_text(s))[0])

    lines = []
    for part in text.split("\n"):
        words = part.split(" ")
        while words:
            lo, hi = 1, len(words)          # words[:lo] is taken (one word at least), words[:hi + 1] too wide
            while lo < hi:
                mid = (lo + hi + 1) // 2
                if width(words[:mid]) > width_px:
                    hi = mid - 1
                else:
                    lo = mid
            lines.append(" ".join(words[:lo]))
            words = words[lo:]
    return "\n".join(lines)


def save_figure(fig, path, *, tight_layout: bool = False, dpi: int = FIGURE_DPI) -> Path:
    """Write ``fig`` to ``path`` (PNG, :data:`FIGURE_DPI`) and close it; returns the path.  Inside
    :func:`figure_note`, the note is printed at the figure's foot.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or path
        The PNG written.
    tight_layout : bool
        Apply ``tight_layout`` first.
    dpi : int, optional
        Resolution [dots per inch] (default :data:`FIGURE_DPI`).

    Returns
    -------
    pathlib.Path
    """
    import matplotlib.pyplot as plt
    note = _FIGURE_NOTE.get()
    if note:
        # wrapped here, once per width, instead of by matplotlib (wrap=True), which measured the note word by
        # word at every layout of every figure: a tenth of the drawing time of an assessment's figures
        fig.text(0.0, -0.01, _wrapped_note(note, fig.get_figwidth() * dpi, _NOTE_FONTSIZE, dpi), ha="left",
                 va="top", fontsize=_NOTE_FONTSIZE, color="#9b1c1c")
    _plain_log_labels(fig)
    _sparse_minor_log_ticks(fig)
    if tight_layout:
        fig.tight_layout()
    # PNG with zlib level 3: about 40 % less encoding time than the default 6, files 5-20 % larger.  Written
    # under a temporary name and renamed: a *.png in the folder is always whole (the report's PDF, laid out
    # beside the figure writers, takes every *.png present as finished)
    path = Path(path)
    part = path.with_name(path.name + ".part")
    try:
        fig.savefig(part, format="png", dpi=dpi, bbox_inches="tight", pil_kwargs={"compress_level": 3})
        os.replace(part, path)
    finally:
        plt.close(fig)
        part.unlink(missing_ok=True)
    return path


def write_frequency_figures(analysis, out: Path) -> list[Path]:
    """Magnitude-frequency, Gumbel and return-level figures of a :class:`~riskrf.FrequencyAnalysis`.

    Parameters
    ----------
    analysis : FrequencyAnalysis
        The fits.
    out : pathlib.Path
        Existing folder.

    Returns
    -------
    list of pathlib.Path
        The files written (without a :func:`figure_note`: the fits use no trajectory).
    """
    with figure_note(None):
        return _frequency_figures(analysis, out)


def _frequency_figures(analysis, out: Path) -> list[Path]:
    from ..frequency.figures import plot_gumbel, plot_magnitude_frequency, plot_return_levels
    ax = plot_magnitude_frequency(analysis.power_law)
    ax.set_title("Magnitude - cumulative frequency")
    written = [save_figure(ax.figure, out / "magnitude_frequency.png")]
    if analysis.gumbel is not None:
        ax = plot_gumbel(analysis.gumbel)
        ax.set_title("Gumbel probability plot of annual maxima")
        written.append(save_figure(ax.figure, out / "gumbel_plot.png"))
        fits = {f"Gumbel ({analysis.gumbel.method})": analysis.gumbel}
        if analysis.gev is not None:
            fits["GEV"] = analysis.gev
        ax = plot_return_levels(fits, power_law=analysis.power_law, maxima=analysis.maxima)
        ax.set_title("Return levels of the annual maximum mass")
        written.append(save_figure(ax.figure, out / "return_levels.png"))
    return written


def write_energy_figures(analysis, out: Path, fence_capacities_kj) -> list[Path]:
    """Energy exceedance and mass-velocity figures of an energy study (``riskrf energy``).

    Parameters
    ----------
    analysis : EnergyAnalysis
        The study.
    out : pathlib.Path
        Existing folder.
    fence_capacities_kj : sequence of float
        Fence capacities marked on the exceedance curve [kJ].

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    from ..hazard.figures import plot_energy_exceedance
    from .fit_figures import plot_mass_velocity
    ax = plot_energy_exceedance(analysis.hazard, fences=list(fence_capacities_kj),
                                n_bootstrap=min(analysis.n_bootstrap, 200), seed=analysis.seed)
    ax.set_title("Impact energy at the barrier line")
    written = [save_figure(ax.figure, out / "energy_exceedance.png")]
    ax = plot_mass_velocity(analysis.hazard, seed=analysis.seed)
    ax.set_title("Mass and velocity of arriving falls")
    written.append(save_figure(ax.figure, out / "mass_velocity.png"))
    if getattr(analysis, "sensitivity", None) is not None and len(analysis.sensitivity):
        from .fit_figures import plot_design_energy_sensitivity
        ax = plot_design_energy_sensitivity(analysis.sensitivity)
        ax.set_title("Design energy over the judgement inputs")
        written.append(save_figure(ax.figure, out / "design_energy_sensitivity.png"))
    if getattr(analysis, "tornado", None) is not None and len(analysis.tornado.table):
        from .fit_figures import plot_design_energy_tornado
        axes = plot_design_energy_tornado(analysis.tornado)
        written.append(save_figure(axes[0].figure, out / "design_energy_tornado.png", tight_layout=True))
    return written


def write_simulation_figures(result, out: Path, collectors, *, file_names=None, fences=()) -> list[Path]:
    """Profile with trajectories, one distribution figure per collector, and envelopes (when binned).

    Parameters
    ----------
    result : simulation.SimulationResult
        The run.
    out : pathlib.Path
        Existing folder.
    collectors : sequence of str
        Collectors with a distribution figure.
    file_names : dict, optional
        Collector name → file name (default ``collector_<name>.png``).
    fences : sequence of (float, float, str)
        (x [m], height [m], label) drawn on the profile at their height.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    from simulation.plotting import (
        plot_collector_distributions,
        plot_envelopes,
        plot_profile,
    )
    file_names = file_names or {}
    written = [save_figure(plot_profile(result, fences=fences).figure, out / "profile_trajectories.png")]
    for name in collectors:
        axes = plot_collector_distributions(result, name)
        written.append(save_figure(axes[0][0].figure, out / file_names.get(name, f"collector_{name}.png")))
    if result.scenario.settings.envelope_bins:
        axes = plot_envelopes(result)
        written.append(save_figure(axes[0].figure, out / "envelopes.png"))
    return written


def write_frequency_study(analysis, out: Path, **options) -> list[Path]:
    """Every file of a :class:`~riskrf.FrequencyAnalysis`: its data files (:meth:`~riskrf.FrequencyAnalysis.write`,
    ``options`` passed on) then its figures; returns every file written.

    Parameters
    ----------
    analysis : FrequencyAnalysis
        The fits.
    out : pathlib.Path
        Existing folder.
    **options
        Passed to :meth:`~riskrf.FrequencyAnalysis.write`.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    return analysis.write(out, **options) + write_frequency_figures(analysis, Path(out))


def write_energy_study(analysis, out: Path) -> list[Path]:
    """Every file of an energy study (:class:`~riskrf.hazard.energy_study.EnergyAnalysis`): its data files, then
    the figures, with the checked fences' capacities drawn on the exceedance curve; returns every file written.

    Parameters
    ----------
    analysis : EnergyAnalysis
        The study.
    out : pathlib.Path
        Existing folder.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    written = analysis.write(out)
    return written + write_energy_figures(analysis, Path(out), [float(n.split(" kJ")[0]) for n in analysis.fences])
