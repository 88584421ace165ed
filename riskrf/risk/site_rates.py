"""A site's rate model (the ``[rates]`` table): the hazard's annual rate and closure options computed from it.

A site file may name a dated record and a daily rainfall record (``[rates]``).
:func:`evaluate_rates` fits :func:`riskrf.frequency.rates` to them once per run and
computes from that one model

* the **expected annual rate** over the record's rainfall climate (trend at the
  end of the record), :meth:`RateModel.expected_annual_rate`, optionally under
  a stated change of climate (``rain_factor``; ``heavy_day_mm`` with
  ``heavy_day_change``; an assumption, labelled as one), used as the hazard's
  rate when ``[inventory] rate_from = "rate_model"``;
* each **closure option given as a rule** (``threshold_mm`` + ``window_days``,
  or ``warning_levels``): the share of falls while closed and the closure hours
  per year, :func:`riskrf.risk.closure.closure_rule` / :func:`~riskrf.risk.closure.warning_closure`.

How the rate enters the hazard (``rate_from = "rate_model"``).  The rate model
counts recorded events of any size; the hazard needs the rate of falls of at
least ``m_min`` (the power law's lower bound).  The share at or above ``m_min``
is taken from the site inventory's sized falls, so the hazard's rate is

.. math::  \\lambda_{\\ge m_{min}} = \\lambda_{model} \\cdot \\frac{n_{\\ge m_{min}}}{n_{sized}} \\cdot s,

with :math:`\\lambda_{model}` the expected annual rate, :math:`s` the site's
``rate_scale`` (the share of the recorded source above this road; it still
applies).  The falls below ``m_min`` are scaled in the same way.  In practice
this is a factor :math:`f = \\lambda_{model} / (n_{sized} / D)` (D the
inventory's duration) multiplying ``rate_scale`` wherever the inventory's
rate is used.  The record should be the site's own (the default: ``record``
left out means ``inventory.path``); another record's absolute rate is
applied as given.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import pandas as pd

from ..core import file_schemas as _fs
from ..core.schema import record_class
from ..core.validation import is_finite_number

#: Fields of ``[rates]`` and their defaults (those of ``riskrf rates``), from the file's one declaration
#: (:data:`riskrf.core.file_schemas.RATES`).
RATES_FIELDS = _fs.RATES.defaults()
#: Fields ``[inventory]`` gains for the rate source.
INVENTORY_RATE_FIELDS = {"rate_from": "inventory", "rain_factor": None, "heavy_day_mm": None,
                         "heavy_day_change": None}
RATE_SOURCES = ("inventory", "rate_model")

#: The checked ``[rates]`` table (:func:`check_rates`) as a typed record: its declared fields (the record filled in
#: from the inventory when left out, ``season`` None for ``"none"``), ``record_is_inventory`` (the record is the
#: site inventory, read with its reader options), and what was read from its files: ``rainfall_read`` (the daily
#: rainfall, :func:`riskrf.io.rainfall.read_rainfall`), ``record_read`` (the dated record,
#: :func:`riskrf.frequency.inventory.reader.read_inventory`) and ``warnings_read`` (the rainstorm warning list,
#: None when not given).  ``site.rates`` of :class:`riskrf.app.site.Site`.
SiteRatesTable = record_class(_fs.RATES, name="SiteRatesTable",
                              extra=(("record_is_inventory", bool, False), ("rainfall_read", object, None),
                                     ("record_read", object, None), ("warnings_read", object, None)))
SiteRatesTable.__module__ = __name__


def inventory_record(inventory):
    """The site's ``[inventory]`` table as its typed record (:data:`riskrf.core.file_schemas.SITE_RECORDS`).

    Parameters
    ----------
    inventory : InventoryTable, dict or None
        ``site.inventory`` (returned as it is), or the table as written in a mitigation or site file (its declared
        fields are read into the record; others are left to :func:`riskrf.app.site.load_site`, which refuses them),
        or None (no inventory: every default).

    Returns
    -------
    InventoryTable
        The record.
    """
    if isinstance(inventory, _fs.INVENTORY.record_type):
        return inventory
    given = inventory if isinstance(inventory, dict) else {}
    return _fs.INVENTORY.record({k: v for k, v in given.items() if _fs.INVENTORY.field(k) is not None})


def check_rates(given, inventory, path, error=ValueError) -> tuple:
    """Validate ``[rates]`` (``given``; None when absent) and the rate fields of ``[inventory]``.

    Returns the checked ``[rates]`` table as a :data:`SiteRatesTable` (defaults filled, the rainfall, the record and
    the warning list read) or None, and the defaults applied.  Raises ``error`` naming the file, field and value.

    Parameters
    ----------
    given : dict or None
        The site file's ``[rates]`` table as written; None when absent.
    inventory : InventoryTable or dict
        The site file's ``[inventory]`` table (:func:`inventory_record`; its rate fields are checked, and its
        path, start, end and reader options stand in for a record left out).
    path : str or pathlib.Path
        The site file; paths in the table are relative to its directory.
    error : type, optional
        Exception class raised on bad input.

    Returns
    -------
    rates : SiteRatesTable or None
        The checked ``[rates]`` table, or None when ``given`` is None.
    defaults_used : list of str
        The defaults applied, as ``"rates.field = value"`` (empty when ``given`` is None).

    Raises
    ------
    Exception
        ``error``, naming the file, field and value.
    """
    path = Path(path)
    inventory = inventory_record(inventory)
    src = _check_inventory_rate_fields(inventory, path, error)
    if given is None:
        if src == "rate_model":
            raise error(f"{path}: inventory.rate_from = \"rate_model\" needs a [rates] table (record, rainfall) to "
                        "fit the rate model")
        return None, []
    r, used = _merge_rates_table(given, inventory, path, error)
    _check_rates_files(r, path, error)
    r = _check_rates_model_fields(r, inventory.heavy_day_mm, path, error)
    return _read_rates_inputs(r, inventory, path, error), used


def _check_inventory_rate_fields(inventory, path: Path, error) -> str:
    """Check the rate fields of ``[inventory]``: ``rate_from`` and the stated change of climate.

    Parameters
    ----------
    inventory : InventoryTable
        The site file's ``[inventory]`` table (``rate_from``, ``rain_factor`` [-], ``heavy_day_mm`` [mm/day],
        ``heavy_day_change`` [-]).
    path : pathlib.Path
        The site file, named in errors.
    error : type
        Exception class raised for a bad rate source or change of climate.

    Returns
    -------
    str
        The rate source, one of :data:`RATE_SOURCES`.

    Raises
    ------
    Exception
        ``error``, naming the file, field and value.
    """
    src = inventory.rate_from
    if src not in RATE_SOURCES:
        raise error(f"{path}: inventory.rate_from = {src!r} must be one of {list(RATE_SOURCES)} (the inventory's "
                    "mean rate, or the expected rate of the [rates] model)")
    rf, hm, hc = inventory.rain_factor, inventory.heavy_day_mm, inventory.heavy_day_change
    climate = [(k, v) for k, v in (("rain_factor", rf), ("heavy_day_mm", hm), ("heavy_day_change", hc))
               if v is not None]
    if climate and src != "rate_model":
        raise error(f"{path}: inventory.{climate[0][0]} = {climate[0][1]!r} states a change of climate for the "
                    "rate model's rate; it needs inventory.rate_from = \"rate_model\"")
    if rf is not None and (not is_finite_number(rf) or rf <= 0):
        raise error(f"{path}: inventory.rain_factor = {rf!r} must be a number > 0 (1.1: every rainfall 10 % heavier)")
    if (hm is None) != (hc is None):
        raise error(f"{path}: inventory.heavy_day_mm = {hm!r} and inventory.heavy_day_change = {hc!r}: give both "
                    "(the daily rainfall of a heavy-rain day and the change of their frequency, 0.1 = +10 %)")
    if hm is not None and (not is_finite_number(hm) or hm <= 0):
        raise error(f"{path}: inventory.heavy_day_mm = {hm!r} must be a daily rainfall > 0 mm")
    if hc is not None and (not is_finite_number(hc) or hc <= -1):
        raise error(f"{path}: inventory.heavy_day_change = {hc!r} must be a number > -1 (0.1 = heavy days 10 % "
                    "more frequent)")
    return src


def _merge_rates_table(given, inventory, path: Path, error) -> tuple:
    """The ``[rates]`` table with its defaults filled in; the record defaults to the site inventory.

    Parameters
    ----------
    given : object
        The site file's ``[rates]`` table as read (checked to be a table).
    inventory : InventoryTable
        The site file's ``[inventory]`` table (``path``, ``start``, ``end`` stand in for a missing record).
    path : pathlib.Path
        The site file, named in errors.
    error : type
        Exception class raised on bad input.

    Returns
    -------
    rates : SiteRatesTable
        Every field of :data:`RATES_FIELDS` and ``record_is_inventory`` (nothing read yet).
    defaults_used : list of str
        The defaults applied, as text.

    Raises
    ------
    Exception
        ``error`` for a table that is not one, an unknown field (with a did-you-mean), no rainfall or no record.
    """
    if not isinstance(given, dict):
        raise error(f"{path}: [rates] must be a table")
    import difflib
    for key in given:
        if key not in RATES_FIELDS:
            close = difflib.get_close_matches(key, list(RATES_FIELDS), n=1)
            raise error(f"{path}: unknown field rates.{key!r}"
                        + (f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(RATES_FIELDS)}"))
    r = SiteRatesTable(**given)
    used = [f"rates.{k} = {v!r}" for k, v in RATES_FIELDS.items() if k not in given and v is not None]
    if r.rainfall is None:
        raise error(f"{path}: rates.rainfall is required (a daily rainfall file: the Hong Kong Observatory layout or "
                    "the generic date,rainfall_mm CSV)")
    if r.record is None and inventory.path is None:
        raise error(f"{path}: rates.record is required (the dated inventory the rate model counts)")
    if r.record is None:
        r = replace(r, record=inventory.path, start=r.start if r.start is not None else inventory.start,
                    end=r.end if r.end is not None else inventory.end, record_is_inventory=True)
        used.append(f"rates.record = {r.record!r} (inventory.path)")
    return r, used


def _check_rates_files(r, path: Path, error) -> None:
    """The files of a merged ``[rates]`` table (record, rainfall, warnings) exist; its start and end are dates.

    Parameters
    ----------
    r : SiteRatesTable
        The merged ``[rates]`` table (:func:`_merge_rates_table`).
    path : pathlib.Path
        The site file; the table's paths are relative to its directory.
    error : type
        Exception class raised on bad input.

    Raises
    ------
    Exception
        ``error``, naming the file, field and value (and the resolved path of a missing file).
    """
    base = path.parent
    for key, v in (("record", r.record), ("rainfall", r.rainfall), ("warnings", r.warnings)):
        if v is None:
            continue
        if not isinstance(v, str):
            raise error(f"{path}: rates.{key} = {v!r} must be a file name")
        if not (base / v).is_file():
            raise error(f"{path}: rates.{key} = {v!r}: file not found ({(base / v).resolve()})")
    for key, v in (("start", r.start), ("end", r.end)):
        if v is not None:
            try:
                pd.Timestamp(str(v))
            except ValueError:
                raise error(f"{path}: rates.{key} = {v!r} is not a date YYYY-MM-DD") from None


def _check_rates_model_fields(r, heavy_day_mm, path: Path, error):
    """The model options of a merged ``[rates]`` table: period, windows, rainfall transform, season, trend.

    Parameters
    ----------
    r : SiteRatesTable
        The merged ``[rates]`` table (:func:`_merge_rates_table`).
    heavy_day_mm : float or None
        ``inventory.heavy_day_mm`` [mm/day]; when given the model must be daily with the day itself as first window.
    path : pathlib.Path
        The site file, named in errors.
    error : type
        Exception class raised on bad input.

    Returns
    -------
    SiteRatesTable
        ``r`` with its season normalised (``"none"`` becomes None).

    Raises
    ------
    Exception
        ``error``, naming the file, field and value.
    """
    from ..frequency.rates.design import _PERIODS, _SEASONS
    from ..frequency.rates.result import _TRANSFORMS

    if r.period not in _PERIODS:
        raise error(f"{path}: rates.period = {r.period!r} must be one of {list(_PERIODS)}")
    w = r.windows_days
    if not (isinstance(w, list) and w and all(isinstance(x, int) and not isinstance(x, bool) and x >= 1 for x in w)
            and w == sorted(set(w))):
        raise error(f"{path}: rates.windows_days = {w!r} must be increasing whole numbers of days >= 1, e.g. "
                    "[1, 3, 15]")
    if r.rain_transform not in _TRANSFORMS:
        raise error(f"{path}: rates.rain_transform = {r.rain_transform!r} must be one of {list(_TRANSFORMS)}")
    season = None if r.season == "none" else r.season
    if season not in _SEASONS:
        raise error(f"{path}: rates.season = {r.season!r} must be one of harmonic, wet, month, none")
    r = replace(r, season=season)
    if not isinstance(r.trend, bool):
        raise error(f"{path}: rates.trend = {r.trend!r} must be true or false")
    if heavy_day_mm is not None and (r.period != "day" or r.windows_days[0] != 1):
        raise error(f"{path}: inventory.heavy_day_mm needs a daily rate model whose first window is the day itself "
                    f"(rates.period = 'day', windows_days starting with 1); got period {r.period!r}, windows "
                    f"{r.windows_days!r}")
    return r


def _reader_options(inventory) -> dict:
    """The inventory reader's options given in ``[inventory]`` (:data:`READER_OPTIONS` that are set)."""
    from ..frequency.inventory.reader import READER_OPTIONS
    return {k: getattr(inventory, k) for k in READER_OPTIONS if getattr(inventory, k) is not None}


