"""Argument checks shared by every module: each error names the argument and the value."""
from __future__ import annotations

import math
import warnings

import numpy as np

from simulation.errors import RiskrfError  # noqa: F401  (its home is the lower package; exported by riskrf)
from simulation.units import DEFAULT_DENSITY_KG_M3, DENSITY_RANGE_KG_M3  # noqa: F401  (their home; riskrf modules import them from here)




class RiskrfWarning(UserWarning):
    """A result was computed, but a user should know something about it."""


def warn(message: str) -> None:
    """Issue a :class:`RiskrfWarning` that points at the caller's caller.

    Parameters
    ----------
    message : str
        The warning's text (naming the file, field or argument it is about).
    """
    warnings.warn(message, RiskrfWarning, stacklevel=3)


def is_finite_number(value) -> bool:
    """True when ``value`` is a finite int or float as read from a file (a bool is not a number).

    Parameters
    ----------
    value : object
        The value as given (e.g. a TOML field), in any unit.

    Returns
    -------
    bool
        Whether ``value`` is an ``int`` or ``float``, not a ``bool``, and finite.
    """
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def as_positive_array(values, name: str, *, allow_empty: bool = False) -> np.ndarray:
    """Return ``values`` as a 1-D float array, all finite and > 0.

    Parameters
    ----------
    values : array_like
        Numbers in any unit (masses [kg], volumes [m³], ...); flattened.
    name : str
        The argument's name, for the message.
    allow_empty : bool
        Accept an empty input (default: refuse it).

    Returns
    -------
    numpy.ndarray
        1-D float64 array, same unit as ``values``.

    Raises
    ------
    TypeError
        ``values`` is not numeric.
    ValueError
        Naming ``name``, the first bad position and its value (not finite or <= 0), or an empty input.
    """
    try:
        arr = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be numeric; got {values!r:.80}") from exc
    if arr.size == 0 and not allow_empty:
        raise ValueError(f"{name} is empty: at least one value is needed")
    bad = ~np.isfinite(arr) | (arr <= 0)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{name}[{i}] = {float(arr[i])!r}: every value must be finite and > 0")
    return arr


def check_positive(value, name: str) -> float:
    """Return ``value`` as a float, raising if it is not finite and > 0.

    Parameters
    ----------
    value : float
        The number, in any unit.
    name : str
        The argument's name, for the message.

    Returns
    -------
    float
        ``float(value)``, same unit.

    Raises
    ------
    TypeError, ValueError
        Naming ``name`` and ``value``.
    """
    try:
        v = float(value)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a number; got {value!r}") from exc
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be finite and > 0; got {value!r}")
    return v


def check_density(value, name: str = "density_kg_m3") -> float:
    """Return a rock density [kg/m³] as a float, refusing one outside :data:`DENSITY_RANGE_KG_M3`.

    Parameters
    ----------
    value : float
        The density as given [kg/m³].
    name : str
        The argument or field, for the message (e.g. ``"--density"`` or ``"site.toml: inventory.density_kg_m3"``).

    Returns
    -------
    float
        The density [kg/m³].

    Raises
    ------
    TypeError, ValueError
        Naming ``name`` and the value; a value below 500 suggests g/cm³ (2.65 → 2650 kg/m³).
    """
    v = check_positive(value, name)
    lo, hi = DENSITY_RANGE_KG_M3
    if not lo <= v <= hi:
        hint = (f"; {v:g} looks like g/cm3 or t/m3: {v:g} g/cm3 is {v * 1000:g} kg/m3" if 0.5 <= v <= 6 else
                f"; {v:g} looks like g/m3: that is {v / 1000:g} kg/m3" if lo * 1000 <= v <= hi * 1000 else "")
        raise ValueError(f"{name} = {value!r}: a rock density must lie between {lo:,.0f} and {hi:,.0f} kg/m3 "
                         f"(pumice to magnetite ore; granite 2,650, limestone 2,700){hint}")
    return v


def check_probability_level(level, name: str = "level") -> float:
    """Return a confidence level in (0, 1).

    Parameters
    ----------
    level : float
        Confidence level, e.g. 0.95 (not 95).
    name : str
        The argument's name, for the message.

    Returns
    -------
    float
        The level [-].
    """
    v = float(level)
    if not 0.0 < v < 1.0:
        raise ValueError(f"{name} must lie strictly between 0 and 1; got {level!r}")
    return v


def check_return_periods(T, name: str = "T") -> np.ndarray:
    """Return periods in years must be > 1 (a T-year event has annual probability 1/T).

    Parameters
    ----------
    T : float or array_like
        Return period(s) [yr].
    name : str
        The argument's name, for the message.

    Returns
    -------
    numpy.ndarray
        ``T`` as a float array [yr], same shape.

    Raises
    ------
    ValueError
        Naming ``name`` and the first value not finite or not > 1 yr.
    """
    arr = np.asarray(T, dtype=float)
    bad = ~np.isfinite(arr) | (arr <= 1.0)
    if bad.any():
        raise ValueError(f"{name} = {arr[bad].ravel()[0]!r}: return periods must be finite and > 1 year")
    return arr


def check_choice(value, name: str, choices) -> str:
    """Return ``value`` if it is one of ``choices``, else raise naming the options.

    Parameters
    ----------
    value : object
        The value given.
    name : str
        The argument's name, for the message.
    choices : iterable
        The accepted values.

    Returns
    -------
    object
        ``value`` unchanged.
    """
    if value not in choices:
        raise ValueError(f"{name} = {value!r} is not one of {', '.join(map(repr, choices))}")
    return value
