"""One typed declaration of the input files: site, mitigation options, corridor and slope scenario.

Each table of a file is a :class:`Table` of :class:`Field` declarations: type, unit, allowed range, default
and meaning.  :func:`check` holds a parsed TOML document against a :class:`FileSchema` before any work and
raises one message naming the file, the table, the field and the value (``site.toml: traffic.vehicles_per_day
= 0 must be a number > 0 vehicles/day``); :func:`render_markdown` writes the same declarations as the
file-format reference (``docs/reference/file-formats-generated.md``); :func:`record_class` makes of the same
declarations the typed record a checked table is read into (:meth:`Table.record`: a frozen dataclass, one attribute
per declared field in declaration order, with the declared default), so that a field's name, type, unit and default
have one home and the code reads ``site.hazard.n_blocks``, never ``site.hazard["n_blocks"]``.

The hand-written readers (:func:`riskrf.app.site.load_site`, :func:`riskrf.risk.mitigation_inputs.parse_mitigation`,
:func:`riskrf.app.corridor.load_corridor`, :func:`simulation.load_scenario`) keep what a flat declaration cannot
say (unknown fields with a did-you-mean, one field depending on another, files that must exist, option
geometry inside the profile); they run after :func:`check`, so every type and range here is enforced first.

Plain frozen dataclasses rather than pydantic: the checks are ranges of scalars and lists in a handful of
tables, the messages must keep the ``file: table.field = value`` form users and tests rely on (pydantic's
error format would have to be rewritten field by field), and the package gains no dependency.
"""
from __future__ import annotations

import copy
import dataclasses
import datetime as _dt
import functools
import keyword
import math
import re
from dataclasses import dataclass

#: A field without a default must be given.
REQUIRED = object()


@dataclass(frozen=True)
class Field:
    """One field of a table.

    ``kind``: ``"number"``, ``"integer"`` (a whole number), ``"text"``, ``"path"`` (a file relative to the
    file that names it), ``"bool"``, ``"date"``, ``"numbers"`` (a list of numbers), ``"range"`` (``[low,
    high]``), ``"number|numbers"``, ``"any"`` (checked by its reader).  ``low``/``high`` bound numbers
    (``low_open``/``high_open``: strict), ``choices`` lists allowed values, ``unit`` is written in messages
    and docs, ``default`` is :data:`REQUIRED`, ``None`` (optional, no value) or the value used when left out.
    """
    name: str
    kind: str
    unit: str = ""
    doc: str = ""
    default: object = None
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple = ()

    def need(self) -> str:
        """What a valid value is, in words (the end of an error message).

        Returns
        -------
        str
            E.g. ``"must be a number > 0 kg/m3"`` or ``"must be one of 'fence', 'ditch'"`` (with the field's unit).
        """
        if self.choices:
            return "must be one of " + ", ".join(repr(c) for c in self.choices)
        what = {"integer": "a whole number", "number": "a number", "numbers": "a list of numbers",
                "range": "[low, high] with low <= high", "number|numbers": "a number or a list of numbers",
                "text": "text", "path": "a file name (relative to this file)", "bool": "true or false",
                "date": "a date YYYY-MM-DD"}.get(self.kind, "a value")
        bounds = []
        if self.low is not None:
            bounds.append(f"> {self.low:g}" if self.low_open else f">= {self.low:g}")
        if self.high is not None:
            bounds.append(f"< {self.high:g}" if self.high_open else f"<= {self.high:g}")
        text = f"must be {what}" + (" " + " and ".join(bounds) if bounds else "")
        return text + (f" {self.unit}" if self.unit and self.kind in ("number", "integer", "numbers", "range",
                                                                       "number|numbers") else "")

    def problem(self, value) -> str | None:
        """``None`` when ``value`` is valid, else :meth:`need`.

        Parameters
        ----------
        value : object
            The value read from the file (None when the field is absent), in the field's ``unit``.

        Returns
        -------
        str or None
            None when valid; else what a valid value is.
        """
        if value is None:
            return None if self.default is not REQUIRED else self.need()
        if self.choices:
            return None if value in self.choices else self.need()
        k = self.kind
        if k in ("number", "integer"):
            return None if self._scalar_ok(value, whole=k == "integer") else self.need()
        if k == "numbers":
            ok = isinstance(value, list) and len(value) > 0 and all(self._scalar_ok(v) for v in value)
            return None if ok else self.need()
        if k == "number|numbers":
            ok = self._scalar_ok(value) or (isinstance(value, list) and len(value) > 0
                                            and all(self._scalar_ok(v) for v in value))
            return None if ok else self.need()
        if k == "range":
            ok = (isinstance(value, list) and len(value) == 2 and all(self._scalar_ok(v) for v in value)
                  and value[0] <= value[1])
            return None if ok else self.need()
        if k in ("text", "path"):
            return None if isinstance(value, str) and (k == "text" or value.strip()) else self.need()
        if k == "bool":
            return None if isinstance(value, bool) else self.need()
        if k == "date":
            if isinstance(value, (_dt.date, _dt.datetime)):
                return None
            try:
                _dt.date.fromisoformat(str(value))
                return None
            except ValueError:
                return self.need()
        return None

    def _scalar_ok(self, v, whole: bool = False) -> bool:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            return False
        if whole and not (isinstance(v, int) or float(v).is_integer()):
            return False
        if self.low is not None and not (v > self.low if self.low_open else v >= self.low):
            return False
        if self.high is not None and not (v < self.high if self.high_open else v <= self.high):
            return False
        return True


