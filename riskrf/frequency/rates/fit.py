""":func:`rate_model`: the count regressions fitted to the design, compared and tested.

The Poisson GLM and the negative binomial (NB2) regression, its dispersion found by profiling
(:func:`_fit_negbin`); their comparison by AIC and deviance with the overdispersion tests (likelihood ratio of
alpha = 0 on the boundary, Cameron & Trivedi 1990); the preferred model, its rate ratios with Wald intervals and
the likelihood-ratio test of the trend.
"""
from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from scipy import stats

from ..inventory.record import Inventory
from .result import RateModel, _exog
from .design import (DEFAULT_WINDOWS_DAYS, MIN_PERIODS, _add_counts, _add_covariate_columns, _add_rainfall_columns,
                     _add_season_trend_columns, _check_rate_arguments, _counted_events, _covariate_inputs, _note,
                     _record_periods, _term_table)


_NB_ALPHA_MIN = 1e-8   # smallest dispersion searched: NB2 with alpha below it is the Poisson model in practice
_NB_ALPHA_MAX = 1e3    # largest dispersion searched (a variance 1,000 mu^2 above the mean)


def _fit_negbin(y, X, offset, pois, GLM, families, NegativeBinomial):
    """Maximum-likelihood NB2 regression, found by profiling the dispersion alpha.

    At a fixed alpha the NB2 model is a generalised linear model fitted by IRLS, which is stable;
    the profile log-likelihood is maximised over log(alpha) in [1e-8, 1e3] (bounded Brent search),
    and statsmodels' NB2 model evaluated at that optimum gives the usual standard errors.  Started instead from the Poisson fit with a fixed alpha guess,
    quasi-Newton search diverged to NaN on short records (statsmodels 0.15).

    Returns
    -------
    statsmodels NegativeBinomialResults
        With finite parameters; raises ValueError otherwise.
    """
    from scipy.optimize import minimize_scalar

    start = pois.params.to_numpy()

    def profile(log_alpha):
        g = GLM(y, X, family=families.NegativeBinomial(alpha=float(np.exp(log_alpha))), offset=offset).fit(
            start_params=start)
        return -g.llf if np.isfinite(g.llf) else np.inf

    opt = minimize_scalar(profile, bounds=(np.log(_NB_ALPHA_MIN), np.log(_NB_ALPHA_MAX)), method="bounded",
                          options={"xatol": 1e-4})
    alpha = float(np.exp(opt.x))
    beta = np.asarray(GLM(y, X, family=families.NegativeBinomial(alpha=alpha), offset=offset).fit(
        start_params=start).params)
    model = NegativeBinomial(y, X, offset=offset, loglike_method="nb2")
    # The profile optimum is the maximum-likelihood estimate (coefficients exact at that alpha, alpha to a
    # relative 1e-4): statsmodels evaluates it without further iterations, the Hessian once for the standard
    # errors.  (Newton iterations on top cost minutes on long daily records: each Hessian evaluates polygamma
    # terms per day.)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        nb = model.fit(start_params=np.r_[beta, alpha], disp=0, maxiter=0, method="nm")
    nb.mle_retvals["converged"] = bool(np.isfinite(nb.llf) and np.isfinite(-opt.fun))
    if not np.all(np.isfinite(nb.params)):
        raise ValueError("no finite negative binomial estimate")
    return nb


