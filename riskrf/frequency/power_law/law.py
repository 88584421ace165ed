"""Formulas of the (optionally upper-truncated) power law of one fall's size above m_min.

P(M > m) = (m / m_min)^-b, or renormalised between m_min and m_max when truncated (Corominas et al. 2018):
P(M > m) = (m^-b - m_max^-b) / (m_min^-b - m_max^-b); b is the cumulative exponent (Clauset's alpha = b + 1).
Sizes in kg (or any one size unit), b dimensionless.
"""
from __future__ import annotations

import numpy as np
from scipy import optimize


def _truncated_sf(m, b, m_min, m_max):
    """P(M > m) for the (optionally upper-truncated) power law on [m_min, m_max]."""
    m = np.asarray(m, dtype=float)
    z = np.clip(m, m_min, m_max if m_max is not None else np.inf)
    if m_max is None:
        return (z / m_min) ** (-b)
    top = m_max ** (-b)
    return np.clip((z ** (-b) - top) / (m_min ** (-b) - top), 0.0, 1.0)


def _truncated_isf(p, b, m_min, m_max):
    p = np.asarray(p, dtype=float)
    if m_max is None:
        return m_min * p ** (-1.0 / b)
    top = m_max ** (-b)
    return (top + p * (m_min ** (-b) - top)) ** (-1.0 / b)


def _loglik_power(x, b, m_min, m_max):
    """Pointwise log density of the (truncated) power law with cumulative exponent b."""
    norm = m_min ** (-b) - (m_max ** (-b) if m_max is not None else 0.0)
    return np.log(b) - (b + 1.0) * np.log(x) - np.log(norm)


def _mle_truncated_b(x, m_min, m_max):
    """MLE of b for the upper-truncated law, and its standard error from the observed information."""
    def nll(b):
        return -np.sum(_loglik_power(x, b, m_min, m_max))
    b0 = len(x) / np.sum(np.log(x / m_min))
    res = optimize.minimize_scalar(nll, bounds=(1e-6, max(20.0, 5 * b0)), method="bounded",
                                   options={"xatol": 1e-10})
    b = float(res.x)
    h = 1e-4 * b
    info = (nll(b + h) - 2 * nll(b) + nll(b - h)) / h ** 2
    return b, float(1.0 / np.sqrt(info)) if info > 0 else np.nan