@dataclass(frozen=True)
class Table:
    """One TOML table (``[name]``), or an array of tables (``[[name]]``, ``array=True``) whose entries are
    named by their ``name`` field in messages; ``record_name`` names its record class when the default
    (:func:`record_class`) would be the name of another file's table of the same name."""
    name: str
    fields: tuple
    doc: str = ""
    array: bool = False
    record_name: str | None = None

    def field(self, name: str) -> Field | None:
        """The declaration of ``name`` (None when the table has no such field).

        Parameters
        ----------
        name : str
            Field name as written in the file.

        Returns
        -------
        Field or None
        """
        return next((f for f in self.fields if f.name == name), None)

    def defaults(self) -> dict:
        """``{field: default}`` of every field (``None`` for optional fields without a default).

        Returns
        -------
        dict
            Field name → default value (in the field's unit), required fields mapped to None.
        """
        return {f.name: (None if f.default is REQUIRED else f.default) for f in self.fields}

    @functools.cached_property
    def record_type(self) -> type:
        """The typed record of this table (:func:`record_class`), built once per table.

        Returns
        -------
        type
            A frozen, slotted dataclass with one attribute per declared field, in declaration order.
        """
        return record_class(self, name=self.record_name)

    def record(self, values: dict):
        """A checked table (``{field: value}``, e.g. the merged table of a reader) as its typed record.

        Parameters
        ----------
        values : dict
            Field name -> value (in the field's unit); fields left out take the declared default (None for
            required or optional fields without one).

        Returns
        -------
        object
            An instance of :attr:`record_type`.

        Raises
        ------
        TypeError
            For a key the table does not declare (the readers refuse unknown fields with a did-you-mean first).
        """
        return self.record_type(**values)


@dataclass(frozen=True)
class FileSchema:
    """The tables of one input file."""
    name: str
    tables: tuple
    doc: str = ""

    def table(self, name: str) -> Table | None:
        """The declaration of table ``name`` (dotted for sub-tables, e.g. ``"materials.*"``).

        Parameters
        ----------
        name : str
            Dotted table name (``*`` for any key).

        Returns
        -------
        Table or None
        """
        return next((t for t in self.tables if t.name == name), None)