def rate_model(inventory: Inventory, covariates=None, *, rainfall=None, period: str = "day",
               windows_days=DEFAULT_WINDOWS_DAYS, season: str | None = "harmonic", trend: bool = True,
               rain_per_mm: float = 100.0, rain_transform: str = "linear", level: float = 0.95,
               min_periods: int = MIN_PERIODS) -> RateModel:
    """Fit Poisson and negative-binomial regressions of event counts on rainfall, season and trend.

    Parameters
    ----------
    inventory : Inventory
        A dated inventory with a known record period (``start``/``end``).  All
        events count, censored sizes included (:meth:`Inventory.all_events`);
        events without a full date are left out of daily and monthly models
        with a warning that counts them.
    covariates : Rainfall, str, Path or pandas.DataFrame, optional
        Daily rainfall (a :class:`~riskrf.io.rainfall.Rainfall` or a file for
        :func:`~riskrf.io.rainfall.read_rainfall`), or a DataFrame indexed by date
        with further numeric covariates (e.g. ``temperature_c``,
        ``freeze_thaw``): daily values are summed (``*_mm``, ``*_days``,
        ``freeze_thaw``) or averaged (others) over monthly or yearly periods.
        Every covariate must cover every day of the record period.
    rainfall : Rainfall, str or Path, optional
        Daily rainfall, when ``covariates`` is a DataFrame.
    period : {"day", "month", "year"}
        Counting period.  Default ``"day"``.
    windows_days : tuple of int
        Antecedent rainfall bands for daily counts, as increasing window
        lengths [days]: (1, 3, 15) gives the day's own rainfall, the 2 days
        before and days 3-14 before, each its own term.  Monthly and yearly
        models use the period's rainfall total.
    season : {"harmonic", "wet", "month", None}
        Season terms: an annual sine/cosine pair (default), an April-September
        wet-season indicator, or calendar-month indicators (January the
        reference).  Not used for yearly counts.
    trend : bool
        Include a log-linear trend in the year (rate ratio per year).
    rain_per_mm : float
        Rainfall rate ratios refer to this many mm (default 100 mm).
    rain_transform : {"linear", "sqrt", "log1p"}
        How rainfall enters the linear predictor.  ``"linear"`` (default): the
        rate ratio is per ``rain_per_mm`` mm, the same at any rainfall.
        ``"sqrt"`` / ``"log1p"``: the term is sqrt(mm) or log(1 + mm), scaled so
        that the rate ratio compares ``rain_per_mm`` mm with none; the effect of
        each further mm then shrinks, which daily counts often need (a linear
        term lets the rate explode on the wettest days; compare the models'
        AIC and ``expected_total`` against the observed total).
    level : float
        Confidence level of the intervals (default 0.95).
    min_periods : int
        Fewest periods the model is fitted to (default 20; fewer raise).

    Returns
    -------
    RateModel

    Raises
    ------
    ValueError
        Naming the inventory or rainfall file, row and value: a record period
        that is unknown, fewer than ``min_periods`` periods, an event dated
        outside the rainfall record, a rainfall gap inside the period (gaps are
        never filled), a covariate not covering the period.
    """
    _check_rate_arguments(inventory, period, season, level, rain_per_mm, rain_transform)
    extra, rain, windows = _covariate_inputs(covariates, rainfall, windows_days)
    src = inventory.source
    if inventory.start is None or inventory.end is None:
        raise ValueError(f"{src}: the record period (start, end) is unknown; a rate model needs it "
                         "(give start/end to read_inventory or in the sidecar .toml)")
    start, end = pd.Timestamp(inventory.start), pd.Timestamp(inventory.end)
    notes: list[str] = []
    events = _counted_events(inventory, period, notes)
    days, starts, exposure, key = _record_periods(start, end, period, min_periods, src)

    # Rainfall: every event date and every day of the period with its antecedent window must be covered.
    design = pd.DataFrame({"period_start": starts, "exposure_days": exposure})
    rain_cols: list[tuple[str, str]] = []
    if rain is not None:
        rain_cols = _add_rainfall_columns(design, rain, events, period, windows, start, end, days, key, starts, src)
    elif extra is None:
        _note(notes, f"{src}: no rainfall or other covariates given; the model has only season and trend terms")
    extra_cols = []
    if extra is not None:
        extra_cols = _add_covariate_columns(design, extra, period, start, end, days, key, starts, src)
    season_frame, season_used, year_ref = _add_season_trend_columns(design, period, season, trend, start, end, notes)
    _add_counts(design, events, period, start, end, src)
    terms = _term_table(design, rain_cols, season_frame, trend, extra_cols, rain_per_mm, rain_transform)

    y = design["count"].to_numpy(float)
    X = _exog(design, terms)
    offset = np.log(design["exposure_days"].to_numpy(float))
    pois, nb = _fit_count_models(y, X, offset, src, notes)
    comparison, overdispersion, nb_glm = _compare_models(y, X, offset, pois, nb)

    preferred, reason, res, glm_pref = _preferred_model(pois, nb, nb_glm, overdispersion)
    rate_ratios = _rate_ratio_table(res, terms, level)
    trend_info = _trend_test(y, X, offset, res, preferred, rate_ratios, year_ref) if trend else None

    return RateModel(design=design, terms=terms, period=period, poisson=pois, negbin=nb, preferred=preferred,
                     reason=reason, comparison=comparison, overdispersion=overdispersion, rate_ratios=rate_ratios,
                     trend=trend_info, level=level, year_ref=year_ref, inventory_source=src,
                     rainfall_source=rain.source if rain is not None else "", start=start, end=end,
                     season=season_used, windows_days=windows if period == "day" else (),
                     notes=tuple(list(inventory.notes) + notes), _glm_preferred=glm_pref, rainfall=rain)


