"""Design standards for flexible rock fall barriers: ETAG 027 / EAD 340059 and UNI 11211-4.

Evidence tags follow ``shared/research/domain-methods.md`` section 3: [V] seen in a
source, [R] recalled, to be confirmed against the standard's text.  Every factor is
a named default that a user can override.

* ETAG 027 (2008/2013), replaced in 2018 by EAD 340059-00-0106 [V]: a kit is rated by
  its maximum energy level MEL (one impact) and service energy level SEL = MEL/3 [R]
  (two impacts without maintenance).
* UNI 11211-4 (2012, rev. 2018; Peila & Ronco 2009, NHESS 9:1291): design energy
  E_d = 1/2 m_d v_d^2 with m_d = Vol rho gamma_VolF gamma_gamma and v_d = v_t gamma_Tr gamma_Dp,
  v_t the 95th-percentile velocity [V]; the check is E_d <= E_barrier / gamma_E.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..core.format import sig
from ..core.units import DAYS_PER_YEAR, SEL_PER_MEL, kinetic_energy_kj
from ..core.validation import check_positive

#: ETAG 027 energy classes (MEL and SEL in kJ) [R: confirm against the EAD 340059 table].
ETAG027_CLASSES = pd.DataFrame({
    "class": [0, 1, 2, 3, 4, 5, 6, 7, 8],
    "MEL_kj": [100, 250, 500, 1000, 1500, 2000, 3000, 4500, np.nan],
    "SEL_kj": [np.nan, 85, 170, 330, 500, 660, 1000, 1500, np.nan],
}).set_index("class")

#: UNI 11211-4 partial factors with the values the RocFall UNI 11211 design page quotes from
#: UNI 11211-4:2012 and Peila & Ronco (2009) [V]; gamma_E values [R].
UNI11211_FACTORS = {
    "gamma_Tr": {"restitution back-analysed": 1.02, "restitution from literature": 1.10},
    "gamma_Dp": {"high-quality topography": 1.02, "low-quality topography": 1.10},
    "gamma_VolF": {"precise block survey": 1.02, "rough block survey": 1.10},
    "gamma_gamma": {"unit weight": 1.0},
    "gamma_E": {"against SEL": 1.0, "against MEL": 1.2},
    "velocity_percentile": 95,
}


def service_energy_level(mel_kj):
    """SEL = MEL / 3 (ETAG 027) [kJ].

    Parameters
    ----------
    mel_kj : float
        Maximum energy level of the kit [kJ].

    Returns
    -------
    float
        Service energy level [kJ].

    References
    ----------
    EOTA (2008/2013). ETAG 027, Guideline for European Technical Approval of falling rock protection kits;
    replaced by EAD 340059-00-0106 (2018).
    """
    return check_positive(mel_kj, "mel_kj") * SEL_PER_MEL


@dataclass(frozen=True)
class UNI11211Design:
    """UNI 11211-4 design values: characteristic and design energy [kJ], design mass [kg], velocity [m/s]."""

    characteristic_energy_kj: float
    design_energy_kj: float
    design_mass_kg: float
    design_velocity_ms: float
    factors: dict

    def check(self, barrier_energy_kj: float, gamma_E: float) -> bool:
        """E_d <= E_barrier / gamma_E.

        Parameters
        ----------
        barrier_energy_kj : float
            The barrier's rated energy (SEL or MEL) [kJ].
        gamma_E : float
            Partial factor on the barrier energy [-] (1.0 against SEL, 1.2 against MEL: :data:`UNI11211_FACTORS`).

        Returns
        -------
        bool
            Whether the design energy is within the factored capacity.
        """
        return self.design_energy_kj <= check_positive(barrier_energy_kj, "barrier_energy_kj") / gamma_E


def uni11211_design_energy(volume_m3: float, density_kg_m3: float, velocity_ms: float, *, gamma_Tr: float = 1.10,
                           gamma_Dp: float = 1.10, gamma_VolF: float = 1.10, gamma_gamma: float = 1.0
                           ) -> UNI11211Design:
    """UNI 11211-4 design energy E_d = 1/2 (Vol rho gamma_VolF gamma_gamma) (v_t gamma_Tr gamma_Dp)^2.

    Defaults are the cautious values (restitution from literature, low-quality
    topography, rough block survey); pass 1.02 where the better case applies.

    Parameters
    ----------
    volume_m3 : float
        Design block volume Vol [m³].
    density_kg_m3 : float
        Rock density rho [kg/m³].
    velocity_ms : float
        The 95th-percentile velocity v_t at the barrier [m/s].
    gamma_Tr, gamma_Dp, gamma_VolF, gamma_gamma : float
        Partial factors [-] on the trajectory simulation, the topography, the volume and the unit weight
        (1.0-2.0).

    Returns
    -------
    UNI11211Design
        Characteristic and design energy [kJ], design mass [kg] and velocity [m/s], the factors used.

    References
    ----------
    UNI 11211-4:2012, Opere di difesa dai crolli in roccia, parte 4: progetto definitivo ed esecutivo.
    Peila, D. & Ronco, C. (2009). Technical note: Design of rockfall net fences and the new ETAG 027 European
    guideline. Natural Hazards and Earth System Sciences 9, 1291-1298.
    """
    vol = check_positive(volume_m3, "volume_m3")
    rho = check_positive(density_kg_m3, "density_kg_m3")
    v = check_positive(velocity_ms, "velocity_ms")
    factors = {"gamma_Tr": gamma_Tr, "gamma_Dp": gamma_Dp, "gamma_VolF": gamma_VolF, "gamma_gamma": gamma_gamma}
    for name, value in factors.items():
        if not 1.0 <= float(value) <= 2.0:
            raise ValueError(f"{name} = {value!r}: UNI 11211-4 partial factors lie between 1.0 and 2.0")
    m_d = vol * rho * gamma_VolF * gamma_gamma
    v_d = v * gamma_Tr * gamma_Dp
    return UNI11211Design(characteristic_energy_kj=kinetic_energy_kj(vol * rho, v),
                          design_energy_kj=kinetic_energy_kj(m_d, v_d), design_mass_kg=m_d,
                          design_velocity_ms=v_d, factors=factors)


def check_fence(hazard, mel_kj: float, height_m: float, *, T: float = 100.0, free_board_m: float = 0.5,
                design_life_years: float = 50.0, n_bootstrap: int = 300, seed=1, design_energy=None) -> pd.DataFrame:
    """Check a fence of capacity MEL [kJ] and height [m] against an :class:`~riskrf.EnergyHazard`.

    Energy: the T-year impact energy (with its interval) against MEL and SEL = MEL/3,
    the annual frequency and design-life probability of impacts above each.
    Height: the 95th-percentile bounce height plus ``free_board_m`` against the
    fence height (UNI 11211-4 form), and the share of arriving falls passing over.
    Parameters
    ----------
    hazard : EnergyHazard
        The hazard at the fence line.
    mel_kj : float
        The fence's maximum energy level [kJ].
    height_m : float
        The fence's height [m].
    T : float
        Return period of the design energy [yr].
    free_board_m : float
        Margin added to the 95th-percentile bounce height [m].
    design_life_years : float
        Period of the probabilities of an impact above MEL and SEL [yr].
    n_bootstrap : int
        Replicates of the energy's interval.
    seed : int
        Seed of the interval.
    design_energy : tuple of float, optional
        (e_T, lower, upper) [kJ] computed before, reused.

    Returns
    -------
    pandas.DataFrame
        One row per check: ``check``, ``demand``, ``capacity``, ``unit`` (kJ or m), ``interval``, ``adequate``,
        ``note``.

    References
    ----------
    EOTA (2008/2013). ETAG 027, Guideline for European Technical Approval of falling rock protection kits;
    replaced by EAD 340059-00-0106 (2018).
    UNI 11211-4:2012 (the height check).
    """
    mel = check_positive(mel_kj, "mel_kj")
    H = check_positive(height_m, "height_m")
    sel = service_energy_level(mel)
    if design_energy is None:
        e_T = float(hazard.energy_at_return_period(T))
        lo, hi = hazard.energy_at_return_period_ci(T, n_bootstrap=n_bootstrap, seed=seed)
    else:
        e_T, lo, hi = design_energy
    rows = []
    for name, cap in (("MEL", mel), ("SEL", sel)):
        lam = float(hazard.annual_frequency(cap))
        rows.append({"check": f"{T:g}-year energy vs {name}", "demand": e_T, "capacity": cap, "unit": "kJ",
                     "interval": f"{sig(lo, 2)} - {sig(hi, 2)}", "adequate": e_T <= cap,
                     "note": f"impacts above {name}: {lam:.3g}/yr (1 in {1 / lam if lam > 0 else np.inf:.3g} yr), "
                             f"P(in {design_life_years:g} yr) = {-np.expm1(-lam * design_life_years):.3f}"})
    if hazard.heights_m is not None:
        h95 = float(hazard.height_percentile(95))
        over = float(hazard.height_exceedance(H))
        rows.append({"check": "p95 bounce height + free board vs height", "demand": h95 + free_board_m,
                     "capacity": H, "unit": "m", "interval": "", "adequate": h95 + free_board_m <= H,
                     "note": f"{over:.1%} of arriving falls pass over (centre above the fence)"})
    table = pd.DataFrame(rows)
    return table


# ---- damage states of a barrier in service (fences, attenuators, sheds) ------------------------------
#: Outcome of one fall at a barrier: passes over it, held without damage (E <= SEL), held with damage that
#: costs a repair (SEL < E <= MEL), breaks through and destroys it (E > MEL), or passes while it is out of service.
OUTCOMES = ("over", "held", "held, repair", "destroyed", "passed, out of service")


def damage_state_shares(energy_kj, over, mel_kj: float):
    """Shares of falls per column of ``energy_kj`` (rows: simulated blocks; columns e.g. mass classes) that pass
    over (``over``, per row, or per row and column), are held below SEL, held between SEL and MEL, or break through above MEL.

    With no simulated falls (no rows: none reached the barrier in that slope model) every share is 0, not
    nan: the shares multiply an arrival rate of zero.

    Parameters
    ----------
    energy_kj : array_like
        Impact energies [kJ], rows the simulated blocks (columns optional).
    over : array_like of bool
        Whether each block passes over the barrier (per row, or per row and column).
    mel_kj : float
        Maximum energy level [kJ]; SEL = MEL/3.

    Returns
    -------
    tuple of numpy.ndarray
        (passing, held_repair, destroyed) shares [-] per column; passing = over + destroyed.
    """
    e = np.asarray(energy_kj, dtype=float)
    over = np.asarray(over, dtype=bool)
    if over.ndim < e.ndim:                  # one flag per row; a 2-D ``over`` (per row and column) is used as is
        over = over.reshape(-1, *([1] * (e.ndim - 1)))
    mel = check_positive(mel_kj, "mel_kj")
    if e.shape[0] == 0:
        zero = np.zeros(e.shape[1:])
        return zero, zero.copy(), zero.copy()
    working = ~over
    through = working & (e > mel)
    held_repair = working & (e > service_energy_level(mel)) & (e <= mel)
    return np.mean(over | through, axis=0), np.mean(held_repair, axis=0), np.mean(through, axis=0)


def out_of_service_share(destructive_rate_per_year, repair_days):
    """Long-run share of time a barrier is out of service: lambda t / (1 + lambda t).

    Impacts above MEL arrive at ``destructive_rate_per_year`` while it works (Poisson); each
    leaves it down for ``repair_days`` (an assumption stated with the results), during which
    it takes no impacts: an alternating renewal process with mean up time 1/lambda.

    Parameters
    ----------
    destructive_rate_per_year : float or array_like
        Rate lambda of impacts above MEL while in service [1/yr].
    repair_days : float or array_like
        Time out of service after each [days].

    Returns
    -------
    numpy.ndarray
        Long-run share of time out of service [-].

    References
    ----------
    Ross, S. M. (2014). Introduction to Probability Models, 11th ed. Academic Press, chapter 7 (alternating
    renewal processes: the long-run share of time "on" is E[on] / (E[on] + E[off])).
    """
    lam = np.asarray(destructive_rate_per_year, dtype=float)
    t = np.asarray(repair_days, dtype=float) / DAYS_PER_YEAR
    return lam * t / (1.0 + lam * t)


def barrier_history(times_years, energies_kj, heights_m, *, mel_kj: float, height_m: float | None = None,
                    repair_days: float, repair_cost: float = 0.0, replacement_cost: float = 0.0) -> pd.DataFrame:
    """Falls at one barrier in time order with the damage-state model: what happened to each and what it cost.

    A fall passes over when its bounce height exceeds ``height_m`` (None: a shed roof,
    nothing passes over); while the barrier works a fall with energy above MEL destroys
    it, passes and costs ``replacement_cost``, and the barrier is out of service for
    ``repair_days`` so every later fall in that time passes; a fall between SEL = MEL/3
    and MEL is held and costs ``repair_cost``; below SEL it is held at no cost.

    Parameters
    ----------
    times_years : array_like
        Times of the falls [yr], increasing.
    energies_kj : array_like
        Impact energies [kJ].
    heights_m : array_like or None
        Bounce heights at the barrier [m] (None: zero).
    mel_kj : float
        Maximum energy level [kJ].
    height_m : float, optional
        Barrier height [m] (None: a shed roof).
    repair_days : float
        Time out of service after a destruction [days].
    repair_cost, replacement_cost : float
        Cost of a repair and of a replacement [currency].

    Returns
    -------
    pandas.DataFrame
        One row per fall: ``time_years``, ``energy_kj``, ``height_m``, ``outcome``, ``cost``, ``passes``.
    """
    t = np.asarray(times_years, dtype=float)
    e = np.asarray(energies_kj, dtype=float)
    h = np.zeros_like(e) if heights_m is None else np.asarray(heights_m, dtype=float)
    if not (t.shape == e.shape == h.shape):
        raise ValueError(f"times_years, energies_kj and heights_m need the same length; got {t.size}, {e.size}, "
                         f"{h.size}")
    if np.any(np.diff(t) < 0):
        raise ValueError("times_years must be in increasing order")
    mel = check_positive(mel_kj, "mel_kj")
    sel = service_energy_level(mel)
    back_in_service = -np.inf
    outcome, cost = [], []
    for ti, ei, hi in zip(t, e, h):
        if ti < back_in_service:
            outcome.append("passed, out of service")
            cost.append(0.0)
        elif height_m is not None and hi > height_m:
            outcome.append("over")
            cost.append(0.0)
        elif ei > mel:
            outcome.append("destroyed")
            cost.append(float(replacement_cost))
            back_in_service = ti + float(repair_days) / DAYS_PER_YEAR
        elif ei > sel:
            outcome.append("held, repair")
            cost.append(float(repair_cost))
        else:
            outcome.append("held")
            cost.append(0.0)
    return pd.DataFrame({"time_years": t, "energy_kj": e, "height_m": h, "outcome": outcome, "cost": cost,
                         "passes": [o in ("over", "destroyed", "passed, out of service") for o in outcome]})
