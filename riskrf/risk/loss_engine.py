"""The loss engine of the mitigation study: every option's costs and road-user risk for S sets of input values.

The engine works on typed arrays only: the inputs are a :class:`Parameters` (one array per input, option costs and
effect parameters as columns), each option is an :class:`OptionChain` of typed stages acting in series on the falls
(:class:`ReleaseStage`, :class:`RetentionStage`, :class:`BarrierStage`, :class:`ClosureStage`,
:class:`ExposureStage`), and the result is a :class:`LossResult` of (S, K) arrays.  The names of the inputs used by
the tornado and break-even tables ("rate_factor", "capital_cost:fence", ...) live in :class:`ParameterSpace`, which
turns a dict of named arrays into a :class:`Parameters`.

    expected total cost = capital + PV(renewals) + PV(maintenance, repairs, replacements) + PV(expected losses)

(Wyllie 2014, 8.5.5; Wyllie, McCammon & Brumund 1980.)  Road losses per fall reaching the road: a moving vehicle at
the impact point (Bunce et al. 1997, per lane), a vehicle striking the rock lying on the road, deaths with a
vulnerability that depends on block mass (:mod:`riskrf.risk.road_risk`), vehicle damage, closure and clean-up.
Fences, attenuators and sheds have damage states (:func:`riskrf.hazard.barriers.damage_state_shares`) and are out of
service after a destructive impact (:func:`riskrf.hazard.barriers.out_of_service_share`).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..hazard.barriers import out_of_service_share
from ..hazard.mass_models import mass_model
from .economics import pv_factor, renewal_factor
from .road_risk import commuter_passage_probability, commuter_strike_probability, occupancy_distribution, \
    vulnerability_by_mass
from .road_users import lane_hit_probability, lane_strike_probability

#: Number of logarithmic mass bins of the engine's mass grid.
MASS_BINS = 120


def closure_cost_per_fall(co, vehicles_per_day):
    """Cost of one fall reaching the road besides injuries and vehicle damage [currency]: the agency's closure
    cost per day and the road users' delay (each of the vehicles_per_day x closure days detours for
    ``detour_hours`` at ``value_of_time_per_hour``), plus clean-up.

    Parameters
    ----------
    co : riskrf.risk.mitigation_inputs.Consequences
        Closure days per fall, cost per closure day, detour hours, value of time per hour, clean-up cost per fall.
    vehicles_per_day : float or numpy.ndarray
        Two-way traffic [vehicles/day].

    Returns
    -------
    float or numpy.ndarray
        Cost per fall reaching the road [currency].
    """
    days = co.closure_days_per_fall
    return days * co.closure_cost_per_day + days * np.asarray(vehicles_per_day, dtype=float) * co.detour_hours \
        * co.value_of_time_per_hour + co.cleanup_cost_per_fall


# ---- the mass grid ------------------------------------------------------------------------------------------
class MassGrid(NamedTuple):
    """Mass bins of the engine: ``edges`` (J + 1) and representative masses ``mid`` (J) [kg], and ``small`` (J),
    the fixed histogram of the inventory's falls below the power law's m_min (sums to 1, or zeros)."""

    edges: np.ndarray
    mid: np.ndarray
    small: np.ndarray


def mass_grid(mass, small_fall_masses_kg, small_falls_per_year: float, uncertainty) -> MassGrid:
    """The mass grid of a study: geometric bins from below the smallest fall (the power law's m_min, or the mass
    model's 1e-9 quantile, and the small falls' masses) to the largest (the power law's m_max, else 1e6 m_min, and
    the sampled m_max; or the 1 - 1e-9 quantile).  With fragmentation the grid reaches down to the finest
    generation (each generation divides the mass by 8).

    Parameters
    ----------
    mass : object
        The study's mass distribution, as accepted by :func:`riskrf.hazard.mass_models.mass_model`.
    small_fall_masses_kg : array_like or None
        Masses of the inventory's falls below the power law's m_min [kg].
    small_falls_per_year : float
        Frequency of those small falls [1/yr].
    uncertainty : object
        The study's uncertainty settings (``m_max_kg`` range [kg], ``fractal_dimension``,
        ``fragmentation_iterations``).

    Returns
    -------
    MassGrid
        Bin edges and middle masses [kg] and the small falls' histogram [-].
    """
    mm = mass_model(mass)
    lo_model, hi = mm.grid_bounds_kg(uncertainty.m_max_kg[1] if uncertainty.m_max_kg else None)
    lo_candidates = [lo_model]
    if small_fall_masses_kg is not None and len(small_fall_masses_kg):
        lo_candidates.append(float(np.min(small_fall_masses_kg)))
    lo = 0.999 * min(lo_candidates)
    if uncertainty.fractal_dimension:     # fragments keep their own masses: down to the finest generation
        lo /= 8.0 ** uncertainty.fragmentation_iterations
    edges = np.geomspace(lo, hi, MASS_BINS + 1)
    mid = np.sqrt(edges[:-1] * edges[1:])
    small = np.zeros(MASS_BINS)
    if small_fall_masses_kg is not None and len(small_fall_masses_kg) and small_falls_per_year > 0:
        small = np.histogram(np.clip(small_fall_masses_kg, lo, hi), edges)[0].astype(float)
        small /= small.sum()
    return MassGrid(edges, mid, small)


def mass_pmf(edges: np.ndarray, mass, b=None, m_max=None) -> np.ndarray:
    """Probability of each mass bin for one fall of at least m_min; arrays (S, J) for sampled b and m_max [kg]
    (a power law truncated at m_max), else (1, J) from the mass model's survival function.  The last bin takes
    the tail.

    Parameters
    ----------
    edges : numpy.ndarray
        Mass bin edges (J + 1) [kg].
    mass : object
        The study's mass distribution, as accepted by :func:`riskrf.hazard.mass_models.mass_model`.
    b : numpy.ndarray, optional
        Sampled power-law exponents (S,) [-].
    m_max : numpy.ndarray, optional
        Sampled largest masses (S,) [kg].

    Returns
    -------
    numpy.ndarray
        Bin probabilities [-], shape (S, J) or (1, J).
    """
    return mass_model(mass).bin_probabilities(edges, b, m_max)


def fragment_matrix(grid: MassGrid, fractal_dimension, iterations: int) -> np.ndarray:
    """(S, J, J): expected fragments in mass bin k of one event in mass bin j, by fractal fragmentation
    (Perfect 1997, :func:`riskrf.hazard.design_block.fractal_fragments`) of the bin's middle mass for each sampled
    D, over ``iterations`` generations.  With fragmentation the mass grid reaches down to the finest generation of
    its lightest event, so every fragment keeps its own mass (fragments' masses add up to the event's, within the
    bins' widths).

    Parameters
    ----------
    grid : MassGrid
        The mass grid.
    fractal_dimension : float or array_like
        Fractal dimension D of fragmentation [-], one per sample (S,).
    iterations : int
        Number of fragmentation generations.

    Returns
    -------
    numpy.ndarray
        Expected fragments per event [-], shape (S, J, J).

    References
    ----------
    Perfect, E. (1997). Fractal models for the fragmentation of rocks and soils: a review. Engineering Geology 48,
    185-198.
    """
    from ..hazard.design_block import fractal_fragments
    edges, mid, _ = grid
    D = np.atleast_1d(np.asarray(fractal_dimension, dtype=float))
    Du, which = np.unique(D, return_inverse=True)     # each distinct D once (a scan holds D at one value)
    tables = [fractal_fragments(1.0, float(d), iterations) for d in Du]      # per unit volume of the event
    share = tables[0]["volume_m3"].to_numpy()                                # fragment / event volume (D-free)
    counts = np.array([t["count"].to_numpy() for t in tables])[which.ravel()]     # (S, G)
    k = np.clip(np.searchsorted(edges, mid[:, None] * share[None, :], side="right") - 1, 0, mid.size - 1)
    out = np.zeros((D.size, mid.size, mid.size))
    rows = np.arange(mid.size)
    for g in range(share.size):                   # one generation at a time: (row, bin) pairs are distinct
        out[:, rows, k[:, g]] += counts[:, g][:, None]
    return out


class Fragments(NamedTuple):
    """Events broken into fragments: events per year by mass bin (S, J), the fragment matrix F (S, J, J) and
    fragments per year by mass bin (S, J)."""

    events: np.ndarray
    matrix: np.ndarray
    blocks: np.ndarray


def events_at_road(frag: Fragments, x, v_d, v_s):
    """Fragments reaching the road -> the events they came from: (events per year by event mass bin,
    vulnerability given the event meets a vehicle, moving and striking), each (S, J).

    A share tau_k = x_k / fragments_k of bin k's fragments reaches the road under the option; an event's
    reaching fragments are taken as Poisson, so the event reaches the road with probability
    1 - exp(-sum_k F_jk tau_k).  A vehicle meets an event's debris once (the exposure is per event, as for an
    intact block); it is fatal unless every reaching fragment spares it: 1 - exp(-sum_k F_jk tau_k v_k),
    given the event reaches the road, divided by that probability.

    Parameters
    ----------
    frag : Fragments
        Events per year (S, J) [1/yr], fragment matrix (S, J, J) [-] and fragments per year (S, J) [1/yr].
    x : numpy.ndarray
        Fragments per year reaching the road by mass bin (S, J) [1/yr].
    v_d, v_s : numpy.ndarray
        Vulnerability of a fragment of each mass bin, direct hit and strike (S, J) or (J,) [-].

    Returns
    -------
    events : numpy.ndarray
        Events per year reaching the road by event mass bin (S, J) [1/yr].
    v_d_event, v_s_event : numpy.ndarray
        Vulnerability given the event meets a vehicle, moving and striking (S, J) [-].
    """
    lam_events, F, blocks = frag
    with np.errstate(invalid="ignore", divide="ignore"):
        tau = np.where(blocks > 0, np.clip(x / blocks, 0.0, 1.0), 0.0)
    reach = -np.expm1(-np.einsum("sjk,sk->sj", F, tau))
    out = []
    for v in (v_d, v_s):
        lethal = -np.expm1(-np.einsum("sjk,sk->sj", F, tau * v))
        with np.errstate(invalid="ignore", divide="ignore"):
            out.append(np.where(reach > 0, np.clip(lethal / reach, 0.0, 1.0), 0.0))
    return lam_events * reach, out[0], out[1]


def released_share(frag: Fragments, event_scale) -> np.ndarray:
    """(S, J): share of each fragment mass bin still released when a source measure scales the events by
    ``event_scale`` (S, J) (by the event's mass bin).

    Parameters
    ----------
    frag : Fragments
        Events per year (S, J) [1/yr], fragment matrix (S, J, J) [-] and fragments per year (S, J) [1/yr].
    event_scale : numpy.ndarray
        Factor on the events of each mass bin (S, J) [-].

    Returns
    -------
    numpy.ndarray
        Share of each fragment mass bin still released (S, J) [-].
    """
    lam_events, F, blocks = frag
    released = np.einsum("sj,sjk->sk", lam_events * event_scale, F)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(blocks > 0, released / blocks, 0.0)


# ---- the inputs ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Parameters:
    """Values of the engine's inputs for S samples (arrays of length S; per option (S, N) with N the study's
    options in order; ``effect`` (S, M) the effect parameters, columns given by :class:`ParameterSpace`).

    Money in the study's currency, ``discount_rate`` a fraction per year, ``vehicles_per_day`` two-way,
    ``repair_days`` [days], ``b`` the power-law exponent, ``m_max_kg`` [kg], ``material_draw`` the index of the
    slope model (0: the reference).  Optional inputs are None when the study has none."""

    rate_factor: np.ndarray
    value_of_statistical_life: np.ndarray
    vulnerability_factor: np.ndarray
    vehicles_per_day: np.ndarray
    discount_rate: np.ndarray
    material_draw: np.ndarray
    capital_cost: np.ndarray
    annual_maintenance: np.ndarray
    repair_days: np.ndarray
    effect: np.ndarray
    b: np.ndarray | None = None
    rate_sampling_factor: np.ndarray | None = None
    m_max_kg: np.ndarray | None = None
    fractal_dimension: np.ndarray | None = None

    @property
    def size(self) -> int:
        """Number of samples S."""
        return len(self.rate_factor)


_SCALARS = ("rate_factor", "value_of_statistical_life", "vulnerability_factor", "vehicles_per_day", "discount_rate",
            "b", "rate_sampling_factor", "m_max_kg", "fractal_dimension")
_PER_OPTION = ("capital_cost", "annual_maintenance", "repair_days")


class ParameterSpace:
    """Where each named input of a study sits in a :class:`Parameters`.

    Names are those of :meth:`MitigationStudy.central_parameters`: the study-wide inputs by their field name,
    option inputs as "capital_cost:<option>", "annual_maintenance:<option>", "repair_days:<option>", and the effect
    parameters ("retention:<option or ditch group>", "rate_reduction:<option>", "scaling_effectiveness:<option>",
    "closure_share:<option>") as columns of ``Parameters.effect``, numbered by :meth:`column` in the order the
    option effects ask for them.
    """

    def __init__(self, option_names):
        self.options = {name: k for k, name in enumerate(option_names)}
        self.effects: dict[str, int] = {}

    def column(self, name: str) -> int:
        """Column of ``Parameters.effect`` holding the effect parameter ``name`` (allocated on first use).

        Parameters
        ----------
        name : str
            Effect parameter name, e.g. ``"retention:fence"``.

        Returns
        -------
        int
            Column index in ``Parameters.effect``.
        """
        return self.effects.setdefault(name, len(self.effects))

    def typed(self, named: dict) -> Parameters:
        """The :class:`Parameters` of a dict of named arrays (all of one length S).

        Parameters
        ----------
        named : dict
            Input name -> array of S values (units as in :class:`Parameters`).

        Returns
        -------
        Parameters
            The typed inputs.
        """
        S = len(next(iter(named.values())))
        N = len(self.options)
        per_option = {f: np.zeros((S, N)) for f in _PER_OPTION}
        per_option["repair_days"][:] = np.nan
        scalars = {}
        effect_values = {}
        for name, v in named.items():
            field, _, option = name.partition(":")
            if not option and field in _SCALARS:
                scalars[field] = np.asarray(v, dtype=float)
            elif name == "material_draw":
                continue
            elif field in _PER_OPTION and option in self.options:
                per_option[field][:, self.options[option]] = v
            else:
                effect_values[self.column(name)] = v
        effect = np.zeros((S, len(self.effects)))
        for j, v in effect_values.items():
            effect[:, j] = v
        draw = named["material_draw"].astype(int) if "material_draw" in named else np.zeros(S, dtype=int)
        return Parameters(material_draw=draw, effect=effect, **per_option,
                          **{f: scalars.get(f) for f in _SCALARS})


# ---- the stages of an option --------------------------------------------------------------------------------
class _Flow:
    """Falls per year by mass bin (S, J) as they pass an option's stages, and what the stages add up."""

    def __init__(self, x, S, frag, lam):
        self.x = x
        self.frag = frag
        self.ev_scale = 1.0                                       # source measures on events (fragmentation)
        self.g_prev = None if frag is None else np.ones_like(lam)
        self.users = np.ones(S)          # share of falls meeting open road (a closure protects users only)
        self.repairs = np.zeros(S)
        self.replacements = np.zeros(S)
        self.repair_money = np.zeros(S)
        self.on_road = False
        self.before_structures = None


