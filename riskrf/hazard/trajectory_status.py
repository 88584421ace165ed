"""Is the trajectory model calibrated on this slope?  The status every output of an assessment states.

A run whose slope materials are riskrf's presets (``preset = NAME`` in the scenario) is **uncalibrated**: the
presets' values were not fitted to this slope, and on real releases held out of their derivation they were both
biased and over-confident.  :func:`trajectory_model_status` says so, with the size of that error as measured
(:data:`UNCALIBRATED_HELD_OUT`, the "published presets" rows of the leave-one-dataset-out table
``docs/validation/presets_loo.csv``; a test checks the two agree), and what would calibrate it.  A scenario whose
materials are all typed is reported as "typed": riskrf cannot tell whether those values were fitted to the slope.

Runout in metres, errors in percent of the observed median.
"""
from __future__ import annotations

from dataclasses import dataclass, field

#: The published presets on real releases held out of their derivation (docs/validation/presets_loo.csv, rows
#: "published presets"): data set -> (observed stops, median runout error [%], share of the real stops beyond
#: the simulated p95 and p99 [-]).  Authume: the C2ROP quarry releases of Garcia et al. (2022), Engineering
#: Geology 310:106855 (real stop points of 41 and 48 blocks; see docs/validation/trajectories.md for the data's
#: caveats); Evans & Hungr (1993): one talus shadow angle.
UNCALIBRATED_HELD_OUT = {
    "authume_p1": (41, -81.73, 0.6829, 0.0),
    "authume_p2": (48, -61.82, 0.9792, 0.9792),
    "evans_hungr_1993": (1, -13.75, 0.0, 0.0),
}


@dataclass(frozen=True)
class TrajectoryModelStatus:
    """``status`` ("uncalibrated", "calibration used for the uncertainty", "typed" or "no simulation"),
    ``presets`` (material -> preset name), ``text`` (the sentence for the outputs) and ``calibrations`` (the
    calibration files the site uses, if any)."""

    status: str
    presets: dict = field(default_factory=dict)
    text: str = ""
    calibrations: tuple = ()

    @property
    def uncalibrated(self) -> bool:
        """True when the run's own materials come from presets and no calibration of the site is used."""
        return self.status == "uncalibrated"

    @property
    def figure_note(self) -> str | None:
        """The line stamped on the figures drawn from the trajectories (None unless uncalibrated)."""
        if not self.uncalibrated:
            return None
        return (f"UNCALIBRATED trajectory model (presets, not fitted to this slope): a screening estimate; on "
                f"held-out real releases the presets gave {held_out_range()}.")

    def to_dict(self) -> dict:
        """JSON-ready: status, presets, calibrations, the held-out errors of the presets and the text.

        Returns
        -------
        dict
            ``status``, ``presets``, ``calibrations``, ``held_out_errors_of_the_presets`` and ``text``.
        """
        return {"status": self.status, "presets": dict(self.presets), "calibrations": list(self.calibrations),
                "held_out_errors_of_the_presets": {
                    k: {"observed_stops": n, "median_error_pct": e, "share_beyond_p95": b95,
                        "share_beyond_p99": b99} for k, (n, e, b95, b99) in UNCALIBRATED_HELD_OUT.items()},
                "text": self.text}


def held_out_range() -> str:
    """The presets' held-out errors in words: the range of median errors and the largest share beyond p99.

    Returns
    -------
    str
        E.g. "median runout 14 to 82 % short, and up to 98 % of the real stops beyond the simulated p99".
    """
    errs = [e for _, e, _, _ in UNCALIBRATED_HELD_OUT.values()]
    beyond = max(b for *_, b in UNCALIBRATED_HELD_OUT.values())
    lo, hi = sorted(abs(e) for e in errs)[0], sorted(abs(e) for e in errs)[-1]
    side = "short" if all(e < 0 for e in errs) else "off"
    return (f"median runout {lo:.0f} to {hi:.0f} % {side}, and up to {beyond:.0%} of the real stops beyond the "
            "simulated p99")


def trajectory_model_status(scenario_data: dict | None, *, calibration_bootstrap: str | None = None,
                            posterior: str | None = None) -> TrajectoryModelStatus:
    """The calibration status of a run's trajectory model, with the sentence every output carries.

    Parameters
    ----------
    scenario_data : dict or None
        The scenario's TOML tables (None: the run simulates nothing, e.g. typed velocities).
    calibration_bootstrap : str, optional
        ``[uncertainty] calibration_bootstrap`` of the site (a calibration's bootstrap, used for the material
        draws of the uncertainty study).
    posterior : str, optional
        ``[model_uncertainty] posterior`` of the site (a posterior sample, used by the model-uncertainty stage).

    Returns
    -------
    TrajectoryModelStatus
        The status and its sentence.
    """
    if scenario_data is None:
        return TrajectoryModelStatus("no simulation", text="no trajectory simulation: the velocities are typed")
    materials = scenario_data.get("materials") or {}
    presets = {str(name): str(spec["preset"]) for name, spec in materials.items()
               if isinstance(spec, dict) and "preset" in spec}
    calibrations = tuple(c for c in (calibration_bootstrap, posterior) if c)
    if not presets:
        return TrajectoryModelStatus(
            "typed", text="trajectory model: the slope materials are typed in the scenario (riskrf cannot tell "
                          "whether they were calibrated on this slope)", calibrations=calibrations)
    named = ", ".join(f"{m} = {p}" for m, p in presets.items())
    if calibrations:
        return TrajectoryModelStatus(
            "calibration used for the uncertainty", presets, calibrations=calibrations,
            text=(f"trajectory model: the run's own materials are presets ({named}); the site's calibration "
                  f"({', '.join(calibrations)}) is used for the uncertainty of the decision, not for the "
                  "central run"))
    return TrajectoryModelStatus(
        "uncalibrated", presets, text=(
            f"UNCALIBRATED trajectory model: the slope materials are riskrf's presets ({named}), not fitted to this "
            f"slope.  On real releases held out of their derivation the presets gave {held_out_range()} "
            "(docs/validation/trajectories.md): read run-out, speeds, bounce heights and energies as a screening "
            "estimate.  Calibrate on test releases (riskrf calibrate-pooled).  What a release campaign is worth to the "
            "decision is stated beside the ranking when the slope materials are sampled ([uncertainty.materials]), "
            "and with draws of its own by a [model_uncertainty] table."))


__all__ = ["TrajectoryModelStatus", "UNCALIBRATED_HELD_OUT", "held_out_range", "trajectory_model_status"]
