"""Notebook display of result objects, shared by :mod:`simulation` and :mod:`riskrf` (which may import simulation;
simulation imports nothing of riskrf).

A result class mixes in :class:`Displayed`, defines ``summary()`` (a :class:`pandas.DataFrame`) and a short
``__repr__`` (usually built with :func:`short_repr`); Jupyter then shows the repr as a title above the summary
table (``_repr_html_``).  Nothing here imports pandas or matplotlib at module level.
"""
from __future__ import annotations

import html
import numbers


def fmt(value) -> str:
    """A value as short text for a repr: numbers to 4 significant digits, strings quoted, others by ``repr``.

    Parameters
    ----------
    value : object
        The value to show.

    Returns
    -------
    str
        ``"1.235e+05"``/``"0.8707"`` for a float, ``"12"`` for an integer, ``"'name'"`` for a string.
    """
    if isinstance(value, bool) or value is None:
        return repr(value)
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return f"{float(value):.4g}"
    if isinstance(value, str):
        return repr(value if len(value) <= 60 else value[:57] + "...")
    return repr(value)


def short_repr(obj, *parts, **fields) -> str:
    """``ClassName(part, ..., key=value, ...)`` on one line, values through :func:`fmt`.

    Parameters
    ----------
    obj : object
        The object whose class names the repr.
    *parts : str
        Free text items shown first, as given (e.g. ``"1,234 events"``).
    **fields : object
        Named values, shown as ``key=value``; ``None`` values are left out.

    Returns
    -------
    str
        One line.
    """
    items = [str(p) for p in parts] + [f"{k}={fmt(v)}" for k, v in fields.items() if v is not None]
    return f"{type(obj).__name__}({', '.join(items)})"


class Displayed:
    """Mix-in: ``_repr_html_`` (Jupyter's rich display) from the object's ``repr`` and its ``summary()`` table."""

    def _repr_html_(self) -> str:
        """HTML for a notebook: the short repr as a title, then ``summary()`` as a table.

        Returns
        -------
        str
            An HTML fragment (a ``<div>``).
        """
        table = self.summary()
        body = table.to_html(index=not _plain_index(table), float_format=lambda v: f"{v:.4g}", na_rep="",
                             border=0)
        return f"<div><p><b>{html.escape(repr(self))}</b></p>{body}</div>"


def _plain_index(table) -> bool:
    """True when the table's index is the default 0..n-1 (not worth showing)."""
    import pandas as pd
    return isinstance(table.index, pd.RangeIndex) and table.index.start == 0 and table.index.step == 1


def axes(ax=None, figsize=(7.0, 4.5)):
    """``ax``, or the axes of a new matplotlib figure (pyplot imported only here, no global style changed).

    Parameters
    ----------
    ax : matplotlib.axes.Axes or None
        Axes to draw on; None for a new figure.
    figsize : tuple of float
        Size of a new figure [inches].

    Returns
    -------
    matplotlib.axes.Axes
    """
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt
    return plt.figure(figsize=figsize).add_subplot()