def _fit_count_models(y, X, offset, src: str, notes: list):
    """Fit the Poisson and the negative binomial (NB2) regressions of the counts.

    Parameters
    ----------
    y : numpy.ndarray
        Counts per period.
    X : pandas.DataFrame
        Model matrix (:func:`_exog`).
    offset : numpy.ndarray
        log of the exposure [days].
    src : str
        The inventory's source for messages.
    notes : list of str
        The model's notes; a negative binomial fit that fails or does not converge is noted (and warned).

    Returns
    -------
    pois : statsmodels GLMResults
        The Poisson fit.
    nb : statsmodels NegativeBinomialResults or None
        The NB2 fit; None when it failed.
    """
    # the model classes used, not statsmodels.api (which imports all of statsmodels: 0.7 s more)
    from statsmodels.discrete.discrete_model import NegativeBinomial
    from statsmodels.genmod import families
    from statsmodels.genmod.generalized_linear_model import GLM
    from statsmodels.tools.sm_exceptions import ConvergenceWarning

    try:
        pois = GLM(y, X, family=families.Poisson(), offset=offset).fit()
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise ValueError(f"{src}: the Poisson rate model cannot be fitted to these counts and covariates "
                         f"({exc}); check the rainfall record for impossible values") from None
    if not np.all(np.isfinite(pois.params)):
        raise ValueError(f"{src}: the Poisson rate model has no finite estimate for these counts and "
                         f"covariates; check the rainfall record for impossible values")
    trouble = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ConvergenceWarning)
        try:
            nb = _fit_negbin(y, X, offset, pois, GLM, families, NegativeBinomial)
        except (np.linalg.LinAlgError, ValueError) as exc:
            nb = None
            trouble.append(str(exc))
    trouble += [str(w.message) for w in caught if issubclass(w.category, (ConvergenceWarning, RuntimeWarning))]
    if nb is None or not np.all(np.isfinite(nb.params)) or (trouble and not nb.mle_retvals.get("converged", False)):
        _note(notes, f"negative binomial model did not converge ({'; '.join(trouble)[:200] or 'no finite estimate'}); "
                     f"the Poisson model is used")
        nb = None
    return pois, nb


def _compare_models(y, X, offset, pois, nb):
    """Goodness of fit of both models and the overdispersion tests.

    The likelihood-ratio test of alpha = 0 lies on the boundary, so its p-value is half the chi-square(1)
    tail (Cameron & Trivedi 2013, section 3.4); Cameron & Trivedi's (1990) auxiliary regression is the second test.

    Parameters
    ----------
    y, X, offset
        Counts, model matrix and log exposure [days].
    pois, nb
        The fits of :func:`_fit_count_models`.

    Returns
    -------
    comparison : pandas.DataFrame
        Per model: log-likelihood, AIC, deviance, residual df, Pearson chi2 per df, alpha, expected and
        observed totals.
    overdispersion : dict
        alpha and both tests (empty without a negative binomial fit).
    nb_glm : statsmodels GLMResults or None
        The NB2 model at its fitted alpha as a GLM.
    """
    from statsmodels.genmod import families
    from statsmodels.genmod.generalized_linear_model import GLM
    from statsmodels.regression.linear_model import OLS

    comparison = {"Poisson": {"loglik": pois.llf, "aic": pois.aic, "deviance": pois.deviance,
                              "df_resid": pois.df_resid, "pearson_chi2_per_df": pois.pearson_chi2 / pois.df_resid,
                              "alpha": 0.0, "expected_total": float(np.sum(pois.mu)), "observed_total": y.sum()}}
    overdispersion = {}
    nb_glm = None
    if nb is not None:
        alpha = float(nb.params["alpha"])
        # the NB2 model at its fitted alpha as a GLM (deviance, Pearson chi2, predictions with intervals),
        # started from the maximum-likelihood coefficients so IRLS begins at the solution
        nb_glm = GLM(y, X, family=families.NegativeBinomial(alpha=max(alpha, _NB_ALPHA_MIN)), offset=offset).fit(
            start_params=nb.params.drop("alpha").to_numpy())
        comparison["negative binomial"] = {"loglik": nb.llf, "aic": nb.aic, "deviance": nb_glm.deviance,
                                           "df_resid": nb.df_resid - 1,
                                           "pearson_chi2_per_df": nb_glm.pearson_chi2 / (nb_glm.df_resid - 1),
                                           "alpha": alpha, "expected_total": float(np.sum(nb_glm.mu)),
                                           "observed_total": y.sum()}
        lr = max(2 * (nb.llf - pois.llf), 0.0)
        mu = np.asarray(pois.mu)
        aux = ((y - mu) ** 2 - y) / mu
        ct = OLS(aux, mu).fit()
        ct_t = float(ct.tvalues[0])
        overdispersion = {"alpha": alpha, "lr_statistic": lr, "lr_p_value": 0.5 * stats.chi2.sf(lr, 1),
                          "ct_statistic": ct_t, "ct_p_value": float(stats.t.sf(ct_t, ct.df_resid))}
    comparison = pd.DataFrame(comparison).T
    comparison.index.name = "model"
    return comparison, overdispersion, nb_glm


