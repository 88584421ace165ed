"""An option as a whole: the class of each kind, combined options and the engine's view of an option.

:data:`KIND_CLASSES` and :func:`effect_of` (the kind's class wrapping an option record), ``combined``
(:class:`Combined`: its components in series, costs added), :func:`effect_basis` (typed, computed, derived or
derived with an ASSUMED part, in words) and :func:`option_chain` (the components' stages in the order they act,
the slope geometry changes re-simulated together).
"""
from __future__ import annotations

from ..loss_engine import OptionChain, RetentionStage
from .base import DoNothing, EXPOSURE, GEOMETRY, MitigationError, OptionEffect
from .slope import Bench, Bund, CatchDitch, Drape, Scaling
from .road import Barrier, Closure, Realignment, Shed


class Combined(OptionEffect):
    """``combined``: its components in series; costs and effects are theirs."""

    needs_capital_cost = False

    @classmethod
    def finish_spec(cls, kind, spec, vals, at):
        """Check and read the components ``options`` (two or more option names) and nothing else.

        Parameters
        ----------
        kind : str
            The table's ``kind`` (``"combined"``).
        spec : dict
            The ``[[options]]`` table as read.
        vals : dict
            The values to build the option from; ``options`` set in place to a tuple of names.
        at : str
            ``"<source>: option '<name>'"``, the start of every error message.

        Returns
        -------
        None
            Raises a MitigationError when the components are missing or other fields are given.
        """
        comps = spec.get("options")
        if not isinstance(comps, list) or len(comps) < 2 or not all(isinstance(c, str) for c in comps):
            raise MitigationError(f"{at}: a combined option needs options = [\"name\", \"name\", ...] "
                                  "(two or more)")
        extra = {k for k in spec if k not in ("name", "kind", "options", "description")}
        if extra:
            raise MitigationError(f"{at}: a combined option takes its costs and effects from its "
                                  f"components; remove {sorted(extra)}")
        vals["options"] = tuple(comps)

    def describe(self, currency=""):
        return "combination of " + " + ".join(self.option.options)

    def components(self, option_named):
        """The options acting for this one: a combined option's components.

        Parameters
        ----------
        option_named : callable
            ``option_named(name)`` returns the study's option record of that name.

        Returns
        -------
        list
            The option records acting for this option.
        """
        return [option_named(n) for n in self.option.options]

    def parameters(self):
        """No parameters of its own: a combined option's costs and effects are its components'.

        Returns
        -------
        list of tuple
            ``(name, central value)`` pairs; costs in the study's currency, effects as shares [-], repair times [day].
        """
        return []


#: Kinds with fields no other kind takes (their classes' ``own_fields``), in the order a table is checked for them.
OWN_FIELD_KINDS = ("closure", "scaling", "drape")

#: The class of each option kind.
KIND_CLASSES = {"none": DoNothing, "scaling": Scaling, "ditch": CatchDitch, "fence": Barrier, "attenuator": Barrier,
                "shed": Shed, "realignment": Realignment, "closure": Closure, "combined": Combined, "bench": Bench,
                "bund": Bund, "drape": Drape}


def effect_of(option) -> OptionEffect:
    """The behaviour of ``option`` (its kind's class, wrapping it).

    Parameters
    ----------
    option : riskrf.risk.mitigation_inputs.Option
        The option record (its ``kind`` one of :data:`OPTION_KINDS`).

    Returns
    -------
    OptionEffect
        The instance of the kind's class (:data:`KIND_CLASSES`) wrapping ``option``.
    """
    return KIND_CLASSES[option.kind](option)


def scaling_effect(option) -> tuple:
    """:meth:`Scaling.effect` of a scaling option.

    Parameters
    ----------
    option : riskrf.risk.mitigation_inputs.Option
        A ``scaling`` option record.

    Returns
    -------
    tuple
        As :meth:`Scaling.effect`: initial effectiveness [-], its range [-], half-life [yr], cycle mean [-] and the
        cycle means at the range's ends [-].
    """
    return Scaling(option).effect()


def effect_basis(option, components) -> str:
    """How the effect of ``option`` (made of ``components``) is known: typed (an ASSUMPTION), computed, derived,
    or derived with an ASSUMED part, in words.

    Parameters
    ----------
    option : riskrf.risk.mitigation_inputs.Option
        The option whose effect basis is wanted.
    components : list of riskrf.risk.mitigation_inputs.Option
        The options acting for it (itself, or a combined option's components).

    Returns
    -------
    str
        The basis in words; a typed effectiveness starts with ``"ASSUMPTION"``.
    """
    effects = [effect_of(c) for c in components]
    typed = [e.option.name for e in effects if e.typed]
    if typed:
        return "ASSUMPTION: typed effectiveness (" + ", ".join(typed) + ")"
    sole = {e.sole_basis for e in effects}
    if len(sole) == 1 and None not in sole:
        return sole.pop()
    assumed = [b for b in (e.assumed_basis(len(components)) for e in effects) if b is not None]
    if len(assumed) == 1:
        return assumed[0][1]
    if assumed:                 # every assumed part named, lowest priority first; the derived rest once
        tail = "; others derived (simulation and site geometry)"
        texts = [t.removesuffix(tail) for _, t in sorted(assumed, key=lambda b: b[0])]
        return "; ".join(texts) + (tail if len(components) > len(assumed) else "")
    return "derived (simulation and site geometry)"


def option_chain(option, components, site, space, index_of: dict) -> OptionChain:
    """The engine's view of ``option``: the stages of its ``components`` in series (releases, typed retentions, the
    slope geometry changes re-simulated together, barriers, sheds, closures, realignments) and their costs.
    ``index_of``: option name -> position in the study.

    Parameters
    ----------
    option : riskrf.risk.mitigation_inputs.Option
        The option.
    components : list of riskrf.risk.mitigation_inputs.Option
        The options acting for it, in any order (sorted here by the order in which they act).
    site : riskrf.risk.slope_models.SlopeModels
        The site's slope models.
    space : object
        The engine's parameter space; ``space.column(name)`` gives the sampled values of an effect parameter.
    index_of : dict
        Option name -> position in the study.

    Returns
    -------
    riskrf.risk.loss_engine.OptionChain
        The option's name, its stages in series and ``(option index, life [yr])`` of each component.
    """
    effects = [effect_of(c) for c in components]
    stages = []
    for order in range(EXPOSURE + 1):
        for e in effects:
            if e.order == order:
                stages += e.stages(site, space, index_of[e.option.name])
        if order == GEOMETRY:
            geo = [e for e in effects if e.order == GEOMETRY]
            if geo:
                site.need_context(geo[0].option, "x_m")
                key = "+".join(e.option.name for e in geo)
                ret0, _, _, by_mass = site.geometry_retention(key, [e.geometry_measure() for e in geo])
                # retention by mass bin and slope model, as a shift from the overall reference retention (the
                # parameter)
                stages.append(RetentionStage(key, space.column(f"retention:{key}"), shift=by_mass - ret0))
    return OptionChain(option.name, tuple(stages), tuple((index_of[c.name], c.life_years) for c in components))