@dataclass(frozen=True)
class ReleaseStage:
    """A source measure: removes the share ``effect[:, param]`` of the releases, of every size (a typed rate
    reduction, ``target`` None) or of the targeted releases ``target`` (J,) (scaling by zone and mass range: the
    share of the release line and the mass bins it covers; the parameter is its mean effectiveness)."""

    option: str
    param: int
    target: np.ndarray | None = None
    after_road = False
    downstream = False          # acts on the releases, before the falls reach the structures
    stops_falls = False
    moves_road = False

    def apply(self, flow: _Flow, P: Parameters, d) -> None:
        """Apply this stage to the falls in ``flow`` for the parameter samples ``P`` (in place).

        Parameters
        ----------
        flow : _Flow
            Falls per year by mass bin (S, J) [1/yr] and the totals the stages add up; changed in place.
        P : Parameters
            The S parameter samples.
        d : numpy.ndarray of int
            Slope model of each sample (S,), ``P.material_draw``.
        """
        if self.target is not None:
            m = 1.0 - np.clip(P.effect[:, self.param], 0.0, 1.0)[:, None] * self.target[None, :]
        else:
            m = (1.0 - P.effect[:, self.param])[:, None]
        if flow.frag is None:
            flow.x = flow.x * m
        else:           # a source measure removes events (by the event's mass), hence their fragments
            flow.ev_scale = flow.ev_scale * m
            g = released_share(flow.frag, flow.ev_scale)
            with np.errstate(invalid="ignore", divide="ignore"):
                flow.x = np.where(flow.g_prev > 0, flow.x * g / flow.g_prev, 0.0)
            flow.g_prev = g