def _read_rates_inputs(r, inventory, path: Path, error):
    """Read the rainfall, the record and the warning list of a checked ``[rates]`` table.

    The record's period must be known and covered by the rainfall, with the longest antecedent window of a daily
    model.  The readers' warnings are silenced here: they come again when the model is fitted.

    Parameters
    ----------
    r : SiteRatesTable
        The checked ``[rates]`` table (files, dates and model options checked).
    inventory : InventoryTable
        The site file's ``[inventory]`` table (its reader options apply when the record is the inventory).
    path : pathlib.Path
        The site file; the rainfall, record and warning files are relative to its directory.
    error : type
        Exception class raised when a file cannot be read or the rainfall does not cover the record.

    Returns
    -------
    SiteRatesTable
        ``r`` with ``rainfall_read``, ``record_read`` and ``warnings_read`` (None when not given).

    Raises
    ------
    Exception
        ``error``, naming the file, field, value and the reader's message.
    """
    from .closure import read_rainstorm_warnings
    from ..io.rainfall import read_rainfall
    from ..frequency.inventory.reader import read_inventory

    base = path.parent
    w = r.windows_days
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")       # gaps are reported again when the model is fitted
            rainfall = read_rainfall(base / r.rainfall)
    except ValueError as exc:
        raise error(f"{path}: rates.rainfall = {r.rainfall!r}: {exc}") from exc
    # the record and its period against the rainfall (gaps, coverage with the antecedent window), read now
    reader = _reader_options(inventory) if r.record_is_inventory else {}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")       # the reader's notes come again with the model's
            record = read_inventory(base / r.record, start=r.start, end=r.end, **reader)
    except (ValueError, TypeError) as exc:
        raise error(f"{path}: rates.record = {r.record!r}: {exc}") from exc
    if record.start is None or record.end is None:
        raise error(f"{path}: rates.record = {r.record!r}: its record period is unknown; give rates.start and "
                    "rates.end (or a sidecar .toml with [record] start, end)")
    lead = max(w) - 1 if r.period == "day" else 0
    start = pd.Timestamp(record.start) - pd.Timedelta(days=lead)
    try:
        rainfall.check_covers(start, record.end, f"rates.record {r.record!r} ({pd.Timestamp(record.start).date()} "
                              f"to {pd.Timestamp(record.end).date()}" + (f", with its {max(w)}-day antecedent "
                                                                         "window)" if lead else ")"))
    except ValueError as exc:
        raise error(f"{path}: rates.rainfall = {r.rainfall!r}: {exc}") from exc
    warning_list = None
    if r.warnings is not None:
        try:
            warning_list = read_rainstorm_warnings(base / r.warnings)
        except ValueError as exc:
            raise error(f"{path}: rates.warnings = {r.warnings!r}: {exc}") from exc
    return replace(r, rainfall_read=rainfall, record_read=record, warnings_read=warning_list)


