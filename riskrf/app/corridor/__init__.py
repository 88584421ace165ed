"""Corridor scale: many rock cuts along a road, screened with the RHRS and assessed quantitatively in parallel.

A corridor file (TOML) holds corridor-wide defaults (mass law, traffic, consequences, economics,
options, simulation size, seed) and names a sections table (CSV, Excel or Parquet) with one row per
section.  Everything is read and checked by :func:`load_corridor` before any work starts; every error
names the file, the row, the section id, the column and the value.

Each section's chain is one task on a ``dask.distributed`` client (:func:`run_corridor`):

    generated cut profile (or a scenario file)
      -> mass-coupled EnergyHazard at the barrier line, as ``riskrf assess`` (n blocks with masses log-uniform
         over the mass law, reach and speed by mass class; rate of the section; P(reach road) from the same run)
      -> simulation.run of the scenario's own seeder (n blocks): the reference of the option effects
      -> MitigationStudy: road-user risk of every option, ranking by expected total cost
      -> one result row (RHRS score, risk of doing nothing, best option, its cost)

The seed of each section is ``SeedSequence(seed, spawn_key=(crc32(section id),))``: the child that
``SeedSequence(seed).spawn`` would give at that key, fixed by the section id, so results are identical
for any number of workers, any order of completion and any subset of sections (``--resume``).

Units: lengths m, chainage m, rates per year, money in the corridor currency.

Where it lives
--------------
- :mod:`~riskrf.app.corridor.model`: the validated corridor (:class:`Corridor`, :class:`Section`,
  :class:`CorridorError`), the sections-table column vocabulary and the seed of a section;
- :mod:`~riskrf.app.corridor.file`: :func:`load_corridor`, the corridor TOML and the sections table read and
  checked; :mod:`~riskrf.app.corridor.rows` one row of the table, :mod:`~riskrf.app.corridor.rates` the mass law
  and the rates of falls, :mod:`~riskrf.app.corridor.cut` the generated cut profile;
- :mod:`~riskrf.app.corridor.sections`: one section assessed (:func:`assess_section`: hazard, options, ranking);
- :mod:`~riskrf.app.corridor.run`: :func:`run_corridor`, every section as a task on a dask client
  (the client itself: :mod:`riskrf.app.cluster`);
- :mod:`~riskrf.app.corridor.result`: :class:`CorridorResult`, the corridor table, budget curve and programmes;
- :mod:`~riskrf.app.corridor.outputs`: :func:`write_corridor`, the output directory and summary.json.

The names below are importable from ``riskrf.app.corridor`` itself; everything else from its module.
"""
from __future__ import annotations

from ..cluster import _shutdown, connect  # noqa: F401  (riskrf.app.hazard_map imports them from here)
from .model import Corridor, CorridorError, Section
from .file import load_corridor
from .sections import assess_section
from .result import CorridorResult
from .run import run_corridor
from .outputs import write_corridor

__all__ = ["Corridor", "CorridorError", "CorridorResult", "Section", "assess_section", "connect", "load_corridor",
           "run_corridor", "write_corridor"]
