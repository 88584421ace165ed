"""The impact laws under their former module name: everything here lives in :mod:`simulation.contact`.

Kept so that code importing ``simulation.impact`` keeps working; new code imports :mod:`simulation.contact`.
"""
from .contact import (CRSP_VELOCITY_SCALE_MS, EN_CONSTANT, EN_VELOCITY, EN_WYLLIE, EN_WYLLIE_MAX,  # noqa: F401
                      ET_CONSTANT, ET_COULOMB, ET_FRICTION, impact, impact_body, normal_restitution, rebound,
                      stronge_body, stronge_sphere, wyllie_normal_restitution)
