"""The validated corridor: :class:`Corridor`, :class:`Section`, :class:`CorridorError`, the sections-table columns.

What :func:`riskrf.app.corridor.load_corridor` returns and every later stage reads: the column vocabulary of
the sections table (units in the names), the corridor and its sections as frozen records, the seed of a section
(a child of the corridor seed keyed by the crc32 of its id) and the checks shared by the readers.
Lengths and chainage m, rates per year, money in the corridor currency.
"""
from __future__ import annotations

import difflib
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...core.validation import RiskrfError
from ...risk import rhrs


#: Columns of the sections table (units in the names); ``rhrs_*`` columns are the RHRS attributes of
#: :data:`riskrf.risk.rhrs.RATE_FIELDS` prefixed with ``rhrs_``.
GEOMETRY_COLUMNS = ("cut_height_m", "face_angle_deg", "ditch_width_m", "ditch_depth_m", "runout_to_road_m",
                    "road_width_m")
#: Optional geometry of a generated cut: a horizontal catch bench in the face (width 0: no bench).
BENCH_COLUMNS = ("bench_width_m", "bench_height_m")
NUMBER_COLUMNS = GEOMETRY_COLUMNS + BENCH_COLUMNS + ("chainage_from", "chainage_to", "falls_per_year", "falls_per_km_year",
                                     "falls_per_m2_year", "vehicles_per_day", "speed_kmh", "release_zone_share",
                                     "cut_length_m")
RATE_COLUMNS = ("falls_per_year", "falls_per_km_year", "falls_per_m2_year")
#: Ways to give a section's rate: one of the rate columns, or ``inventory`` (the section's own inventory file).
RATE_SOURCES = RATE_COLUMNS + ("inventory",)
TEXT_COLUMNS = ("id", "scenario", "face_material", "ditch_material", "road_material", "options", "inventory",
                "notes")
RHRS_COLUMNS = tuple("rhrs_" + f for f in rhrs.RATE_FIELDS)
#: Sections-table columns that give an RHRS attribute when its ``rhrs_*`` column is empty (named in errors).
_RHRS_SOURCE_COLUMNS = {"slope_height_m": "'rhrs_slope_height_m' (or 'cut_height_m')",
                        "roadway_width_m": "'rhrs_roadway_width_m' (or 'road_width_m')",
                        "sight_distance_m": "'rhrs_sight_distance_m' (or 'rhrs_percent_dsd')",
                        "decision_sight_distance_m": "'rhrs_decision_sight_distance_m' (or 'rhrs_percent_dsd')",
                        "block_size_m or volume_m3": "'rhrs_block_size_m' or 'rhrs_volume_m3'"}
ALL_COLUMNS = TEXT_COLUMNS + NUMBER_COLUMNS + RHRS_COLUMNS


#: Most falls a year one section may be given.  A deliberately loose bound against unit and typing mistakes
#: (per m2 read as per km, 10^6 for 10^-6): 10,000 a year is 27 falls a day reaching one road section, a
#: slope that closes its road rather than one a corridor screening ranks.
MAX_SECTION_FALLS_PER_YEAR = 10_000.0
#: Per-metre cost fields of corridor options, multiplied by the section's cut length (``cut_length_m``: the length
#: of rock cut along the road that the works treat; default ``rhrs_slope_length_m``, else the section length).
PER_M_FIELDS = ("capital_cost_per_m", "annual_maintenance_per_m", "replacement_cost_per_m")


class CorridorError(RiskrfError, ValueError):
    """A corridor file or sections table is invalid; the message lists every bad field found."""


@dataclass(frozen=True)
class Section:
    """One validated section: id, chainage [m], its scenario (generated or read), rate and traffic."""

    id: str
    row: int
    chainage_from_m: float
    chainage_to_m: float
    scenario: object = field(repr=False)
    geometry: str
    falls_per_year: float
    vehicles_per_day: float
    speed_kmh: float
    options: tuple
    rating: rhrs.RHRSRating | None = None
    notes: str = ""
    rate_source: str = ""
    cut_length_m: float | None = None
    line: tuple | None = field(default=None, repr=False)

    @property
    def works_length_m(self) -> float:
        """Length [m] that per-metre option costs are paid on: the cut length, else the section length."""
        return self.length_m if self.cut_length_m is None else self.cut_length_m

    @property
    def length_m(self) -> float:
        """Length of the section along the chainage [m]."""
        return self.chainage_to_m - self.chainage_from_m


@dataclass(frozen=True)
class Corridor:
    """A validated corridor: sections, mass law, study inputs, simulation size and seed."""

    name: str
    path: Path
    sections: tuple
    mass: object
    mass_note: str
    rate_basis: str
    study: dict = field(repr=False)
    options: tuple = ()
    n_blocks: int = 2000
    option_blocks: int = 1000
    seed: int = 1
    currency: str = "CHF"
    errors: tuple = ()
    defaults_used: tuple = ()
    crs: str | None = None
    centreline: object = field(default=None, repr=False)
    rhrs_variant: str = "fhwa"

    def section(self, sid: str) -> Section:
        """The section with id ``sid`` (StopIteration when there is none).

        Parameters
        ----------
        sid : str
            Section id.

        Returns
        -------
        Section
            The section with that id.
        """
        return next(s for s in self.sections if s.id == sid)


def _section_key(sid: str) -> int:
    """crc32 of a section id: the key of its seed and of its partition file (ids must not share one)."""
    return zlib.crc32(sid.encode("utf-8"))


def _section_seed(seed: int, sid: str) -> int:
    """Seed of one section: the SeedSequence(seed) child at spawn key crc32(id), as an integer."""
    child = np.random.SeedSequence(int(seed), spawn_key=(_section_key(sid),))
    return int(child.generate_state(1, dtype=np.uint64)[0]) >> 1          # < 2**63: fits int64 columns


def _unknown(keys, allowed, where, source):
    for key in keys:
        if key not in allowed:
            close = difflib.get_close_matches(str(key), list(allowed), n=1)
            raise CorridorError(f"{source}: unknown field {where}{key!r}" + (f"; did you mean {close[0]!r}?" if close
                                                                           else f"; allowed: {sorted(allowed)}"))


def _check_corridor_gdf(gdf, where: str) -> float:
    """The programme's gross-disproportion factor (>= 1), or a :class:`CorridorError` naming ``where`` and the value.

    Parameters
    ----------
    gdf : float
        Gross-disproportion factor [-].
    where : str
        File and field (``corridor.toml: criteria.disproportion_factor``) or the CLI argument (``--gdf``).

    Returns
    -------
    float
        The factor.
    """
    from ...risk.programme import check_gdf
    try:
        return check_gdf(gdf, where)
    except ValueError as exc:
        raise CorridorError(str(exc)) from None
