"""Named physical constants and unit factors shared by :mod:`simulation` and :mod:`riskrf`.

One home for each number: energies are reported in kJ (barrier ratings are in kJ),
masses in kg, lengths in m.  :mod:`riskrf.core.units` re-exports everything here.
"""
from __future__ import annotations

J_PER_KJ = 1000.0
"""Joules per kilojoule: E [kJ] = 1/2 m v^2 / J_PER_KJ with m in kg and v in m/s."""

KG_PER_TONNE = 1000.0
"""Kilograms per tonne."""

STANDARD_GRAVITY_MS2 = 9.81
"""Acceleration of gravity [m/s^2] used by default in trajectories and potential energies."""

DEFAULT_DENSITY_KG_M3 = 2650.0
"""Default rock density [kg/m^3] (quartz-rich rock; Wyllie 2014, table 1.1 gives 2,500-2,800 for
most rock types).  Used when an inventory or scenario gives none, and always reported as a default."""

#: Bulk densities of rock [kg/m³] accepted everywhere.  Rocks span about 1,000 (pumice, porous tuff) to 3,300
#: (peridotite), massive ores up to about 5,200 (magnetite) (Schön 2015, Physical Properties of Rocks, 2nd ed.,
#: chapter 2, tables 2.1-2.4); the bounds leave a margin on both sides.  A value such as 2.65 is g/cm³ typed
#: for kg/m³, and 2,650,000 is g/m³: both would make every mass 1,000 times wrong.
DENSITY_RANGE_KG_M3 = (500.0, 6000.0)

SPHERE_INERTIA = 0.4
"""I / (m r^2) of a solid sphere, 2/5."""

CYLINDER_INERTIA = 0.5
"""I / (m r^2) of a solid cylinder or disc rolling on its curved face, 1/2."""

INERTIA_FACTORS = {"sphere": SPHERE_INERTIA, "cylinder": CYLINDER_INERTIA, "disc": CYLINDER_INERTIA}
"""I / (m r^2) by block shape (a disc or plate rolls on its rim like a short cylinder: 1/2)."""


def block_radius(mass, density_kg_m3, shape="sphere", aspect_ratio=1.0):
    """Radius [m] of blocks of the given masses [kg] and density [kg/m3].

    A sphere: m = 4/3 pi rho r^3.  A cylinder or disc of length 2 r x aspect_ratio: m = 2 pi rho r^3 aspect_ratio.

    Parameters
    ----------
    mass : float or array_like
        Block mass(es) [kg].
    density_kg_m3 : float
        Bulk density [kg/m³].
    shape : str
        ``"sphere"`` (default), ``"cylinder"`` or ``"disc"``.
    aspect_ratio : float
        Length of a cylinder or disc over its diameter [-] (1: as long as wide).

    Returns
    -------
    numpy.ndarray or float
        Radius [m], the shape of ``mass``.
    """
    import numpy as np
    if shape in ("cylinder", "disc"):
        return (np.asarray(mass) / (2.0 * np.pi * density_kg_m3 * aspect_ratio)) ** (1.0 / 3.0)
    return (3.0 * np.asarray(mass) / (4.0 * np.pi * density_kg_m3)) ** (1.0 / 3.0)


def box_rolling_cylinder(l1_m, l2_m, l3_m):
    """The cylinder a block of measured bounding-box sizes rolls as: (radius [m], aspect ratio [-]).

    A block rolls about its longest axis (the stable axis of an elongated body), so its rolling radius is the
    mean half-width of its cross-section, r = (L2 + L3) / 4, and its length L1 = 2 r x aspect ratio.  ASSUMPTION:
    the block is modelled as that cylinder (inertia factor 1/2, :data:`CYLINDER_INERTIA`); the cross-section of a
    box rolls with its centre between L3 / 2 and half its diagonal above the ground, and this mean radius lies
    between them.  Its consequence, that flat and elongated blocks meet a larger rolling resistance
    (roughness / r) and stop sooner, is what full-scale releases show (Authume: stop distance rises with
    L3 / L1 and L2 / L1, Spearman 0.39-0.69; ``docs/validation/trajectories.md``).

    Parameters
    ----------
    l1_m, l2_m, l3_m : float
        The block's three bounding-box sizes [m], in any order (each finite and > 0).

    Returns
    -------
    tuple of float
        (radius [m], length over diameter [-]).

    Raises
    ------
    ValueError
        A size that is not a finite number > 0 (the message names it and its value).
    """
    import math
    sizes = []
    for name, v in (("l1_m", l1_m), ("l2_m", l2_m), ("l3_m", l3_m)):
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise ValueError(f"{name} = {v!r} must be a block size [m]") from None
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} = {v!r} must be a finite block size > 0 m")
        sizes.append(v)
    long, mid, short = sorted(sizes, reverse=True)
    radius = (mid + short) / 4.0
    return radius, long / (2.0 * radius)


def kinetic_energy_kj(mass_kg, speed_ms, angular_velocity_rads=0.0, radius_m=0.0, inertia_factor=SPHERE_INERTIA):
    """Translational plus rotational kinetic energy [kJ]: (1/2 m v^2 + 1/2 k m r^2 w^2) / 1000.

    Works on scalars and NumPy arrays.

    Parameters
    ----------
    mass_kg : float or array_like
        Block mass [kg].
    speed_ms : float or array_like
        Translational speed of the centre of mass [m/s].
    angular_velocity_rads : float or array_like
        Angular velocity [rad/s] (default 0: translation only).
    radius_m : float or array_like
        Block radius [m].
    inertia_factor : float
        k = I / (m r²) [-]: 0.4 for a sphere, 0.5 for a cylinder (:data:`INERTIA_FACTORS`).

    Returns
    -------
    float or numpy.ndarray
        Kinetic energy [kJ].

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, eq. 3.1 (translation) and eq. 3.2 (rotation,
    I = k m r²).
    """
    return 0.5 * mass_kg * (speed_ms * speed_ms
                            + inertia_factor * radius_m * radius_m * angular_velocity_rads * angular_velocity_rads) \
        / J_PER_KJ


def mass_for_energy_kg(energy_kj, speed_ms):
    """Mass [kg] whose translational kinetic energy at ``speed_ms`` is ``energy_kj``: m = 2 E / v^2.

    The speed is floored at 1e-150 m/s so that v = 0 gives a huge mass rather than a division error.  Works on
    scalars and NumPy arrays.

    Parameters
    ----------
    energy_kj : float or array_like
        Translational kinetic energy [kJ].
    speed_ms : float or array_like
        Speed [m/s].

    Returns
    -------
    numpy.ndarray or float
        Mass [kg].

    References
    ----------
    Wyllie, D. C. (2014). Rock Fall Engineering. CRC Press, eq. 3.1 (inverted).
    """
    import numpy as np
    v2 = np.maximum(np.asarray(speed_ms, dtype=float) ** 2, 1e-300)
    return 2.0 * J_PER_KJ * energy_kj / v2
