"""The decision commands: ``riskrf decide`` (mitigation options or a decision tree), ``riskrf assess`` (the whole
chain for a site file, 2-D or 3-D) and ``riskrf demo`` (``assess`` on the bundled site)."""
from __future__ import annotations

from pathlib import Path

from .steps import _read, build_energy_hazard


def cmd_decide(args) -> int:
    """``riskrf decide``: rank mitigation options (site file) or roll back a decision tree file.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..risk.decision_tree import DecisionTree
    from ..risk.mitigation import load_mitigation
    from ..io.outputs import atomic_output_dir, write_json
    from ..report.decision_figures import plot_risk_profiles
    from ..risk.figures import plot_tornado, plot_tree
    from ..report.files import save_figure
    from ..report.mitigation_text import study_report, write_mitigation_outputs

    if (args.tree is None) == (args.options is None):
        raise ValueError("give a decision tree file (riskrf decide TREE.json) or --options OPTIONS.toml with "
                         "--inventory and --scenario, not both")
    from ..app.preflight import check_energy_args, check_number, check_out
    check_number(args.risk_tolerance, "--risk-tolerance", low=0, low_open=True,
                 what=" (in money; leave it out for expected values)")
    out = check_out(args, "decision")
    if args.tree is None:
        if args.inventory is None:
            raise ValueError("riskrf decide --options needs --inventory INVENTORY and --scenario SCENARIO "
                             "(or --velocities FILE)")
        check_energy_args(args, road_collector=args.road_collector)
    if args.tree is not None:
        tree = DecisionTree.from_file(args.tree)
        rb = tree.rollback(risk_tolerance=args.risk_tolerance)
        ranking = tree.ranking(risk_tolerance=args.risk_tolerance)
        print(f"Decision tree {args.tree} (objective {tree.objective}"
              + (f", exponential utility with risk tolerance {args.risk_tolerance:g}" if args.risk_tolerance
                 else ", expected values") + ")")
        print(ranking.to_string(index=False))
        print("\nOptimal policy:")
        for path, choice in rb.policy.items():
            print(f"  at {path}: {choice}")
        evpi = {var: tree.evpi(var) for var in tree.variables()}
        for var, value in evpi.items():
            print(f"  EVPI of {var!r}: {value:.6g}")
        tornado = tree.tornado() if tree.parameters else None
        with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
            ranking.to_csv(tmp / "ranking.csv", index=False)
            profiles = tree.risk_profile()
            profiles.to_csv(tmp / "risk_profiles.csv", index=False)
            write_json({"objective": tree.objective, "value": rb.value, "options": rb.option_values,
                        "policy": rb.policy, "evpi": evpi},
                       tmp / "decision.json")
            n_leaves = _count_leaves(tree.root)
            if n_leaves <= MAX_DRAWN_LEAVES:
                save_figure(plot_tree(tree).figure, tmp / "tree.png")
            else:           # a diagram of thousands of branches is unreadable and takes minutes to draw
                print(f"note: tree.png not drawn: {n_leaves:,} end branches (more than {MAX_DRAWN_LEAVES}); "
                      "ranking.csv and risk_profiles.csv hold every option")
            if profiles["option"].nunique() <= MAX_DRAWN_PROFILES:
                save_figure(plot_risk_profiles(profiles).figure, tmp / "risk_profiles.png")
            else:
                print(f"note: risk_profiles.png not drawn: {profiles['option'].nunique():,} options (more than "
                      f"{MAX_DRAWN_PROFILES}); risk_profiles.csv holds them")
            if tornado is not None and len(tornado):
                tornado.to_csv(tmp / "tornado.csv", index=False)
                ax = plot_tornado(tornado)
                save_figure(ax.figure, tmp / "tornado.png")
        print(f"\nWrote ranking.csv, decision.json and figures to {out}/")
        return 0

    from ..risk.mitigation_inputs import check_mitigation_file
    check_mitigation_file(args.options)          # every option and table checked before the inventory is read
    inv = _read(args, args.inventory)
    gr, hazard, result = build_energy_hazard(args, inv)
    from ..app.assess.decision import road_share, study_context
    road = args.road_collector or "road"
    study = load_mitigation(args.options, hazard, road_share=road_share(result, hazard.collector, road),
                            **study_context(result, hazard.collector, road, args.option_blocks,
                                            args.seed, inv, hazard, args.rate_scale))
    report = study_report(study)
    print(report["text"])
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        write_mitigation_outputs(study, report, tmp)
    print(f"\nWrote ranking.csv, tornado.csv, break_even.csv, decision.json and figures to {out}/")
    return 0


#: Decision-tree figures are drawn up to these sizes (end branches; options with a risk profile).
MAX_DRAWN_LEAVES = 400
MAX_DRAWN_PROFILES = 40


def _count_leaves(node) -> int:
    """End branches below ``node`` (iteratively: a tree may be deeper than Python's recursion limit)."""
    count, stack = 0, [node]
    while stack:
        n = stack.pop()
        if n.branches:
            stack.extend(b.child for b in n.branches)
        else:
            count += 1
    return count


def cmd_assess(args) -> int:
    """``riskrf assess``: the whole chain for a site file, written atomically to ``--out``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from ..app.assess.outputs import write_assessment
    from ..app.assess.run import run_assessment
    from ..io.outputs import atomic_output_dir
    from ..app.site import load_site

    from ..app.preflight import check_number, check_out
    check_number(args.n, "-n", low=1)
    out = check_out(args, f"{Path(args.site).stem}-assessment")
    site = load_site(args.site)          # every input is checked before anything is computed
    if site.three_d:
        return _assess_terrain(site, args, out)
    from .runner import TwoCores
    runner = TwoCores()                  # the simulator compiled and the figures drawn on the other core
    from ..app.assess.site_inputs import site_trajectory_status
    from ..report.files import figure_note
    # an uncalibrated trajectory model is stamped on every figure drawn from the trajectories
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp, \
            figure_note(site_trajectory_status(site).figure_note):
        # figures of each stage are drawn into the temporary output beside the later stages
        assessment = run_assessment(site, seed=args.seed, n_blocks=args.n, figures_dir=tmp / "figures",
                                    runner=runner)
        s = write_assessment(assessment, tmp, runner=runner)
    stages = ", ".join(f"{k} {v:.1f} s" for k, v in assessment.timings.items())
    print(f"\nStage times: {stages}.")
    if assessment.warnings:
        print(f"{len(assessment.warnings)} warning(s), also listed in the report:")
        from ..io.outputs import relative_paths
        for w in assessment.warnings:
            print(f"  - {relative_paths(w, site.path.parent)}")        # paths relative to the site file
    print(f"Rate of falls from the {s['hazard']['rate_source']}.")
    print(f"Lowest expected total cost: {s['best_option']} (then {s['second_option']}).")
    print(f"Recommendation: {s['recommendation']['option'] or 'none'} ({s['recommendation']['basis']}).")
    if "resolution" in s["recommendation"]:
        print(f"Resolution: {s['recommendation']['resolution']['text']}")
    if assessment.model_uncertainty is not None:
        print("\n".join(assessment.model_uncertainty.text()))
    print(f"Report: {(out / 'report.html').resolve()}")
    return 0


def _assess_terrain(site, args, out) -> int:
    """``riskrf assess`` for a site on 3-D terrain (:mod:`riskrf.app.assess3d`)."""
    from ..app.assess3d import run_terrain_assessment
    from ..io.outputs import atomic_output_dir
    with atomic_output_dir(out, overwrite=args.overwrite) as tmp:
        a = run_terrain_assessment(site, seed=args.seed, n_blocks=args.n)
        s = a.write(tmp)
    print(f"\nStage times: {', '.join(f'{k} {v:.1f} s' for k, v in a.timings.items())}.")
    hz = s["hazard"]
    print(f"3-D terrain: {hz['line']}; reach {hz['reach_probability']:.3g}, "
          f"{hz['arrival_rate_per_year']:.3g} falls/yr at the line.")
    if s["road"] is not None:
        r = s["road"]
        print(f"Road {r['road']!r}: {r['falls_per_year']:.3g} falls/yr over {r['length_m']:.0f} m, "
              f"{r['deaths_per_year']:.3g} deaths/yr; worst metre at {r['worst_metre_start_m']:.0f} m.")
    for w in a.warnings:
        print(f"  - {w}")
    print("Not done on 3-D terrain: " + "; ".join(s["not_done_on_3d_terrain"]) + ".")
    print(f"Outputs: {out.resolve()}")
    return 0


def cmd_demo(args) -> int:
    """``riskrf demo``: ``assess`` on the bundled demo site.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (see :func:`build_parser`).

    Returns
    -------
    int
        Exit status: 0 on success, 2 for bad input (errors raised here are reported by :func:`main`).
    """
    from importlib import resources

    with resources.as_file(resources.files("riskrf") / "data" / "demo_site.toml") as site:
        args.site = str(site)
        if args.out is None:
            args.out = "riskrf-demo"
        print(f"riskrf demo: the bundled site {site.name} (real Lauterbrunnen inventory, shipped road-cut "
              "scenario, illustrative costs)")
        return cmd_assess(args)
