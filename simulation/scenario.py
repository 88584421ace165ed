"""Scenarios: slope profile, materials, seeder, collectors and settings, read from TOML.

The documentation (File formats, "Scenario files") describes every field.  Unknown fields are an
error (with a did-you-mean), and every error names the file and the field.
"""
from __future__ import annotations

import difflib
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import stats

from .errors import RiskrfError
from .materials import FIELD_DEFAULTS, PresetError, resolve_material
from .contact import (CRSP_VELOCITY_SCALE_MS, EN_CONSTANT, EN_VELOCITY, EN_WYLLIE, ET_CONSTANT, ET_COULOMB, ET_FRICTION,
                      ROLLING_RESISTANCE_CAP_DEG)
from .slope import Profile
from ._display import Displayed, short_repr
from .units import DEFAULT_DENSITY_KG_M3, DENSITY_RANGE_KG_M3, INERTIA_FACTORS, STANDARD_GRAVITY_MS2, block_radius


class ScenarioError(RiskrfError, ValueError):
    """A scenario file or dictionary is invalid; the message names the file and field."""


def _check_keys(table: dict, allowed, where: str, source: str):
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(key, list(allowed), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else f"; allowed: {', '.join(sorted(allowed))}"
            raise ScenarioError(f"{source}: unknown field {where}{key!r}{hint}")


def _number(value, where: str, source: str, *, lo=-math.inf, hi=math.inf, lo_open=False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(f"{source}: {where} must be a number; got {value!r}")
    v = float(value)
    if not math.isfinite(v) or v < lo or v > hi or (lo_open and v == lo):
        rng = f"{'(' if lo_open else '['}{lo:g}, {hi:g}]"
        raise ScenarioError(f"{source}: {where} = {value!r} is outside the physical range {rng}")
    return v


@dataclass(frozen=True)
class Distribution:
    """A sampling distribution given in a scenario: a number, or a table with ``dist``.

    ``{dist = "uniform", low, high}``, ``{dist = "normal", mean, std, min?, max?}``
    (truncated), ``{dist = "lognormal", median, sigma, max?}`` (sigma of ln x),
    ``{dist = "triangular", low, mode, high}``.
    """

    kind: str
    params: dict = field(default_factory=dict)

    @classmethod
    def parse(cls, spec, where: str, source: str, *, lo=-math.inf, hi=math.inf, lo_open=False) -> "Distribution":
        """A distribution from a scenario field: a number (constant) or a table with ``dist`` (uniform, normal,
        lognormal, triangular) and its parameters, checked within [lo, hi] (``lo_open``: lo excluded).
        Parameters
        ----------
        spec : float or dict
            The field's value as read.
        where : str
            The field, for messages (e.g. ``"seeder.mass_kg"``).
        source : str
            The file, for messages.
        lo, hi : float
            Bounds every draw must respect, in the field's unit.
        lo_open : bool
            ``lo`` itself excluded.

        Returns
        -------
        Distribution

        Raises
        ------
        ScenarioError
            Naming the file, the field and the value.
        """
        if isinstance(spec, (int, float)) and not isinstance(spec, bool):
            return cls("constant", {"value": _number(spec, where, source, lo=lo, hi=hi, lo_open=lo_open)})
        if not isinstance(spec, dict) or "dist" not in spec:
            raise ScenarioError(f"{source}: {where} must be a number or a table with 'dist'; got {spec!r}")
        kind = spec["dist"]
        fields = {"uniform": {"low", "high"}, "normal": {"mean", "std", "min", "max"},
                  "lognormal": {"median", "sigma", "max"}, "triangular": {"low", "mode", "high"},
                  "constant": {"value"}}
        if kind not in fields:
            raise ScenarioError(f"{source}: {where}.dist = {kind!r} is not one of {sorted(fields)}")
        _check_keys({k: v for k, v in spec.items() if k != "dist"}, fields[kind], f"{where}.", source)
        p = {k: _number(v, f"{where}.{k}", source) for k, v in spec.items() if k != "dist"}
        required = {"uniform": ("low", "high"), "normal": ("mean", "std"), "lognormal": ("median", "sigma"),
                    "triangular": ("low", "mode", "high"), "constant": ("value",)}[kind]
        for k in required:
            if k not in p:
                raise ScenarioError(f"{source}: {where} ({kind}) needs {k!r}")
        if kind in ("uniform", "triangular") and not p["low"] <= p.get("mode", p["low"]) <= p["high"]:
            raise ScenarioError(f"{source}: {where} needs low <= mode <= high; got {spec}")
        if "min" in p and "max" in p and not p["min"] < p["max"]:
            raise ScenarioError(f"{source}: {where} needs min < max; got min = {p['min']:g}, max = {p['max']:g}")
        if kind == "lognormal" and not p["median"] > 0:
            raise ScenarioError(f"{source}: {where}.median = {p['median']:g} must be > 0 (a lognormal law's median; "
                                "its logarithm is the law's centre)")
        if kind == "lognormal" and "max" in p and p["max"] < p["median"]:
            raise ScenarioError(f"{source}: {where}.max = {p['max']:g} lies below the median = {p['median']:g}: the "
                                "truncation would leave only the law's lower tail (every draw near max); check both "
                                "values and their units")
        if p.get("std", 0) < 0 or p.get("sigma", 0) < 0:
            raise ScenarioError(f"{source}: {where} spread must be >= 0; got {spec}")
        dist = cls(kind, p)
        lo_v, hi_v = dist.bounds()
        if lo_v < lo or hi_v > hi or (lo_open and lo_v == lo and kind != "lognormal"):
            raise ScenarioError(f"{source}: {where} = {spec} reaches values outside the physical range "
                                f"[{lo:g}, {hi:g}]")
        return dist

    def bounds(self):
        """(lowest, highest) value the distribution can draw (-inf/inf for an untruncated normal; 0/inf for a lognormal
        without ``max``).

        Returns
        -------
        tuple of float
            In the field's unit.
        """
        p = self.params
        if self.kind == "constant":
            return p["value"], p["value"]
        if self.kind in ("uniform", "triangular"):
            return p["low"], p["high"]
        if self.kind == "normal":
            return p.get("min", -math.inf if p["std"] > 0 else p["mean"]), \
                p.get("max", math.inf if p["std"] > 0 else p["mean"])
        return (0.0 if p["sigma"] > 0 else p["median"]), p.get("max", math.inf if p["sigma"] > 0 else p["median"])


    def sample(self, rng: np.random.Generator, n: int) -> np.ndarray:
        """``n`` draws with ``rng`` (a NumPy Generator).

        Parameters
        ----------
        rng : numpy.random.Generator
            The stream.
        n : int
            Draws.

        Returns
        -------
        numpy.ndarray
            In the field's unit.
        """
        p = self.params
        if self.kind == "constant":
            return np.full(n, p["value"])
        if self.kind == "uniform":
            return rng.uniform(p["low"], p["high"], n)
        if self.kind == "triangular":
            if p["low"] == p["high"]:
                return np.full(n, p["low"])
            return rng.triangular(p["low"], p["mode"], p["high"], n)
        if self.kind == "normal":
            if p["std"] == 0:
                return np.full(n, p["mean"])
            a = (p.get("min", -np.inf) - p["mean"]) / p["std"]
            b = (p.get("max", np.inf) - p["mean"]) / p["std"]
            return stats.truncnorm.ppf(rng.uniform(size=n), a, b, loc=p["mean"], scale=p["std"])
        # lognormal, optionally truncated above
        u = rng.uniform(size=n)
        if "max" in p and p["sigma"] > 0:
            u = u * stats.norm.cdf(math.log(p["max"] / p["median"]) / p["sigma"])
        return p["median"] * np.exp(p["sigma"] * stats.norm.ppf(u)) if p["sigma"] > 0 else np.full(n, p["median"])


#: Defaults of the 3-D kernel's lateral deviation at impacts (``Material.lateral_deviation``, D [-], and
#: ``lateral_deviation_speed_ms``, v_D [m/s]; :func:`simulation.kernel3d_contact.deviation_sd`): chosen [D] so that
#: the rule's spread spans the range Rockyfor3D describes (Dorren 2016, section 3.5 pp. 21-23) [R] and checked
#: against the lateral scatter of the Authume stops (docs/validation/authume-3d.md).
DEFAULT_LATERAL_DEVIATION = 1.0
DEFAULT_LATERAL_DEVIATION_SPEED_MS = 10.0


@dataclass(frozen=True)
class Material:
    """Impact and ground-contact behaviour of a slope material.

    normal law: ``en_law`` (constant/wyllie/velocity) with mean and spread of e_N;
    tangential law: ``et_law`` friction (Stronge sphere, friction angle) or constant e_T;
    ``roughness_m``: asperity amplitude; the slope angle at an impact is perturbed
    uniformly within +-atan(roughness / block radius);
    ``ground_motion``: ``"roll"`` (sphere rolling, a = 5/7 g (sin psi - tan(phi_g) cos psi))
    or ``"slide"`` (a = g (sin psi - tan(phi_g) cos psi)), phi_g = ``ground_friction_angle_deg``: tan(phi_g)
    is the rolling-resistance coefficient mu_r (resisting torque mu_r N r);
    ``en_velocity_scale_ms``: v0 of the Pfeiffer & Bowen (1989) scaling e_N / (1 + (v_n / v0)^2) (inf: none;
    ``normal_restitution.velocity_scale_ms`` in a file); ``hop_height_m``: a rebound that would rise less
    than this above the surface is ground contact (``contact_hop_height_m``; 0: the numerical
    ``contact_velocity_ms`` alone decides, as before); ``rolling_drag`` kappa [-]: in ground contact the block
    also decelerates by (kappa / r) v^2 (rolling over asperities, ploughing; 0: none);
    ``rolling_size_coefficient`` K [-]: the rolling resistance is tan(phi_g) + s c / sqrt(s^2 + c^2), s = K (roughness / r)^a
    and c = tan(cap) - tan(phi_g) (:func:`simulation.contact.rolling_resistance`: Kirkby & Statham's tan(phi_g) + s
    for large blocks, never above the cap from the size term), so small blocks stop sooner (0: tan(phi_g) alone);
    ``rolling_resistance_cap_deg`` [deg]: that cap (default 38, :data:`simulation.contact.ROLLING_RESISTANCE_CAP_DEG`,
    the steepest angle of repose of loose debris; a terrain of boulders larger than the blocks may state more);
    ``rolling_size_exponent`` a [-]: the exponent of the size ratio (default 1, Kirkby & Statham's form);
    ``ground_friction_std_deg`` [deg]: the spread of phi_g between blocks: each block rolls with phi_g + z_b sd,
    z_b one standard normal deviate per block, the same on every material (its own shape and angularity: a rounder
    block rolls farther everywhere; 0: every block the same, the default; the kernels' per-block draw); ``et_normal_scale_ms``: vt0 of the Pfeiffer & Bowen (1989) scaling of the
    tangential energy by 1 / ((v_n / (vt0 e_N))^2 + 1) after a constant or Coulomb law (inf: none;
    ``tangential.normal_scale_ms`` in a file, 76.2 m/s in CRSP); ``lateral_deviation`` D [-] and
    ``lateral_deviation_speed_ms`` v_D [m/s] (3-D kernel only): after each impact the block's direction of travel
    turns about the ground normal by a random angle of sd D (roughness / r) s_b / (1 + v / v_D) [rad] (s_b the
    block's own deviation factor; 0: no deviation; :func:`simulation.kernel3d_contact.deviation_sd`).  In a file, ``preset = NAME`` starts from a
    named material and ``preset_basis = "data"`` beside it from its data-derived table
    (:func:`simulation.materials.preset`).
    See :mod:`simulation.contact`.
    """

    name: str
    en_law: int
    en_mean: float
    en_std: float
    et_law: int
    et_mean: float
    et_std: float
    friction_deg: float
    friction_std_deg: float
    roughness_m: float
    ground_motion: str
    ground_friction_deg: float
    allow_energy_gain: bool
    en_velocity_scale_ms: float = math.inf
    hop_height_m: float = 0.0
    rolling_drag: float = 0.0
    rolling_size_coefficient: float = FIELD_DEFAULTS["rolling_size_coefficient"]
    rolling_resistance_cap_deg: float = ROLLING_RESISTANCE_CAP_DEG
    rolling_size_exponent: float = FIELD_DEFAULTS["rolling_size_exponent"]
    ground_friction_std_deg: float = FIELD_DEFAULTS["ground_friction_std_deg"]
    et_normal_scale_ms: float = math.inf
    lateral_deviation: float = DEFAULT_LATERAL_DEVIATION
    lateral_deviation_speed_ms: float = DEFAULT_LATERAL_DEVIATION_SPEED_MS

    @classmethod
    def parse(cls, name: str, spec: dict, source: str) -> "Material":
        """A material from its scenario table ``materials.<name>`` (a preset and/or restitution, tangential,
        roughness [m], ground motion and friction angle [deg] fields), checked; errors name ``source`` and field.

        Parameters
        ----------
        name : str
            The material's name.
        spec : dict
            Its table as read.
        source : str
            The file, for messages.

        Returns
        -------
        Material
        """
        where = f"materials.{name}."
        if not isinstance(spec, dict):
            raise ScenarioError(f"{source}: materials.{name} must be a table of material fields; got {spec!r}")
        _check_keys(spec, {"preset", "preset_basis", "normal_restitution", "tangential", "roughness_m", "ground_motion",
                           "ground_friction_angle_deg", "rolling_resistance", "allow_energy_gain",
                           "contact_hop_height_m", "rolling_drag", "rolling_size_coefficient", "rolling_resistance_cap_deg",
                           "rolling_size_exponent", "ground_friction_std_deg", "lateral_deviation",
                           "lateral_deviation_speed_ms"}, where, source)
        if "preset_basis" in spec and "preset" not in spec:
            raise ScenarioError(f"{source}: {where}preset_basis = {spec['preset_basis']!r} needs a preset beside it")
        given = set(spec)
        if "preset" in spec:            # a named material from published ranges (simulation.materials)
            try:
                spec = resolve_material(spec, f"materials.{name}", source)
            except PresetError as exc:
                raise ScenarioError(str(exc)) from None
        gain = bool(spec.get("allow_energy_gain", False))
        en_max = 10.0 if gain else 1.0
        en = spec.get("normal_restitution", {"law": "wyllie"})
        if isinstance(en, str):
            en = {"law": en}
        if isinstance(en, (int, float)) and not isinstance(en, bool):
            en = {"law": "constant", "mean": en}
        if not isinstance(en, dict):
            raise ScenarioError(f"{source}: {where}normal_restitution must be a number, a law name or a table")
        _check_keys(en, {"law", "mean", "std", "velocity_scale_ms"}, f"{where}normal_restitution.", source)
        laws = {"constant": EN_CONSTANT, "wyllie": EN_WYLLIE, "velocity": EN_VELOCITY}
        if en.get("law", "constant") not in laws:
            raise ScenarioError(f"{source}: {where}normal_restitution.law = {en.get('law')!r} is not one of "
                                f"{sorted(laws)}")
        en_law = laws[en.get("law", "constant")]
        if en_law == EN_WYLLIE and "mean" in en:
            raise ScenarioError(f"{source}: {where}normal_restitution.mean = {en['mean']!r} is not used by "
                                "law 'wyllie' (the law gives e_N from the impact angle; 'std' sets its spread); "
                                "set law = 'constant' to give a mean")
        en_mean = 0.0 if en_law == EN_WYLLIE else _number(en.get("mean"), f"{where}normal_restitution.mean",
                                                           source, lo=0.0, hi=en_max)
        en_std = _number(en.get("std", 0.0), f"{where}normal_restitution.std", source, lo=0.0, hi=1.0)
        en_v0 = math.inf
        if "velocity_scale_ms" in en:
            if en_law == EN_VELOCITY:
                raise ScenarioError(f"{source}: {where}normal_restitution.velocity_scale_ms is not used with law "
                                    f"'velocity' (which scales by {CRSP_VELOCITY_SCALE_MS} m/s itself); use law "
                                    "'constant' with velocity_scale_ms to choose the scale")
            en_v0 = _number(en["velocity_scale_ms"], f"{where}normal_restitution.velocity_scale_ms", source,
                            lo=0.0, hi=1e6, lo_open=True)

        et = spec.get("tangential", {"law": "friction", "friction_angle_deg": 30.0})
        if not isinstance(et, dict):
            raise ScenarioError(f"{source}: {where}tangential must be a table with 'law'")
        _check_keys(et, {"law", "mean", "std", "friction_angle_deg", "std_deg", "normal_scale_ms"},
                    f"{where}tangential.", source)
        if et.get("law", "friction") == "friction":
            et_law, et_mean, et_std = ET_FRICTION, 0.0, 0.0
            phi = _number(et.get("friction_angle_deg", 30.0), f"{where}tangential.friction_angle_deg", source,
                          lo=0.0, hi=89.0)
            phi_std = _number(et.get("std_deg", 0.0), f"{where}tangential.std_deg", source, lo=0.0, hi=30.0)
        elif et["law"] == "constant":
            et_law, phi, phi_std = ET_CONSTANT, 0.0, 0.0
            if "friction_angle_deg" in et:
                raise ScenarioError(f"{source}: {where}tangential.friction_angle_deg is not used by law 'constant'; "
                                    "law 'coulomb' bounds e_T by friction")
            et_mean = _number(et.get("mean"), f"{where}tangential.mean", source, lo=0.0, hi=en_max)
            et_std = _number(et.get("std", 0.0), f"{where}tangential.std", source, lo=0.0, hi=1.0)
        elif et["law"] == "coulomb":
            et_law = ET_COULOMB
            et_mean = _number(et.get("mean"), f"{where}tangential.mean", source, lo=0.0, hi=1.0)
            et_std = _number(et.get("std", 0.0), f"{where}tangential.std", source, lo=0.0, hi=1.0)
            phi = _number(et.get("friction_angle_deg", 30.0), f"{where}tangential.friction_angle_deg", source,
                          lo=0.0, hi=89.0)
            phi_std = _number(et.get("std_deg", 0.0), f"{where}tangential.std_deg", source, lo=0.0, hi=30.0)
        else:
            raise ScenarioError(f"{source}: {where}tangential.law = {et['law']!r} is not 'friction', 'constant' "
                                "or 'coulomb'")
        et_v0 = math.inf
        if "normal_scale_ms" in et:
            if et_law == ET_FRICTION:
                raise ScenarioError(f"{source}: {where}tangential.normal_scale_ms = {et['normal_scale_ms']!r} is not "
                                    "used by law 'friction' (Stronge's impulse law); it scales the 'constant' and "
                                    "'coulomb' laws")
            et_v0 = _number(et["normal_scale_ms"], f"{where}tangential.normal_scale_ms", source, lo=0.0, hi=1e6,
                            lo_open=True)
        motion = spec.get("ground_motion", "roll")
        if motion not in ("roll", "slide"):
            raise ScenarioError(f"{source}: {where}ground_motion = {motion!r} is not 'roll' or 'slide'")
        if "rolling_resistance" in spec:
            if "ground_friction_angle_deg" in given:
                raise ScenarioError(f"{source}: {where}rolling_resistance and ground_friction_angle_deg both given; "
                                    "they are one quantity (rolling_resistance = tan(ground_friction_angle_deg))")
            mu_r = _number(spec["rolling_resistance"], f"{where}rolling_resistance", source, lo=0.0, hi=50.0)
            spec = dict(spec, ground_friction_angle_deg=math.degrees(math.atan(mu_r)))
        return cls(name=name, en_law=en_law, en_mean=en_mean, en_std=en_std, et_law=et_law, et_mean=et_mean,
                   et_std=et_std, friction_deg=phi, friction_std_deg=phi_std,
                   roughness_m=_number(spec.get("roughness_m", 0.0), f"{where}roughness_m", source, lo=0.0, hi=10.0),
                   ground_motion=motion,
                   ground_friction_deg=_number(spec.get("ground_friction_angle_deg", 30.0 if motion == "slide"
                                                        else 15.0), f"{where}ground_friction_angle_deg", source,
                                               lo=0.0, hi=89.0),
                   allow_energy_gain=gain, en_velocity_scale_ms=en_v0, et_normal_scale_ms=et_v0,
                   hop_height_m=_number(spec.get("contact_hop_height_m", 0.0), f"{where}contact_hop_height_m",
                                        source, lo=0.0, hi=10.0),
                   rolling_drag=_number(spec.get("rolling_drag", 0.0), f"{where}rolling_drag", source, lo=0.0, hi=10.0),
                   rolling_size_coefficient=_number(
                       spec.get("rolling_size_coefficient", FIELD_DEFAULTS["rolling_size_coefficient"]),
                       f"{where}rolling_size_coefficient", source, lo=0.0, hi=10.0),
                   rolling_resistance_cap_deg=_number(
                       spec.get("rolling_resistance_cap_deg", ROLLING_RESISTANCE_CAP_DEG),
                       f"{where}rolling_resistance_cap_deg", source, lo=0.0, hi=89.0),
                   rolling_size_exponent=_number(
                       spec.get("rolling_size_exponent", FIELD_DEFAULTS["rolling_size_exponent"]),
                       f"{where}rolling_size_exponent", source, lo=0.0, hi=3.0),
                   ground_friction_std_deg=_number(
                       spec.get("ground_friction_std_deg", FIELD_DEFAULTS["ground_friction_std_deg"]),
                       f"{where}ground_friction_std_deg", source, lo=0.0, hi=20.0),
                   lateral_deviation=_number(spec.get("lateral_deviation", DEFAULT_LATERAL_DEVIATION),
                                             f"{where}lateral_deviation", source, lo=0.0, hi=20.0),
                   lateral_deviation_speed_ms=_number(spec.get("lateral_deviation_speed_ms",
                                                               DEFAULT_LATERAL_DEVIATION_SPEED_MS),
                                                      f"{where}lateral_deviation_speed_ms", source, lo=0.0, hi=1e4,
                                                      lo_open=True))


#: I / (m r^2) of the block shapes: a solid sphere, and a solid cylinder (disc, wheel) rolling on its rim.


@dataclass(frozen=True)
class Seeder:
    """Where blocks start: a point or a line (uniform in x) at ``height_m`` above the ground.

    ``shape`` "sphere" (radius from mass and density), "cylinder" (a wheel rolling on its rim, length =
    ``aspect_ratio`` x diameter) or "disc" (a plate rolling on its rim, thickness = ``aspect_ratio`` x
    diameter, default 0.3); the shape sets the inertia factor I / (m r^2) (2/5, 1/2, 1/2), which sets how
    a block shares its energy between translation and spin at impacts and in rolling (a rolling sphere
    accelerates at 5/7 g sin psi, a cylinder or disc at 2/3), and, with the mass and density, the radius
    (a flat disc of a given mass has a larger radius than a sphere, so it sees a smoother slope).
    ``downslope_speed_ms`` [m/s]: a release speed along the ground under the release point, in its falling
    sense (a push, so blocks released on ground flatter than their rolling-resistance angle still start;
    None: no push).
    """

    x_low: float
    x_high: float
    height_m: Distribution
    mass_kg: Distribution
    density_kg_m3: float
    vx_ms: Distribution
    vz_ms: Distribution
    angular_velocity_rads: Distribution
    shape: str = "sphere"
    aspect_ratio: float = 1.0
    downslope_speed_ms: Distribution | None = None

    def radius(self, mass):
        """Radius [m] of blocks of the given masses [kg].

        Parameters
        ----------
        mass : float or array_like
            Block mass [kg].

        Returns
        -------
        numpy.ndarray or float
            Radius [m] (:func:`simulation.units.block_radius` with the seeder's density, shape and aspect ratio).
        """
        return block_radius(mass, self.density_kg_m3, self.shape, self.aspect_ratio)

    @property
    def inertia_factor(self) -> float:
        """I / (m r^2) of the block shape (2/5 sphere, 1/2 cylinder; ``simulation.units.INERTIA_FACTORS``)."""
        return INERTIA_FACTORS[self.shape]


@dataclass(frozen=True)
class Collector:
    """A vertical line at ``x`` [m]; with ``capacity_kj`` it is a barrier of height ``height_m``."""

    name: str
    x: float
    capacity_kj: float | None = None
    height_m: float | None = None

    @property
    def is_barrier(self) -> bool:
        """True when the collector is a barrier (it has a capacity)."""
        return self.capacity_kj is not None


@dataclass(frozen=True)
class Settings:
    """Numerical settings of a simulation (scenario table ``[settings]``).

    ``gravity_ms2`` [m/s^2] (default 9.81); ``contact_velocity_ms`` [m/s]: rebounds slower than this, normal to
    the slope, turn into rolling or sliding; ``stop_velocity_ms`` [m/s]: slower than this with static friction
    holding, the block stops; ``max_events``: per block (reaching it is reported); ``envelope_bins``: bins along
    x for the envelopes (0 = off); ``max_rolling_slope_deg`` [deg]: no rolling or sliding in ground contact on
    segments steeper than this -- a block there leaves the face and meets it in impacts (90, the default: any
    slope; :func:`simulation.contact.steep_face_launch`).  With a material's ``contact_hop_height_m`` > 0 the
    contact velocity is only a numerical floor under the hop speed sqrt(2 g cos(beta) h)
    (:func:`simulation.contact.contact_speed`).
    """
    gravity_ms2: float = STANDARD_GRAVITY_MS2
    contact_velocity_ms: float = 0.5
    stop_velocity_ms: float = 0.05
    max_events: int = 5000
    envelope_bins: int = 50
    max_rolling_slope_deg: float = 90.0

    @property
    def sin_max_roll(self) -> float:
        """Sine of ``max_rolling_slope_deg`` as the kernels take it (exactly 1.0 at 90 deg: any slope)."""
        return float(np.sin(np.radians(self.max_rolling_slope_deg))) if self.max_rolling_slope_deg < 90 else 1.0


@dataclass(frozen=True, repr=False)
class Scenario(Displayed):
    """A checked trajectory scenario (docs: File formats, "Scenario files"): slope ``profile``, ``materials``, the block
    ``seeder``, ``collectors`` (lines where crossings are recorded; barriers among them), numerical
    ``settings``, and the ``source`` file named in errors.  Run it with :func:`simulation.run`.
    """
    name: str
    description: str
    profile: Profile
    materials: tuple
    seeder: Seeder
    collectors: tuple
    settings: Settings
    source: str = "<dict>"

    def __repr__(self) -> str:
        p = self.profile
        return short_repr(self, repr(self.name), f"profile {p.x[0]:.4g}-{p.x[-1]:.4g} m, {p.n_segments} segments",
                          f"{len(self.materials)} materials", "collectors " + ", ".join(c.name for c in self.collectors))

    def summary(self):
        """The scenario at a glance (one-column table): source, profile extent [m], materials, release zone [m],
        collectors (barriers with capacity [kJ] and height [m]).

        Returns
        -------
        pandas.DataFrame
            Index: quantity; column ``value``.
        """
        import pandas as pd
        p, sd = self.profile, self.seeder
        rows = {"source": self.source, "profile x [m]": f"{p.x[0]:.4g} to {p.x[-1]:.4g}",
                "profile z [m]": f"{p.z.min():.4g} to {p.z.max():.4g}", "segments": p.n_segments,
                "materials": ", ".join(p.material_names), "release x [m]": f"{sd.x_low:.4g} to {sd.x_high:.4g}"}
        for c in self.collectors:
            rows[f"collector {c.name} x [m]"] = (f"{c.x:.4g}; barrier {c.capacity_kj:g} kJ, {c.height_m:g} m high"
                                                 if c.is_barrier else f"{c.x:.4g}")
        return pd.DataFrame({"value": pd.Series(rows, dtype=object)})

    def plot(self, ax=None):
        """The slope profile coloured by material, with the release zone and the collectors.

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).

        Returns
        -------
        matplotlib.axes.Axes
            x: horizontal distance [m]; z: elevation [m], equal scales (:func:`simulation.plotting.plot_profile`).
        """
        from .plotting import plot_profile
        return plot_profile(self, ax)

    def collector_index(self, name: str) -> int:
        """Index of the collector named ``name``; a KeyError listing the collectors when there is none.

        Parameters
        ----------
        name : str
            Collector name.

        Returns
        -------
        int
        """
        names = [c.name for c in self.collectors]
        if name not in names:
            raise KeyError(f"{self.source}: no collector named {name!r}; collectors are {names}")
        return names.index(name)

    def with_barrier(self, name: str, capacity_kj: float, height_m: float) -> "Scenario":
        """A copy whose collector ``name`` is a barrier of the given capacity [kJ] and height [m].

        Parameters
        ----------
        name : str
            Collector name.
        capacity_kj : float
            Barrier capacity [kJ].
        height_m : float
            Barrier height [m].

        Returns
        -------
        Scenario
        """
        from dataclasses import replace
        i = self.collector_index(name)
        cols = list(self.collectors)
        cols[i] = replace(cols[i], capacity_kj=float(capacity_kj), height_m=float(height_m))
        return replace(self, collectors=tuple(cols))


def parse_tables_and_materials(data: dict, required: tuple, optional: tuple, source: str) -> tuple:
    """Check a scenario dictionary's top-level tables (``required`` must be there; ``name``, ``description`` and
    ``optional`` may be) and parse its ``[materials]``: the part a profile and a terrain scenario share.

    Parameters
    ----------
    data : dict
        The parsed scenario TOML.
    required, optional : tuple of str
        Tables that must be present, and tables that may be.
    source : str
        Where the dictionary came from, for error messages.

    Returns
    -------
    tuple of Material
        The parsed materials, in the file's order.
    """
    _check_keys(data, {"name", "description", *required, *optional}, "", source)
    for key in required:
        if key not in data:
            raise ScenarioError(f"{source}: missing [{key}] table")
    mats = data["materials"]
    if not isinstance(mats, dict) or not mats:
        raise ScenarioError(f"{source}: [materials] must define at least one material table")
    return tuple(Material.parse(name, spec, source) for name, spec in mats.items())


def parse_settings(st: dict, source: str, *, max_events: int = 5000, envelopes: bool = True) -> Settings:
    """The checked ``[settings]`` table of a scenario (:class:`Settings`; every field optional).

    Parameters
    ----------
    st : dict
        The ``[settings]`` table.
    source : str
        Where it came from, for error messages.
    max_events : int, optional
        Default event limit per block (the 3-D kernel takes a larger one).
    envelopes : bool, optional
        Whether ``envelope_bins`` may be given (2-D profiles only; 0 otherwise).

    Returns
    -------
    Settings
    """
    _check_keys(st, set(Settings.__dataclass_fields__) - (set() if envelopes else {"envelope_bins"}), "settings.",
                source)
    return Settings(
        gravity_ms2=_number(st.get("gravity_ms2", STANDARD_GRAVITY_MS2), "settings.gravity_ms2", source, lo=0.0,
                            lo_open=True),
        contact_velocity_ms=_number(st.get("contact_velocity_ms", 0.5), "settings.contact_velocity_ms", source,
                                    lo=0.0, lo_open=True),
        stop_velocity_ms=_number(st.get("stop_velocity_ms", 0.05), "settings.stop_velocity_ms", source, lo=0.0),
        max_events=int(_number(st.get("max_events", max_events), "settings.max_events", source, lo=1)),
        envelope_bins=int(_number(st.get("envelope_bins", 50), "settings.envelope_bins", source, lo=0, hi=10000))
        if envelopes else 0,
        max_rolling_slope_deg=_number(st.get("max_rolling_slope_deg", 90.0), "settings.max_rolling_slope_deg",
                                      source, lo=0.0, hi=90.0, lo_open=True))


def scenario_from_dict(data: dict, source: str = "<dict>", base_dir: Path | None = None) -> Scenario:
    """Build and validate a :class:`Scenario` from a parsed TOML dictionary.

    Parameters
    ----------
    data : dict
        The scenario's tables (docs: File formats, "Scenario files"); lengths in m, masses in kg, speeds in m/s.
    source : str
        Name used in messages.
    base_dir : pathlib.Path, optional
        Folder that relative file names are read from.

    Returns
    -------
    Scenario

    Raises
    ------
    ScenarioError
        Naming the file, the field and the value.
    """
    materials = parse_tables_and_materials(data, ("profile", "materials", "seeder"), ("collectors", "settings"),
                                           source)
    names = [m.name for m in materials]

    prof = data["profile"]
    _check_keys(prof, {"x", "z", "points", "materials", "material"}, "profile.", source)
    if "points" in prof:
        pts = np.asarray(prof["points"], dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise ScenarioError(f"{source}: profile.points must be a list of [x, z] pairs")
        x, z = pts[:, 0], pts[:, 1]
    else:
        if "x" not in prof or "z" not in prof:
            raise ScenarioError(f"{source}: [profile] needs x and z (or points)")
        x, z = np.asarray(prof["x"], dtype=float), np.asarray(prof["z"], dtype=float)
    seg_mats = prof.get("materials", prof.get("material", names[0]))
    if isinstance(seg_mats, str):
        seg_mats = [seg_mats] * (len(x) - 1)
    for i, m in enumerate(seg_mats):
        if m not in names:
            close = difflib.get_close_matches(str(m), names, n=1)
            raise ScenarioError(f"{source}: profile.materials[{i}] = {m!r} is not a defined material "
                                f"({', '.join(names)}){f'; did you mean {close[0]!r}?' if close else ''}")
    try:
        profile = Profile.build(x, z, [names.index(m) for m in seg_mats], names, source=f"{source}: profile")
    except ValueError as exc:
        raise ScenarioError(str(exc)) from exc

    sd = data["seeder"]
    _check_keys(sd, {"type", "x", "height_m", "mass_kg", "density_kg_m3", "vx_ms", "vz_ms",
                     "angular_velocity_rads", "shape", "aspect_ratio", "downslope_speed_ms"}, "seeder.", source)
    shape = sd.get("shape", "sphere")
    if shape not in INERTIA_FACTORS:
        raise ScenarioError(f"{source}: seeder.shape = {shape!r} is not one of {sorted(INERTIA_FACTORS)}")
    kind = sd.get("type", "line" if isinstance(sd.get("x"), list) else "point")
    if kind not in ("point", "line"):
        raise ScenarioError(f"{source}: seeder.type = {kind!r} is not 'point' or 'line'")
    xs = sd.get("x")
    if kind == "line":
        if not (isinstance(xs, list) and len(xs) == 2):
            raise ScenarioError(f"{source}: a line seeder needs x = [x_start, x_end]; got {xs!r}")
        x_low, x_high = (_number(v, "seeder.x", source) for v in xs)
    else:
        x_low = x_high = _number(xs, "seeder.x", source)
    for v in (x_low, x_high):
        if not profile.contains(v) or v >= profile.x[-1]:
            raise ScenarioError(f"{source}: seeder.x = {v:g} m is outside the profile "
                                f"[{profile.x[0]:g}, {profile.x[-1]:g}) m")
    if x_high < x_low:
        raise ScenarioError(f"{source}: seeder.x = {xs!r} must be [low, high]")
    if "mass_kg" not in sd:
        raise ScenarioError(f"{source}: seeder.mass_kg is required (a number or a distribution table)")
    seeder = Seeder(
        x_low=x_low, x_high=x_high,
        height_m=Distribution.parse(sd.get("height_m", 1.0), "seeder.height_m", source, lo=0.0, hi=1e4),
        mass_kg=Distribution.parse(sd["mass_kg"], "seeder.mass_kg", source, lo=0.0, hi=1e9, lo_open=True),
        density_kg_m3=_number(sd.get("density_kg_m3", DEFAULT_DENSITY_KG_M3), "seeder.density_kg_m3", source,
                              lo=DENSITY_RANGE_KG_M3[0], hi=DENSITY_RANGE_KG_M3[1]),
        vx_ms=Distribution.parse(sd.get("vx_ms", 0.0), "seeder.vx_ms", source, lo=-200, hi=200),
        vz_ms=Distribution.parse(sd.get("vz_ms", 0.0), "seeder.vz_ms", source, lo=-200, hi=200),
        angular_velocity_rads=Distribution.parse(sd.get("angular_velocity_rads", 0.0),
                                                 "seeder.angular_velocity_rads", source, lo=-1e3, hi=1e3),
        shape=shape, aspect_ratio=_number(sd.get("aspect_ratio", 0.3 if shape == "disc" else 1.0),
                                          "seeder.aspect_ratio", source, lo=0.01, hi=100.0),
        downslope_speed_ms=(Distribution.parse(sd["downslope_speed_ms"], "seeder.downslope_speed_ms", source, lo=0.0,
                                               hi=200.0) if "downslope_speed_ms" in sd else None))

    collectors = []
    for i, c in enumerate(data.get("collectors", [])):
        where = f"collectors[{i}]."
        _check_keys(c, {"name", "x", "capacity_kj", "height_m"}, where, source)
        if "name" not in c or "x" not in c:
            raise ScenarioError(f"{source}: {where[:-1]} needs a name and an x")
        cx = _number(c["x"], f"{where}x", source)
        if not profile.x[0] < cx < profile.x[-1]:
            raise ScenarioError(f"{source}: {where}x = {cx:g} m (collector {c['name']!r}) is outside the profile "
                                f"({profile.x[0]:g}, {profile.x[-1]:g}) m")
        cap = c.get("capacity_kj")
        cap = None if cap is None else _number(cap, f"{where}capacity_kj", source, lo=0.0, lo_open=True)
        h = c.get("height_m")
        h = None if h is None else _number(h, f"{where}height_m", source, lo=0.0, lo_open=True)
        if cap is not None and h is None:
            raise ScenarioError(f"{source}: {where}height_m is required for a barrier (capacity_kj given)")
        collectors.append(Collector(str(c["name"]), cx, cap, h))
    cnames = [c.name for c in collectors]
    if len(set(cnames)) != len(cnames):
        raise ScenarioError(f"{source}: collector names must be unique; got {cnames}")

    settings = parse_settings(data.get("settings", {}), source)
    return Scenario(name=str(data.get("name", Path(source).stem)), description=str(data.get("description", "")),
                    profile=profile, materials=materials, seeder=seeder, collectors=tuple(collectors),
                    settings=settings, source=source)


def load_scenario(path) -> Scenario:
    """Read a scenario TOML file (documentation: File formats, "Scenario files").

    Parameters
    ----------
    path : str or path
        The TOML file.

    Returns
    -------
    Scenario

    Raises
    ------
    FileNotFoundError, ScenarioError
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"scenario file not found: {path}")
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:   # a binary file: named, not a bare codec error
        raise ScenarioError(f"{path}: not valid TOML: {exc}") from exc
    return scenario_from_dict(data, source=str(path), base_dir=path.parent)
