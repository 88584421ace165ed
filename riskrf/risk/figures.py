"""Figures of the decision stage: the decision tree, the tornado chart and a mitigation study's tornado and ranking.

Each ``plot_x(result, ax=None) -> Axes`` draws on the given axes (or a new figure) and never changes global
matplotlib state; matplotlib is imported only when a figure is drawn.  The results' ``plot()`` methods call these
functions, and :mod:`riskrf.report` re-exports them.
"""
from __future__ import annotations

import numpy as np

from ..core.figures import _axes


def _fmt(v):
    a = abs(v)
    if a >= 1e6:
        return f"{v / 1e6:.3g}M"
    if a >= 1e3:
        return f"{v / 1e3:.3g}k"
    return f"{v:.3g}"


def _nodes(node):
    yield node
    for b in node.branches:
        yield from _nodes(b.child)


def plot_tree(tree, ax=None, *, max_label: int = 28):
    """Decision-tree diagram: squares decide, circles are chance, triangles end; the optimal path is red.

    Each node shows its rolled-back value; each branch its name, probability and cost.

    Parameters
    ----------
    tree : DecisionTree
        The tree.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    max_label : int
        Longest branch label [characters] before it is shortened.

    Returns
    -------
    matplotlib.axes.Axes
    """
    rb = tree.rollback()
    leaves = []
    pos = {}

    def layout(node, depth):
        if not node.branches:
            y = float(len(leaves))
            leaves.append(node)
        else:
            ys = [layout(b.child, depth + 1) for b in node.branches]
            y = float(np.mean(ys))
        pos[id(node)] = (depth, y)
        return y
    layout(tree.root, 0)
    n_leaves = max(len(leaves), 1)
    depth = max(d for d, _ in pos.values()) + 1
    ax = _axes(ax, figsize=(3.2 * depth + 2, 0.45 * n_leaves + 1.5))
    values = {id(node): rb.node_values[node.path] for node in _nodes(tree.root)}   # one rollback: decision_tree

    markers, lines = {}, {}              # drawn at the end, one call per style (far fewer artists to draw)

    def draw(node, on_path):
        x, y = pos[id(node)]
        marker = {"decision": "s", "chance": "o", "terminal": "<"}[node.type]
        markers.setdefault((marker, "C3" if on_path else "0.3"), []).append((x, y))
        if node.type != "terminal" or values[id(node)] != 0:
            ax.annotate(_fmt(values[id(node)]), (x, y), xytext=(-4, -12), textcoords="offset points", ha="right",
                        fontsize="x-small", color="C3" if on_path else "0.2", fontweight="bold")
        chosen = rb.policy.get(node.path) if node.type == "decision" else None
        for b in node.branches:
            cx, cy = pos[id(b.child)]
            best = on_path and (node.type != "decision" or b.name == chosen)
            lines.setdefault(best, []).append([(x, y), (x + 0.15, cy), (cx, cy)])
            label = b.name if len(b.name) <= max_label else b.name[:max_label - 1] + "…"
            extra = []
            if b.probability is not None:
                extra.append(f"p={tree._probability(b):.3g}")
            net = tree._net(b)
            if net:
                extra.append(f"{'cost' if tree.objective == 'min' else 'value'} {_fmt(net)}")
            ax.annotate(label + (f"  ({', '.join(extra)})" if extra else ""), ((x + cx) / 2 + 0.05, cy),
                        xytext=(0, 3), textcoords="offset points", fontsize="x-small", va="bottom")
            draw(b.child, best)
    draw(tree.root, True)
    from matplotlib.collections import LineCollection
    for best, segs in lines.items():
        ax.add_collection(LineCollection(segs, colors="C3" if best else "0.6", linewidths=2.2 if best else 0.9,
                                         zorder=1))
    for (marker, color), xy in markers.items():
        xs, ys = zip(*xy)
        ax.plot(xs, ys, marker, ls="none", ms=9, color=color, zorder=3)
    ax.set_xlim(-0.3, depth - 0.2)
    ax.set_ylim(-1, n_leaves)
    ax.invert_yaxis()
    ax.axis("off")
    ax.set_title(f"{tree.root.name or 'decision'}: best = {tree.ranking()['option'].iloc[0]} "
                 f"({'expected cost' if tree.objective == 'min' else 'expected value'} {_fmt(rb.value)})")
    return ax


