"""Figures of a rate model (riskrf.frequency.rates): seasonality and the response to rainfall."""
from __future__ import annotations

from pathlib import Path

from .files import save_figure


def write_rate_figures(model, out: Path, response) -> list[Path]:
    """Seasonality (observed and expected events per calendar month) and, for daily models, the expected
    daily rate against the first rainfall band with its interval; PNG files in ``out``.

    Parameters
    ----------
    model : RateModel
        The fitted rate model.
    out : pathlib.Path
        Existing folder.
    response : object
        The model's rainfall response (:meth:`RateModel.rainfall_response`).

    Returns
    -------
    list of pathlib.Path
        The PNG files written.
    """
    from matplotlib.figure import Figure     # object API: no pyplot, no backend change

    written = []
    if model.period == "year":
        return written
    season = model.predicted_by_season()
    fig = Figure(figsize=(6.4, 3.8))
    ax = fig.subplots()
    ax.bar(season.index, season["observed_per_month"], color="0.75", label="observed")
    ax.plot(season.index, season["expected_per_month"], "o-", color="C3",
            label=f"expected ({model.preferred}, record rainfall)")
    ax.set_xticks(range(1, 13), ["J", "F", "M", "A", "M", "J", "J", "A", "S", "O", "N", "D"])
    ax.set_xlabel("month")
    ax.set_ylabel("events per month per year")
    ax.set_title(f"Seasonality, {model.start.year}-{model.end.year}", fontsize=10)
    ax.legend(fontsize=8)
    written.append(save_figure(fig, out / "seasonality.png", tight_layout=True))
    if response is not None:
        band = response.columns[0]
        label = model.terms.set_index("term").loc[band, "label"].split(" (")[0]
        fig = Figure(figsize=(6.4, 3.8))
        ax = fig.subplots()
        ax.plot(response[band], response["events_per_day"], color="C0")
        ax.fill_between(response[band], response["ci_low"], response["ci_high"], color="C0", alpha=0.25,
                        label=f"{model.level:.0%} interval")
        ax.set_xlabel(f"{label} [mm]")
        ax.set_ylabel("expected events per day")
        ax.set_yscale("log")
        ax.set_title(f"Rate against rainfall ({model.preferred}; other bands at their means)", fontsize=10)
        ax.legend(fontsize=8)
        written.append(save_figure(fig, out / "rainfall_response.png", tight_layout=True))
    return written


def write_rate_study(model, out: Path) -> list[Path]:
    """Every file of a :class:`~riskrf.RateModel`: its tables (:meth:`~riskrf.RateModel.write`), then the
    seasonality and (daily models with rainfall terms) rainfall-response figures.

    Parameters
    ----------
    model : RateModel
        The fitted rate model.
    out : pathlib.Path
        Existing folder.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    written = model.write(out)
    return written + write_rate_figures(model, Path(out), model.rainfall_response())


def plot_rainfall(rainfall, ax=None):
    """Daily rainfall against date (missing days left blank).

    Parameters
    ----------
    rainfall : Rainfall
        The daily record [mm].
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
        x: date; y: daily rainfall [mm].
    """
    from .axes import _axes
    ax = _axes(ax, figsize=(9.0, 3.5))
    ax.plot(rainfall.daily.index, rainfall.daily.to_numpy(), lw=0.5, color="C0")
    ax.set_xlabel("date")
    ax.set_ylabel("daily rainfall [mm]")
    ax.set_title(Path(str(rainfall.source)).name, fontsize="small")
    return ax


def plot_rate_counts(model, ax=None):
    """Events per calendar year: recorded (bars) and expected by the preferred model (line).

    Parameters
    ----------
    model : RateModel
        The fitted rate model.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
        x: year; y: events per year.
    """
    import numpy as np
    import pandas as pd

    from .axes import _axes
    ax = _axes(ax)
    year = pd.to_datetime(model.design["period_start"]).dt.year.to_numpy()
    observed = pd.Series(model.design["count"].to_numpy(), index=year).groupby(level=0).sum()
    ax.bar(observed.index, observed.to_numpy(), color="0.75", label="recorded")
    expected = pd.Series(np.asarray(model.fitted(), dtype=float), index=year).groupby(level=0).sum()
    ax.plot(expected.index, expected.to_numpy(), "o-", ms=3, color="C3", label=f"expected ({model.preferred})")
    ax.set_xlabel("year")
    ax.set_ylabel("events per year")
    ax.legend(fontsize="small")
    return ax