def problems(data: dict, schema: FileSchema, source) -> list[str]:
    """Every field of ``data`` that breaks its declaration in ``schema``, as ``"source: table.field = value must
    be ..."`` messages, in the order of the declarations.  Tables and fields that ``schema`` does not declare
    are left to the file's own reader (it names unknown fields with a did-you-mean).

    Parameters
    ----------
    data : dict
        The file as read (e.g. by :mod:`tomllib`).
    schema : FileSchema
        The declarations to hold it against.
    source : str or path
        The file's name, for the messages.

    Returns
    -------
    list of str
        One message per invalid or missing required field; empty when all are valid.
    """
    out = []
    if not isinstance(data, dict):
        return out
    for table in schema.tables:
        parts = table.name.split(".")
        found = _lookup(data, parts)
        for where, entries in found:
            if table.array:
                if not isinstance(entries, list):
                    continue
                items = [(f"{where}[{i}]" + (f" ({e.get('name')!r})" if isinstance(e, dict) and e.get("name")
                                              else ""), e) for i, e in enumerate(entries)]
            else:
                items = [(where, entries)]
            for label, entry in items:
                if not isinstance(entry, dict):
                    continue
                for f in table.fields:
                    value = entry.get(f.name)
                    if f.name not in entry and f.default is not REQUIRED:
                        continue
                    why = f.problem(value)
                    if why:
                        shown = "missing" if f.name not in entry else f"= {value!r}"
                        out.append(f"{source}: {label}.{f.name} {shown} {why}"
                                   + (f" ({f.doc})" if f.doc else ""))
    return out


def _lookup(data: dict, parts: list) -> list:
    """(dotted name, value) of every table matching ``parts`` (``*`` matches any key)."""
    level = [("", data)]
    for p in parts:
        nxt = []
        for where, d in level:
            if not isinstance(d, dict):
                continue
            keys = list(d) if p == "*" else ([p] if p in d else [])
            for k in keys:
                nxt.append((f"{where}.{k}" if where else k, d[k]))
        level = nxt
    return level


def check(data: dict, schema: FileSchema, source, *, error=ValueError) -> None:
    """Raise ``error`` with the first problem :func:`problems` finds (file, table, field, value, what is
    allowed); return quietly when every declared field is valid.

    Parameters
    ----------
    data : dict
        The file as read.
    schema : FileSchema
        The declarations to hold it against.
    source : str or path
        The file's name, for the message.
    error : type
        Exception class raised (default :class:`ValueError`; readers pass their :class:`~riskrf.RiskrfError`
        subclass).

    Raises
    ------
    error
        With the first problem found.
    """
    found = problems(data, schema, source)
    if found:
        raise error(found[0])


#: Python type of each field kind, the annotation of the record's attribute (not enforced: :func:`check` is).
KIND_TYPES = {"number": float, "integer": int, "text": str, "path": str, "bool": bool, "date": object,
              "numbers": list, "range": list, "number|numbers": object, "any": object}


def _record_as_dict(self) -> dict:
    """``{field: value}`` of every attribute, in declaration order (shallow: lists are not copied); for the
    readers that take a table as a dict (e.g. :func:`riskrf.hazard.design_basis.design_basis_from_site`).

    Returns
    -------
    dict
        Field name -> value.
    """
    return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}


def record_class(table: Table, *, name: str | None = None, extra=()) -> type:
    """A frozen, slotted dataclass generated from ``table``'s declarations: one attribute per :class:`Field`, in
    declaration order, annotated with the field kind's Python type (:data:`KIND_TYPES`) and defaulting to the
    declared default (None for required fields and optional fields without one; a list default is copied for
    each record).  An attribute the table does not declare raises :class:`AttributeError`; the record cannot be
    changed (:func:`dataclasses.replace` makes a changed copy).  ``as_dict()`` gives the fields as a dict.

    Parameters
    ----------
    table : Table
        The declarations.
    name : str, optional
        Class name (default: the table's name in CamelCase + ``"Table"``, e.g. ``DesignBlockTable``).
    extra : sequence of (name, type, default), optional
        Attributes a reader adds after its checks that are not fields of the file (e.g. a file it read), after the
        declared ones.

    Returns
    -------
    type
        The record class.
    """
    if name is None:
        name = "".join(p.capitalize() for p in re.split(r"[^0-9A-Za-z]+", table.name) if p) + "Table"
    spec = []
    for f in table.fields:
        if not f.name.isidentifier() or keyword.iskeyword(f.name):
            raise ValueError(f"table {table.name!r}: field {f.name!r} is not a Python name; it cannot be a record "
                             "attribute")
        default = None if f.default is REQUIRED else f.default
        if isinstance(default, (list, dict, set)):
            value = dataclasses.field(default_factory=functools.partial(copy.deepcopy, default))
        else:
            value = dataclasses.field(default=default)
        spec.append((f.name, KIND_TYPES.get(f.kind, object), value))
    for attr, kind, default in extra:
        spec.append((attr, kind, dataclasses.field(default=default)))
    doc = (f"The checked [{table.name}] table as a typed record, generated from its declaration "
           f"(:func:`riskrf.core.schema.record_class`). {table.doc}").strip()
    cls = dataclasses.make_dataclass(name, spec, frozen=True, slots=True, namespace={"as_dict": _record_as_dict,
                                                                                   "__doc__": doc})
    cls.__module__ = __name__
    return cls