def check_closure_options(options, rates, path, error=ValueError) -> None:
    """Closure options given as rules need a daily ``[rates]`` model, and warning rules its warning list.

    Parameters
    ----------
    options : iterable of riskrf.risk.mitigation_inputs.Option
        The study's options.
    rates : SiteRatesTable or None
        The checked ``[rates]`` table (:func:`check_rates`), or None.
    path : str or pathlib.Path
        The site file, named in errors.
    error : type, optional
        Exception class raised on bad input.

    Raises
    ------
    Exception
        ``error``, naming the file, option and field.
    """
    for o in options:
        if o.kind != "closure" or not o.has_closure_rule:
            continue
        where = f"{path}: option {o.name!r}"
        if rates is None:
            raise error(f"{where}: a closure rule ({o.rule_text()}) is computed from the site's rate model: add a "
                        "[rates] table (record, rainfall), or type share_while_closed and closure_hours_per_year "
                        "(an assumption)")
        if rates.period != "day":
            raise error(f"{where}: a closure rule needs a daily rate model; rates.period = {rates.period!r}")
        if o.warning_levels is not None:
            if rates.warnings_read is None:
                raise error(f"{where}: warning_levels = {list(o.warning_levels)!r} needs the rainstorm warning list: "
                            "give rates.warnings (a file)")
            known = set(rates.warnings_read["level"])
            bad = [v for v in o.warning_levels if v not in known]
            if bad:
                raise error(f"{where}: warning_levels {bad!r} do not occur in rates.warnings = "
                            f"{rates.warnings!r} (levels: {sorted(known)})")


