"""Rock fall inventories: reading, validating and summarising a record of falls.

An inventory is a list of rock falls with a size (volume in m³ or mass in kg),
optionally a date (full date or year only) and a location, together with the
length of the period over which falls were recorded.  The record period turns
counts into annual rates (Wyllie 2014, section 8.4), so it is never guessed
silently: it is given as an argument, read from a sidecar TOML file beside the
inventory (``<name>.toml`` with a ``[record]`` table), or inferred from the dates
with a warning.

Years with no recorded fall are kept in :meth:`Inventory.annual_maxima` as
missing values (NaN), never dropped and never set to zero: the extreme-value
fits then use the mixed model that gives such years their own probability
(see :func:`riskrf.fit_gumbel`).

Censored sizes.  Agency registers often give a size only as a bound or an
estimate.  In a size column a value may be written ``<1`` (the size is below
1: an upper bound), ``>20`` (above 20: a lower bound) or ``~15`` (about 15: an
approximate estimate); an empty size means "not recorded".  Such events are
never dropped and never given a made-up size: they are kept in
:attr:`Inventory.censored` (column ``censoring`` = ``below``, ``above``,
``approximate`` or ``unknown``, with the bound or estimate in ``volume_m3`` /
``mass_kg``), left out of the size fits (power law, annual maxima) with a
warning that counts them, and counted by rate models through
:meth:`Inventory.all_events`.

Where it lives
--------------
The package is cut where the reading has seams; the public names (:func:`read_inventory`, :class:`Inventory`,
:data:`DEFAULT_DENSITY_KG_M3`) import from here or from :mod:`riskrf`:

- :mod:`~riskrf.frequency.inventory.record`: :class:`Inventory`, the validated record and what is derived from it
  (events of any size, annual maxima, completeness, summary, plot);
- :mod:`~riskrf.frequency.inventory.reader`: :func:`read_inventory`, the file and its sidecar ``[record]`` table,
  the reader options, the columns recognised by name and unit, censored size cells, volumes and masses;
- :mod:`~riskrf.frequency.inventory.checks`: the checks of the events while they are read: record period, events
  outside it, censored sizes set apart, duplicated rows, sizes that look like a unit mistake.
"""
from __future__ import annotations

from ...core.units import DEFAULT_DENSITY_KG_M3
from .record import Inventory
from .reader import read_inventory

__all__ = ["DEFAULT_DENSITY_KG_M3", "Inventory", "read_inventory"]