@dataclass(frozen=True)
class RetentionStage:
    """A ditch, bench, bund or drape (or several simulated together): retains the share ``effect[:, param]`` of the
    falls, shifted by mass bin and slope model by ``shift`` (models, J) when the retention is derived."""

    option: str
    param: int
    shift: np.ndarray | None = None
    after_road = False
    downstream = True
    stops_falls = True
    moves_road = False

    def apply(self, flow: _Flow, P: Parameters, d) -> None:
        """Apply this stage to the falls in ``flow`` for the parameter samples ``P`` (in place).

        Parameters
        ----------
        flow : _Flow
            Falls per year by mass bin (S, J) [1/yr] and the totals the stages add up; changed in place.
        P : Parameters
            The S parameter samples.
        d : numpy.ndarray of int
            Slope model of each sample (S,), ``P.material_draw``.
        """
        ret = P.effect[:, self.param][:, None] + (self.shift[d] if self.shift is not None else 0.0)
        flow.x = flow.x * (1.0 - np.clip(ret, 0.0, 1.0))


@dataclass(frozen=True)
class ContainmentStage:
    """A drape: keeps on the face the share ``effect[:, containment]`` (its containment efficiency, an ASSUMPTION)
    of the falls released under the mesh; the share of the falls that start under it, by mass bin and slope
    model, is ``effect[:, share] + shift[d]`` (derived from the simulation: release points of the blocks that reach
    the road).  Retained share = containment x share under the mesh."""

    option: str
    containment: int
    share: int
    shift: np.ndarray | None = None
    after_road = False
    downstream = True
    stops_falls = True
    moves_road = False

    def apply(self, flow: _Flow, P: Parameters, d) -> None:
        """Apply this stage to the falls in ``flow`` for the parameter samples ``P`` (in place).

        Parameters
        ----------
        flow : _Flow
            Falls per year by mass bin (S, J) [1/yr] and the totals the stages add up; changed in place.
        P : Parameters
            The S parameter samples.
        d : numpy.ndarray of int
            Slope model of each sample (S,), ``P.material_draw``.
        """
        under = P.effect[:, self.share][:, None] + (self.shift[d] if self.shift is not None else 0.0)
        kept = np.clip(P.effect[:, self.containment], 0.0, 1.0)[:, None] * np.clip(under, 0.0, 1.0)
        flow.x = flow.x * (1.0 - kept)


