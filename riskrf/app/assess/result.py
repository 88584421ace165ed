"""What one assessment computed: :class:`Assessment`, its fields in the order of the chain, where its rate came
from (:attr:`Assessment.rate_source`) and its headline numbers with units (:meth:`Assessment.summary`, written to
summary.json by :func:`riskrf.app.assess.outputs.write_assessment`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ... import __version__
from ...frequency.inventory.record import Inventory
from ...frequency.study import FrequencyAnalysis
from ...hazard.energy_study import INTERVAL_COVERS, EnergyAnalysis
from ...risk.mitigation import MitigationStudy
from ..site import Site


@dataclass
class Assessment:
    """Everything one ``riskrf assess`` run computed for a site, in the order of the chain.

    Fields: the :class:`~riskrf.app.site.Site` read, its :class:`~riskrf.frequency.inventory.Inventory`, the frequency analyses
    (power law, and annual maxima when dated), the simulation ``result`` (:class:`simulation.SimulationResult`),
    the :class:`~riskrf.hazard.energy_study.EnergyAnalysis` at the barrier line, the
    :class:`~riskrf.risk.mitigation.MitigationStudy` and its ``decision`` (recommendation dict), the ``seed`` and
    number of simulated blocks, ``warnings`` raised on the way, stage ``timings`` [s] and the site's rate model
    (``rates``, or None).  Written to files by :func:`write_assessment`; nothing here prints.
    """
    site: Site
    inventory: Inventory
    frequency: FrequencyAnalysis
    maxima_frequency: FrequencyAnalysis | None
    result: object
    energy: EnergyAnalysis
    study: MitigationStudy
    decision: dict
    seed: int
    n_blocks: int
    warnings: list = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    rates: object = None            # SiteRates of the site's [rates] model (riskrf.risk.site_rates), or None
    release_factor: float = 1.0     # rate_basis = "road": released falls per fall recorded on the road
    #: the governing design basis's requirement at the barrier line and along the profile (SiteDesign), or None
    design: object = None
    #: the trajectory model's uncertainty carried to the design energies and the ranking
    #: (:class:`~riskrf.app.model_uncertainty.ModelUncertaintyStudy`), None unless the site asks for it
    model_uncertainty: object = None
    #: whether the trajectory model is calibrated on this slope
    #: (:class:`~riskrf.hazard.trajectory_status.TrajectoryModelStatus`); its sentence leads the warnings when not
    trajectory_model: object = None
    #: figures already being drawn beside the computation: {"dir": Path, "pending": [part with result(), ...]}
    #: (see ``run_assessment(figures_dir=..., runner=...)``); empty when ``write_assessment`` draws them all.
    drawing: dict = field(default_factory=dict, repr=False)

    @property
    def rate_source(self) -> str:
        """Where the hazard's annual rate comes from, in words."""
        inv = self.inventory
        if self.site.inventory.rate_from == "rate_model" and self.rates is not None:
            text = "rate model: " + self.rates.rate_text()
        else:
            text = (f"inventory: {inv.n_events:,} recorded falls in {inv.duration_years:.3g} years "
                    f"({self.frequency.power_law.rate_min:.4g} per year at or above m_min)")
        scale = self.site.inventory.rate_scale
        text += (f"; times rate_scale {scale:g} (typed: share of the recorded source above this road)"
                 if scale != 1 else "")
        if self.site.inventory.rate_basis == "road":
            return text + (f"; rate_basis = 'road': the record counts falls that reached the road, so the release "
                           f"rate is {self.release_factor:.4g} times it (1 / P(road | release), simulated; doing "
                           "nothing reproduces the recorded road falls)")
        return text + "; rate_basis = 'release': the record counts falls released from the slope"

    def summary(self) -> dict:
        """Every headline number, machine-readable, with units.

        Returns
        -------
        dict
            JSON-ready headline numbers (``summary.json``); the units are listed under ``units``: mass [kg], volume
            [m3], energy [kJ], height [m], velocity [m/s], rate [1/yr], return period [yr] and money [site currency].
        """
        fr, gr = self.frequency, self.frequency.power_law
        hz = self.energy.hazard
        ranking = self.decision["ranking"]
        nothing = ranking[ranking["kind"] == "none"]
        out = {
            "site": self.site.name, "riskrf_version": __version__, "seed": self.seed, "n_blocks": self.n_blocks,
            "units": {"mass": "kg", "volume": "m3", "energy": "kJ", "height": "m", "velocity": "m/s",
                      "rate": "1/yr", "return_period": "yr", "money": self.study.currency},
            "inventory": {"source": self.inventory.source, "events": self.inventory.n_events,
                          "duration_years": self.inventory.duration_years,
                          "density_kg_m3": self.inventory.density_kg_m3,
                          "density_is_default": self.inventory.density_is_default},
            "power_law": {"b": gr.b, "b_stderr": gr.b_stderr, "b_ci": list(gr.b_ci), "a": gr.a, "m_min_kg": gr.m_min,
                          "m_min_method": gr.m_min_method, "rate_min_per_year": gr.rate_min,
                          "bootstrap_p_value": fr.bootstrap_p},
            "whole_wall_design_masses": fr.design_masses().assign(basis=WHOLE_WALL_BASIS).to_dict(orient="records"),
            "whole_wall_design_masses_basis": WHOLE_WALL_BASIS,
            "site_design_masses": self.energy.site_masses.to_dict(orient="records")
            if self.energy.site_masses is not None else None,
            "design_block": self.energy.design_block.to_dict() if self.energy.design_block is not None else None,
            "design_energy_sensitivity": self.energy.sensitivity.to_dict(orient="records")
            if self.energy.sensitivity is not None else None,
            "design_energy_tornado": self.energy.tornado.to_dict() if self.energy.tornado is not None else None,
            "design_energy_interval_covers": INTERVAL_COVERS,
            "hazard": {"power_law_for_hazard": {"b": float(hz.mass.b), "m_max_kg": hz.mass.m_max,
                                                "m_min_kg": float(hz.mass.m_min)},
                       "mass_coupled": hz.mass_coupled,
                       "falls_per_year": hz.rate_per_year, "rate_source": self.rate_source,
                       "rate_basis": self.site.inventory.rate_basis,
                       "release_factor": self.release_factor,
                       "reach_probability": hz.reach_probability,
                       "arrivals_per_year": hz.arrival_rate,
                       "road_share": self.study.road_share,
                       "energy_p95_kj": float(hz.energy_percentile(95)[0]),
                       "energy_p99_kj": float(hz.energy_percentile(99)[0]),
                       "height_p95_m": float(hz.height_percentile(95)) if hz.heights_m is not None else None},
            "design_energies": self.energy.design.to_dict(orient="records"),
            "fences": self.energy.fence_verdicts().to_dict(orient="records"),
            "ranking": ranking.to_dict(orient="records"),
            "options": self.decision["options"],
            "recommendation": self.decision["recommendation"],
            "effort": self.decision.get("effort"),
            "required_barrier_option": (self.study.required_barrier.to_dict()
                                        if self.study.required_barrier is not None else None),
            "uncertainty": self.decision["uncertainty"],
            "best_option": ranking["option"].iloc[0],
            "second_option": ranking["option"].iloc[1],
            "break_even": self.decision["break_even"].to_dict(orient="records"),
            "value_of_information": self.decision["value_of_information"],
            "release_campaign": self.decision.get("release_campaign"),
            "individual_risk_do_nothing": float(nothing["individual_risk"].iloc[0]) if len(nothing) else None,
            "fn_zone": dict(zip(ranking["option"], ranking["fn_zone"])),
            "defaults_used": list(self.site.defaults_used),
            "warnings": self.warnings,
            "trajectory_model": self.trajectory_model.to_dict() if self.trajectory_model is not None else None,
            "timings_s": self.timings,
        }
        if self.rates is not None:
            out["rate_model"] = self.rates.summary()
        if self.model_uncertainty is not None:
            out["model_uncertainty"] = self.model_uncertainty.to_dict()
        if self.design is not None:
            out.update(self.design.to_dict())
        if fr.gumbel is not None or (self.maxima_frequency and self.maxima_frequency.gumbel is not None):
            src = fr if fr.gumbel is not None else self.maxima_frequency
            out["annual_maxima"] = {"source": src.inventory.source, "gumbel": dict(zip(src.gumbel.param_names,
                                                                                      src.gumbel.params)),
                                    "gev": dict(zip(src.gev.param_names, src.gev.params)) if src.gev else None,
                                    "deviance_test": src.deviance, "preferred_model": src.preferred_model()}
        return out


#: What the inventory fit's design-mass table is, in the outputs of an assessment.
WHOLE_WALL_BASIS = ("whole monitored wall (inventory fit), untruncated power law, rate not scaled: reference only, "
                    "not the site's design masses (site_design_masses.csv)")
