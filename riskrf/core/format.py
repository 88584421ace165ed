"""Numbers for people: significant figures, money and probabilities, used by error messages and reports alike.

Numbers carry only the figures their uncertainty supports: 2-3 significant figures for estimated quantities
(an energy with a ±45 % interval is "300,000 kJ", not "3.044e+05 kJ"), whole units with thousands separators
and the currency for money, and never Python's ``e+05`` notation.  Very small probabilities are written as
"2.9 × 10⁻⁶".  Plain Python (no numpy, pandas or matplotlib), so every stage can import it.
"""
from __future__ import annotations

import math

_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def sig(x, digits: int = 3) -> str:
    """``x`` to ``digits`` significant figures, with thousands separators and no exponent notation
    between 10⁻³ and 10¹²; outside that range as "a.b × 10ⁿ".  NaN and None give an empty string.

    Parameters
    ----------
    x : float, int, None or object
        The number, in whatever unit the caller prints beside it; a value ``float()`` cannot read is returned
        as ``str(x)``.
    digits : int
        Significant figures kept (default 3).

    Returns
    -------
    str
        E.g. ``sig(304412.7)`` → ``"304,000"``, ``sig(0.000029)`` → ``"2.9 × 10⁻⁵"``; ``"∞"`` for infinity,
        a minus sign (U+2212) for negatives.
    """
    if x is None:
        return ""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return str(x)
    if math.isnan(v):
        return ""
    if math.isinf(v):
        return "∞" if v > 0 else "−∞"
    if v == 0:
        return "0"
    exponent = math.floor(math.log10(abs(v)))
    if exponent < -3 or exponent >= 12:
        mantissa = v / 10 ** exponent
        m = f"{mantissa:.{max(digits - 1, 0)}f}".rstrip("0").rstrip(".")
        if m in ("10", "-10"):                     # rounding carried over
            m, exponent = m[:-1], exponent + 1
        return f"{m} × 10{str(exponent).translate(_SUPERSCRIPT)}"
    decimals = max(digits - 1 - exponent, 0)
    if decimals:
        text = f"{v:,.{decimals}f}".rstrip("0").rstrip(".")      # 0.50 -> 0.5: no false precision either way
    else:
        text = f"{round(v, -(exponent - digits + 1)):,.0f}"
    return text.replace("-", "−") if text.startswith("-") else text


def money(x, currency: str = "", sig: int | None = None) -> str:
    """Money for a manager: whole units with thousands separators and the currency, e.g. "1,250,000 CHF".

    Parameters
    ----------
    x : float or None
        The amount, in ``currency``; None or NaN give an empty string.
    currency : str
        Currency label written after the number (e.g. ``"CHF"``); empty for none.
    sig : int, optional
        Round to that many significant figures first, for uncertain amounts (means, intervals, expected
        losses): ``money(775390, "CHF", sig=3)`` gives "775,000 CHF".  Typed inputs (capital costs) are shown in
        full (``sig=None``).

    Returns
    -------
    str
        Whole units with thousands separators, then the currency.
    """
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return ""
    v = float(x)
    if sig is not None and v != 0 and math.isfinite(v):
        v = round(v, int(sig) - 1 - math.floor(math.log10(abs(v))))
    text = f"{v:,.0f}".replace("-", "−")
    return f"{text} {currency}".strip()


def probability(p) -> str:
    """A probability or annual frequency: 2 significant figures, powers of ten below 0.001.

    Parameters
    ----------
    p : float
        A probability [-] or an annual frequency [1/yr].

    Returns
    -------
    str
        ``sig(p, 2)``: e.g. ``"0.012"``, ``"2.9 × 10⁻⁶"``.
    """
    return sig(p, 2)