@dataclass(frozen=True)
class BarrierStage:
    """A fence, attenuator (at the barrier line or its own line) or shed (over the road, ``after_road``, covering
    ``coverage`` of the exposed length): per slope model and mass bin (models, J) the share of falls passing a
    working structure, held above its SEL (a repair) and destroying it (a replacement, then out of service for
    ``repair_days``).  ``param``: the column of a typed retention replacing ``passing``; ``component``: the
    option's index (its capital cost, the default replacement cost, and its repair days)."""

    option: str
    component: int
    passing: np.ndarray
    held_sel: np.ndarray
    destroy: np.ndarray
    coverage: float = 1.0
    after_road: bool = False
    param: int | None = None
    repair_cost_per_impact: float = 0.0
    replacement_cost: float | None = None
    downstream = True
    stops_falls = True
    moves_road = False

    def apply(self, flow: _Flow, P: Parameters, d) -> None:
        """Apply this stage to the falls in ``flow`` for the parameter samples ``P`` (in place).

        Parameters
        ----------
        flow : _Flow
            Falls per year by mass bin (S, J) [1/yr] and the totals the stages add up; changed in place.
        P : Parameters
            The S parameter samples.
        d : numpy.ndarray of int
            Slope model of each sample (S,), ``P.material_draw``.
        """
        reach = flow.x * self.coverage
        lam_d = (reach * self.destroy[d]).sum(axis=1)
        down = out_of_service_share(lam_d, P.repair_days[:, self.component])
        held = (reach * self.held_sel[d]).sum(axis=1) * (1.0 - down)
        destroyed = lam_d * (1.0 - down)
        flow.repairs += held
        flow.replacements += destroyed
        flow.repair_money += held * self.repair_cost_per_impact + destroyed * (
            P.capital_cost[:, self.component] if self.replacement_cost is None else self.replacement_cost)
        working = self.passing[d] if self.param is None else (1.0 - P.effect[:, self.param])[:, None]
        passing = down[:, None] + (1.0 - down[:, None]) * working
        flow.x = flow.x * (1.0 - self.coverage) + reach * passing


