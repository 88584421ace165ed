"""Mitigation options as transformations of the site: one small class per option kind.

Each option of a study (a :class:`riskrf.risk.mitigation_inputs.Option` read from the ``[[options]]`` tables) is
wrapped by the class of its kind (:func:`effect_of`), which says what it does to the falls and what it costs
(CLIMADA's measures: a measure changes the hazard, the exposure or the vulnerability; one engine,
:mod:`riskrf.risk.loss_engine`, computes the losses):

* ``none`` (:class:`DoNothing`): the site as it is;
* ``scaling`` (:class:`Scaling`, scaling and bolting): removes the release of blocks between ``min_mass_kg`` and
  ``max_mass_kg`` from the source zone ``zone_x_m`` (the share of the release line it covers follows from the
  scenario's seeder), with an ASSUMED effectiveness decaying over its life;
* ``ditch`` (:class:`CatchDitch`): a catchment dug into the profile (``x_m``, ``width_m``, ``depth_m``); its
  retention is derived by re-simulating the scenario with the new profile; ``bench``, ``bund``, ``drape``
  (:class:`Bench`, :class:`Bund`, :class:`Drape`) change the slope likewise
  (:mod:`riskrf.risk.geometry_measures`);
* ``fence`` / ``attenuator`` (:class:`Barrier`): a barrier line (``capacity_kj`` = MEL, ``height_m``) at the
  barrier collector or at its own ``x_m``; falls pass over (the block's underside, simulated centre height minus
  the radius of a block of that mass, above the fence: the simulator's own barrier rule,
  ``simulation.kernel.barrier_outcome``) or through (energy above MEL, block by block);
* ``shed`` (:class:`Shed`): covers ``covered_length_m`` of the exposed road with a capacity ``capacity_kj``;
* ``realignment`` (:class:`Realignment`): moves the road to ``road_x_m`` on the profile (share of falls still
  reaching it from the simulated run-out), or away from the slope altogether;
* ``closure`` (:class:`Closure`): closes the road while a rainfall or warning rule holds; falls still reach the
  road but meet no road user;
* ``combined`` (:class:`Combined`): several of the above in series, each acting on the falls the previous ones let
  through, costs added: no double counting.

A typed ``retention`` (ditch, slope measures, barriers) or ``rate_reduction`` (scaling) replaces the derived effect;
it is then an assumption and says so in every output.

The protocol of a kind: :meth:`OptionEffect.parameters` (its costs and effect parameters, named as in the tornado),
:meth:`OptionEffect.stages` (its typed stages for the engine, derived from the slope models of
:class:`riskrf.risk.slope_models.SlopeModels`), :meth:`OptionEffect.describe` and the effect basis
(derived / ASSUMED / typed) of :func:`effect_basis`.

Where it lives
--------------
The package is cut by what the kinds act on; import each name from its module:

- :mod:`~riskrf.risk.options.base`: the kinds (:data:`~riskrf.risk.options.base.OPTION_KINDS`), the order in
  which an option's elements act, ``MitigationError``, the protocol ``OptionEffect`` and ``none``;
- :mod:`~riskrf.risk.options.slope`: ``scaling``, ``ditch``, ``bench``, ``bund``, ``drape`` and their ASSUMED
  defaults (scaling effectiveness, drape containment);
- :mod:`~riskrf.risk.options.road`: ``fence`` / ``attenuator`` and ``shed`` (structures with damage states),
  ``realignment``, ``closure``;
- :mod:`~riskrf.risk.options.chain`: the class of each kind (``KIND_CLASSES``, ``effect_of``), ``combined``, the
  effect basis and the engine's view of an option (``option_chain``).
"""
