"""Named constants and unit factors used throughout riskrf (one home for each number).

The physical constants live in :mod:`simulation.units` (the simulator needs them too)
and are re-exported here; the design-practice ratios live here.
"""
from __future__ import annotations

from simulation.units import (
                              CYLINDER_INERTIA,
                              DEFAULT_DENSITY_KG_M3,
                              INERTIA_FACTORS,
                              J_PER_KJ,
                              KG_PER_TONNE,
                              SPHERE_INERTIA,
                              STANDARD_GRAVITY_MS2,
                              kinetic_energy_kj,
                              mass_for_energy_kg,
)

SEL_PER_MEL = 1.0 / 3.0
"""Service energy level of a flexible barrier as a share of its maximum energy level,
SEL = MEL / 3 (ETAG 027, 2013, section 2.2; EAD 340059-00-0106, 2018)."""

HOURS_PER_DAY = 24.0
DAYS_PER_YEAR = 365.25
M_PER_KM = 1000.0

#: Return periods of the design tables (design masses, design energies) [yr].
DESIGN_RETURN_PERIODS = (10, 50, 100, 300, 1000)

__all__ = ["CYLINDER_INERTIA", "DAYS_PER_YEAR", "DEFAULT_DENSITY_KG_M3", "DESIGN_RETURN_PERIODS", "HOURS_PER_DAY", "INERTIA_FACTORS", "J_PER_KJ", "KG_PER_TONNE",
           "M_PER_KM", "SEL_PER_MEL", "SPHERE_INERTIA", "STANDARD_GRAVITY_MS2", "kinetic_energy_kj", "mass_for_energy_kg"]