@dataclass(frozen=True)
class ClosureStage:
    """A road closure: the share ``effect[:, param]`` of the falls occurs while the road is closed; they still
    reach the road (clean-up) but meet no road user."""

    option: str
    param: int
    after_road = False
    downstream = False
    stops_falls = False
    moves_road = False

    def apply(self, flow: _Flow, P: Parameters, d) -> None:
        """Apply this stage to the falls in ``flow`` for the parameter samples ``P`` (in place).

        Parameters
        ----------
        flow : _Flow
            Falls per year by mass bin (S, J) [1/yr] and the totals the stages add up; changed in place.
        P : Parameters
            The S parameter samples.
        d : numpy.ndarray of int
            Slope model of each sample (S,), ``P.material_draw``.
        """
        flow.users = flow.users * (1.0 - P.effect[:, self.param])


@dataclass(frozen=True)
class ExposureStage:
    """A realignment: the share ``factor`` (per slope model) of the falls still reaching the moved road."""

    option: str
    factor: np.ndarray
    after_road = False
    downstream = True
    stops_falls = False
    moves_road = True

    def apply(self, flow: _Flow, P: Parameters, d) -> None:
        """Apply this stage to the falls in ``flow`` for the parameter samples ``P`` (in place).

        Parameters
        ----------
        flow : _Flow
            Falls per year by mass bin (S, J) [1/yr] and the totals the stages add up; changed in place.
        P : Parameters
            The S parameter samples.
        d : numpy.ndarray of int
            Slope model of each sample (S,), ``P.material_draw``.
        """
        flow.x = flow.x * self.factor[d][:, None]