def plot_tornado(table, ax=None, *, currency: str = "", xlabel: str | None = None, annotate: bool = False):
    """Tornado chart from :meth:`MitigationStudy.tornado`, :meth:`DecisionTree.tornado` or any table with columns
    ``parameter``, ``base`` and ``cost_at_low``/``cost_at_high`` or ``value_at_low``/``value_at_high``.

    ``xlabel``: the quantity on the x axis (default: the expected total cost of the best option);
    ``annotate``: write the value at the end of each bar.

    Parameters
    ----------
    table : pandas.DataFrame
        The tornado table (values in ``currency``).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).
    currency : str
        Currency label of the axis.
    xlabel : str, optional
        Axis label.
    annotate : bool
        Write the values.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax, figsize=(7, 0.5 * len(table) + 1.5))
    base = float(table["base"].iloc[0])
    lo_col = "cost_at_low" if "cost_at_low" in table else "value_at_low"
    hi_col = "cost_at_high" if "cost_at_high" in table else "value_at_high"
    lows, highs = table[lo_col].to_numpy(dtype=float), table[hi_col].to_numpy(dtype=float)
    rows = np.arange(len(table))
    ax.barh(rows, lows - base, left=base, color="C0", alpha=0.8, label="input low")
    ax.barh(rows, highs - base, left=base, color="C3", alpha=0.8, label="input high")
    for i, lo, hi in zip(rows, lows, highs) if annotate else ():
        for v in (lo, hi):
            if np.isfinite(v) and v != base:
                ax.annotate(_fmt(v), (v, i), xytext=(3 if v > base else -3, 0), textcoords="offset points",
                            ha="left" if v > base else "right", va="center", fontsize="x-small")
    ax.axvline(base, color="k", lw=1)
    ax.set_yticks(range(len(table)), table["parameter"])
    ax.invert_yaxis()
    ax.set_xlabel(xlabel or f"expected total cost of the best option {currency}".strip())
    ax.legend(fontsize="small")
    ax.grid(True, axis="x", alpha=0.3)
    return ax


def plot_study_tornado(study, ax=None):
    """Tornado chart of a mitigation study (:meth:`MitigationStudy.tornado`) in its currency.

    Parameters
    ----------
    study : MitigationStudy
        The study.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
    """
    return plot_tornado(study.tornado(), ax, currency=study.currency)


def plot_study_ranking(study, ax=None):
    """Expected total cost of each option of a mitigation study with its 5-95 % interval over the joint samples
    (:meth:`MitigationStudy.ranking`), cheapest at the top; the cost at central values as an open circle.

    Parameters
    ----------
    study : MitigationStudy
        The study.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
    """
    rank = study.ranking()
    ax = _axes(ax, figsize=(7, 0.45 * len(rank) + 1.5))
    y = np.arange(len(rank))
    mean = rank["expected_total_cost"].to_numpy(dtype=float)
    err = np.vstack([mean - rank["cost_p05"].to_numpy(dtype=float), rank["cost_p95"].to_numpy(dtype=float) - mean])
    ax.errorbar(mean, y, xerr=np.clip(err, 0, None), fmt="o", color="C0", capsize=3,
                label="expected total cost, 5-95 %")
    ax.plot(rank["cost_at_central_values"], y, "o", mfc="none", color="C3", label="at central values")
    ax.set_yticks(y, rank["option"])
    ax.invert_yaxis()
    ax.set_xlabel(f"expected total cost {study.currency}".strip())
    ax.legend(fontsize="small")
    ax.grid(True, axis="x", alpha=0.3)
    return ax


def plot_model_ranking(ranking, ax=None):
    """Each option's expected cost under every draw (points) and over the draws (bar).

    Parameters
    ----------
    ranking : ModelUncertainRanking
        The result drawn.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default a new figure).

    Returns
    -------
    matplotlib.axes.Axes
        The axes drawn on (expected total cost [currency] on x, log scale when all costs are positive).
    """
    ax = _axes(ax, figsize=(7, 0.45 * len(ranking.options) + 1.5))
    order = np.argsort(ranking.expected_costs())[::-1]
    y = np.arange(len(order))
    ax.barh(y, ranking.expected_costs()[order], color="0.8", label="expected over the draws")
    for i, k in enumerate(order):
        ax.plot(ranking.costs[:, k], np.full(ranking.n_draws, y[i]), "o", color="C0", ms=3,
                label="one draw of the trajectory model" if i == 0 else None)
    ax.set_yticks(y)
    ax.set_yticklabels([ranking.options[k] for k in order])
    if np.all(ranking.costs > 0):
        ax.set_xscale("log")
    ax.set_xlabel(f"expected total cost [{ranking.currency}]" if ranking.currency else "expected total cost")
    ax.legend(fontsize="small", loc="lower right")
    return ax


def plot_road_profile(profile, ax=None):
    """Falls and deaths per year per metre along the road (matplotlib axes).

    Parameters
    ----------
    profile : RoadRiskProfile
        The result drawn.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (a new figure when None).

    Returns
    -------
    matplotlib.axes.Axes
        The axes of the falls (deaths on a twin axis).
    """
    ax = _axes(ax, figsize=(8, 3.5))
    t = profile.table
    mid = 0.5 * (t["start_m"] + t["end_m"])
    ax.step(mid, t["falls_per_year_per_m"], where="mid", color="tab:blue", label="falls reaching the road")
    ax.set_xlabel(f"position along {profile.road} [m]")
    ax.set_ylabel("falls per year per metre")
    ax2 = ax.twinx()
    ax2.step(mid, t["deaths_per_year_per_m"], where="mid", color="tab:red", label="road-user deaths")
    ax2.set_ylabel("deaths per year per metre", color="tab:red")
    ax.set_title(f"{profile.road}: {profile.totals()['falls_per_year']:.3g} falls/yr reach the road")
    return ax
