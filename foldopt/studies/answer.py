"""The answer: one object per result that every view renders and nothing else.

An :class:`Answer` holds what a user asked and what the result says, in the objective's own terms: the question
(site, period, load, objective), what was taken from the study rather than asked for, the result (the best fold
angle and its t_solar; for an annual objective its value per design and, for ``worst-month``, the month; for a
re-fold schedule each visit's date and fold angle and what it adds), the designs compared, the near-optimal
range of the fold angle with the recommended angle at its centre, and notes that name the design they concern.
The terminal's lines (:meth:`Answer.lines`), ``--format json`` (:meth:`Answer.to_dict`), ``report.html`` and
``result.answer`` in a notebook all show this one object; :mod:`foldopt.studies.result_answers` makes it
of each kind of result.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

from foldopt.columnar import Columns, as_frame


def plain(value):
    """JSON-ready: None for NaN, Python numbers for numpy's, text for dates.

    Parameters
    ----------
    value : object
        A number, a date, text, or a dict, list or tuple of them (nested).

    Returns
    -------
    object
        ``value`` with dict keys as text, tuples as lists, dates in ISO format, numpy scalars as
        Python's, and NaN and infinities as None.
    """
    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if hasattr(value, "isoformat"):
        return value.isoformat()
    if hasattr(value, "item"):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def records(table) -> list[dict]:
    """A table's rows as JSON-ready records (NaN as null, numbers exact); none for None.

    Parameters
    ----------
    table : pandas.DataFrame, foldopt.columnar.Columns or None

    Returns
    -------
    list of dict
        One :func:`plain` dict per row, column to value.
    """
    if isinstance(table, Columns):
        names = table.columns
        return [plain(dict(zip(names, row))) for row in zip(*(table[n] for n in names))]
    return [] if table is None else [plain(row) for row in table.to_dict(orient="records")]


@dataclass(frozen=True)
class Answer:
    """What a result says, for every view.

    Attributes
    ----------
    kind : str
        ``study`` (one day), ``sweep`` (cases), ``annual`` (one fold angle over many days), ``size``, ``reproduce``
        or ``map``.
    title : str
    question : dict
        Label -> text: site, period, load, objective, panel, models...
    defaults : dict or None
        ``{"study": source, "taken": [...]}``: what was taken from the study, not asked for.
    result : dict
        The answer in the objective's own terms.
    design_rows : pandas.DataFrame or foldopt.columnar.Columns
        The designs compared (one row per design, or per case/load and design); ``designs`` is
        it as a DataFrame.
    near_optimal_rows : pandas.DataFrame or foldopt.columnar.Columns
        Per case and load: the near-optimal range of the fold angle and the recommended angle;
        ``near_optimal`` is it as a DataFrame.
    schedule_rows : pandas.DataFrame or foldopt.columnar.Columns
        Re-fold schedules: per load, number of settings and visit, the date and fold angle, with the schedule's
        objective and what its last setting adds; ``schedule`` is it as a DataFrame.
    notes : list of dict
        ``{"note": ..., "designs": [...], "cases": n}``: each note and the designs it concerns.
    summary : list of str
        The answer in words, first on every view.
    """

    kind: str
    title: str
    question: dict
    defaults: dict | None
    result: dict
    design_rows: object = field(default_factory=lambda: Columns({}))
    near_optimal_rows: object = field(default_factory=lambda: Columns({}))
    schedule_rows: object = field(default_factory=lambda: Columns({}))
    notes: list = field(default_factory=list)
    summary: tuple = ()

    # The tables as DataFrames on first use: the terminal's lines need none of them, and a day's
    # study holds its rows as Columns until then, so that its answer is printed before pandas loads.
    @functools.cached_property
    def designs(self):
        """pandas.DataFrame: the designs compared (``design_rows``)."""
        return as_frame(self.design_rows)

    @functools.cached_property
    def near_optimal(self):
        """pandas.DataFrame: the near-optimal fold angles (``near_optimal_rows``)."""
        return as_frame(self.near_optimal_rows)

    @functools.cached_property
    def schedule(self):
        """pandas.DataFrame: the re-fold schedules (``schedule_rows``)."""
        return as_frame(self.schedule_rows)

    def lines(self) -> list[str]:
        """The terminal's words: the summary, with the "from" line second."""
        lines = list(self.summary[:1])
        if self.defaults:
            lines.append(f"  from {self.defaults['study']}: {', '.join(self.defaults['taken'])}")
        lines += list(self.summary[1:])
        for note in self.notes:
            lines.append(f"note: {note_text(note)}")
        return lines

    def to_dict(self) -> dict:
        """The answer as JSON-ready data (NaN as null)."""
        return {
            "kind": self.kind,
            "title": self.title,
            "question": plain(self.question),
            "defaults": self.defaults,
            "result": plain(self.result),
            "designs": records(self.design_rows),
            "near_optimal": records(self.near_optimal_rows),
            "schedule": records(self.schedule_rows),
            "notes": plain(self.notes),
            "lines": self.lines(),
        }

    def tables(self) -> list[tuple[str, object]]:
        """The answer's tables with their titles, for a report."""
        return [
            (title, table)
            for title, table in (
                ("Designs compared", self.designs),
                (
                    "Near-optimal ranges"
                    if self.kind == "optimize"
                    else "Near-optimal fold angles",
                    self.near_optimal,
                ),
                ("Re-fold schedules", self.schedule),
            )
            if len(table)
        ]


def note_text(note: dict) -> str:
    """A note of :func:`~foldopt.studies.result_answers.design_notes` as text, ``load above peak (tracker:single-axis,
    tracker:single-axis-net)``; the designs are left out where a note concerns every design.

    Parameters
    ----------
    note : dict
    """
    designs = note.get("designs")
    where = f" ({', '.join(designs)})" if designs else ""
    cases = f" in {note['cases']} of {note['of']} cases" if note.get("cases") is not None else ""
    return f"{note['note']}{where}{cases}"