@dataclass(frozen=True)
class SiteRates:
    """What a run takes from the site's rate model (see the module docstring).

    Attributes
    ----------
    record, rainfall : str
        The dated record and the rainfall file the model was fitted to.
    period : str
        Counting period of the model.
    preferred : str
        The preferred count model (``"negative binomial"`` or ``"Poisson"``).
    start, end : pandas.Timestamp
        The record period.
    observed_rate : float
        Recorded events per year in the model's record [1/yr].
    expected_rate : float
        Expected events per year over the record's rainfall climate, trend at the end of the record [1/yr].
    climate_rate : float
        The same under the stated change of climate (= ``expected_rate`` when none) [1/yr].
    climate : str
        The stated change of climate in words ("" when none).
    closures : dict
        Option name -> :class:`riskrf.risk.closure.ClosureRule` for the closure options given as rules.
    model_summary : pandas.DataFrame
        :meth:`RateModel.summary` of the fitted model.
    notes : tuple of str
        Warnings raised while fitting.
    """

    record: str
    rainfall: str
    period: str
    preferred: str
    start: pd.Timestamp
    end: pd.Timestamp
    observed_rate: float
    expected_rate: float
    climate_rate: float
    climate: str
    closures: dict
    model_summary: pd.DataFrame
    notes: tuple = field(default_factory=tuple)

    def rate_text(self) -> str:
        """Where the hazard's rate comes from, in words, for rate_from = "rate_model".

        Returns
        -------
        str
            The sentence, rates in events per year [1/yr].
        """
        every = {"day": "daily", "month": "monthly", "year": "yearly"}.get(self.period, self.period)
        text = (f"expected rate of the {self.preferred} {every} rate model of {Path(self.record).name} "
                f"({self.start.year}-{self.end.year}) on the rainfall of {Path(self.rainfall).name}: "
                f"{self.expected_rate:.4g} events per year over the record's rainfall climate, trend at "
                f"{self.end.year} (recorded mean {self.observed_rate:.4g})")
        if self.climate:
            text += (f"; under the stated change of climate ({self.climate}; an ASSUMPTION) "
                     f"{self.climate_rate:.4g} events per year")
        return text

    def hazard_factor(self, inventory) -> float:
        """Factor on ``rate_scale`` making the inventory's rate the model's: climate_rate / (sized falls / duration).

        Parameters
        ----------
        inventory : riskrf.frequency.inventory.Inventory
            The site inventory (its sized falls ``masses`` and ``duration_years`` [yr]).

        Returns
        -------
        float
            The factor [-].

        Raises
        ------
        ValueError
            When the inventory has no sized falls.
        """
        n = int(len(inventory.masses))
        if n == 0:
            raise ValueError(f"{inventory.source}: no sized falls; the rate model's rate cannot be split by size")
        return self.climate_rate / (n / inventory.duration_years)

    def summary(self) -> dict:
        """Machine-readable figures (summary.json).

        Returns
        -------
        dict
            Record, rainfall, period, model, dates, rates [1/yr], change of climate, closures (share [-], hours per year
            [h/yr], closures per year [1/yr], cost per hour [currency/h]) and notes.
        """
        return {"record": self.record, "rainfall": self.rainfall, "period": self.period,
                "preferred_model": self.preferred, "start": str(self.start.date()), "end": str(self.end.date()),
                "observed_rate_per_year": self.observed_rate, "expected_rate_per_year": self.expected_rate,
                "climate_change": self.climate or None, "climate_rate_per_year": self.climate_rate,
                "closures": {name: {"rule": c.rule, "share_while_closed": c.effectiveness,
                                    "recorded_share_while_closed": c.observed_share,
                                    "closure_hours_per_year": c.closure_hours_per_year,
                                    "closures_per_year": c.closures_per_year, "cost_per_hour": c.cost_per_hour,
                                    "evaluated_from": str(c.start.date()), "evaluated_to": str(c.end.date())}
                             for name, c in self.closures.items()},
                "notes": list(self.notes)}


