"""Decision trees: decision, chance and terminal nodes to any depth (Wyllie 2014, 8.5.5).

A tree is a nested dictionary (JSON or TOML file)::

    {"type": "decision", "name": "mitigation", "objective": "min",
     "parameters": {"p_hit": 0.02, "c_hit": 2.5e6},          # optional named values
     "branches": [
        {"name": "do nothing", "cost": 0,
         "child": {"type": "chance", "variable": "rock fall", "branches": [
             {"name": "vehicle hit", "probability": "p_hit", "cost": "c_hit"},
             {"name": "no hit", "probability": "1 - p_hit", "cost": 0}]}},
        {"name": "fence", "cost": 450000, "child": {...}}]}

A branch carries ``cost`` (paid when taken) and ``payoff`` (gained); numbers may be
expressions of the ``parameters`` (+ - * / ** and parentheses), so one-way
sensitivity, tornado charts and break-even values can vary them.  ``objective``
"min" (default) minimises expected net cost, "max" maximises expected net payoff.
Chance nodes may name the uncertain ``variable`` they represent; nodes with the
same variable are the same uncertainty, which is what the expected value of
perfect information about it refers to.  ``{"ref": "name"}`` reuses a subtree
defined under the top-level ``"nodes"`` table (cycles are an error).
Rollback: expectation at chance nodes, best branch at decision nodes (Clemen &
Reilly 2001, ch. 4); with ``risk_tolerance`` R, certainty equivalents of the
exponential utility u(x) = 1 - exp(-x/R) replace expectations.
"""
from __future__ import annotations

import ast
import json
import math
import sys
import operator
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..core.validation import RiskrfError
from simulation._display import Displayed, short_repr

PROBABILITY_TOLERANCE = 1e-6

_OPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
        ast.Pow: operator.pow, ast.USub: operator.neg, ast.UAdd: operator.pos}


class TreeError(RiskrfError, ValueError):
    """A decision tree is malformed; the message names the node path and the field."""


def _evaluate(expr, params: dict, where: str):
    """Value of a number or an arithmetic expression of named parameters; always finite."""
    try:
        value = _evaluate_raw(expr, params, where)
    except OverflowError:
        raise TreeError(f"{where}: {expr!r} overflows: the result is not a finite number") from None
    except ZeroDivisionError:
        raise TreeError(f"{where}: {expr!r}: division by zero") from None
    if not math.isfinite(value):
        raise TreeError(f"{where}: {expr!r} is not a finite number")
    return value


def _evaluate_raw(expr, params: dict, where: str):
    if isinstance(expr, bool):
        raise TreeError(f"{where}: {expr!r} is not a number")
    if isinstance(expr, (int, float)):
        try:
            return float(expr)
        except OverflowError:
            raise TreeError(f"{where}: {expr:.6g} is not a finite number (too large)") from None
    if not isinstance(expr, str):
        raise TreeError(f"{where}: {expr!r} is not a number or an expression")
    try:
        tree = ast.parse(expr, mode="eval")
    except SyntaxError as exc:
        raise TreeError(f"{where}: cannot read expression {expr!r}") from exc

    def ev(node):
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id not in params:
                raise TreeError(f"{where}: unknown parameter {node.id!r} in {expr!r}; parameters are "
                                f"{sorted(params)}")
            return float(params[node.id])
        if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](ev(node.operand))
        raise TreeError(f"{where}: only numbers, parameter names and + - * / ** are allowed in {expr!r}")
    return ev(tree)


@dataclass
class Branch:
    """One branch of a node: its name, the node it leads to and its cost (a number or a parameter name)."""
    name: str
    child: "Node"
    cost: object = 0.0
    payoff: object = 0.0
    probability: object = None


@dataclass
class Node:
    """A decision, chance or terminal node of a decision tree."""
    type: str                       # "decision", "chance" or "terminal"
    name: str = ""
    branches: list = field(default_factory=list)
    variable: str | None = None
    value: object = 0.0             # terminal value (a payoff for "max", a cost for "min")
    path: str = ""


@dataclass(frozen=True)
class Rollback:
    """Result of rolling back a tree: the value of every node and the best branch of every decision."""

    value: float
    option_values: dict             # top-level decision: branch name -> value
    policy: dict                    # decision node path -> chosen branch
    objective: str
    node_values: dict = field(default_factory=dict)   # node path -> rolled-back value (for diagrams)


