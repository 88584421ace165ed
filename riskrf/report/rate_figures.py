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


