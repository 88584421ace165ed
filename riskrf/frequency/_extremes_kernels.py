"""Compiled inner loops of the GEV/Gumbel maximum-likelihood fit and profile-likelihood interval.

Kept apart from :mod:`riskrf.frequency.extremes` so that the statistics read as statistics.
:func:`profile_nll_min` minimises the negative log-likelihood of a Gumbel
(``model=0``) or GEV (``model=1``) fit over its free parameters at a fixed
return level z, in the feasible reparametrisation described in
:meth:`riskrf.frequency.extremes.GEVFit._profile_map`; a small Nelder-Mead simplex search
(Nelder & Mead 1965, the standard coefficients 1, 2, 1/2, 1/2) does the work.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def profile_nll(model, u, z, ly, x, lo, hi):
    """Negative log-likelihood at return level z; ``ly = ln(-ln(1 - q))``, q the exceedance probability.

    model 0 (Gumbel): u = (ln sigma,), mu = z + sigma ly.
    model 2 (full GEV fit, Coles 2001 eq. 3.7): u = ((mu - z) / ly, ln(sigma / ly), xi), z and ly
    then being a reference location and scale.
    model 1 (GEV): u = (xi, t), sigma = max(0, xi (z - lo), xi (z - hi)) e^(xi ly) + e^t,
    mu = z - sigma (e^(-xi ly) - 1) / xi  (Coles 2001, eq. 3.4 solved for mu).
    """
    n = x.shape[0]
    if model == 2:
        # full GEV likelihood in standardised coordinates: mu = z + ly u0, sigma = ly e^u1, xi = u2
        if not (abs(u[1]) < 700.0 and abs(u[2]) < 20.0):
            return np.inf
        mu = z + ly * u[0]
        sigma = ly * np.exp(u[1])
        xi = u[2]
        s = 0.0
        if abs(xi) < 1e-8:
            for i in range(n):
                w = (x[i] - mu) / sigma
                s += w + np.exp(-w)
            return n * np.log(sigma) + s
        for i in range(n):
            arg = 1.0 + xi * (x[i] - mu) / sigma
            if arg <= 0.0:
                return np.inf
            la = np.log(arg)
            s += (1.0 + 1.0 / xi) * la + np.exp(-la / xi)
        return n * np.log(sigma) + s
    if model == 0:
        t = u[0]
        if not abs(t) < 700.0:
            return np.inf
        sigma = np.exp(t)
        mu = z + sigma * ly
        s = 0.0
        for i in range(n):
            w = (x[i] - mu) / sigma
            s += w + np.exp(-w)
        return n * np.log(sigma) + s
    xi = u[0]
    t = u[1]
    if not (abs(xi) < 20.0 and abs(t) < 700.0):
        return np.inf
    reach = max(0.0, max(xi * (z - lo), xi * (z - hi)))
    sigma = reach * np.exp(xi * ly) + np.exp(t)
    s = 0.0
    if abs(xi) < 1e-8:
        mu = z + sigma * ly
        for i in range(n):
            w = (x[i] - mu) / sigma
            s += w + np.exp(-w)
        return n * np.log(sigma) + s
    base = np.exp(-xi * ly)
    for i in range(n):
        arg = base + xi * (x[i] - z) / sigma
        if arg <= 0.0:
            return np.inf
        la = np.log(arg)
        s += (1.0 + 1.0 / xi) * la + np.exp(-la / xi)
    return n * np.log(sigma) + s


@njit(cache=True)
def profile_nll_min(model, u0, z, ly, x, step, xatol, fatol, maxiter):
    """Nelder-Mead minimum of :func:`profile_nll` from ``u0`` (initial simplex u0 + step e_i).

    Written with scalar loops only (the k + 1 vertices kept in order by insertion, no row slicing, sorting or
    array reductions): numba then compiles it in about 2 CPU-s instead of 7.

    Returns (minimum, argmin).
    """
    lo = x[0]
    hi = x[0]
    for i in range(1, x.shape[0]):
        lo = min(lo, x[i])
        hi = max(hi, x[i])
    k = u0.shape[0]
    sim = np.empty((k + 1, k))
    row = np.empty(k)
    f = np.empty(k + 1)
    for j in range(k + 1):
        for i in range(k):
            sim[j, i] = u0[i]
        if j > 0:
            sim[j, j - 1] += step
        for i in range(k):
            row[i] = sim[j, i]
        f[j] = profile_nll(model, row, z, ly, x, lo, hi)
    xr = np.empty(k)
    xe = np.empty(k)
    xc = np.empty(k)
    cen = np.empty(k)
    for _ in range(maxiter):
        for a in range(1, k + 1):        # insertion sort of the k + 1 vertices by f
            b = a
            while b > 0 and f[b] < f[b - 1]:
                f[b], f[b - 1] = f[b - 1], f[b]
                for i in range(k):
                    sim[b, i], sim[b - 1, i] = sim[b - 1, i], sim[b, i]
                b -= 1
        xspread = 0.0
        fspread = 0.0
        for j in range(1, k + 1):
            fspread = max(fspread, abs(f[j] - f[0]))
            for i in range(k):
                xspread = max(xspread, abs(sim[j, i] - sim[0, i]))
        if xspread <= xatol and fspread <= fatol:
            break
        for i in range(k):
            cen[i] = 0.0
            for j in range(k):
                cen[i] += sim[j, i] / k
        for i in range(k):
            xr[i] = cen[i] + (cen[i] - sim[k, i])
        fr = profile_nll(model, xr, z, ly, x, lo, hi)
        if fr < f[0]:
            for i in range(k):
                xe[i] = cen[i] + 2.0 * (cen[i] - sim[k, i])
            fe = profile_nll(model, xe, z, ly, x, lo, hi)
            if fe < fr:
                for i in range(k):
                    sim[k, i] = xe[i]
                f[k] = fe
            else:
                for i in range(k):
                    sim[k, i] = xr[i]
                f[k] = fr
        elif fr < f[k - 1]:
            for i in range(k):
                sim[k, i] = xr[i]
            f[k] = fr
        else:
            if fr < f[k]:
                for i in range(k):
                    xc[i] = cen[i] + 0.5 * (xr[i] - cen[i])
            else:
                for i in range(k):
                    xc[i] = cen[i] + 0.5 * (sim[k, i] - cen[i])
            fc = profile_nll(model, xc, z, ly, x, lo, hi)
            if fc < min(fr, f[k]):
                for i in range(k):
                    sim[k, i] = xc[i]
                f[k] = fc
            else:
                for j in range(1, k + 1):
                    for i in range(k):
                        sim[j, i] = sim[0, i] + 0.5 * (sim[j, i] - sim[0, i])
                        row[i] = sim[j, i]
                    f[j] = profile_nll(model, row, z, ly, x, lo, hi)
    best = 0
    for j in range(1, k + 1):
        if f[j] < f[best]:
            best = j
    for i in range(k):
        row[i] = sim[best, i]
    return f[best], row