def evaluate_rates(rates, base, inventory, options=()) -> SiteRates:
    """Fit the rate model of a checked ``[rates]`` table (:func:`check_rates`) and compute the expected rates and
    every closure rule among ``options``.  ``base`` is the directory paths are relative to.

    Parameters
    ----------
    rates : SiteRatesTable
        The checked ``[rates]`` table (``site.rates``).
    base : str or pathlib.Path
        Directory the table's paths are relative to.
    inventory : InventoryTable or dict
        The site file's ``[inventory]`` table (:func:`inventory_record`; change of climate: ``rain_factor``,
        ``heavy_day_mm`` [mm], ``heavy_day_change``).
    options : iterable of riskrf.risk.mitigation_inputs.Option, optional
        The study's options; closure rules among them are evaluated.

    Returns
    -------
    SiteRates
        Rates [1/yr] and closure rules of the fitted model.
    """
    from .closure import closure_rule, warning_closure
    from ..frequency.inventory.reader import read_inventory
    from ..frequency.rates.fit import rate_model

    base = Path(base)
    inventory = inventory_record(inventory)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        record = rates.record_read          # read by check_rates
        if record is None:
            reader = _reader_options(inventory) if rates.record_is_inventory else {}
            record = read_inventory(base / rates.record, start=rates.start, end=rates.end, **reader)
        model = rate_model(record, rates.rainfall_read, period=rates.period,
                           windows_days=tuple(rates.windows_days), season=rates.season, trend=rates.trend,
                           rain_transform=rates.rain_transform)
        expected = model.expected_annual_rate()
        rf, hm, hc = inventory.rain_factor, inventory.heavy_day_mm, inventory.heavy_day_change
        climate = []
        if rf is not None and rf != 1:
            climate.append(f"every rainfall x {rf:g}")
        if hm is not None and hc:
            climate.append(f"days with >= {hm:g} mm {hc:+.0%} as frequent")
        changed = model.expected_annual_rate(rain_factor=rf if rf is not None else 1.0, heavy_day_mm=hm,
                                             heavy_day_change=hc or 0.0) if climate else expected
        closures = {}
        for o in options:
            if o.kind != "closure" or not o.has_closure_rule:
                continue
            if o.threshold_mm is not None:
                closures[o.name] = closure_rule(model, o.threshold_mm, window_days=int(o.window_days or 1),
                                                cost_per_hour=o.cost_per_closure_hour)
            else:
                closures[o.name] = warning_closure(model, rates.warnings_read, levels=o.warning_levels,
                                                   cost_per_hour=o.cost_per_closure_hour)
    notes = []
    for w in [str(c.message) for c in caught if issubclass(c.category, UserWarning)] + list(model.notes):
        if w not in notes:
            notes.append(w)
    years = model.design["exposure_days"].sum() / 365.25
    return SiteRates(record=str(base / rates.record), rainfall=str(base / rates.rainfall), period=model.period,
                     preferred=model.preferred, start=model.start, end=model.end,
                     observed_rate=float(model.n_events / years), expected_rate=float(expected),
                     climate_rate=float(changed), climate="; ".join(climate), closures=closures,
                     model_summary=model.summary(), notes=tuple(notes))


