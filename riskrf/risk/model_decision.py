"""Ranking under the trajectory model's uncertainty, and the value of calibrating the slope's materials first.

The mitigation study (:class:`~riskrf.risk.mitigation.MitigationStudy`) is run once per draw theta_j of the
slope's material parameters (a posterior sample, or the presets' spread), giving the expected total cost
C[j, k] of option k given theta_j (expected over the study's other uncertain inputs, with the same samples of
those for every draw).  From that table, with prior weights pi_j of the draws (equal by default):

* **probability each option is best** given the trajectory model: sum of pi_j over the draws where k has the
  least cost;
* **EVPI of the material parameters** (a partial EVPI: the other inputs stay uncertain; Raiffa & Schlaifer
  1961; Brennan et al. 2007, Med. Decis. Making 27:448, eq. 3)::

      EVPI = min_k sum_j pi_j C[j, k]  -  sum_j pi_j min_k C[j, k]

* **EVSI of a field calibration** of the materials (preposterior analysis, Raiffa & Schlaifer 1961, ch. 4;
  Ades, Lu & Claxton 2004, Med. Decis. Making 24:207): a calibration releases N blocks and observes where they
  stop.  For each draw theta_t taken as the truth (every draw in turn, with its prior weight) R synthetic
  calibrations are simulated; each updates the prior draws by importance weights w_j proportional to
  pi_j prod_i p_j(x_i), with p_j the per-stop likelihood of the pooled calibration
  (:func:`simulation.stop_density`: a Gaussian kernel density of the stops simulated under theta_j, mixed with
  a uniform share over the profile); the option chosen after the calibration is
  delta = argmin_k sum_j w_j C[j, k], and it costs C[t, delta] under the truth.  The synthetic stops are drawn
  from the same kernel density under theta_t, so that the data and the likelihood are one model (the
  preposterior analysis is then coherent: the posterior weights average to the prior).  Then::

      EVSI = sum_t pi_t mean_r ( C[t, k0] - C[t, delta_tr] ),     k0 = argmin_k sum_j pi_j C[j, k]

  a paired estimator with its Monte Carlo standard error (stratified by t).  Because C[t, delta] >=
  min_k C[t, k], the estimate never exceeds the EVPI; it is 0 when the data cannot change the choice (N = 0)
  and tends to the EVPI as the data identify the draw.  A negative estimate (Monte Carlo noise around 0) is
  reported as 0, with the raw value and its error kept.

"Calibrate first, then decide" when the EVSI exceeds the calibration's cost.  The answer is about the choice
among the options as stated; a calibration also narrows the design energy, which has its own value not counted
here.

References
----------
Raiffa, H. & Schlaifer, R. (1961) Applied Statistical Decision Theory. Harvard, ch. 4.  Ades, A.E., Lu, G. &
Claxton, K. (2004) Medical Decision Making 24:207-227.  Brennan, A., Kharroubi, S., O'Hagan, A. & Chilcott, J.
(2007) Medical Decision Making 27:448-470.  Wilkinson, R.D. (2013) Stat. Appl. Genet. Mol. Biol. 12:129 (the
kernel likelihood).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from simulation._display import Displayed, short_repr

from ..core.format import money
from ..core.validation import RiskrfError


class DecisionValueError(RiskrfError, ValueError):
    """Inputs of a ranking under model uncertainty or of a value-of-information analysis that do not fit; the
    message names the argument and the value."""


def _weights(weights, J: int) -> np.ndarray:
    if weights is None:
        return np.full(J, 1.0 / J)
    w = np.asarray(weights, dtype=float).ravel()
    if w.size != J or not np.all(np.isfinite(w)) or np.any(w < 0) or w.sum() <= 0:
        raise DecisionValueError(f"weights must be {J} finite numbers >= 0 with a positive sum; got {w.tolist()}")
    return w / w.sum()


def expected_value_of_perfect_information(costs, weights=None) -> float:
    """EVPI [currency] of the uncertain draws for a table ``costs`` (draws x options) of expected costs:
    min_k E[C_k] - E[min_k C_k] (>= 0).

    Parameters
    ----------
    costs : array_like, shape (J, K)
        Expected cost of option k given draw j [currency]; at least one draw and one option.
    weights : array_like, shape (J,), optional
        Prior weights of the draws [-] (finite, >= 0, positive sum; normalised here).  None: equal weights.

    Returns
    -------
    float
        EVPI [currency], ``min_k sum_j pi_j C[j, k] - sum_j pi_j min_k C[j, k]``, clipped at 0.

    Raises
    ------
    DecisionValueError
        When ``weights`` does not fit the draws.

    References
    ----------
    Raiffa, H. & Schlaifer, R. (1961) Applied Statistical Decision Theory. Harvard, ch. 4.  Brennan, A.,
    Kharroubi, S., O'Hagan, A. & Chilcott, J. (2007) Medical Decision Making 27:448-470, eq. 3.
    """
    C = np.asarray(costs, dtype=float)
    w = _weights(weights, C.shape[0])
    return max(float((w @ C).min() - w @ C.min(axis=1)), 0.0)


@dataclass(frozen=True)
class EVPIEstimate:
    """An EVPI estimated from a finite sample of draws, with its Monte Carlo error and an upper bound
    (:func:`evpi_estimate`).  Money in the ranking's currency.

    ``value``: the estimate (:func:`expected_value_of_perfect_information`); ``standard_error``: its Monte Carlo
    error over the draws; ``upper_bound``: a 97.5 % upper bound -- the larger of ``value + 2 standard_error`` and
    the bound from a normal approximation of the cost differences (which stays above 0 when no draw happens to
    change the choice); ``n_draws``: the draws it comes from.
    """

    value: float
    standard_error: float
    upper_bound: float
    n_draws: int

    def text(self, currency: str = "") -> str:
        """The estimate for a report line: never a bare 0.

        Parameters
        ----------
        currency : str, optional
            Currency label.

        Returns
        -------
        str
            ``"X (+- 2 s.e. Y over J draws)"``, or for an estimate of 0 ``"0 (at most Z: no draw of J changes the
            choice)"``.
        """
        cur = f" {currency}" if currency else ""
        if self.value <= 0.0:
            return (f"0{cur} (at most {money(self.upper_bound, sig=2)}{cur}, 97.5 % upper bound: no draw of "
                    f"{self.n_draws} changes the choice)")
        return (f"{money(self.value, sig=3)}{cur} (+- {money(2 * self.standard_error, sig=2)}{cur}, 2 s.e. over "
                f"{self.n_draws} draws; at most {money(self.upper_bound, sig=2)}{cur})")

    def to_dict(self) -> dict:
        """JSON-ready fields.

        Returns
        -------
        dict
            ``value``, ``standard_error`` and ``upper_bound_97_5`` [currency], ``draws``.
        """
        return {"value": self.value, "standard_error": self.standard_error, "upper_bound_97_5": self.upper_bound,
                "draws": self.n_draws}


def evpi_estimate(costs, weights=None) -> EVPIEstimate:
    """EVPI [currency] of a table ``costs`` (draws x options) with its Monte Carlo error and an upper bound.

    The estimate is the mean regret of the option chosen now, ``r_j = C[j, k0] - min_k C[j, k]``; its standard
    error is that of a (weighted) mean over the draws.  With few draws every draw may pick the same option, and
    the estimate is then exactly 0 with a standard error of 0: an artefact of the sample, not a finding.  The upper
    bound therefore also uses EVPI <= sum_k E[(C_k0 - C_k)^+] with each difference taken as normal, its mean and
    standard deviation at their 97.5 % confidence limits over the draws (E[d^+] = s phi(m/s) + m Phi(m/s)).
    Where few draws (about 10 or fewer) change the choice, the regret is so skewed that the standard error
    understates the spread (tests: sd of the z-score 2.6 at 9 of 400 draws); the upper bound still covers.

    Parameters
    ----------
    costs : array_like, shape (J, K)
        Expected cost of option k given draw j [currency]; at least 2 draws and 2 options.
    weights : array_like, shape (J,), optional
        Prior weights of the draws [-] (finite, >= 0, positive sum).  None: equal weights.

    Returns
    -------
    EVPIEstimate

    Raises
    ------
    DecisionValueError
        When the table has fewer than 2 draws or 2 options, or ``weights`` does not fit.

    References
    ----------
    Raiffa, H. & Schlaifer, R. (1961) Applied Statistical Decision Theory. Harvard, ch. 4 (EVPI of a normal
    difference of two actions).  Brennan, A., Kharroubi, S., O'Hagan, A. & Chilcott, J. (2007) Medical Decision
    Making 27:448-470, eq. 3.
    """
    from scipy import stats
    C = np.asarray(costs, dtype=float)
    if C.ndim != 2 or C.shape[0] < 2 or C.shape[1] < 2:
        raise DecisionValueError(f"costs must be a table of at least 2 draws x 2 options; got shape {C.shape}")
    w = _weights(weights, C.shape[0])
    n_eff = 1.0 / float(w @ w)                               # effective number of draws (J for equal weights)
    k0 = int(np.argmin(w @ C))
    regret = C[:, k0] - C.min(axis=1)
    value = max(float(w @ regret), 0.0)
    dof = n_eff / (n_eff - 1.0) if n_eff > 1.0 else float("nan")

    def _se(x, mean):
        return float(np.sqrt(dof * (w ** 2) @ (x - mean) ** 2))

    se = _se(regret, value)
    chi = stats.chi2.ppf(0.025, max(n_eff - 1.0, 1.0))
    tail = 0.0
    for k in range(C.shape[1]):
        if k == k0:
            continue
        d = C[:, k0] - C[:, k]                               # > 0 where option k is the cheaper one
        m = float(w @ d)
        s = float(np.sqrt(dof * (w @ (d - m) ** 2)))
        m_up = m + 2.0 * s / np.sqrt(n_eff)
        s_up = s * np.sqrt(max(n_eff - 1.0, 1.0) / chi)
        if s_up > 0:
            tail += s_up * stats.norm.pdf(m_up / s_up) + m_up * stats.norm.cdf(m_up / s_up)
        else:
            tail += max(m_up, 0.0)
    return EVPIEstimate(value=value, standard_error=se, upper_bound=max(value + 2.0 * se, tail),
                        n_draws=int(C.shape[0]))


@dataclass(frozen=True)
class CalibrationValue:
    """The expected value of sample information of a field calibration (:meth:`ModelUncertainRanking.calibration_value`).

    Money in the ranking's currency.  ``evsi``: the estimate, negative noise shown as 0; ``evsi_estimate`` and
    ``standard_error``: the raw paired estimate and its Monte Carlo error over the synthetic calibrations (the
    draws held fixed); ``evpi``: the ceiling, with ``evpi_standard_error`` and ``evpi_upper_bound`` over the draws
    (:func:`evpi_estimate`; the EVSI never exceeds the EVPI, so that bound is the EVSI's too);
    ``probability_decision_changes``: share of the synthetic calibrations after which another option than
    ``best_now`` is chosen; ``after_calibration``: per option, the share of synthetic calibrations after which it
    is chosen.  ``calibration_cost`` (None: not stated) and ``cost_is_assumption`` say what the EVSI is weighed
    against.
    """

    evsi: float
    evsi_estimate: float
    standard_error: float
    evpi: float
    n_releases: int
    n_datasets: int
    best_now: str
    probability_decision_changes: float
    after_calibration: dict
    calibration_cost: float | None = None
    cost_is_assumption: bool = False
    currency: str = ""
    obs_error_m: float = 0.5
    notes: tuple = ()
    evpi_standard_error: float = float("nan")
    evpi_upper_bound: float = float("nan")
    n_draws: int = 0

    @property
    def calibrate_first(self) -> bool | None:
        """True when the EVSI exceeds the calibration's cost (None without a cost)."""
        return None if self.calibration_cost is None else bool(self.evsi > self.calibration_cost)

    def verdict(self) -> str:
        """One sentence: calibrate first or decide now, with the numbers.

        Returns
        -------
        str
            "calibrate first, then decide: ..." or "decide now: ..." with the EVSI, its 2 standard errors, the EVPI
            and the calibration cost [currency]; or the EVSI alone when no cost is stated.
        """
        cur = f" {self.currency}" if self.currency else ""
        evpi = EVPIEstimate(self.evpi, self.evpi_standard_error, self.evpi_upper_bound, self.n_draws)
        lead = f"EVSI of a field calibration with {self.n_releases} released blocks: "
        bounded = self.n_draws > 0 and np.isfinite(self.evpi_upper_bound)
        if bounded and self.evsi <= 0.0 and self.evpi <= 0.0:
            head = (f"{lead}0{cur}, as is the EVPI of the material parameters (no draw of {self.n_draws} changes the "
                    f"choice; both at most {money(self.evpi_upper_bound, sig=2)}{cur}, the EVPI's 97.5 % upper bound)")
        elif bounded and self.evsi <= 0.0:
            head = (f"{lead}0{cur} (no synthetic calibration changed the choice; at most the EVPI of the material "
                    f"parameters, {evpi.text(self.currency)})")
        else:
            head = (f"{lead}{money(self.evsi, sig=3)}{cur} (+- {money(2 * self.standard_error, sig=2)}{cur}, 2 s.e.; "
                    "EVPI of the material parameters "
                    + (evpi.text(self.currency) if bounded else f"{money(self.evpi, sig=3)}{cur}") + ")")
        if self.calibration_cost is None:
            return head + "; no calibration cost stated"
        cost = (f"{money(self.calibration_cost, sig=3)}{cur}"
                + (" (ASSUMED default)" if self.cost_is_assumption else " (stated)"))
        close = abs(self.evsi - self.calibration_cost) < 2 * self.standard_error
        tail = " (within the Monte Carlo error of the EVSI: close call)" if close else ""
        if self.calibrate_first:
            return f"calibrate first, then decide: {head} exceeds the calibration's cost {cost}{tail}"
        return f"decide now: {head} does not exceed the calibration's cost {cost}{tail}"

    def to_dict(self) -> dict:
        """JSON-ready fields and the verdict.

        Returns
        -------
        dict
            EVSI, its raw estimate and standard error, EVPI, calibration cost [currency], release and data-set counts,
            the choices before and after calibration, ``calibrate_first``, the verdict and the notes.
        """
        return {"evsi": self.evsi, "evsi_estimate": self.evsi_estimate, "standard_error": self.standard_error,
                "evpi_material_parameters": self.evpi, "evpi_standard_error": self.evpi_standard_error,
                "evpi_upper_bound_97_5": self.evpi_upper_bound, "draws": self.n_draws,
                "calibration_releases": self.n_releases,
                "synthetic_calibrations": self.n_datasets, "best_now": self.best_now,
                "probability_decision_changes": self.probability_decision_changes,
                "chosen_after_calibration": self.after_calibration, "calibration_cost": self.calibration_cost,
                "calibration_cost_is_assumption": self.cost_is_assumption, "currency": self.currency,
                "calibrate_first": self.calibrate_first, "verdict": self.verdict(), "notes": list(self.notes)}

    def summary(self) -> pd.DataFrame:
        """The figures as a one-column table.

        Returns
        -------
        pandas.DataFrame
            Column ``value`` indexed by field name (the fields of :meth:`to_dict` except the notes; money in
            [currency]).
        """
        d = self.to_dict()
        d.pop("notes")
        d["chosen_after_calibration"] = "; ".join(f"{k} {v:.0%}" for k, v in self.after_calibration.items())
        return pd.DataFrame({"value": pd.Series(d, dtype=object)})


@dataclass(frozen=True)
class ModelUncertainRanking(Displayed):
    """Expected total cost of each option under each draw of the trajectory model.

    ``costs`` (draws x options): expected total cost [currency] given the draw (over the study's other uncertain
    inputs); ``sample_costs`` (draws x samples x options, optional): the study's joint samples under each draw,
    for the joint intervals and the split of each option's cost variance; ``draws``: the material values of the
    draws (one row each); ``weights``: prior weights of the draws (None: equal).
    """

    options: tuple
    costs: np.ndarray = field(repr=False)
    draws: pd.DataFrame = field(default=None, repr=False)
    sample_costs: np.ndarray | None = field(default=None, repr=False)
    weights: np.ndarray | None = field(default=None, repr=False)
    currency: str = ""
    basis: str = ""

    def __post_init__(self):
        C = np.asarray(self.costs, dtype=float)
        if C.ndim != 2 or C.shape[0] < 2 or C.shape[1] != len(self.options) or len(self.options) < 2:
            raise DecisionValueError(f"costs must be a table of at least 2 draws x {len(self.options)} options "
                                     f"(at least 2); got shape {C.shape}")
        if not np.all(np.isfinite(C)):
            j, k = np.argwhere(~np.isfinite(C))[0]
            raise DecisionValueError(f"costs[{j}, {k}] (draw {j}, option {self.options[k]!r}) = {float(C[j, k])}: "
                                     "costs must be finite numbers")
        object.__setattr__(self, "costs", C)
        object.__setattr__(self, "weights", _weights(self.weights, C.shape[0]))
        if self.sample_costs is not None:
            S = np.asarray(self.sample_costs, dtype=float)
            if S.ndim != 3 or S.shape[0] != C.shape[0] or S.shape[2] != C.shape[1]:
                raise DecisionValueError(f"sample_costs must be draws x samples x options {C.shape[0]} x S x "
                                         f"{C.shape[1]}; got shape {S.shape}")
            object.__setattr__(self, "sample_costs", S)

    def __repr__(self) -> str:
        return short_repr(self, f"{len(self.options)} options", f"{self.n_draws} draws", best=self.best_now(),
                          evpi=self.evpi(), currency=self.currency or None,
                          joint_samples=None if self.sample_costs is None else self.sample_costs.shape[1])

    @property
    def n_draws(self) -> int:
        """Number of draws of the trajectory model."""
        return self.costs.shape[0]

    def expected_costs(self) -> np.ndarray:
        """Expected total cost of each option over the draws [currency].

        Returns
        -------
        numpy.ndarray, shape (K,)
            ``sum_j pi_j C[j, k]`` per option [currency], in the order of ``options``.
        """
        return self.weights @ self.costs

    def best_now(self) -> str:
        """The option of least expected cost with the current information.

        Returns
        -------
        str
            Name of the option with the least expected cost over the draws.
        """
        return self.options[int(np.argmin(self.expected_costs()))]

    def probability_best(self) -> np.ndarray:
        """P(option is best | trajectory model), over the draws (the study's other inputs at their expectation).

        Returns
        -------
        numpy.ndarray, shape (K,)
            Probability [-] that each option (order of ``options``) has the least cost, summed prior weight of the
            draws where it does; sums to 1.
        """
        best = np.argmin(self.costs, axis=1)
        return np.bincount(best, weights=self.weights, minlength=len(self.options))

    def evpi(self) -> float:
        """EVPI of the material parameters [currency] (partial EVPI; see the module docstring).

        Returns
        -------
        float
            EVPI [currency], from :func:`expected_value_of_perfect_information`.

        References
        ----------
        Brennan, A., Kharroubi, S., O'Hagan, A. & Chilcott, J. (2007) Medical Decision Making 27:448-470, eq. 3.
        """
        return expected_value_of_perfect_information(self.costs, self.weights)

    def evpi_estimate(self) -> EVPIEstimate:
        """EVPI of the material parameters with its Monte Carlo error over the draws and an upper bound.

        Returns
        -------
        EVPIEstimate
            From :func:`evpi_estimate` (its ``value`` equals :meth:`evpi`).
        """
        return evpi_estimate(self.costs, self.weights)

    def summary(self) -> pd.DataFrame:
        """One row per option, least expected cost first: expected total cost, the trajectory model's 5-95 %
        range of the expected cost, P(best) given the model, and with ``sample_costs`` the joint 5-95 % range,
        the joint P(best) and the share of the cost's variance that comes from the trajectory model.

        Returns
        -------
        pandas.DataFrame
            Columns ``rank``, ``option``, ``expected_total_cost`` [currency], ``model_cost_p05``/``model_cost_p95``
            [currency], ``probability_best_given_model`` [-]; with ``sample_costs`` also ``joint_cost_p05``/
            ``joint_cost_p95`` [currency], ``share_of_variance_from_trajectory_model`` [-] and
            ``probability_best_joint`` [-].
        """
        exp = self.expected_costs()
        rows = []
        for k, name in enumerate(self.options):
            c = self.costs[:, k]
            row = {"option": name, "expected_total_cost": float(exp[k]),
                   "model_cost_p05": float(np.quantile(c, 0.05)), "model_cost_p95": float(np.quantile(c, 0.95)),
                   "probability_best_given_model": float(self.probability_best()[k])}
            if self.sample_costs is not None:
                s = self.sample_costs[:, :, k]
                between = float(self.weights @ (s.mean(axis=1) - self.weights @ s.mean(axis=1)) ** 2)
                within = float(self.weights @ s.var(axis=1))
                row.update(joint_cost_p05=float(np.quantile(s, 0.05)), joint_cost_p95=float(np.quantile(s, 0.95)),
                           share_of_variance_from_trajectory_model=between / (between + within)
                           if between + within > 0 else np.nan)
            rows.append(row)
        if self.sample_costs is not None:
            best = np.argmin(self.sample_costs, axis=2)                       # (J, S)
            p = np.array([self.weights @ (best == k).mean(axis=1) for k in range(len(self.options))])
            for row, pk in zip(rows, p):
                row["probability_best_joint"] = float(pk)
        df = pd.DataFrame(rows).sort_values("expected_total_cost", kind="stable").reset_index(drop=True)
        df.insert(0, "rank", np.arange(1, len(df) + 1))
        return df

    def per_draw(self) -> pd.DataFrame:
        """One row per draw: its material values, each option's expected cost and the best option.

        Returns
        -------
        pandas.DataFrame
            One row per draw: ``draw`` (0, 1, ...), the material values (when ``draws`` is given),
            ``cost:<option>`` [currency], ``best_option`` and ``weight`` [-].
        """
        t = pd.DataFrame(self.costs, columns=[f"cost:{o}" for o in self.options])
        t["best_option"] = [self.options[i] for i in np.argmin(self.costs, axis=1)]
        t["weight"] = self.weights
        if self.draws is not None:
            t = pd.concat([self.draws.reset_index(drop=True), t], axis=1)
        t.insert(0, "draw", np.arange(len(t)))
        return t

    def calibration_value(self, stops, *, n_releases: int, profile_range_m, obs_error_m: float = 0.5,
                          n_datasets: int = 200, seed=1, calibration_cost: float | None = None,
                          cost_is_assumption: bool = False) -> CalibrationValue:
        """EVSI of a field calibration of N released blocks (preposterior analysis; see the module docstring).

        Parameters
        ----------
        stops : sequence of arrays
            Per draw, the stop positions x [m] of blocks simulated as the calibration would release them (e.g.
            the scenario's seeder run under that draw).
        n_releases : int
            Blocks released and observed in the calibration (N >= 0; 0 gives EVSI 0).
        profile_range_m : (x_start, x_end)
            The profile's extent [m] (the uniform share of the likelihood spreads over it).
        obs_error_m : float
            Smallest kernel width [m] (the observation error of a stop), as in the pooled calibration.
        n_datasets : int
            Synthetic calibrations per draw taken as the truth.
        seed : int
            Seed of the synthetic calibrations.
        calibration_cost : float, optional
            Cost of the calibration [currency], weighed against the EVSI.
        cost_is_assumption : bool
            The cost is a default, not a stated site value (said in the verdict).

        Returns
        -------
        CalibrationValue
        """
        from simulation.pooled.likelihood import DEFENSIVE_SHARE, stop_bandwidth, stop_density

        J, K = self.costs.shape
        stops = [np.asarray(s, dtype=float).ravel() for s in stops]
        if len(stops) != J:
            raise DecisionValueError(f"stops: give the simulated stops of each of the {J} draws; got {len(stops)}")
        for j, s in enumerate(stops):
            if s.size < 2 or not np.all(np.isfinite(s)):
                raise DecisionValueError(f"stops[{j}]: at least 2 finite simulated stops [m] are needed; got {s.size}")
        if isinstance(n_releases, bool) or not isinstance(n_releases, (int, np.integer)) or n_releases < 0:
            raise DecisionValueError(f"n_releases = {n_releases!r} must be a whole number >= 0")
        if isinstance(n_datasets, bool) or not isinstance(n_datasets, (int, np.integer)) or n_datasets < 1:
            raise DecisionValueError(f"n_datasets = {n_datasets!r} must be a whole number >= 1")
        try:
            x0, x1 = (float(v) for v in profile_range_m)
        except (TypeError, ValueError):
            raise DecisionValueError(f"profile_range_m = {profile_range_m!r} must be (x_start, x_end) in m") from None
        if not (np.isfinite(x0) and np.isfinite(x1) and x0 < x1):
            raise DecisionValueError(f"profile_range_m = {profile_range_m!r} must satisfy x_start < x_end")
        if not (isinstance(obs_error_m, (int, float)) and obs_error_m > 0):
            raise DecisionValueError(f"obs_error_m = {obs_error_m!r} must be > 0 m")
        if calibration_cost is not None and not (np.isfinite(calibration_cost) and calibration_cost >= 0):
            raise DecisionValueError(f"calibration_cost = {calibration_cost!r} must be a finite number >= 0")
        length = x1 - x0
        pi = self.weights
        rng = np.random.default_rng(np.random.SeedSequence([int(seed), 29]))
        h = np.array([stop_bandwidth(s, obs_error_m) for s in stops])
        # log p_j(x) on a grid fine against the narrowest kernel (log-density linear between nodes: error
        # <= step^2 / (8 h^2) = 1/512 in log), the floor of the uniform share outside it
        lo = min(x0, min(s.min() for s in stops) - 8 * h.max())
        hi = max(x1, max(s.max() for s in stops) + 8 * h.max())
        grid = np.arange(lo, hi + h.min() / 8, h.min() / 8)
        floor = np.log(DEFENSIVE_SHARE / length)
        logp = np.array([np.log(stop_density(s, grid, length, obs_error_m)) for s in stops])   # (J, G)
        R, N = int(n_datasets), int(n_releases)
        # synthetic calibrations: for each true draw t, R data sets of N stops from its kernel density
        X = np.empty((J, R, N))
        for t, s in enumerate(stops):
            X[t] = s[rng.integers(0, s.size, (R, N))] + h[t] * rng.standard_normal((R, N))
            uniform = rng.uniform(size=(R, N)) < DEFENSIVE_SHARE
            X[t][uniform] = rng.uniform(x0, x1, int(uniform.sum()))
        loglik = np.zeros((J, R, J))
        for j in range(J):
            loglik[:, :, j] = np.interp(X, grid, logp[j], left=floor, right=floor).sum(axis=2)
        lw = loglik + np.log(np.maximum(pi, 1e-300))[None, None, :]
        lw -= lw.max(axis=2, keepdims=True)
        w = np.exp(lw)
        w /= w.sum(axis=2, keepdims=True)
        k0 = int(np.argmin(pi @ self.costs))
        chosen = np.argmin(w @ self.costs, axis=2)                              # (J, R)
        realised = self.costs[np.arange(J)[:, None], chosen]                    # C[t, delta_tr]
        gain = self.costs[:, k0][:, None] - realised                            # (J, R)
        raw = float(pi @ gain.mean(axis=1))
        se = float(np.sqrt(pi ** 2 @ (gain.var(axis=1, ddof=1) / R))) if R > 1 else float("nan")
        evpi = self.evpi_estimate()
        after = {o: float(pi @ (chosen == k).mean(axis=1)) for k, o in enumerate(self.options)}
        notes = [f"preposterior analysis over the {J} draws (each taken as the truth with its prior weight), {R} "
                 f"synthetic calibrations of {N} stops each; likelihood: the pooled calibration's kernel density "
                 f"(at least {obs_error_m:g} m wide) of the draws' simulated stops",
                 "the calibration is taken to release blocks as the scenario's seeder does and to observe where they "
                 "stop; the value counts only the choice among the options (not a narrower design energy)"]
        return CalibrationValue(evsi=max(raw, 0.0), evsi_estimate=raw, standard_error=se, evpi=evpi.value,
                                evpi_standard_error=evpi.standard_error, evpi_upper_bound=evpi.upper_bound,
                                n_draws=evpi.n_draws,
                                n_releases=N, n_datasets=R, best_now=self.options[k0],
                                probability_decision_changes=float(pi @ (chosen != k0).mean(axis=1)),
                                after_calibration=after,
                                calibration_cost=None if calibration_cost is None else float(calibration_cost),
                                cost_is_assumption=bool(cost_is_assumption), currency=self.currency,
                                obs_error_m=float(obs_error_m), notes=tuple(notes))

    def text(self) -> list[str]:
        """Plain-text lines: the ranking over the draws and the EVPI.

        Returns
        -------
        list of str
            A heading, one line per option (expected cost and 5-95 % range [currency], P(best | model), variance share)
            and the EVPI [currency].
        """
        cur = f" {self.currency}" if self.currency else ""
        lines = [f"Ranking over {self.n_draws} draws of the trajectory model:"]
        for _, r in self.summary().iterrows():
            share = r.get("share_of_variance_from_trajectory_model", np.nan)
            lines.append(f"  {r['rank']}. {r['option']}: {money(r['expected_total_cost'], sig=3)}{cur} "
                         f"(model 5-95 % {money(r['model_cost_p05'], sig=3)}-{money(r['model_cost_p95'], sig=3)}); "
                         f"P(best | model) {r['probability_best_given_model']:.2f}"
                         + (f"; {share:.0%} of its cost variance from the trajectory model"
                            if np.isfinite(share) else ""))
        lines.append(f"  EVPI of the material parameters: {self.evpi_estimate().text(self.currency)}")
        return lines

    def plot(self, ax=None):
        """Each option's expected cost under every draw (points) and over the draws (bar).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).

        Returns
        -------
        matplotlib.axes.Axes
            The axes drawn on (expected total cost [currency] on x, log scale when all costs are positive).
        """
        from .figures import plot_model_ranking
        return plot_model_ranking(self, ax=ax)


__all__ = ["CalibrationValue", "DecisionValueError", "EVPIEstimate", "ModelUncertainRanking", "evpi_estimate",
           "expected_value_of_perfect_information"]