class DecisionTree(Displayed):
    """A decision tree with rollback, ranking, risk profiles, sensitivity and value of information."""

    def __init__(self, root: Node, objective: str = "min", parameters: dict | None = None, source: str = "<dict>"):
        if objective not in ("min", "max"):
            raise TreeError(f"{source}: objective = {objective!r} is not 'min' or 'max'")
        self.root = root
        self.objective = objective
        self.parameters = dict(parameters or {})
        self.source = source
        self.validate()

    # ---- construction ---------------------------------------------------------------
    @classmethod
    def from_dict(cls, spec: dict, source: str = "<dict>") -> "DecisionTree":
        """Tree from a dict as read from TOML/JSON; ``source`` names it in error messages.

        Parameters
        ----------
        spec : dict
            The tree as read from TOML/JSON (``type``, ``branches``, optional ``parameters``, ``objective``, ``nodes``).
        source : str, optional
            Name of the tree's origin in error messages.

        Returns
        -------
        DecisionTree
            The checked tree.

        Raises
        ------
        TreeError
            When the tree is malformed (names the source and the node path).
        """
        if not isinstance(spec, dict):
            raise TreeError(f"{source}: a tree must be a table/object; got {type(spec).__name__}")
        params = spec.get("parameters", {})
        if not isinstance(params, dict):
            raise TreeError(f"{source}: parameters must be a table of name = number")
        for k, v in params.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise TreeError(f"{source}: parameter {k!r} = {v!r} is not a finite number")
        defs = spec.get("nodes", {})
        try:
            root = _build(spec, defs, source, (), source)
            return cls(root, spec.get("objective", "min"), params, source)
        except RecursionError:
            raise TreeError(f"{source}: the tree is nested too deeply to evaluate (more than about "
                            f"{sys.getrecursionlimit() // 4} levels)") from None

    @classmethod
    def from_file(cls, path) -> "DecisionTree":
        """Tree from a TOML or JSON file; every field is checked before use.

        Parameters
        ----------
        path : str or pathlib.Path
            A ``.toml`` or ``.json`` tree file.

        Returns
        -------
        DecisionTree
            The checked tree.

        Raises
        ------
        FileNotFoundError
            When ``path`` does not exist.
        TreeError
            When the file cannot be parsed or the tree is malformed.
        """
        path = Path(path)
        if not path.exists():
            raise FileNotFoundError(f"decision tree file not found: {path}")
        if path.is_dir():
            raise TreeError(f"{path} is a directory, not a decision tree file (.json or .toml)")
        try:
            if path.suffix.lower() == ".toml":
                with open(path, "rb") as fh:
                    data = tomllib.load(fh)
            else:
                data = json.loads(path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise TreeError(f"{path}: cannot parse: {exc}") from exc
        except RecursionError:
            raise TreeError(f"{path}: the tree is nested too deeply to read") from None
        return cls.from_dict(data, source=str(path))

    def with_parameters(self, **values) -> "DecisionTree":
        """A copy of the tree with some parameters set to new values (unknown names are refused).

        Parameters
        ----------
        **values : float
            New values of existing parameters (units as in the tree: probabilities [-], costs in its currency).

        Returns
        -------
        DecisionTree
            The new tree (this one is unchanged).

        Raises
        ------
        TreeError
            When a name is not a parameter of the tree.
        """
        unknown = set(values) - set(self.parameters)
        if unknown:
            raise TreeError(f"{self.source}: unknown parameter(s) {sorted(unknown)}; parameters are "
                            f"{sorted(self.parameters)}")
        return DecisionTree(self.root, self.objective, {**self.parameters, **values}, self.source)

    # ---- validation -----------------------------------------------------------------
    def validate(self):
        """Check probabilities (each chance node sums to 1), node types and parameter references."""
        def walk(node):
            if node.type == "chance":
                total = 0.0
                for b in node.branches:
                    p = _evaluate(b.probability, self.parameters, f"{b.child.path}: probability")
                    if p < -PROBABILITY_TOLERANCE or p > 1 + PROBABILITY_TOLERANCE:
                        raise TreeError(f"{b.child.path}: probability {p:g} is outside [0, 1]")
                    total += p
                if abs(total - 1.0) > PROBABILITY_TOLERANCE:
                    raise TreeError(f"{node.path}: probabilities sum to {total:.10g}, not 1")
            if node.type == "terminal":
                _evaluate(node.value, self.parameters, f"{node.path}: value")
            for b in node.branches:
                _evaluate(b.cost, self.parameters, f"{b.child.path}: cost")
                _evaluate(b.payoff, self.parameters, f"{b.child.path}: payoff")
                walk(b.child)
        walk(self.root)

    # ---- rollback -------------------------------------------------------------------
    def _whole_tree_name(self) -> str:
        """The one course of a tree whose root is not a decision (its name, else "the tree")."""
        return self.root.name or "the tree"

    def _probability(self, branch) -> float:
        """The probability of a chance branch, its expression evaluated with the tree's parameters [-]."""
        return _evaluate(branch.probability, self.parameters, branch.name)

    def _net(self, branch) -> float:
        cost = _evaluate(branch.cost, self.parameters, branch.name)
        payoff = _evaluate(branch.payoff, self.parameters, branch.name)
        return cost - payoff if self.objective == "min" else payoff - cost

    def rollback(self, *, risk_tolerance: float | None = None, fixed: dict | None = None) -> Rollback:
        """Expected value (or certainty equivalent) of every option and the optimal policy.

        ``risk_tolerance`` R switches to exponential utility (certainty equivalents).
        ``fixed`` maps a chance ``variable`` to the outcome known to occur (used for
        the value of perfect information).

        Parameters
        ----------
        risk_tolerance : float, optional
            Risk tolerance R of the exponential utility u(x) = 1 - exp(-x/R), in the tree's currency (e.g.
            [CHF]); expected values when None.
        fixed : dict, optional
            Chance variable -> outcome known to occur.

        Returns
        -------
        Rollback
            Value of the tree, of every option of the top decision and of every node (net cost for ``"min"``, net payoff
            for ``"max"``, in the tree's currency), and the optimal policy.

        References
        ----------
        Clemen, R. T. and Reilly, T. (2001). Making Hard Decisions with DecisionTools. Duxbury, ch. 4.
        """
        policy = {}
        node_values = {}
        better = min if self.objective == "min" else max
        sign = 1.0 if self.objective == "max" else -1.0     # values are payoffs for max, costs for min

        def value(node):
            v = _value(node)
            node_values[node.path] = v
            return v

        def _value(node):
            if node.type == "terminal":
                return _evaluate(node.value, self.parameters, f"{node.path}: value")
            vals = [self._net(b) + value(b.child) for b in node.branches]
            if node.type == "decision":
                best = better(range(len(vals)), key=lambda i: vals[i])
                policy[node.path] = node.branches[best].name
                return vals[best]
            probs = np.array([_evaluate(b.probability, self.parameters, b.name) for b in node.branches])
            if fixed and node.variable in fixed:
                names = [b.name for b in node.branches]
                if fixed[node.variable] not in names:
                    raise TreeError(f"{node.path}: outcome {fixed[node.variable]!r} of {node.variable!r} is not one "
                                    f"of {names}")
                probs = np.array([1.0 if n == fixed[node.variable] else 0.0 for n in names])
            vals = np.array(vals)
            if risk_tolerance is None:
                return float(np.dot(probs, vals))
            R = float(risk_tolerance)
            if R <= 0:
                raise TreeError(f"risk_tolerance must be > 0; got {risk_tolerance!r}")
            # CE of u(x) = 1 - exp(-x/R) on payoffs x = sign * value; shifted for numerical safety.
            x = sign * vals
            shift = x.min()
            ce = shift - R * np.log(np.dot(probs, np.exp(-(x - shift) / R)))
            return float(sign * ce)

        if self.root.type != "decision":
            return Rollback(value(self.root), {}, policy, self.objective, node_values)
        options = {b.name: self._net(b) + value(b.child) for b in self.root.branches}
        best = better(options, key=options.get)
        policy[self.root.path] = best
        node_values[self.root.path] = options[best]
        return Rollback(options[best], options, policy, self.objective, node_values)

    def ranking(self, **kwargs) -> pd.DataFrame:
        """Options of the top decision, best first, with their expected value and rank.

        Parameters
        ----------
        **kwargs
            Passed to :meth:`rollback` (``risk_tolerance``, ``fixed``).

        Returns
        -------
        pandas.DataFrame
            Columns ``option``, ``expected_value`` (in the tree's currency), ``difference_from_best`` and ``rank``, best
            first.
        """
        rb = self.rollback(**kwargs)
        values = dict(rb.option_values) or {self._whole_tree_name(): rb.value}   # no decision: the tree is one course
        df = pd.DataFrame({"option": list(values), "expected_value": list(values.values())})
        df = df.sort_values("expected_value", ascending=self.objective == "min").reset_index(drop=True)
        best = df["expected_value"].iloc[0]
        df["difference_from_best"] = (df["expected_value"] - best).abs()
        df["rank"] = np.arange(1, len(df) + 1)
        return df

    def summary(self) -> pd.DataFrame:
        """The options of the top decision ranked by expected value (:meth:`ranking` at the tree's parameters).

        Returns
        -------
        pandas.DataFrame
            Columns ``option``, ``expected_value`` (net cost for ``objective="min"``, net payoff for ``"max"``,
            in the tree's currency), ``difference_from_best`` and ``rank``, best first.
        """
        return self.ranking()

    def __repr__(self) -> str:
        n = 0
        stack = [self.root]
        while stack:
            node = stack.pop()
            n += 1
            stack.extend(b.child for b in node.branches if b.child is not None)
        return short_repr(self, repr(self.root.name), f"{n} nodes", objective=self.objective,
                          source=self.source if self.source != "<dict>" else None)

    def plot(self, ax=None, **kwargs):
        """The tree: squares decide, circles are chance, triangles end; the optimal path in red (drawn by :func:`riskrf.risk.figures.plot_tree`).

        Parameters
        ----------
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (a new figure when None).
        **kwargs
            Passed to the drawing function.

        Returns
        -------
        matplotlib.axes.Axes
        """
        from .figures import plot_tree
        return plot_tree(self, ax=ax, **kwargs)

    # ---- risk profiles ------------------------------------------------------------------
    def risk_profile(self, option: str | None = None) -> pd.DataFrame:
        """Distribution of outcomes (net value) of an option under the optimal later policy.

        Columns: option, outcome value, probability, cumulative probability.

        Parameters
        ----------
        option : str, optional
            One option of the top decision; all options when None.

        Returns
        -------
        pandas.DataFrame
            Columns ``option``, ``value`` (net outcome, in the tree's currency), ``probability`` [-] and ``cumulative``
            [-].

        Raises
        ------
        TreeError
            When ``option`` is not an option of the top decision.
        """
        rb = self.rollback()
        names = [b.name for b in self.root.branches] if self.root.type == "decision" else [self._whole_tree_name()]
        if option is not None and option not in names:
            raise TreeError(f"{self.source}: no option {option!r}; options are {names}")
        rows = []
        if self.root.type != "decision":          # a tree without a first decision: the tree is the one course
            rows = [{"option": self._whole_tree_name(), "value": val, "probability": p}
                    for val, p in self._outcomes(self.root, 0.0, 1.0, rb.policy)]
        for b in (self.root.branches if self.root.type == "decision" else []):
            if option is not None and b.name != option:
                continue
            for val, p in self._outcomes(b.child, self._net(b), 1.0, rb.policy):
                rows.append({"option": b.name, "value": val, "probability": p})
        df = pd.DataFrame(rows, columns=["option", "value", "probability"])
        df = df.groupby(["option", "value"], as_index=False)["probability"].sum()
        df["cumulative"] = df.groupby("option")["probability"].cumsum()
        return df

    def _outcomes(self, node, acc, prob, policy):
        if node.type == "terminal":
            yield acc + _evaluate(node.value, self.parameters, node.path), prob
            return
        if node.type == "decision":
            chosen = next(b for b in node.branches if b.name == policy[node.path])
            yield from self._outcomes(chosen.child, acc + self._net(chosen), prob, policy)
            return
        for b in node.branches:
            p = _evaluate(b.probability, self.parameters, b.name)
            if p > 0:
                yield from self._outcomes(b.child, acc + self._net(b), prob * p, policy)

    # ---- sensitivity ----------------------------------------------------------------------
    def sensitivity(self, parameter: str, values) -> pd.DataFrame:
        """One-way sensitivity: the value of every option as ``parameter`` takes each of ``values``.

        Parameters
        ----------
        parameter : str
            Name of a tree parameter.
        values : array_like
            Values it takes (its units: probability [-] or the tree's currency).

        Returns
        -------
        pandas.DataFrame
            One row per value: the parameter, the value of every option (in the tree's currency) and ``best``.

        Raises
        ------
        TreeError
            When a value makes the tree invalid (names the parameter and value).
        """
        rows = []
        for v in np.asarray(values, dtype=float):
            t = self.with_parameters(**{parameter: float(v)})
            try:
                rb = t.rollback()
            except TreeError as exc:
                raise TreeError(f"{parameter} = {v:g}: {exc}") from exc
            rows.append({parameter: v, **rb.option_values, "best": t.ranking()["option"].iloc[0]})
        return pd.DataFrame(rows)

    def break_even(self, parameter: str, low: float, high: float, *, option_a=None, option_b=None, tol=1e-10):
        """Value of ``parameter`` in [low, high] at which options a and b (default: best and second) tie.

        Returns None when they do not cross in the range.

        Parameters
        ----------
        parameter : str
            Name of a tree parameter.
        low, high : float
            The search range of the parameter (its units).
        option_a, option_b : str, optional
            The two options compared; the best and second best at the tree's parameters by default.
        tol : float, optional
            Relative tolerance of the root [-].

        Returns
        -------
        float or None
            The break-even value of ``parameter`` (its units), or None when the options do not cross in the range.
        """
        rank = self.ranking()
        a = option_a or rank["option"].iloc[0]
        b = option_b or rank["option"].iloc[1]

        def diff(v):
            ov = self.with_parameters(**{parameter: v}).rollback().option_values
            return ov[a] - ov[b]
        fa, fb = diff(low), diff(high)
        if fa == 0:
            return float(low)
        if np.sign(fa) == np.sign(fb):
            return None
        from scipy.optimize import brentq
        return float(brentq(diff, low, high, xtol=tol * max(1.0, abs(low), abs(high))))

    def tornado(self, ranges: dict | None = None, *, swing: float = 0.2) -> pd.DataFrame:
        """Swing of the optimal value as each parameter moves over its range (default +-``swing``).

        Sorted by swing, widest first (the bars of a tornado chart).

        Parameters
        ----------
        ranges : dict, optional
            Parameter name -> (low, high) (the parameter's units); others vary by +-``swing``.
        swing : float, optional
            Relative change of a parameter without a range [-].

        Returns
        -------
        pandas.DataFrame
            Columns ``parameter``, ``low``, ``high``, ``value_at_low``, ``value_at_high``, ``swing`` and ``base``
            (values in the tree's currency), widest swing first.
        """
        base = self.rollback().value
        rows = []
        for name, v in self.parameters.items():
            lo, hi = (ranges or {}).get(name, (v * (1 - swing), v * (1 + swing)))
            try:
                vlo = self.with_parameters(**{name: lo}).rollback().value
                vhi = self.with_parameters(**{name: hi}).rollback().value
            except TreeError:
                continue      # a range that breaks the tree (probabilities) is skipped
            rows.append({"parameter": name, "low": lo, "high": hi, "value_at_low": vlo, "value_at_high": vhi,
                         "swing": abs(vhi - vlo), "base": base})
        return pd.DataFrame(rows).sort_values("swing", ascending=False).reset_index(drop=True)

    # ---- value of information ------------------------------------------------------------
    def variables(self) -> dict:
        """Chance variables: name -> {outcome: probability} (from their first occurrence).

        Returns
        -------
        dict
            Variable name -> {outcome name: probability [-]}.
        """
        out = {}

        def walk(node):
            if node.type == "chance" and node.variable and node.variable not in out:
                out[node.variable] = {b.name: _evaluate(b.probability, self.parameters, b.name)
                                      for b in node.branches}
            for b in node.branches:
                walk(b.child)
        walk(self.root)
        return out

    def evpi(self, variable: str) -> float:
        """Expected value of perfect information about a chance ``variable``.

        The decision maker learns the outcome before the first decision: the
        expectation over outcomes of the best value given each outcome, compared
        with the best value now.  Non-negative by construction.

        Parameters
        ----------
        variable : str
            A chance variable of the tree.

        Returns
        -------
        float
            EVPI, in the tree's currency, >= 0.

        Raises
        ------
        TreeError
            When no chance node has that variable.

        References
        ----------
        Clemen, R. T. and Reilly, T. (2001). Making Hard Decisions with DecisionTools. Duxbury, ch. 4.
        """
        variables = self.variables()
        if variable not in variables:
            raise TreeError(f"{self.source}: no chance node with variable {variable!r}; variables are "
                            f"{sorted(variables)}")
        now = self.rollback().value
        informed = sum(p * self.rollback(fixed={variable: outcome}).value
                       for outcome, p in variables[variable].items())
        return float(now - informed if self.objective == "min" else informed - now)

    def evsi(self, with_information: str, without_information: str) -> float:
        """Expected value of sample information: value of the option that gathers information (a survey,
        monitoring) before its cost, minus the value of deciding without it.

        Parameters
        ----------
        with_information : str
            The option of the top decision that gathers the information.
        without_information : str
            The option of deciding without it.

        Returns
        -------
        float
            EVSI, in the tree's currency.

        Raises
        ------
        TreeError
            When either name is not an option of the top decision.

        References
        ----------
        Clemen, R. T. and Reilly, T. (2001). Making Hard Decisions with DecisionTools. Duxbury, ch. 4.
        """
        rb = self.rollback()
        branches = {b.name: b for b in self.root.branches}
        for name in (with_information, without_information):
            if name not in branches:
                raise TreeError(f"{self.source}: no option {name!r}; options are {list(branches)}")
        v_with = rb.option_values[with_information] - self._net(branches[with_information])
        v_without = rb.option_values[without_information]
        return float(v_without - v_with if self.objective == "min" else v_with - v_without)

    def enumerate_policies(self):
        """Every combination of choices at every decision node (for checks): yields (policy, value)."""
        decisions = []

        def walk(node):
            if node.type == "decision":
                decisions.append(node)
            for b in node.branches:
                walk(b.child)
        walk(self.root)
        from itertools import product
        for combo in product(*[[b.name for b in d.branches] for d in decisions]):
            policy = {d.path: c for d, c in zip(decisions, combo)}
            root_choice = policy.get(self.root.path)
            chosen = next((b for b in self.root.branches if b.name == root_choice), None) \
                if self.root.type == "decision" else None
            if chosen is None:
                continue
            total = sum(p * v for v, p in self._outcomes(chosen.child, self._net(chosen), 1.0, policy))
            yield policy, total


def _build(spec, defs, source, stack, path) -> Node:
    if not isinstance(spec, dict):
        raise TreeError(f"{path}: a node must be a table/object; got {spec!r}")
    if "ref" in spec:
        ref = spec["ref"]
        if ref in stack:
            raise TreeError(f"{path}: reference cycle through {' -> '.join(stack + (ref,))}")
        if ref not in defs:
            raise TreeError(f"{path}: reference to undefined node {ref!r}; defined: {sorted(defs)}")
        return _build(defs[ref], defs, source, stack + (ref,), path)
    kind = spec.get("type", "terminal" if "branches" not in spec else None)
    if kind not in ("decision", "chance", "terminal"):
        raise TreeError(f"{path}: node type {kind!r} is not 'decision', 'chance' or 'terminal'")
    node = Node(type=kind, name=str(spec.get("name", "")), variable=spec.get("variable"), path=path,
                value=spec.get("value", 0.0))
    if kind == "terminal":
        return node
    branches = spec.get("branches")
    if not isinstance(branches, list) or not branches:
        raise TreeError(f"{path}: a {kind} node needs a non-empty list of branches")
    seen = set()
    for i, b in enumerate(branches):
        if not isinstance(b, dict) or "name" not in b:
            raise TreeError(f"{path}: branch {i} needs a name")
        name = str(b["name"])
        if name in seen:
            raise TreeError(f"{path}: duplicate branch name {name!r}")
        seen.add(name)
        allowed = {"name", "cost", "payoff", "probability", "child"}
        unknown = set(b) - allowed
        if unknown:
            raise TreeError(f"{path} > {name}: unknown field(s) {sorted(unknown)}; allowed {sorted(allowed)}")
        if kind == "chance" and "probability" not in b:
            raise TreeError(f"{path} > {name}: missing field 'probability' (branch of a chance node)")
        if kind == "decision" and "probability" in b:
            raise TreeError(f"{path} > {name}: a decision branch cannot have a probability")
        child_spec = b.get("child", {"type": "terminal"})
        child = _build(child_spec, defs, source, stack, f"{path} > {name}")
        node.branches.append(Branch(name=name, child=child, cost=b.get("cost", 0.0), payoff=b.get("payoff", 0.0),
                                    probability=b.get("probability")))
    return node