def _preferred_model(pois, nb, nb_glm, overdispersion: dict):
    """The preferred model: the negative binomial when the LR test rejects alpha = 0 at 5 %, else the Poisson.

    Parameters
    ----------
    pois, nb, nb_glm
        The fits (:func:`_fit_count_models`, :func:`_compare_models`); ``nb`` may be None.
    overdispersion : dict
        The overdispersion tests (:func:`_compare_models`).

    Returns
    -------
    preferred : str
        "negative binomial" or "Poisson".
    reason : str
        Why, with the test's p-value and the AICs.
    res
        The preferred fit.
    glm_pref
        The preferred model as a GLM (for predictions with intervals).
    """
    if nb is not None and overdispersion["lr_p_value"] < 0.05:
        preferred = "negative binomial"
        reason = (f"overdispersion: LR test of alpha = 0 gives p = {overdispersion['lr_p_value']:.3g}; "
                  f"AIC {nb.aic:.1f} vs {pois.aic:.1f}")
        res, glm_pref = nb, nb_glm
    else:
        preferred = "Poisson"
        reason = ("no significant overdispersion" + (f" (p = {overdispersion['lr_p_value']:.3g})" if overdispersion
                  else "") + f"; AIC {pois.aic:.1f}" + (f" vs {nb.aic:.1f}" if nb is not None else ""))
        res, glm_pref = pois, pois
    return preferred, reason, res, glm_pref


def _rate_ratio_table(res, terms: pd.DataFrame, level: float) -> pd.DataFrame:
    """Coefficients, rate ratios exp(beta) with Wald intervals at ``level``, and p-values of every term."""
    z = stats.norm.isf((1 - level) / 2)
    rr = []
    for t in terms.itertuples():
        b, se, p = float(res.params[t.term]), float(res.bse[t.term]), float(res.pvalues[t.term])
        rr.append({"term": t.term, "label": t.label, "unit": t.unit, "coefficient": b, "stderr": se,
                   "rate_ratio": np.exp(b), "ci_low": np.exp(b - z * se), "ci_high": np.exp(b + z * se),
                   "p_value": p})
    return pd.DataFrame(rr)


def _trend_test(y, X, offset, res, preferred: str, rate_ratios: pd.DataFrame, year_ref: float) -> dict:
    """Likelihood-ratio test of the trend: the preferred model with and without ``year_c``.

    Parameters
    ----------
    y, X, offset
        Counts, model matrix and log exposure [days].
    res
        The preferred model's fit.
    preferred : {"Poisson", "negative binomial"}
        The preferred model.
    rate_ratios : pandas.DataFrame
        :func:`_rate_ratio_table` of the preferred model.
    year_ref : float
        Reference year of the trend [yr].

    Returns
    -------
    dict
        Rate ratio per year with its interval, LR statistic, p-value, ``detected`` (p < 0.05), model and
        ``year_ref``.
    """
    from statsmodels.discrete.discrete_model import NegativeBinomial
    from statsmodels.genmod import families
    from statsmodels.genmod.generalized_linear_model import GLM

    X0 = X.drop(columns="year_c")
    if preferred == "Poisson":
        llf0 = GLM(y, X0, family=families.Poisson(), offset=offset).fit().llf
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sp = np.r_[res.params.drop(["year_c"]).to_numpy()]
            llf0 = NegativeBinomial(y, X0, offset=offset, loglike_method="nb2").fit(
                start_params=sp, disp=0, maxiter=300, method="bfgs").llf
    lr_t = max(2 * (res.llf - llf0), 0.0)
    row = rate_ratios.set_index("term").loc["year_c"]
    p_t = float(stats.chi2.sf(lr_t, 1))
    return {"rate_ratio_per_year": float(row["rate_ratio"]), "ci_low": float(row["ci_low"]),
            "ci_high": float(row["ci_high"]), "lr_statistic": lr_t, "p_value": p_t,
            "detected": bool(p_t < 0.05), "model": preferred, "year_ref": year_ref}
