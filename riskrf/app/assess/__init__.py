"""The whole chain for one site: inventory -> fits -> simulation -> energy hazard -> mitigation ranking.

``run_assessment(site)`` computes; ``write_assessment(assessment, directory)`` writes
report.html, summary.json, CSV tables, PNG figures and a copy of the inputs with the
package version and seed.  ``riskrf assess`` and ``riskrf demo`` call both, writing
into a temporary directory that is moved into place only when complete.

Where it lives
--------------
- :mod:`~riskrf.app.assess.run`: :func:`~riskrf.app.assess.run.run_assessment`, the chain stage by stage;
- :mod:`~riskrf.app.assess.site_inputs`: stage 1, what the chain reads from the site file (inventory fits, rate
  model, block survey, sensitivity inputs, masses to simulate, fences, the trajectory model's status);
- :mod:`~riskrf.app.assess.hazard`: stages 2 and 3, the impact-energy hazard at the barrier line
  (:func:`~riskrf.app.assess.hazard.energy_hazard_from_inputs`) and its design values;
- :mod:`~riskrf.app.assess.decision`: stage 4, the mitigation study and its ranking, the road share and slope
  model it needs, the release rate of a road record, the chain repeated per draw of the trajectory model;
- :mod:`~riskrf.app.assess.result`: :class:`~riskrf.app.assess.result.Assessment`, what one run computed;
- :mod:`~riskrf.app.assess.outputs`: stage 5, :func:`~riskrf.app.assess.outputs.write_assessment`.

The names below (those the user guide imports from ``riskrf.app.assess``) are importable from here; everything
else from its module.
"""
from __future__ import annotations

from .decision import road_share, study_context
from .run import run_assessment

__all__ = ["road_share", "run_assessment", "study_context"]