def as_record(table: Table, value, *, source="", error=ValueError):
    """``value`` as the typed record of ``table`` (:attr:`Table.record_type`): the boundary of a reader that takes
    the record a site gives it and also accepts the table as a user writes it (a dict of its fields, or None).

    Parameters
    ----------
    table : Table
        The declarations of the table.
    value : record, dict or None
        A record of ``table`` (returned as it is), a dict of some of its fields (the others take their declared
        defaults) or None (every default).
    source : str or path, optional
        The file the table comes from, named in errors.
    error : type
        Exception class raised (default :class:`ValueError`).

    Returns
    -------
    object
        An instance of :attr:`Table.record_type`.

    Raises
    ------
    error
        For a dict key the table does not declare (``"source: unknown field table.key; allowed: ..."``), or a value
        that is neither a record, a dict nor None.
    """
    where = f"{source}: " if source else ""
    if value is None:
        return table.record({})
    if isinstance(value, table.record_type):
        return value
    if not isinstance(value, dict):
        raise error(f"{where}[{table.name}] = {value!r} must be a table ({table.name}.FIELD = value)")
    names = [f.name for f in table.fields]
    unknown = sorted(set(value) - set(names))
    if unknown:
        raise error(f"{where}unknown field {table.name}.{unknown[0]}; allowed: {', '.join(sorted(names))}")
    return table.record(value)


def _cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def render_markdown(schemas) -> str:
    """The file-format reference: one section per file, one table per TOML table (field, type, unit, allowed
    values, default, meaning), generated from the declarations so that the documentation cannot drift.

    Parameters
    ----------
    schemas : iterable of FileSchema
        The files to document, in order.

    Returns
    -------
    str
        Markdown text.
    """
    lines = ["# Input file formats (generated)", "",
             "Generated from the declarations in `riskrf/core/file_schemas.py` by",
             "`riskrf.core.file_schemas.write_reference()`; do not edit by hand.  Every field below is checked",
             "before any work starts; an error names the file, the table, the field and the value.  Paths are relative to the file that names them.", ""]
    for s in schemas:
        lines += [f"## {s.name}", "", s.doc, ""]
        for t in s.tables:
            head = f"[[{t.name}]]" if t.array else f"[{t.name}]"
            lines += [f"### `{head}`", ""] + ([t.doc, ""] if t.doc else [])
            lines += ["| field | type | unit | allowed | default | meaning |", "|---|---|---|---|---|---|"]
            for f in t.fields:
                allowed = f.need().removeprefix("must be ")
                default = "required" if f.default is REQUIRED else ("" if f.default is None else repr(f.default))
                lines.append(f"| `{f.name}` | {f.kind} | {_cell(f.unit)} | {_cell(allowed)} | {_cell(default)} | "
                             f"{_cell(f.doc)} |")
            lines.append("")
    return "\n".join(lines).rstrip() + "\n"


__all__ = ["KIND_TYPES", "REQUIRED", "Field", "FileSchema", "Table", "as_record", "check", "problems",
           "record_class", "render_markdown"]