@dataclass(frozen=True)
class OptionChain:
    """One option for the engine: its stages in series and its components as (index, life [yr] or None)."""

    name: str
    stages: tuple
    components: tuple


# ---- the results --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LossResult:
    """The engine's results for S samples and K options: arrays (S, K) in the study currency (present values),
    per year or shares; ``names`` the options.  With ``per_bin``: falls on the road by mass bin ``road_bins``
    (S, K, J), the vulnerabilities ``v_d`` / ``v_s`` (S, K, J) and the hit and strike probabilities (S,)."""

    names: list
    capital: np.ndarray
    pv_renewals: np.ndarray
    pv_maintenance: np.ndarray
    pv_expected_loss: np.ndarray
    total: np.ndarray
    road: np.ndarray
    hits: np.ndarray
    strikes: np.ndarray
    deaths: np.ndarray
    eal: np.ndarray
    ir: np.ndarray
    repairs: np.ndarray
    replacements: np.ndarray
    retention: np.ndarray
    effectiveness: np.ndarray
    user_share: np.ndarray
    road_bins: np.ndarray | None = None
    p_st: np.ndarray | None = None
    p_strike: np.ndarray | None = None
    v_d: np.ndarray | None = None
    v_s: np.ndarray | None = None

    def __getitem__(self, key: str):
        """``result["total"]``: the field, as the dict this engine returned before it was typed."""
        return getattr(self, key)


_RESULT_FIELDS = ("capital", "pv_renewals", "pv_maintenance", "pv_expected_loss", "total", "road", "hits", "strikes",
                  "deaths", "eal", "ir", "repairs", "replacements", "retention", "effectiveness", "user_share")