def resolve_closures(options, site_rates: SiteRates | None) -> tuple:
    """The options with each closure rule's share and hours filled in from ``site_rates`` (costs added to the
    annual maintenance, the rule and its source in ``closure_rule``); other options unchanged.

    Parameters
    ----------
    options : iterable of riskrf.risk.mitigation_inputs.Option
        The study's options.
    site_rates : SiteRates or None
        The evaluated rate model.

    Returns
    -------
    tuple of riskrf.risk.mitigation_inputs.Option
        The options, closure rules resolved (share [-], hours per year [h/yr]).

    Raises
    ------
    ValueError
        When a closure rule was not evaluated.
    """
    out = []
    for o in options:
        if o.kind == "closure" and o.has_closure_rule:
            if site_rates is None or o.name not in site_rates.closures:
                raise ValueError(f"option {o.name!r}: its closure rule was not evaluated (no rate model)")
            c = site_rates.closures[o.name]
            o = replace(o, share_while_closed=float(c.effectiveness),
                        closure_hours_per_year=float(c.closure_hours_per_year),
                        annual_maintenance=o.annual_maintenance + c.annual_cost,
                        closure_rule=(f"{c.rule}, computed from the {site_rates.preferred} daily rate model of "
                                      f"{Path(site_rates.record).name} and {Path(site_rates.rainfall).name} over "
                                      f"{c.start.year}-{c.end.year} (recorded falls on closed time: "
                                      f"{c.observed_share:.1%})"))
        out.append(o)
    return tuple(out)
