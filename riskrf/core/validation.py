"""Argument checks shared by every module: each error names the argument and the value."""
from __future__ import annotations

import warnings

import numpy as np


class RiskrfError(Exception):
    """Base of every riskrf input error (site, corridor, mitigation, measures, decision tree, nil hazard), so that
    ``except riskrf.RiskrfError`` catches them all.  Each concrete error also derives from the built-in it was
    before (:class:`ValueError`), so existing ``except ValueError`` code keeps working."""


class RiskrfWarning(UserWarning):
    """A result was computed, but a user should know something about it."""


def warn(message: str) -> None:
    """Issue a :class:`RiskrfWarning` that points at the caller's caller."""
    warnings.warn(message, RiskrfWarning, stacklevel=3)


def as_positive_array(values, name: str, *, allow_empty: bool = False) -> np.ndarray:
    """Return ``values`` as a 1-D float array, all finite and > 0.

    Raises ``ValueError`` naming ``name``, the first bad position and its value.
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
    """Return ``value`` as a float, raising if it is not finite and > 0."""
    try:
        v = float(value)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be a number; got {value!r}") from exc
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be finite and > 0; got {value!r}")
    return v


def check_probability_level(level, name: str = "level") -> float:
    """Return a confidence level in (0, 1)."""
    v = float(level)
    if not 0.0 < v < 1.0:
        raise ValueError(f"{name} must lie strictly between 0 and 1; got {level!r}")
    return v


def check_return_periods(T, name: str = "T") -> np.ndarray:
    """Return periods in years must be > 1 (a T-year event has annual probability 1/T)."""
    arr = np.asarray(T, dtype=float)
    bad = ~np.isfinite(arr) | (arr <= 1.0)
    if bad.any():
        raise ValueError(f"{name} = {arr[bad].ravel()[0]!r}: return periods must be finite and > 1 year")
    return arr


def check_choice(value, name: str, choices) -> str:
    """Return ``value`` if it is one of ``choices``, else raise naming the options."""
    if value not in choices:
        raise ValueError(f"{name} = {value!r} is not one of {', '.join(map(repr, choices))}")
    return value
