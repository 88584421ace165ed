"""The protocol of an option kind (:class:`OptionEffect`), the kinds and the order in which they act.

:data:`OPTION_KINDS` and its groups, the ASSUMED repair days of a destroyed structure, the positions of an
option's elements in series (:data:`RELEASE` ... :data:`EXPOSURE`), :class:`MitigationError`, and
:class:`OptionEffect`: how a kind reads and checks its ``[[options]]`` table, describes itself, names its costs and
effect parameters with their ranges, and gives its typed stages for :mod:`riskrf.risk.loss_engine`.  The kind
``none`` (:class:`DoNothing`) is here as the protocol's plainest case; the other kinds are in
:mod:`~riskrf.risk.options.slope`, :mod:`~riskrf.risk.options.road` and :mod:`~riskrf.risk.options.chain`.
"""
from __future__ import annotations

from ...core.validation import RiskrfError


OPTION_KINDS = ("none", "scaling", "ditch", "fence", "attenuator", "shed", "realignment", "closure", "combined",
                "bench", "bund", "drape")
#: Options that change the slope or hang on it (bench and bund re-simulated like a ditch; a drape: the falls
#: released under it, see :class:`Drape`).
SLOPE_KINDS = ("bench", "bund", "drape")
BARRIER_KINDS = ("fence", "attenuator", "shed")
#: Days a destroyed structure stays out of service (ASSUMPTION; override with ``repair_days``).
DEFAULT_REPAIR_DAYS = {"fence": 30.0, "attenuator": 30.0, "shed": 180.0}


# the order in which the elements of an option act on the falls, in series
RELEASE, TYPED_RETENTION, GEOMETRY, BARRIER, SHED, CLOSURE, EXPOSURE = range(7)


class MitigationError(RiskrfError, ValueError):
    """A mitigation file or option is invalid; the message names the option and field."""


def _typed_retention(o, what: str) -> str:
    return f"{what}; ASSUMED to retain {o.retention:.0%} of falls (typed)"