# ---- the engine ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LossEngine:
    """Every option's costs and risks for a :class:`Parameters`.

    ``reach`` and ``road_share`` (per slope model): P(reach the barrier line) and P(road | barrier line);
    ``road_profile`` (J,) the road share by mass bin over the overall one; ``arrival_profile`` (J,) the reach by
    mass bin over the mean reach (a mass-coupled hazard) or None.
    """

    grid: MassGrid
    mass: object
    rate_per_year: float
    small_falls_per_year: float
    reach: np.ndarray
    road_share: np.ndarray
    road_profile: np.ndarray
    arrival_profile: np.ndarray | None
    exposure: object
    consequences: object
    economics: object
    fragmentation_iterations: int
    chains: tuple

    def evaluate(self, P: Parameters, *, per_bin: bool = False) -> LossResult:
        """Every option for the S samples of ``P``; arrays (S, K).

        Parameters
        ----------
        P : Parameters
            The S parameter samples.
        per_bin : bool, optional
            Also return falls on the road by mass bin, the vulnerabilities and the hit and strike probabilities.

        Returns
        -------
        LossResult
            Arrays (S, K): present values in the study's currency (e.g. [CHF]), frequencies [1/yr], deaths [1/yr],
            individual risk [1/yr] and shares [-].
        """
        edges, mid, small_pmf = self.grid
        S = P.size
        ex, co, ec = self.exposure, self.consequences, self.economics
        d = P.material_draw
        # P(road | barrier line) per sample and mass bin: the slope model's share times the reference run's profile
        # by block mass (heavier blocks run further)
        road_share = np.minimum(self.road_share[d][:, None] * self.road_profile[None, :], 1.0)   # (S, J)
        rate = self.rate_per_year * P.rate_factor * (1.0 if P.rate_sampling_factor is None
                                                     else P.rate_sampling_factor)
        pmf = mass_pmf(edges, self.mass, P.b, P.m_max_kg) if P.b is not None else mass_pmf(edges, self.mass)
        lam = rate[:, None] * pmf + (self.small_falls_per_year * P.rate_factor)[:, None] * small_pmf[None, :]
        frag = None
        if P.fractal_dimension is not None:      # events break up: their fragments are the blocks that travel
            F = fragment_matrix(self.grid, P.fractal_dimension, self.fragmentation_iterations)
            frag = Fragments(lam, F, np.einsum("sj,sjk->sk", lam, F))
            lam = frag.blocks
        arrivals = lam * self.reach[d][:, None]                                    # (S, J) at the barrier line
        if self.arrival_profile is not None:     # mass-coupled: heavier blocks reach the line more often
            arrivals = arrivals * self.arrival_profile[None, :]
        # Bunce et al. (1997) per lane: a fall lands in one lane and only that lane's vehicles can be hit
        lanes = ex.lane_list()
        traffic = np.asarray(P.vehicles_per_day, dtype=float) / ex.vehicles_per_day
        p_st = np.broadcast_to(lane_hit_probability(lanes, ex.vehicle_length_m, traffic), (S,))
        p_strike = ex.share_stopping_on_road * np.broadcast_to(lane_strike_probability(
            lanes, ex.hours_rock_on_road, ex.p_cannot_stop, traffic), (S,))
        vf = P.vulnerability_factor[:, None]
        v_d = np.minimum(vulnerability_by_mass(mid, co.vulnerability_moving_vehicle)[None, :] * vf, 1.0)
        v_s = np.minimum(vulnerability_by_mass(mid, co.vulnerability_striking_rock)[None, :] * vf, 1.0)
        k_occ, p_occ = occupancy_distribution(ex.occupants_per_vehicle, ex.occupants_distribution)
        occ = float(np.dot(k_occ, p_occ))
        p_ts = commuter_passage_probability(ex.commuter_trips_per_day, ex.vehicle_length_m, ex.speed_kmh)
        p_cs = ex.share_stopping_on_road * commuter_strike_probability(ex.commuter_trips_per_day,
                                                                       ex.hours_rock_on_road, ex.p_cannot_stop)
        r = P.discount_rate
        pvf = np.broadcast_to(pv_factor(r, ec.horizon_years), (S,))
        per_fall_cost = np.broadcast_to(closure_cost_per_fall(co, P.vehicles_per_day), (S,))
        names = [c.name for c in self.chains]
        K = len(names)
        res = {k: np.zeros((S, K)) for k in _RESULT_FIELDS}
        road_bins = np.zeros((S, K, mid.size)) if per_bin else None
        vd_all, vs_all = (np.zeros((S, K, mid.size)), np.zeros((S, K, mid.size))) if per_bin else (None, None)
        base_road = (arrivals * road_share).sum(axis=1) if frag is None else \
            events_at_road(frag, arrivals * road_share, v_d, v_s)[0].sum(axis=1)
        for k, chain in enumerate(self.chains):
            capital, renew, maint = self._costs(chain, P, r, S)
            flow = _Flow(arrivals.copy(), S, frag, lam)
            for st in chain.stages:
                if st.after_road and not flow.on_road:
                    flow.x = flow.x * road_share
                    flow.on_road = True
                if st.downstream and flow.before_structures is None:
                    flow.before_structures = flow.x.sum(axis=1) if flow.on_road else \
                        (flow.x * road_share).sum(axis=1)
                st.apply(flow, P, d)
            x = flow.x if flow.on_road else flow.x * road_share
            vd_k, vs_k = v_d, v_s
            if frag is not None:        # from fragments reaching the road to the events they came from
                x_blocks = x
                x, vd_k, vs_k = events_at_road(Fragments(frag.events * flow.ev_scale, frag.matrix,
                                                         frag.blocks * flow.g_prev), x, v_d, v_s)
            road = x.sum(axis=1)
            if flow.before_structures is not None and any(s.stops_falls for s in chain.stages) \
                    and not any(s.moves_road for s in chain.stages):
                passed = road if frag is None else x_blocks.sum(axis=1)     # share of the blocks stopped
                with np.errstate(invalid="ignore", divide="ignore"):
                    stopped_by_structures = np.where(flow.before_structures > 0,
                                                     1.0 - passed / flow.before_structures, 0.0)
            else:
                stopped_by_structures = np.full(S, np.nan)
            users = flow.users
            hits = x * (p_st * users)[:, None]
            strikes = x * (p_strike * users)[:, None]
            n_hits, n_strikes = hits.sum(axis=1), strikes.sum(axis=1)
            deaths = occ * ((hits * vd_k).sum(axis=1) + (strikes * vs_k).sum(axis=1))
            eal = deaths * P.value_of_statistical_life + (n_hits + n_strikes) * co.vehicle_damage \
                + road * per_fall_cost
            ir = (x * (p_ts * vd_k + p_cs * vs_k)).sum(axis=1) * users
            pv_m = pvf * (maint + flow.repair_money)
            pv_l = pvf * eal
            for key, val in (("capital", capital), ("pv_renewals", renew), ("pv_maintenance", pv_m),
                             ("pv_expected_loss", pv_l), ("total", capital + renew + pv_m + pv_l), ("road", road),
                             ("hits", n_hits), ("strikes", n_strikes), ("deaths", deaths),
                             ("eal", eal), ("ir", ir), ("repairs", flow.repairs),
                             ("replacements", flow.replacements), ("retention", stopped_by_structures)):
                res[key][:, k] = val
            with np.errstate(invalid="ignore", divide="ignore"):
                res["effectiveness"][:, k] = np.where(base_road > 0, 1.0 - road / base_road, 0.0)
            res["user_share"][:, k] = users
            if per_bin:
                road_bins[:, k, :] = x
                vd_all[:, k, :], vs_all[:, k, :] = vd_k, vs_k
        if per_bin:
            return LossResult(names, **res, road_bins=road_bins, p_st=p_st, p_strike=p_strike, v_d=vd_all,
                              v_s=vs_all)
        return LossResult(names, **res)

    def _costs(self, chain: OptionChain, P: Parameters, r, S: int):
        """Capital, present value of the renewals, and annual maintenance of an option's components, (S,) each."""
        capital, renew, maint = np.zeros(S), np.zeros(S), np.zeros(S)
        for index, life_years in chain.components:
            kc = P.capital_cost[:, index]
            capital += kc
            maint += P.annual_maintenance[:, index]
            if life_years:
                renew += kc * renewal_factor(life_years, self.economics.horizon_years, r)
        return capital, renew, maint