class OptionEffect:
    """The behaviour of one option kind; wraps the option record ``option``.

    ``order``: where its stages act in the series of a combined option (releases, typed retentions, the
    re-simulated slope geometry, barriers, sheds, closures, realignments).
    """

    order = EXPOSURE
    needs_design_check = False
    #: Fields of an ``[[options]]`` table that only this kind takes (any other kind naming one is an error).
    own_fields = ()
    #: Fields a table of this kind must give, each > 0 (a structure's capacity [kJ] and height [m]).
    required_fields = ()
    #: Geometry fields a table of this kind must give when it has no typed ``retention`` (positions, sizes [m]).
    geometry_fields = ()
    #: Does a table of this kind need ``capital_cost`` (a combined option takes its components' costs)?
    needs_capital_cost = True

    def __init__(self, option):
        self.option = option

    # ---- reading an ``[[options]]`` table (riskrf.risk.mitigation_inputs.parse_option) ------------------------
    @classmethod
    def read_spec(cls, kind: str, spec: dict, vals: dict, at: str) -> None:
        """Check and read the fields of this kind's own rule (before the shared checks of shares and ranges).

        Parameters
        ----------
        kind : str
            The table's ``kind`` (one of :data:`OPTION_KINDS`).
        spec : dict
            The ``[[options]]`` table as read (costs in the study's currency, lengths [m], rainfall [mm]).
        vals : dict
            The values to build the option from; updated in place.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError naming ``at``, the field and its value; nothing to read by default.
        """
        return None

    @classmethod
    def check_effect_spec(cls, kind: str, spec: dict, at: str) -> None:
        """Check that a table of this kind says what the option does, beyond :attr:`required_fields` and
        :attr:`geometry_fields` (e.g. the blocks scaling removes).

        Parameters
        ----------
        kind : str
            The table's ``kind`` (one of :data:`OPTION_KINDS`).
        spec : dict
            The ``[[options]]`` table as read.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError naming ``at`` and the missing fields; nothing more is needed by default.
        """
        return None

    @classmethod
    def finish_spec(cls, kind: str, spec: dict, vals: dict, at: str) -> None:
        """Last check and defaults of a table of this kind (after the shared checks).

        Parameters
        ----------
        kind : str
            The table's ``kind`` (one of :data:`OPTION_KINDS`).
        spec : dict
            The ``[[options]]`` table as read.
        vals : dict
            The values to build the option from; updated in place.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError if the table lists component ``options`` (only a combined option has them).
        """
        if "options" in spec:
            raise MitigationError(f"{at}: options = ... is only for kind = 'combined'")

    # ---- what it is and assumes --------------------------------------------------------------------------
    @property
    def typed(self) -> bool:
        """Does a typed effectiveness (an assumption) replace the derived one?"""
        return self.option.retention is not None or self.option.rate_reduction is not None

    def describe(self, currency: str = "") -> str:
        """What the option does, in words (money in ``currency``).

        Parameters
        ----------
        currency : str, optional
            Currency code printed after money amounts (e.g. ``"CHF"``); empty for none.

        Returns
        -------
        str
            One-line description of the option, assumptions labelled ASSUMED.
        """
        raise NotImplementedError

    @property
    def sole_basis(self) -> str | None:
        """The effect basis when every component of an option is of this kind (else None)."""
        return None

    def assumed_basis(self, n_components: int) -> tuple | None:
        """(priority, text): the effect basis of an option with an assumed part of this kind, lower first.

        Parameters
        ----------
        n_components : int
            Number of components of the option whose basis is wanted.

        Returns
        -------
        tuple or None
            ``(priority, text)``: lower priority wins when several components have an assumed part; None when this kind
            assumes nothing.
        """
        return None

    def check(self, source: str) -> None:
        """Raise a MitigationError if the option cannot enter the engine yet.

        Parameters
        ----------
        source : str
            The file (or other source) the option came from, named in the error message.

        Raises
        ------
        MitigationError
            When the option cannot enter the engine yet.
        """

    def components(self, option_named) -> list:
        """The options acting for this one (itself; a combined option's components), ``option_named`` giving the
        study's option of a name.

        Parameters
        ----------
        option_named : callable
            ``option_named(name)`` returns the study's option record of that name.

        Returns
        -------
        list
            The option records acting for this option.
        """
        return [self.option]

    # ---- costs and effect parameters -----------------------------------------------------------------------
    def parameters(self) -> list:
        """(name, central value) of every input of this option the engine varies: capital cost, annual
        maintenance, typed effects, and the kind's own (scaling effectiveness, closure share, repair days).

        Returns
        -------
        list of tuple
            ``(name, central value)`` pairs; costs in the study's currency, effects as shares [-], repair times [day].
        """
        o = self.option
        p = [(f"capital_cost:{o.name}", o.capital_cost), (f"annual_maintenance:{o.name}", o.annual_maintenance)]
        if o.rate_reduction is not None:
            p.append((f"rate_reduction:{o.name}", o.rate_reduction))
        p += self._release_parameters()
        if o.retention is not None:
            p.append((f"retention:{o.name}", o.retention))
        return p + self._own_parameters()

    def _release_parameters(self) -> list:
        return []

    def _own_parameters(self) -> list:
        return []

    def stated_ranges(self, central: dict) -> dict:
        """name -> (low, high, how) of the option's stated ranges (costs and typed effects).

        Parameters
        ----------
        central : dict
            ``name -> central value`` of the parameters the engine varies; only ranges of names in it are returned.

        Returns
        -------
        dict
            ``name -> (low, high, how)``: the stated bounds (costs in the study's currency, effects as shares [-]) and
            the sampling, typed effectiveness labelled as an assumption.
        """
        o = self.option
        out = {}
        for fld in ("capital_cost", "annual_maintenance", "retention", "rate_reduction"):
            rng = getattr(o, f"{fld}_range")
            if rng is not None and f"{fld}:{o.name}" in central:
                out[f"{fld}:{o.name}"] = (*rng, "uniform, stated" + (" (typed effectiveness: assumption)"
                                                                     if fld in ("retention", "rate_reduction")
                                                                     else ""))
        return out

    def assumed_ranges(self) -> dict:
        """name -> (low, high, how) of the option's assumed (not stated) ranges.

        Returns
        -------
        dict
            ``name -> (low, high, how)``: bounds of each assumed range (same units as the parameter) and how it is
            sampled.
        """
        return {}

    # ---- effect on the falls -------------------------------------------------------------------------------
    def stages(self, site, space, index: int) -> list:
        """The option's typed stages (:mod:`riskrf.risk.loss_engine`), derived with the slope models ``site``
        (:class:`riskrf.risk.slope_models.SlopeModels`); effect parameters get their columns from ``space``;
        ``index``: the option's position in the study.

        Parameters
        ----------
        site : riskrf.risk.slope_models.SlopeModels
            The site's slope models (simulated runs, mass grid, exposed road).
        space : object
            The engine's parameter space; ``space.column(name)`` gives the sampled values of an effect parameter.
        index : int
            The option's position in the study.

        Returns
        -------
        list
            The option's stages (:mod:`riskrf.risk.loss_engine` stage objects), in the order they act.
        """
        return []

    def geometry_measure(self):
        """The profile or surface change to re-simulate (a derived ditch, bench, bund or drape), else None."""
        return None


class DoNothing(OptionEffect):
    """``none``: the site as it is."""

    def describe(self, currency=""):
        return "the site as it is"

    @property
    def sole_basis(self):
        return "-"
